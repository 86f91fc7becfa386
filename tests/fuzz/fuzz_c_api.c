/* fuzz_c_api.c: libFuzzer target driving the whole pyins C ABI from bytes.
 *
 * An input is a configuration (raw struct bytes: garbage doubles, NaN/Inf,
 * random schemes and steps; or one of a few valid presets with fuzzed field
 * patches) followed by up to MAX_OPS operations: pyins_step, pyins_run,
 * pyins_run_decimated, pyins_get_output, pyins_index_reset, pyins_snapshot /
 * pyins_restore (round trips, rollbacks to older snapshots, mutated valid
 * snapshots, blobs made of fuzzed bytes), re-init with another fuzzed
 * configuration, calls with bad arguments and calls on memory that holds no
 * instance. At most MAX_TICKS samples are stepped per input, so one input
 * runs in milliseconds.
 *
 * Only what docs/core.md and pyins_core.h promise is checked (abort on a
 * violation, so libFuzzer saves the input):
 *  - every status is PYINS_OK or a named status (pyins_status_str does not
 *    say "unknown"): negative errors, positive PYINS_W_* sample notices; a
 *    call with exactly one bad argument gets the status documented for it;
 *  - a refused call leaves the instance memory bit-identical: refused init
 *    ("mem is left as it was"), refused restore ("a refused blob leaves the
 *    memory as it was"), NULL / misaligned / not-initialised arguments,
 *    out_every = 0, a too-small decimation buffer ("nothing stepped");
 *  - a rejected sample (negative status) and a dropped duplicate
 *    (PYINS_W_SEQ_REPEAT) leave the state as it was but for the fault bits
 *    and counters (the output record, those masked, is bit-identical); a
 *    non-finite sample is always rejected;
 *  - the tick: +1 for a sample taken (OK, PYINS_W_ENCODER_JUMP), +2..101
 *    for a bridged gap, at least +1 after a lost sequence;
 *  - pyins_init's status equals pyins_config_check's;
 *  - N single steps and one N-sample pyins_run give bit-identical records
 *    and state, going on through notices and stopping at the first rejected
 *    sample (n_done says where); pyins_run_decimated writes the single steps'
 *    records whenever the tick reaches the next multiple of out_every, and
 *    stops with PYINS_E_BUFFER_TOO_SMALL only before a step that would need
 *    one record more than the capacity; pyins_run_nav does the same with
 *    compact records (the single steps' fields of the same names);
 *  - *out of pyins_step equals pyins_get_output afterwards; sticky fault bits
 *    never clear and fault counters never decrease between inits;
 *  - snapshot -> restore -> snapshot reproduces the blob; restoring a
 *    snapshot and stepping on equals never stopping (the clones above are
 *    made through snapshot/restore);
 *  - pyins_index_reset does nothing outside the indexing FAULT state, and
 *    leaves it (first step, A_c and A_s kept) inside it;
 *  - output fields documented as enumerations or ranges are in range
 *    (mode, kf_states, index_state, index_fault, quaternion w >= 0,
 *    heading in [0, 2 pi), IMU yaw in (-pi, pi] when finite).
 * Non-finite outputs after finite but absurd samples are not checked: the
 * docs do not promise otherwise.
 *
 * A restore that accepts a blob whose payload was not written by
 * pyins_snapshot (the fuzzer can satisfy the CRC-32) yields a state the docs
 * say nothing about: the input ends there. With PYINS_FUZZ_UNTRUSTED=1 in
 * the environment the target instead fixes the CRC of fuzzed payloads and
 * keeps stepping such states (robustness exploration, not a contract). */
#include "fuzz_c_api.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pyins_core.h"

#define MEM_MAX 20480u
#define SNAP_MAX (MEM_MAX + 256u)
#define MAX_TICKS 4096u
#define MAX_BATCH 256u
#define MAX_OPS 48

static const double kTwoPi = 6.283185307179586;
static const double kPi = 3.141592653589793;

/* ------------------------------------------------------------------------ */
/* Failure report: libFuzzer saves the input on abort().                     */

static void fail(int line, const char *what, long long a, long long b) {
    fprintf(stderr, "fuzz_c_api.c:%d: invariant violated: %s (%lld, %lld)\n", line, what, a, b);
    fflush(stderr);
    abort();
}
#define REQUIRE(cond, what) \
    do { if (!(cond)) fail(__LINE__, what, 0, 0); } while (0)
#define REQUIRE_EQ(got, want, what) \
    do { long long g_ = (long long)(got), w_ = (long long)(want); \
         if (g_ != w_) fail(__LINE__, what, g_, w_); } while (0)

/* ------------------------------------------------------------------------ */
/* Byte reader: past the end every read gives zeros.                         */

typedef struct {
    const uint8_t *p;
    size_t n;
} reader;

static uint8_t rd_u8(reader *r) {
    uint8_t v = 0;
    if (r->n > 0) {
        v = *r->p;
        r->p++;
        r->n--;
    }
    return v;
}
static uint16_t rd_u16(reader *r) {
    uint16_t lo = rd_u8(r);
    return (uint16_t)(lo | ((uint16_t)rd_u8(r) << 8));
}
static uint32_t rd_u32(reader *r) {
    uint32_t lo = rd_u16(r);
    return lo | ((uint32_t)rd_u16(r) << 16);
}
static double rd_f64_raw(reader *r) {
    uint64_t u = rd_u32(r);
    double d;
    u |= (uint64_t)rd_u32(r) << 32;
    memcpy(&d, &u, sizeof d);
    return d;
}
/* A double biased towards values that matter: specials, small scaled
 * integers over many decades, or raw bits. */
static double rd_f64_mix(reader *r) {
    const uint8_t k = rd_u8(r);
    switch (k & 15u) {
        case 0: return 0.0;
        case 1: return -0.0;
        case 2: return NAN;
        case 3: return INFINITY;
        case 4: return -INFINITY;
        case 5: return DBL_MAX;
        case 6: return DBL_MIN;
        case 7: return 4.9406564584124654e-324; /* smallest subnormal */
        case 8: return -1e300;
        case 14:
        case 15: return rd_f64_raw(r);
        default: {
            /* int16 times 10^e, e in [-12, 3] */
            const int16_t m = (int16_t)rd_u16(r);
            const int e = (int)(k >> 4) - 12;
            return (double)m * pow(10.0, (double)e);
        }
    }
}
static int32_t rd_i32_mix(reader *r) {
    const uint8_t k = rd_u8(r);
    switch (k & 7u) {
        case 0: return 0;
        case 1: return -1;
        case 2: return INT32_MAX;
        case 3: return INT32_MIN;
        case 4: return (int32_t)(k >> 3);          /* 0..31 */
        case 5: return (int32_t)(rd_u16(r) % 3000u);
        case 6: return (int32_t)(int8_t)rd_u8(r);
        default: return (int32_t)rd_u32(r);
    }
}

/* ------------------------------------------------------------------------ */
/* Byte writer for the built-in seeds.                                       */

typedef struct {
    uint8_t *p;
    size_t n, cap;
} writer;

static void wr_u8(writer *w, unsigned v) {
    if (w->n < w->cap) w->p[w->n] = (uint8_t)v;
    w->n++;
}
static void wr_u16(writer *w, unsigned v) {
    wr_u8(w, v & 0xFFu);
    wr_u8(w, (v >> 8) & 0xFFu);
}
static void wr_u32(writer *w, uint32_t v) {
    wr_u16(w, v & 0xFFFFu);
    wr_u16(w, v >> 16);
}
static void wr_bytes(writer *w, const void *src, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) wr_u8(w, ((const uint8_t *)src)[i]);
}

/* ------------------------------------------------------------------------ */
/* Configuration from bytes.                                                 */

enum { T_I32, T_F64 };
typedef struct {
    size_t off;
    int type;
} field;

#define FLD(name, t) {offsetof(pyins_config, name), t}
static const field kFields[] = {
    FLD(tick_hz, T_I32), FLD(vertical_mode, T_I32), FLD(lat_rad, T_F64), FLD(lon_rad, T_F64),
    FLD(height_m, T_F64), FLD(vel_n_mps, T_F64), FLD(euler_b_rad, T_F64), FLD(table_angle_rad, T_F64),
    FLD(coarse_ticks, T_I32), FLD(coarse_first_output_ticks, T_I32),
    FLD(coarse_output_every_ticks, T_I32), FLD(reserved0, T_I32), FLD(coarse_ratio, T_F64),
    FLD(fine_ticks, T_I32), FLD(fine_states, T_I32), FLD(fine_meas_every_ticks, T_I32),
    FLD(fine_correction, T_I32), FLD(fine_gyro_arw, T_F64), FLD(fine_accel_vrw, T_F64),
    FLD(fine_sigma0_att_rad, T_F64), FLD(fine_sigma0_gyro, T_F64), FLD(fine_sigma0_accel, T_F64),
    FLD(index_scheme, T_I32), FLD(index_stop_ticks, T_I32), FLD(index_timeout_ticks, T_I32),
    FLD(index_n_steps, T_I32), FLD(index_rate_rad_s, T_F64), FLD(index_accel_rad_s2, T_F64),
    FLD(index_delta, T_F64), FLD(index_max_flex_rad, T_F64), FLD(index_tolerance_rad, T_F64),
    FLD(index_jump_rad, T_F64), FLD(seq_mode, T_I32), FLD(seq_max_gap_ticks, T_I32),
    FLD(sat_gyro_rad, T_F64), FLD(sat_accel_mps, T_F64), FLD(index_sums, T_I32), FLD(reserved1, T_I32),
    FLD(lever_b_m, T_F64), FLD(lever_p_m, T_F64), FLD(coarse_method, T_I32), FLD(reserved2, T_I32),
    FLD(integrity_nis_window, T_I32), FLD(fine_noise, T_I32), FLD(integrity_nis_max, T_F64),
    FLD(integrity_coarse_rad, T_F64), FLD(fine_pos_sigma_m, T_F64), FLD(fine_sigma0_vel_mps, T_F64),
    FLD(fine_site_accel, T_F64),
};
#undef FLD
#define N_FIELDS ((int)(sizeof kFields / sizeof kFields[0]))
/* Array fields (vel, euler, sigma0_att: 3 doubles; index_steps: 8 x 3). */
#define N_PATCH_TARGETS (N_FIELDS + 6 + 24)

#define N_PRESETS 8

/* Valid, short configurations that reach every mode and indexing scheme
 * within the tick budget. */
static void preset(int k, pyins_config *c) {
    memset(c, 0, sizeof *c);
    c->lat_rad = 0.5977054556379782;
    c->lon_rad = 1.9008380883470242;
    switch (k % N_PRESETS) {
        case 0: /* zeroed: the defaults (navigate at once, no indexing) */
            break;
        case 1: /* coarse, fine (5 states), two-position scheme */
            c->coarse_ticks = 300;
            c->coarse_first_output_ticks = 200;
            c->coarse_output_every_ticks = 50;
            c->fine_ticks = 200;
            c->fine_states = 5;
            c->index_scheme = PYINS_INDEX_TWO_POSITION;
            c->index_stop_ticks = 40;
            break;
        case 2: /* fine 8 states open loop, flexible scheme */
            c->fine_ticks = 150;
            c->fine_states = 8;
            c->fine_correction = PYINS_FINE_OPEN_LOOP;
            c->fine_meas_every_ticks = 3;
            c->index_scheme = PYINS_INDEX_FLEXIBLE_TWO;
            c->index_stop_ticks = 30;
            c->index_max_flex_rad = 2.0;
            break;
        case 3: /* custom cycle, free vertical channel, 50 Hz, short coarse */
            c->tick_hz = 50;
            c->vertical_mode = PYINS_VERTICAL_FREE;
            c->coarse_ticks = 60;
            c->coarse_first_output_ticks = 30;
            c->coarse_output_every_ticks = 10;
            c->coarse_ratio = 0.4;
            c->index_scheme = PYINS_INDEX_CUSTOM;
            c->index_n_steps = 3;
            c->index_steps[0].stop_ticks = 20;
            c->index_steps[0].kind = PYINS_INDEX_FIXED;
            c->index_steps[0].angle_rad = 1.0;
            c->index_steps[1].stop_ticks = 30;
            c->index_steps[1].kind = PYINS_INDEX_FLEX_COS;
            c->index_steps[1].angle_rad = 1.0;
            c->index_steps[2].stop_ticks = 25;
            c->index_steps[2].kind = PYINS_INDEX_FLEX_SIN;
            c->index_steps[2].angle_rad = -1.0;
            c->index_rate_rad_s = 0.5;
            c->index_accel_rad_s2 = 2.0;
            c->index_delta = 0.2;
            c->index_tolerance_rad = 0.01;
            c->index_jump_rad = 0.2;
            c->index_timeout_ticks = 5;
            c->index_max_flex_rad = 3.0;
            c->seq_mode = PYINS_SEQ_CHECK;
            c->seq_max_gap_ticks = 4;
            break;
        case 4: /* single-position forward/reverse at 10 Hz, near the latitude limit, moving */
            c->tick_hz = 10;
            c->lat_rad = -1.5;
            c->vel_n_mps[0] = 5.0;
            c->vel_n_mps[1] = -3.0;
            c->euler_b_rad[2] = 2.5;
            c->table_angle_rad = 7.0;
            c->index_scheme = PYINS_INDEX_SINGLE_FWD_REV;
            c->index_stop_ticks = 10;
            c->index_timeout_ticks = 3;
            c->index_tolerance_rad = 0.05;
            break;
        case 5: /* the derived flexible scheme, turns summed, after a short fine alignment */
            c->fine_ticks = 50;
            c->fine_meas_every_ticks = 1;
            c->index_scheme = PYINS_INDEX_FLEXIBLE_DERIVED;
            c->index_sums = PYINS_INDEX_SUMS_ALL;
            c->index_stop_ticks = 20;
            c->index_delta = 0.5;
            break;
        case 7: /* a moored ship: lever arms, FIT coarse, the moving-base fine filter */
            c->lever_b_m[0] = 0.5;
            c->lever_b_m[1] = 1.5;
            c->lever_b_m[2] = 1.2;
            c->lever_p_m[0] = 0.05;
            c->coarse_ticks = 300;
            c->coarse_first_output_ticks = 200;
            c->coarse_output_every_ticks = 25;
            c->coarse_method = PYINS_COARSE_FIT;
            c->fine_ticks = 300;
            c->fine_states = 12;
            c->fine_meas_every_ticks = 20;
            c->integrity_nis_window = 3;
            c->index_scheme = PYINS_INDEX_TWO_POSITION;
            c->index_stop_ticks = 40;
            break;
        default: /* four-position, fast moves */
            c->index_scheme = PYINS_INDEX_FOUR_POSITION;
            c->index_stop_ticks = 5;
            c->seq_mode = PYINS_SEQ_CHECK;
            c->sat_gyro_rad = 0.01;
            c->sat_accel_mps = 0.5;
            c->index_rate_rad_s = 3.0;
            c->index_accel_rad_s2 = 50.0;
            c->index_jump_rad = 0.5;
            break;
    }
}

static void patch(reader *r, pyins_config *c) {
    const int t = (int)(rd_u8(r) % (unsigned)N_PATCH_TARGETS);
    unsigned char *base = (unsigned char *)c;
    size_t off;
    int type;
    if (t < N_FIELDS) {
        off = kFields[t].off;
        type = kFields[t].type;
    } else if (t < N_FIELDS + 6) {
        static const size_t arr[6] = {offsetof(pyins_config, vel_n_mps), offsetof(pyins_config, vel_n_mps),
                                      offsetof(pyins_config, euler_b_rad), offsetof(pyins_config, euler_b_rad),
                                      offsetof(pyins_config, fine_sigma0_att_rad),
                                      offsetof(pyins_config, fine_sigma0_att_rad)};
        off = arr[t - N_FIELDS] + sizeof(double) * (size_t)(1 + (t - N_FIELDS) % 2);
        type = T_F64;
    } else {
        const int s = (t - N_FIELDS - 6) / 3;
        const int f = (t - N_FIELDS - 6) % 3;
        off = offsetof(pyins_config, index_steps) + (size_t)s * sizeof(pyins_index_step);
        if (f == 0) {
            off += offsetof(pyins_index_step, stop_ticks);
            type = T_I32;
        } else if (f == 1) {
            off += offsetof(pyins_index_step, kind);
            type = T_I32;
        } else {
            off += offsetof(pyins_index_step, angle_rad);
            type = T_F64;
        }
    }
    if (type == T_I32) {
        const int32_t v = rd_i32_mix(r);
        memcpy(base + off, &v, sizeof v);
    } else {
        const double v = rd_f64_mix(r);
        memcpy(base + off, &v, sizeof v);
    }
}

/* kind 0: the raw struct bytes; else preset + up to 15 patches. */
static void read_config(reader *r, pyins_config *c) {
    const uint8_t kind = rd_u8(r);
    if ((kind & 7u) == 0u) {
        size_t i;
        unsigned char *b = (unsigned char *)c;
        for (i = 0; i < sizeof *c; ++i) b[i] = rd_u8(r);
        return;
    }
    preset((int)(kind >> 3), c);
    {
        const int n = rd_u8(r) & 15;
        int i;
        for (i = 0; i < n; ++i) patch(r, c);
    }
}

/* ------------------------------------------------------------------------ */
/* State of one input.                                                       */

typedef struct {
    unsigned char *a;        /* the instance under test */
    unsigned char *b;        /* a clone for the differential checks */
    unsigned char *pre;      /* a copy of a before a call */
    unsigned char *scratch;  /* memory that holds no instance */
    unsigned char *blob;     /* snapshots */
    unsigned char *blob2;
    unsigned char *old_blob; /* an earlier snapshot, for rollbacks */
    int have_old;
    pyins_config old_cfg;    /* the configuration of that snapshot's instance */
    size_t size;             /* pyins_core_size() */
    size_t snap;             /* pyins_snapshot_size() */
    int live;                /* a holds an instance reached through documented calls */
    unsigned ticks_left;
    uint32_t sticky;         /* fault bits seen since the last init/restore */
    pyins_config cfg;
    pyins_output last;       /* state after the last call on a */
    int untrusted;           /* PYINS_FUZZ_UNTRUSTED=1 */
} fuzz;

static unsigned char g_mem[6][MEM_MAX + 64] __attribute__((aligned(64)));
static unsigned char g_blobs[3][SNAP_MAX] __attribute__((aligned(64)));
static pyins_sample g_samples[MAX_BATCH];
static pyins_output g_out_a[MAX_BATCH + 2];
static pyins_output g_out_b[MAX_BATCH + 2];
static pyins_nav g_nav_a[MAX_BATCH + 2];

static void require_named(int st, const char *what) {
    if (st != PYINS_OK) {
        const char *s = pyins_status_str(st);
        if (s == NULL || strstr(s, "unknown") != NULL) fail(__LINE__, what, st, 0);
    }
}

/* Batch calls and API errors return only PYINS_OK or negative statuses. */
static void require_ok_or_error(int st, const char *what) {
    require_named(st, what);
    if (st > 0) fail(__LINE__, what, st, 0);
}

/* The record with the sample-level fault bookkeeping (fault bits,
 * counters) blanked: what a rejected or dropped sample must leave as it was. */
static void masked(const pyins_output *o, pyins_output *m) {
    *m = *o;
    m->fault_flags = 0u;
    memset(&m->n_nonfinite, 0, offsetof(pyins_output, seq) - offsetof(pyins_output, n_nonfinite));
}

static int same_but_faults(const pyins_output *a, const pyins_output *b) {
    pyins_output ma, mb;
    masked(a, &ma);
    masked(b, &mb);
    return memcmp(&ma, &mb, sizeof ma) == 0;
}

/* Fault counters never decrease (they saturate). */
static int counters_kept(const pyins_output *before, const pyins_output *after) {
    return after->n_nonfinite >= before->n_nonfinite && after->n_saturated >= before->n_saturated &&
           after->n_seq_gaps >= before->n_seq_gaps && after->n_seq_bridged >= before->n_seq_bridged &&
           after->n_seq_repeats >= before->n_seq_repeats && after->n_seq_lost >= before->n_seq_lost &&
           after->n_encoder_jumps >= before->n_encoder_jumps;
}

/* Where two instances differ (printed before a failure). */
static void report_diff(const unsigned char *x, const unsigned char *y, size_t n) {
    size_t i;
    int shown = 0;
    for (i = 0; i < n && shown < 16; ++i) {
        if (x[i] != y[i]) {
            fprintf(stderr, "  byte %zu: %02x != %02x\n", i, x[i], y[i]);
            ++shown;
        }
    }
}

static void require_same(const unsigned char *x, const unsigned char *y, size_t n, int line, const char *what) {
    if (memcmp(x, y, n) != 0) {
        report_diff(x, y, n);
        fail(line, what, 0, 0);
    }
}

static void require_unchanged(const fuzz *f, const char *what) {
    require_same(f->a, f->pre, f->size, __LINE__, what);
}

/* Set once a state the docs say nothing about was accepted (only with
 * PYINS_FUZZ_UNTRUSTED=1): output ranges and sticky bits are not checked. */
static int g_garbage = 0;

static void check_output(const pyins_output *o) {
    if (g_garbage) return;
    REQUIRE(o->mode >= PYINS_MODE_IDLE && o->mode <= PYINS_MODE_NAVIGATE, "output mode");
    REQUIRE(o->kf_states == 0 || o->kf_states == 5 || o->kf_states == 8 || o->kf_states == 12,
            "output kf_states");
    REQUIRE(!(o->coarse_wander_rad < 0.0) && !(o->coarse_wander_rad > 1.0 + 1e-12), "coarse_wander_rad in [0, 1]");
    REQUIRE(!(o->align_nis < 0.0), "align_nis >= 0");
    /* from finite samples below saturation and a checked fine_accel_vrw: finite, >= 0 (the
       check takes any positive finite density, DBL_MAX included: fine_vrw reports it as given) */
    REQUIRE(o->coarse_vrw >= 0.0 && isfinite(o->coarse_vrw), "coarse_vrw finite and >= 0");
    REQUIRE(o->fine_vrw >= 0.0 && isfinite(o->fine_vrw), "fine_vrw finite and >= 0");
    REQUIRE(o->index_state >= PYINS_INDEX_IDLE && o->index_state <= PYINS_INDEX_FAULT, "output index_state");
    REQUIRE(o->index_fault >= 0 && o->index_fault <= 3, "output index_fault");
    REQUIRE(o->index_step >= 0 && o->index_step < 8, "output index_step");
    REQUIRE(o->tick >= 0 && o->align_restarts >= 0 && o->index_fallbacks >= 0, "output counters");
    REQUIRE(!(o->quat_nb[0] < 0.0), "quat_nb w >= 0");
    REQUIRE(!(o->quat_np[0] < 0.0), "quat_np w >= 0");
    if (isfinite(o->heading_b_rad) && !(o->heading_b_rad >= 0.0 && o->heading_b_rad < kTwoPi)) {
        fprintf(stderr, "  heading_b_rad %a (yaw %a)\n", o->heading_b_rad, o->euler_b_rad[2]);
        fail(__LINE__, "heading in [0, 2 pi)", 0, 0);
    }
    if (isfinite(o->yaw_p_rad) && !(o->yaw_p_rad > -kPi && o->yaw_p_rad <= kPi)) {
        fprintf(stderr, "  yaw_p_rad %a (yaw %a, table %a)\n", o->yaw_p_rad, o->euler_b_rad[2], o->table_angle_rad);
        fail(__LINE__, "IMU yaw in (-pi, pi]", 0, 0);
    }
}

/* A compact record holds the full record's fields of the same names, bit for bit. */
static int nav_is_output(const pyins_nav *v, const pyins_output *o) {
    return v->tick == o->tick && v->mode == o->mode && v->fault_flags == o->fault_flags &&
           v->state_flags == o->state_flags && v->index_state == o->index_state &&
           memcmp(&v->lat_rad, &o->lat_rad, 6 * sizeof(double)) == 0 &&
           memcmp(v->quat_nb, o->quat_nb, 8 * sizeof(double)) == 0 &&
           memcmp(&v->table_angle_rad, &o->table_angle_rad, sizeof(double)) == 0 &&
           memcmp(&v->motor_rate_cmd_rad_s, &o->motor_rate_cmd_rad_s, 2 * sizeof(double)) == 0;
}

/* pyins_run_decimated, or pyins_run_nav (compact records) when compact. */
static int run_every(fuzz *f, int compact, const pyins_sample *samples, size_t n, size_t every, size_t cap,
                     size_t *n_done, size_t *n_out) {
    return compact ? pyins_run_nav((pyins_core *)f->a, samples, n, every, g_nav_a, cap, n_done, n_out)
                   : pyins_run_decimated((pyins_core *)f->a, samples, n, every, g_out_a, cap, n_done, n_out);
}

static void get_a(fuzz *f, pyins_output *o) {
    pyins_motor_command cmd;
    REQUIRE_EQ(pyins_get_output((const pyins_core *)f->a, o), PYINS_OK, "get_output on a live instance");
    check_output(o);
    /* the motor command alone is the record's, bit for bit */
    REQUIRE_EQ(pyins_get_motor_command((const pyins_core *)f->a, &cmd), PYINS_OK, "get_motor_command");
    REQUIRE(memcmp(&cmd.rate_rad_s, &o->motor_rate_cmd_rad_s, sizeof(double)) == 0 &&
            memcmp(&cmd.angle_rad, &o->table_angle_cmd_rad, sizeof(double)) == 0 &&
            cmd.index_state == o->index_state && cmd.index_fault == o->index_fault,
            "motor command == the record's fields");
    /* and so is the compact record (pyins_get_nav) */
    {
        pyins_nav v;
        REQUIRE_EQ(pyins_get_nav((const pyins_core *)f->a, &v), PYINS_OK, "get_nav");
        REQUIRE(nav_is_output(&v, o), "compact record == the record's fields");
    }
}

/* After a call that may have stepped: sticky fault bits, output ranges. */
static void refresh(fuzz *f) {
    pyins_output o;
    get_a(f, &o);
    REQUIRE(g_garbage || (o.fault_flags & f->sticky) == f->sticky, "sticky fault bits cleared");
    REQUIRE(g_garbage || counters_kept(&f->last, &o), "a fault counter decreased");
    f->sticky = o.fault_flags;
    f->last = o;
}

/* Restart the sticky-bit bookkeeping (after init or restore). */
static void fresh(fuzz *f) {
    pyins_output o;
    get_a(f, &o);
    f->sticky = o.fault_flags;
    f->last = o;
}

/* a and b hold the same state, as far as the outputs tell. (Not a byte
 * comparison: padding inside the instance is not state, and copies of
 * temporaries may fill it with whatever the stack held.) */
static void require_same_state(const fuzz *f, int line, const char *what) {
    pyins_output oa, ob;
    REQUIRE_EQ(pyins_get_output((const pyins_core *)f->a, &oa), PYINS_OK, "get_output a");
    REQUIRE_EQ(pyins_get_output((const pyins_core *)f->b, &ob), PYINS_OK, "get_output b");
    require_same((const unsigned char *)&oa, (const unsigned char *)&ob, sizeof oa, line, what);
}

/* b := a through the documented path (snapshot, restore). */
static void clone_a_to_b(fuzz *f) {
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob2, f->snap), PYINS_OK, "snapshot for clone");
    memset(f->b, 0xA5, f->size);
    REQUIRE_EQ(pyins_restore(f->b, f->size, f->blob2, f->snap), PYINS_OK, "restore own snapshot");
}

/* ------------------------------------------------------------------------ */
/* Samples.                                                                   */

typedef struct {
    int raw;                 /* cycle through up to 8 raw samples from the bytes */
    int n_raw;
    pyins_sample raw_s[8];
    double amp_ang, amp_vel; /* noise amplitudes [rad], [m/s] per tick */
    uint64_t lcg;
    double enc_offset;       /* added to the followed table command */
    int follow;              /* encoder follows the command (else a fixed angle) */
    double enc_fixed;
    unsigned inject_every;   /* 0: never */
    unsigned inject_at;
    int inject_field;
    double inject_value;
    uint32_t seq0;           /* seq of sample 0: the last one taken + 1 */
    unsigned seq_every;      /* 0: seq counts up; else it shifts by seq_delta */
    unsigned seq_at;         /*   at samples seq_at, seq_at + seq_every, ... */
    int32_t seq_delta;       /*   (-1: a repeat, small: a gap, large: lost) */
} gen;

static double exp_amp(uint8_t e) {
    /* 0 -> 0, else 10^(-(e % 13)) : 1 .. 1e-12 */
    if (e == 0) return 0.0;
    return pow(10.0, -(double)(e % 13u));
}

static void read_gen(const fuzz *f, reader *r, gen *g) {
    const uint8_t kind = rd_u8(r);
    memset(g, 0, sizeof *g);
    if ((kind & 3u) == 0u) {
        int i, k;
        g->raw = 1;
        g->n_raw = 1 + (kind >> 2) % 8;
        for (i = 0; i < g->n_raw; ++i) {
            for (k = 0; k < 3; ++k) g->raw_s[i].dtheta_p_rad[k] = rd_f64_raw(r);
            for (k = 0; k < 3; ++k) g->raw_s[i].dv_p_mps[k] = rd_f64_raw(r);
            g->raw_s[i].table_angle_rad = rd_f64_raw(r);
            g->raw_s[i].seq = rd_u32(r);
            g->raw_s[i].reserved = 0u;
        }
        return;
    }
    g->seq0 = f->last.seq + 1u;
    if (kind & 4u) {
        g->seq_every = 1u + rd_u8(r);
        g->seq_at = rd_u8(r) % g->seq_every;
        g->seq_delta = rd_i32_mix(r);
    }
    g->amp_ang = exp_amp(rd_u8(r));
    g->amp_vel = exp_amp(rd_u8(r));
    g->lcg = (uint64_t)rd_u32(r) * 2654435761u + 1u;
    {
        const uint8_t e = rd_u8(r);
        g->follow = (e & 1u) == 0u;
        g->enc_offset = (e & 2u) ? (double)(int8_t)(e & 0xF0u) * 1e-3 : 0.0;
        g->enc_fixed = (double)(e >> 2) * 0.1;
    }
    g->inject_every = rd_u8(r);
    if (g->inject_every > 0) {
        g->inject_at = rd_u8(r) % g->inject_every;
        g->inject_field = rd_u8(r) % 7;
        g->inject_value = rd_f64_mix(r);
    }
}

static double lcg_unit(uint64_t *s) {
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)((int64_t)(*s >> 43) - (int64_t)(1 << 20)) / 1048576.0; /* [-1, 1) */
}

static double wrap_2pi(double a) {
    double w = fmod(a, kTwoPi);
    if (w < 0.0) w += kTwoPi;
    if (!(w < kTwoPi)) w = 0.0;
    return w;
}

/* Sample i of a call, for a static level IMU at the configured latitude plus
 * noise; the encoder reads back the command at the start of the call. */
static void make_sample(const fuzz *f, gen *g, unsigned i, pyins_sample *s) {
    if (g->raw) {
        *s = g->raw_s[i % (unsigned)g->n_raw];
    } else {
        const double hz = (f->cfg.tick_hz > 0 && f->cfg.tick_hz <= 10000) ? (double)f->cfg.tick_hz : 100.0;
        const double dt = 1.0 / hz;
        const double lat = isfinite(f->cfg.lat_rad) ? f->cfg.lat_rad : 0.0;
        const double w = 7.2921151467e-5;
        s->dtheta_p_rad[0] = g->amp_ang * lcg_unit(&g->lcg);
        s->dtheta_p_rad[1] = w * cos(lat) * dt + g->amp_ang * lcg_unit(&g->lcg);
        s->dtheta_p_rad[2] = w * sin(lat) * dt + g->amp_ang * lcg_unit(&g->lcg);
        s->dv_p_mps[0] = g->amp_vel * lcg_unit(&g->lcg);
        s->dv_p_mps[1] = g->amp_vel * lcg_unit(&g->lcg);
        s->dv_p_mps[2] = 9.8 * dt + g->amp_vel * lcg_unit(&g->lcg);
        if (g->follow && isfinite(f->last.table_angle_cmd_rad)) {
            s->table_angle_rad = wrap_2pi(f->last.table_angle_cmd_rad + g->enc_offset);
        } else {
            s->table_angle_rad = g->enc_fixed;
        }
        s->seq = g->seq0 + i;
        if (g->seq_every > 0 && i >= g->seq_at) {
            s->seq += (uint32_t)g->seq_delta * ((i - g->seq_at) / g->seq_every + 1u);
        }
        s->reserved = 0u;
    }
    if (g->inject_every > 0 && i % g->inject_every == g->inject_at) {
        double *fields[7] = {&s->dtheta_p_rad[0], &s->dtheta_p_rad[1], &s->dtheta_p_rad[2],
                             &s->dv_p_mps[0], &s->dv_p_mps[1], &s->dv_p_mps[2], &s->table_angle_rad};
        *fields[g->inject_field] = g->inject_value;
    }
}

static int sample_finite(const pyins_sample *s) {
    return isfinite(s->dtheta_p_rad[0]) && isfinite(s->dtheta_p_rad[1]) && isfinite(s->dtheta_p_rad[2]) &&
           isfinite(s->dv_p_mps[0]) && isfinite(s->dv_p_mps[1]) && isfinite(s->dv_p_mps[2]) &&
           isfinite(s->table_angle_rad);
}

static unsigned take_ticks(fuzz *f, unsigned n) {
    if (n > f->ticks_left) n = f->ticks_left;
    f->ticks_left -= n;
    return n;
}

/* ------------------------------------------------------------------------ */
/* Operations.                                                               */

enum {
    OP_STEP,
    OP_RUN,
    OP_RUN_DECIMATED,
    OP_GET_OUTPUT,
    OP_INDEX_RESET,
    OP_SNAPSHOT,
    OP_RESTORE_OLD,
    OP_RESTORE_MUTATED,
    OP_RESTORE_FUZZED,
    OP_REINIT,
    OP_BAD_ARGS,
    OP_NOT_INIT,
    OP_STATUS_STR,
    N_OPS
};

/* One pyins_step; returns 0 when the input should end. */
static void op_step(fuzz *f, reader *r) {
    gen g;
    pyins_sample s;
    pyins_output out, after;
    int st;
    read_gen(f, r, &g);
    if (take_ticks(f, 1) == 0) return;
    make_sample(f, &g, 0, &s);
    memset(&out, 0xCC, sizeof out);
    st = pyins_step((pyins_core *)f->a, &s, &out);
    require_named(st, "step status");
    if (!sample_finite(&s)) {
        REQUIRE_EQ(st, PYINS_E_SAMPLE_NONFINITE, "non-finite sample rejected");
    }
    if (st == PYINS_E_SAMPLE_NONFINITE) REQUIRE(!sample_finite(&s), "finite sample rejected as non-finite");
    /* every sample-level outcome fills *out with the state after the call */
    get_a(f, &after);
    REQUIRE(memcmp(&out, &after, sizeof out) == 0, "step *out != get_output");
    if (st < 0 || st == PYINS_W_SEQ_REPEAT) {
        REQUIRE(g_garbage || same_but_faults(&after, &f->last), "rejected/dropped sample changed the state");
    } else if (st == PYINS_OK || st == PYINS_W_ENCODER_JUMP) {
        REQUIRE_EQ(after.tick, f->last.tick + 1, "a sample taken is one tick");
    } else if (st == PYINS_W_SEQ_GAP) {
        REQUIRE(after.tick >= f->last.tick + 2 && after.tick <= f->last.tick + 101, "a bridged gap: 2..101 ticks");
    } else if (st == PYINS_W_SEQ_LOST) {
        REQUIRE(after.tick >= f->last.tick + 1, "a lost sequence: at least one tick");
    }
    if (st >= 0 && st != PYINS_W_SEQ_REPEAT && f->cfg.seq_mode == PYINS_SEQ_CHECK) {
        REQUIRE(after.seq == s.seq, "output seq is the last sample's");
    }
    refresh(f);
}

static void op_run(fuzz *f, reader *r) {
    gen g;
    unsigned n = rd_u16(r) % (MAX_BATCH + 1u);
    const uint8_t flags = rd_u8(r);
    const int with_out = (flags & 1u) == 0u;
    const int with_done = (flags & 2u) == 0u;
    size_t n_done = 12345;
    const int64_t t0 = f->last.tick;
    unsigned i;
    int st, st_b = PYINS_OK;
    read_gen(f, r, &g);
    n = take_ticks(f, n);
    for (i = 0; i < n; ++i) make_sample(f, &g, i, &g_samples[i]);
    clone_a_to_b(f);
    st = pyins_run((pyins_core *)f->a, n ? g_samples : NULL, n, with_out ? g_out_a : NULL,
                   with_done ? &n_done : NULL);
    require_ok_or_error(st, "run status");
    for (i = 0; i < n; ++i) {
        st_b = pyins_step((pyins_core *)f->b, &g_samples[i], &g_out_b[i]);
        if (st_b < 0) break;   /* notices go on */
    }
    REQUIRE_EQ(st, i == n ? PYINS_OK : st_b, "run status == first single-step rejection");
    if (with_done) REQUIRE_EQ(n_done, i, "run n_done == samples accepted");
    if (with_out) {
        require_same((const unsigned char *)g_out_a, (const unsigned char *)g_out_b, (size_t)i * sizeof g_out_a[0],
                     __LINE__, "run records != single steps");
    }
    require_same_state(f, __LINE__, "state after run != after single steps");
    if (st == PYINS_E_SAMPLE_NONFINITE) REQUIRE(!sample_finite(&g_samples[i]), "run stopped at a finite sample");
    refresh(f);
    if (i > 0) REQUIRE_EQ(f->last.tick, g_out_b[i - 1].tick, "tick after run");
    else REQUIRE_EQ(f->last.tick, t0, "tick after a run that took nothing");
}

static void op_run_decimated(fuzz *f, reader *r) {
    gen g;
    unsigned n = rd_u16(r) % (MAX_BATCH + 1u);
    const unsigned every_b = rd_u8(r);
    const uint8_t capmode = rd_u8(r);
    const int compact = (capmode & 4u) != 0u;   /* pyins_run_nav */
    size_t every = every_b == 0 ? 0 : (every_b % 64u) + 1u;
    size_t cap, need, n_done = 777, n_out = 777, i, written = 0;
    int st, st_b = PYINS_OK;
    read_gen(f, r, &g);
    n = take_ticks(f, n);
    for (i = 0; i < n; ++i) make_sample(f, &g, (unsigned)i, &g_samples[i]);
    if (capmode % 4u == 3u && every == 0) every = 1;
    need = every == 0 ? 1 : n / every + 1u;
    switch (capmode % 4u) {
        case 1: cap = need + 3u; break;
        case 2: cap = need - 1u; break;   /* too small (every > 0) */
        default: cap = need; break;
    }
    if (cap > MAX_BATCH + 2u) cap = MAX_BATCH + 2u;
    memcpy(f->pre, f->a, f->size);
    if (every == 0) {
        st = run_every(f, compact, g_samples, n, 0, cap, &n_done, &n_out);
        REQUIRE_EQ(st, PYINS_E_BAD_ARG, "out_every 0");
        REQUIRE(n_done == 0 && n_out == 0, "refused run_decimated reports nothing done");
        require_unchanged(f, "out_every 0 changed the state");
        return;
    }
    if (cap < need) {
        st = run_every(f, compact, g_samples, n, every, cap, &n_done, &n_out);
        REQUIRE_EQ(st, PYINS_E_BUFFER_TOO_SMALL, "decimation buffer too small");
        REQUIRE(n_done == 0 && n_out == 0, "refused run_decimated reports nothing done");
        require_unchanged(f, "refused run_decimated stepped");
        return;
    }
    clone_a_to_b(f);
    st = run_every(f, compact, n ? g_samples : NULL, n, every, cap, &n_done, &n_out);
    require_ok_or_error(st, "run_decimated status");
    {
        uint64_t next = ((uint64_t)f->last.tick / every + 1u) * every;
        int stopped_full = 0;
        for (i = 0; i < n; ++i) {
            pyins_output o;
            if (st == PYINS_E_BUFFER_TOO_SMALL && i == n_done && written == cap) {
                /* stopped before a step whose record had no room: check it */
                require_same_state(f, __LINE__, "state where run_decimated stopped");
                st_b = pyins_step((pyins_core *)f->b, &g_samples[i], &o);
                REQUIRE(st_b >= 0 && (uint64_t)o.tick >= next, "run_decimated stopped though the record fitted");
                stopped_full = 1;
                break;
            }
            st_b = pyins_step((pyins_core *)f->b, &g_samples[i], &o);
            if (st_b < 0) break;
            if ((uint64_t)o.tick >= next) {
                REQUIRE(written < cap, "run_decimated wrote past its capacity");
                next = ((uint64_t)o.tick / every + 1u) * every;
                g_out_b[written++] = o;
            }
        }
        if (!stopped_full) {
            REQUIRE_EQ(st, i == n ? PYINS_OK : st_b, "run_decimated status == first single-step rejection");
            require_same_state(f, __LINE__, "state after run_decimated != after single steps");
        }
    }
    REQUIRE_EQ(n_done, i, "run_decimated n_done");
    REQUIRE_EQ(n_out, written, "run_decimated n_out");
    if (compact) {
        for (i = 0; i < written; ++i) {
            REQUIRE(nav_is_output(&g_nav_a[i], &g_out_b[i]), "compact records != single steps' fields");
        }
    } else {
        require_same((const unsigned char *)g_out_a, (const unsigned char *)g_out_b, written * sizeof g_out_a[0],
                     __LINE__, "decimated records != single steps");
    }
    refresh(f);
}

static void op_get_output(fuzz *f) {
    pyins_output o;
    memcpy(f->pre, f->a, f->size);
    get_a(f, &o);
    REQUIRE(memcmp(&o, &f->last, sizeof o) == 0, "get_output differs from the last call's state");
    require_unchanged(f, "get_output changed the state");
}

static void op_index_reset(fuzz *f) {
    pyins_output before, after;
    get_a(f, &before);
    memcpy(f->pre, f->a, f->size);
    REQUIRE_EQ(pyins_index_reset((pyins_core *)f->a), PYINS_OK, "index_reset");
    get_a(f, &after);
    if (before.index_state != PYINS_INDEX_FAULT) {
        require_unchanged(f, "index_reset outside FAULT changed the state");
    } else {
        REQUIRE(after.index_state != PYINS_INDEX_FAULT, "index_reset left FAULT");
        REQUIRE_EQ(after.index_step, 0, "index_reset restarts at the first step");
        REQUIRE(memcmp(&after.index_a_c, &before.index_a_c, sizeof(double)) == 0 &&
                    memcmp(&after.index_a_s, &before.index_a_s, sizeof(double)) == 0,
                "index_reset keeps A_c, A_s");
        REQUIRE_EQ(after.tick, before.tick, "index_reset does not step");
    }
    refresh(f);
}

static void op_snapshot(fuzz *f, reader *r) {
    const uint8_t flags = rd_u8(r);
    memcpy(f->pre, f->a, f->size);
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob, f->snap - 1u), PYINS_E_SNAPSHOT_SIZE,
               "snapshot into a too-small buffer");
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, NULL, f->snap), PYINS_E_NULL, "snapshot NULL buffer");
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob, f->snap + (flags & 7u)), PYINS_OK, "snapshot");
    require_unchanged(f, "snapshot changed the state");
    /* round trip through fresh memory */
    memset(f->b, flags, f->size);
    REQUIRE_EQ(pyins_restore(f->b, f->size + (flags >> 4), f->blob, f->snap), PYINS_OK, "restore own snapshot");
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->b, f->blob2, f->snap), PYINS_OK, "snapshot of restored");
    REQUIRE(memcmp(f->blob, f->blob2, f->snap) == 0, "snapshot -> restore -> snapshot changed the blob");
    require_same(f->a, f->b, f->size, __LINE__, "restored instance differs");
    if (flags & 8u) {
        memcpy(f->old_blob, f->blob, f->snap);
        f->old_cfg = f->cfg;
        f->have_old = 1;
    }
}

static void op_restore_old(fuzz *f) {
    if (!f->have_old) return;
    REQUIRE_EQ(pyins_restore(f->a, f->size, f->old_blob, f->snap), PYINS_OK, "rollback to an older snapshot");
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob2, f->snap), PYINS_OK, "snapshot after rollback");
    REQUIRE(memcmp(f->old_blob, f->blob2, f->snap) == 0, "rollback does not reproduce the blob");
    f->cfg = f->old_cfg;
    fresh(f);
}

/* Restore of a blob into a; refused -> a unchanged; accepted -> a holds the
 * blob's payload. Returns 0 when the accepted payload was not written by
 * pyins_snapshot (the input ends: the docs say nothing about such states). */
static int restore_into_a(fuzz *f, const unsigned char *blob, size_t len, int payload_ours) {
    int st;
    memcpy(f->pre, f->a, f->size);
    st = pyins_restore(f->a, f->size, blob, len);
    require_named(st, "restore status");
    if (st != PYINS_OK) {
        REQUIRE(st == PYINS_E_SNAPSHOT_SIZE || st == PYINS_E_SNAPSHOT_VERSION || st == PYINS_E_SNAPSHOT_CORRUPT,
                "restore refused with a non-snapshot status");
        require_unchanged(f, "refused restore changed the memory");
        return 1;
    }
    REQUIRE_EQ(len, f->snap, "restore accepted a blob of the wrong length");
    REQUIRE(memcmp(f->a, blob + (f->snap - f->size), f->size) == 0, "restored memory != blob payload");
    if (!payload_ours && !f->untrusted) {
        f->live = 0;
        return 0;
    }
    if (!payload_ours) {
        /* exploration only: the state is garbage; keep going without the
         * invariants that need a meaningful state */
        pyins_output o;
        g_garbage = 1;
        REQUIRE_EQ(pyins_get_output((const pyins_core *)f->a, &o), PYINS_OK, "get_output");
        f->sticky = 0;
        f->last = o;
        return 1;
    }
    fresh(f);
    return 1;
}

static void op_restore_mutated(fuzz *f, reader *r) {
    const int n_edits = rd_u8(r) % 8;
    const uint8_t sizemode = rd_u8(r);
    size_t len = f->snap;
    int i, payload_changed = 0;
    REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob, f->snap), PYINS_OK, "snapshot");
    memcpy(f->blob2, f->blob, f->snap);
    for (i = 0; i < n_edits; ++i) {
        const size_t pos = rd_u16(r) % f->snap;
        const uint8_t x = rd_u8(r);
        f->blob[pos] ^= x;
    }
    payload_changed = memcmp(f->blob + (f->snap - f->size), f->blob2 + (f->snap - f->size), f->size) != 0;
    switch (sizemode % 4u) {
        case 1: len = f->snap - 1u - (sizemode >> 2); break;
        case 2: len = f->snap + 1u + (sizemode >> 2); break;
        case 3: len = sizemode >> 2; break;   /* shorter than the header, maybe */
        default: break;
    }
    if (!restore_into_a(f, f->blob, len, !payload_changed)) return;
}

static int op_restore_fuzzed(fuzz *f, reader *r) {
    const uint8_t flags = rd_u8(r);
    const size_t want = rd_u16(r) % (f->snap + 40u);
    const uint8_t fill = rd_u8(r);
    size_t i, len;
    memset(f->blob, fill, f->snap + 64u);
    for (i = 0; i < want && r->n > 0; ++i) f->blob[i] = rd_u8(r);
    len = (flags & 1u) ? f->snap : want;
    if (flags & 2u) {
        /* a valid header (taken from a real snapshot), fuzzed payload */
        REQUIRE_EQ(pyins_snapshot((const pyins_core *)f->a, f->blob2, f->snap), PYINS_OK, "snapshot");
        memcpy(f->blob, f->blob2, 16);  /* magic, format, ABI, size; CRC stays fuzzed */
        if (flags & 4u) {
            /* the instance marker of a real payload, so only the CRC guards */
            memcpy(f->blob + (f->snap - f->size), f->blob2 + (f->snap - f->size), 4);
        }
        if ((flags & 8u) && f->untrusted) {
            /* exploration: a matching CRC-32, so garbage states get stepped */
            uint32_t c = 0xFFFFFFFFu;
            size_t k;
            int b;
            for (k = f->snap - f->size; k < f->snap; ++k) {
                c ^= f->blob[k];
                for (b = 0; b < 8; ++b) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
            }
            c = ~c;
            f->blob[16] = (uint8_t)c;
            f->blob[17] = (uint8_t)(c >> 8);
            f->blob[18] = (uint8_t)(c >> 16);
            f->blob[19] = (uint8_t)(c >> 24);
        }
    }
    if (flags & 16u) {
        /* into memory that holds no instance: refused -> untouched */
        int st;
        memset(f->scratch, fill, f->size);
        memcpy(f->pre, f->scratch, f->size);
        st = pyins_restore(f->scratch, f->size, f->blob, len);
        require_named(st, "restore status");
        if (st != PYINS_OK) REQUIRE(memcmp(f->pre, f->scratch, f->size) == 0, "refused restore changed memory");
        return 1;
    }
    /* an accepted fuzzed payload is never one pyins_snapshot wrote */
    return restore_into_a(f, f->blob, len, 0);
}

/* Re-init over a live instance: refused -> untouched. */
static void op_reinit(fuzz *f, reader *r) {
    pyins_config c;
    int st, chk;
    read_config(r, &c);
    chk = pyins_config_check(&c);
    require_named(chk, "config_check status");
    memcpy(f->pre, f->a, f->size);
    st = pyins_init(f->a, f->size, &c);
    REQUIRE_EQ(st, chk, "init status == config_check status");
    if (st != PYINS_OK) {
        require_unchanged(f, "refused init changed the memory");
        return;
    }
    f->cfg = c;
    fresh(f);
    REQUIRE_EQ(f->last.tick, 0, "fresh instance at tick 0");
    REQUIRE_EQ(f->last.mode, PYINS_MODE_IDLE, "fresh instance idle");
}

/* One call with exactly one bad argument: its documented status, a untouched. */
static void op_bad_args(fuzz *f, reader *r) {
    const uint8_t which = rd_u8(r);
    pyins_core *core = (pyins_core *)f->a;
    pyins_core *mis = (pyins_core *)(f->a + 1);
    pyins_sample s;
    pyins_output o;
    size_t nd = 5, no = 5;
    int st = 0, want = 0;
    memset(&s, 0, sizeof s);
    memcpy(f->pre, f->a, f->size);
    switch (which % 20u) {
        case 0: st = pyins_step(NULL, &s, &o); want = PYINS_E_NULL; break;
        case 1: st = pyins_step(core, NULL, &o); want = PYINS_E_NULL; break;
        case 2: st = pyins_step(core, &s, NULL); want = PYINS_E_NULL; break;
        case 3: st = pyins_step(mis, &s, &o); want = PYINS_E_MISALIGNED; break;
        case 4: st = pyins_run(core, NULL, 1u + (which >> 5), NULL, &nd); want = PYINS_E_NULL; break;
        case 5: st = pyins_run(core, NULL, 0, NULL, &nd); want = PYINS_OK; break;
        case 6: st = pyins_run(mis, &s, 1, NULL, &nd); want = PYINS_E_MISALIGNED; break;
        case 7: st = pyins_run_decimated(core, NULL, 3, 1, g_out_a, 4, &nd, &no); want = PYINS_E_NULL; break;
        case 8: st = pyins_run_decimated(core, &s, 1, 1, NULL, 2, &nd, &no); want = PYINS_E_NULL; break;
        case 9: st = pyins_run_decimated(core, NULL, 0, 5, g_out_a, 1, &nd, &no); want = PYINS_OK; break;
        case 10: st = pyins_get_output(core, NULL); want = PYINS_E_NULL; break;
        case 11: st = pyins_get_output(NULL, &o); want = PYINS_E_NULL; break;
        case 12: st = pyins_index_reset(NULL); want = PYINS_E_NULL; break;
        case 13: st = pyins_index_reset(mis); want = PYINS_E_MISALIGNED; break;
        case 14: st = pyins_snapshot(NULL, f->blob, f->snap); want = PYINS_E_NULL; break;
        case 15: st = pyins_init(f->a, f->size, NULL); want = PYINS_E_NULL; break;
        case 16: st = pyins_init(f->a + 1, f->size, &f->cfg); want = PYINS_E_MISALIGNED; break;
        case 17: st = pyins_init(f->a, f->size - 1u - (which >> 5), &f->cfg); want = PYINS_E_MEM_TOO_SMALL; break;
        case 18: st = pyins_restore(f->a, f->size, NULL, f->snap); want = PYINS_E_NULL; break;
        default: st = pyins_restore(f->a + 1, f->size, f->blob, f->snap); want = PYINS_E_MISALIGNED; break;
    }
    REQUIRE_EQ(st, want, "bad argument status");
    if (which % 20u == 4u || which % 20u == 5u || which % 20u == 6u || which % 20u == 7u) {
        REQUIRE_EQ(nd, 0, "refused run reports nothing done");
    }
    require_unchanged(f, "call with a bad argument changed the state");
}

/* Calls on memory that holds no instance: PYINS_E_NOT_INIT, memory untouched. */
static void op_not_init(fuzz *f, reader *r) {
    const uint8_t which = rd_u8(r);
    const uint8_t fill = rd_u8(r);
    pyins_core *c = (pyins_core *)f->scratch;
    pyins_sample s;
    pyins_output o;
    size_t nd = 1, no = 1;
    int st;
    memset(&s, 0, sizeof s);
    memset(f->scratch, fill, f->size);   /* one repeated byte: never the instance marker */
    memcpy(f->pre, f->scratch, f->size);
    switch (which % 7u) {
        case 0: st = pyins_step(c, &s, &o); break;
        case 1: st = pyins_run(c, &s, 1, &o, &nd); break;
        case 2: st = pyins_run_decimated(c, &s, 1, 1, g_out_a, 2, &nd, &no); break;
        case 3: st = pyins_get_output(c, &o); break;
        case 4: st = pyins_index_reset(c); break;
        case 5: st = pyins_snapshot(c, f->blob, f->snap); break;
        default: st = pyins_run(c, NULL, 0, NULL, &nd); break;
    }
    REQUIRE_EQ(st, PYINS_E_NOT_INIT, "call on memory without an instance");
    REQUIRE(memcmp(f->pre, f->scratch, f->size) == 0, "call on memory without an instance wrote to it");
    if (which % 7u == 1u || which % 7u == 2u || which % 7u == 6u) REQUIRE_EQ(nd, 0, "refused run: n_done");
}

static void op_status_str(reader *r) {
    const int32_t code = (int32_t)rd_u32(r);
    const char *s = pyins_status_str(code);
    REQUIRE(s != NULL && s[0] != '\0', "status_str never NULL or empty");
}

/* ------------------------------------------------------------------------ */

static int untrusted_mode(void) {
    static int mode = -1;
    if (mode < 0) {
        const char *e = getenv("PYINS_FUZZ_UNTRUSTED");
        mode = (e != NULL && e[0] == '1') ? 1 : 0;
    }
    return mode;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    fuzz f;
    reader r;
    uint8_t memmode, fill;
    int st, chk, ops;
    r.p = data;
    r.n = size;
    memset(&f, 0, sizeof f);
    g_garbage = 0;
    f.a = g_mem[0];
    f.b = g_mem[1];
    f.pre = g_mem[2];
    f.scratch = g_mem[3];
    f.blob = g_blobs[0];
    f.blob2 = g_blobs[1];
    f.old_blob = g_blobs[2];
    f.size = pyins_core_size();
    f.snap = pyins_snapshot_size();
    f.ticks_left = MAX_TICKS;
    f.untrusted = untrusted_mode();
    if (f.size > MEM_MAX || f.snap + 64u > SNAP_MAX || pyins_core_align() > 64u) {
        fail(__LINE__, "instance larger than the harness buffers", (long long)f.size, MEM_MAX);
    }

    read_config(&r, &f.cfg);
    memmode = rd_u8(&r);
    fill = rd_u8(&r);
    memset(f.a, fill, f.size + 64u);
    memcpy(f.pre, f.a, f.size);
    chk = pyins_config_check(&f.cfg);
    require_named(chk, "config_check status");
    switch (memmode % 16u) {
        case 1:
            st = pyins_init(NULL, f.size, &f.cfg);
            REQUIRE_EQ(st, PYINS_E_NULL, "init NULL mem");
            break;
        case 2: /* 1..7 bytes off an alignment of at least 8 */
            st = pyins_init(f.a + 1 + (memmode >> 4) % 7u, f.size, &f.cfg);
            REQUIRE_EQ(st, PYINS_E_MISALIGNED, "init misaligned");
            break;
        case 3:
            st = pyins_init(f.a, f.size - 1u - (memmode >> 4), &f.cfg);
            REQUIRE_EQ(st, PYINS_E_MEM_TOO_SMALL, "init too small");
            break;
        default:
            st = pyins_init(f.a, f.size + (memmode >> 4), &f.cfg);
            REQUIRE_EQ(st, chk, "init status == config_check status");
            break;
    }
    require_named(st, "init status");
    if (st != PYINS_OK) {
        require_unchanged(&f, "refused init changed the memory");
        /* without an instance every call says so */
        op_not_init(&f, &r);
        return 0;
    }
    f.live = 1;
    fresh(&f);
    REQUIRE_EQ(f.last.tick, 0, "fresh instance at tick 0");
    REQUIRE_EQ(f.last.mode, PYINS_MODE_IDLE, "fresh instance idle");

    for (ops = 0; ops < MAX_OPS && r.n > 0 && f.live; ++ops) {
        const uint8_t op = rd_u8(&r);
        switch (op % N_OPS) {
            case OP_STEP: op_step(&f, &r); break;
            case OP_RUN: op_run(&f, &r); break;
            case OP_RUN_DECIMATED: op_run_decimated(&f, &r); break;
            case OP_GET_OUTPUT: op_get_output(&f); break;
            case OP_INDEX_RESET: op_index_reset(&f); break;
            case OP_SNAPSHOT: op_snapshot(&f, &r); break;
            case OP_RESTORE_OLD: op_restore_old(&f); break;
            case OP_RESTORE_MUTATED: op_restore_mutated(&f, &r); break;
            case OP_RESTORE_FUZZED: op_restore_fuzzed(&f, &r); break;
            case OP_REINIT: op_reinit(&f, &r); break;
            case OP_BAD_ARGS: op_bad_args(&f, &r); break;
            case OP_NOT_INIT: op_not_init(&f, &r); break;
            default: op_status_str(&r); break;
        }
    }
    return 0;
}

/* ------------------------------------------------------------------------ */
/* Built-in seeds.                                                           */

/* seq_mix: 0 = seq counts up; else the rd_i32_mix byte of the shift made
 * every 50 samples from sample 10 (1 = -1: a repeat; 4 | k << 3: +k). */
static void seed_gen(writer *w, int raw, unsigned amp_ang, unsigned amp_vel, uint32_t seed, unsigned enc,
                     unsigned inject_every, unsigned seq_mix) {
    if (raw) {
        /* one raw sample: the static IMU at 34 deg, 100 Hz */
        const double s[7] = {0.0, 6.027874130954723e-07, 4.103617522881293e-07, 0.0, 0.0,
                             0.09796698857772466, 0.0};
        wr_u8(w, 0u);
        wr_bytes(w, s, sizeof s);
        wr_u32(w, 1u);
        return;
    }
    wr_u8(w, seq_mix ? 5u : 1u);
    if (seq_mix) {
        wr_u8(w, 49u);   /* every 50 */
        wr_u8(w, 10u);   /* from sample 10 */
        wr_u8(w, seq_mix);
    }
    wr_u8(w, amp_ang);
    wr_u8(w, amp_vel);
    wr_u32(w, seed);
    wr_u8(w, enc);
    wr_u8(w, inject_every);
    if (inject_every > 0) {
        wr_u8(w, inject_every - 1u);   /* at the last of each period */
        wr_u8(w, seed % 7u);            /* field */
        wr_u8(w, 2u);                   /* NaN */
    }
}

static void seed_ops(writer *w, int k) {
    /* a long run to reach navigation and indexing, with snapshots on the way */
    wr_u8(w, OP_STEP);
    seed_gen(w, 0, 6, 4, 11u + (uint32_t)k, 0, 0, 0);
    wr_u8(w, OP_RUN);
    wr_u16(w, 256);
    wr_u8(w, 0);
    seed_gen(w, 0, 6, 4, 12u + (uint32_t)k, 0, 0, 0);
    wr_u8(w, OP_SNAPSHOT);
    wr_u8(w, 8);   /* keep it for a rollback */
    wr_u8(w, OP_RUN_DECIMATED);
    wr_u16(w, 250);
    wr_u8(w, 7);
    wr_u8(w, 0);
    seed_gen(w, 0, 7, 5, 13u + (uint32_t)k, 0, 0, 0);
    wr_u8(w, OP_STEP);
    seed_gen(w, 0, 0, 0, 0, 0, 1, 0);   /* a NaN sample */
    wr_u8(w, OP_RUN);
    wr_u16(w, 200);
    wr_u8(w, 0);
    seed_gen(w, 0, 5, 3, 14u + (uint32_t)k, 0, 97, 0);   /* stops at a NaN */
    wr_u8(w, OP_RUN);
    wr_u16(w, 200);
    wr_u8(w, 0);
    seed_gen(w, 0, 6, 4, 21u + (uint32_t)k, 0, 0, 4u | (2u << 3));   /* seq gaps of 2 */
    wr_u8(w, OP_RUN_DECIMATED);
    wr_u16(w, 200);
    wr_u8(w, 9);
    wr_u8(w, 0);
    seed_gen(w, 0, 6, 4, 22u + (uint32_t)k, 0, 0, 1u);   /* seq repeats */
    wr_u8(w, OP_RUN_DECIMATED);
    wr_u16(w, 200);
    wr_u8(w, 64);   /* every 1 */
    wr_u8(w, 4);    /* compact records (pyins_run_nav) */
    seed_gen(w, 0, 6, 4, 24u + (uint32_t)k, 0, 0, 4u | (2u << 3));   /* seq gaps of 2 */
    wr_u8(w, OP_RUN_DECIMATED);
    wr_u16(w, 150);
    wr_u8(w, 2);    /* every 3 */
    wr_u8(w, 5);    /* compact, room to spare */
    seed_gen(w, 0, 6, 4, 25u + (uint32_t)k, 0, 0, 0);
    wr_u8(w, OP_STEP);
    seed_gen(w, 0, 6, 4, 23u + (uint32_t)k, 0, 0, 4u | (30u << 3));
    wr_u8(w, OP_RESTORE_MUTATED);
    wr_u8(w, 1);
    wr_u8(w, 0);
    wr_u16(w, 200);
    wr_u8(w, 0x40);
    wr_u8(w, OP_INDEX_RESET);
    wr_u8(w, OP_GET_OUTPUT);
    wr_u8(w, OP_RESTORE_OLD);
    wr_u8(w, OP_RUN);
    wr_u16(w, 256);
    wr_u8(w, 1);
    seed_gen(w, 0, 4, 2, 15u + (uint32_t)k, 2, 0, 0);   /* encoder held: lag faults */
    wr_u8(w, OP_INDEX_RESET);
    wr_u8(w, OP_BAD_ARGS);
    wr_u8(w, (unsigned)k * 3u);
    wr_u8(w, OP_NOT_INIT);
    wr_u8(w, (unsigned)k);
    wr_u8(w, 0x11);
    wr_u8(w, OP_RESTORE_FUZZED);
    wr_u8(w, 2 | 4);
    wr_u16(w, 64);
    wr_u8(w, 0);
    {
        int i;
        for (i = 0; i < 64; ++i) wr_u8(w, (unsigned)(i * 7 + k));
    }
    wr_u8(w, OP_RUN);
    wr_u16(w, 256);
    wr_u8(w, 0);
    seed_gen(w, 1, 0, 0, 0, 0, 0, 0);
    wr_u8(w, OP_REINIT);
    wr_u8(w, 1u | ((unsigned)(k + 1) << 3));
    wr_u8(w, 0);
    wr_u8(w, OP_RUN);
    wr_u16(w, 256);
    wr_u8(w, 0);
    seed_gen(w, 0, 6, 4, 16u + (uint32_t)k, 0, 0, 0);
    wr_u8(w, OP_STATUS_STR);
    wr_u32(w, (uint32_t)(-30 + k));
}

int fuzz_seed_count(void) { return N_PRESETS + 3; }

size_t fuzz_seed(int k, uint8_t *buf, size_t cap) {
    writer w;
    w.p = buf;
    w.n = 0;
    w.cap = cap;
    if (k < N_PRESETS) {
        wr_u8(&w, 1u | ((unsigned)k << 3));   /* preset k, no patches */
        wr_u8(&w, 0);
        wr_u8(&w, 0);   /* memory mode: plain */
        wr_u8(&w, 0xAB);
        seed_ops(&w, k);
    } else if (k == N_PRESETS) {
        /* the raw bytes of the default configuration */
        pyins_config c;
        pyins_config_default(&c);
        wr_u8(&w, 0);
        wr_bytes(&w, &c, sizeof c);
        wr_u8(&w, 0);
        wr_u8(&w, 0);
        seed_ops(&w, k);
    } else if (k == N_PRESETS + 1) {
        /* a refused configuration: NaN latitude on preset 1 */
        wr_u8(&w, 1u | (1u << 3));
        wr_u8(&w, 1);
        wr_u8(&w, 2);   /* field lat_rad */
        wr_u8(&w, 2);   /* NaN */
        wr_u8(&w, 0);
        wr_u8(&w, 0x5A);
        wr_u8(&w, 3);
        wr_u8(&w, 0x22);
    } else {
        /* preset 1 with patches towards the limits, then the usual ops */
        wr_u8(&w, 1u | (1u << 3));
        wr_u8(&w, 2);
        wr_u8(&w, 14);   /* fine_states = 8 */
        wr_u8(&w, 4 | (8u << 3));
        wr_u8(&w, 22);   /* index_scheme = flexible derived */
        wr_u8(&w, 4 | (6u << 3));
        wr_u8(&w, 0);
        wr_u8(&w, 0);
        seed_ops(&w, k);
    }
    return w.n;
}
