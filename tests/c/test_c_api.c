/* test_c_api.c: C99 test of the pyins C ABI contract: every status code,
 * rejected samples leave the state unchanged, sample-level faults (each
 * status, bit and counter), determinism, run == steps.
 * Prints one line per check and a closing "N passed, M failed" line. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pyins_core.h"

static int n_pass = 0;
static int n_fail = 0;

static void check(int ok, const char *what) {
    if (ok) {
        ++n_pass;
    } else {
        ++n_fail;
        printf("FAIL: %s\n", what);
    }
}

static void check_status(int got, int want, const char *what) {
    char buf[256];
    snprintf(buf, sizeof buf, "%s: got %d (%s), want %d", what, got, pyins_status_str(got), want);
    check(got == want, buf);
}

/* 16-byte aligned storage for one instance, plus room to misalign it. */
static unsigned char *aligned_mem(size_t size, unsigned char **raw) {
    *raw = (unsigned char *)malloc(size + 64);
    uintptr_t p = (uintptr_t)(*raw);
    p = (p + 63u) & ~(uintptr_t)63u;
    return (unsigned char *)p;
}

static pyins_sample static_sample(void) {
    /* Level, yaw 0, latitude 0: Earth rate along North (y), gravity up. */
    pyins_sample s;
    memset(&s, 0, sizeof s);
    s.dtheta_p_rad[1] = 7.2921151467e-5 * 0.01;
    s.dv_p_mps[2] = 9.7803253359 * 0.01;
    s.table_angle_rad = 0.0;
    return s;
}

/* Equal but for the sample-level fault bookkeeping (bits and counters). */
static int same_state(const pyins_output *a, const pyins_output *b) {
    pyins_output x = *a, y = *b;
    x.fault_flags = y.fault_flags = 0u;
    x.n_nonfinite = y.n_nonfinite = 0u;
    x.n_saturated = y.n_saturated = 0u;
    x.n_seq_gaps = y.n_seq_gaps = 0u;
    x.n_seq_bridged = y.n_seq_bridged = 0u;
    x.n_seq_repeats = y.n_seq_repeats = 0u;
    x.n_seq_lost = y.n_seq_lost = 0u;
    x.n_encoder_jumps = y.n_encoder_jumps = 0u;
    x.seq = y.seq = 0u;
    return memcmp(&x, &y, sizeof x) == 0;
}

static void sample_faults(unsigned char *mem, unsigned char *mem2, size_t size);

int main(void) {
    const size_t size = pyins_core_size();
    const size_t align = pyins_core_align();
    unsigned char *raw = NULL;
    unsigned char *mem = aligned_mem(size, &raw);
    pyins_config cfg;
    pyins_output out;
    int st;

    check(pyins_abi_version() == ((PYINS_ABI_VERSION_MAJOR << 16) | PYINS_ABI_VERSION_MINOR),
          "abi version matches header");
    check(pyins_sizeof_config() == sizeof(pyins_config), "sizeof config");
    check(pyins_sizeof_sample() == sizeof(pyins_sample), "sizeof sample");
    check(pyins_sizeof_output() == sizeof(pyins_output), "sizeof output");
    check(size > 0 && align >= 8 && (align & (align - 1)) == 0, "size and align sane");

    /* Status strings: every code has its own, unknown codes are named so. */
    {
        const int codes[] = {PYINS_OK, PYINS_E_NULL, PYINS_E_MISALIGNED, PYINS_E_MEM_TOO_SMALL,
                             PYINS_E_NOT_INIT, PYINS_E_SAMPLE_NONFINITE, PYINS_E_BAD_ARG,
                             PYINS_E_BUFFER_TOO_SMALL, PYINS_E_CONFIG_RATE,
                             PYINS_E_CONFIG_LAT, PYINS_E_CONFIG_LON, PYINS_E_CONFIG_HEIGHT,
                             PYINS_E_CONFIG_VEL, PYINS_E_CONFIG_ATT, PYINS_E_CONFIG_MODE,
                             PYINS_E_CONFIG_ALIGN_RATIO, PYINS_E_CONFIG_ALIGN_EARLY,
                             PYINS_E_CONFIG_ALIGN_LONG, PYINS_E_CONFIG_ALIGN_TICKS,
                             PYINS_E_CONFIG_FINE, PYINS_E_CONFIG_NOISE,
                             PYINS_E_CONFIG_INDEX_SCHEME, PYINS_E_CONFIG_INDEX_EMPTY,
                             PYINS_E_CONFIG_INDEX_RATE, PYINS_E_CONFIG_INDEX_DELTA,
                             PYINS_E_CONFIG_INDEX_STEP, PYINS_E_SNAPSHOT_SIZE,
                             PYINS_E_SNAPSHOT_VERSION, PYINS_E_SNAPSHOT_CORRUPT,
                             PYINS_E_SAMPLE_SATURATED, PYINS_E_CONFIG_SATURATION, PYINS_E_CONFIG_SEQ,
                             PYINS_E_CONFIG_INDEX_SUMS, PYINS_E_CONFIG_LEVER, PYINS_E_CONFIG_COARSE_METHOD,
                             PYINS_E_CONFIG_INTEGRITY,
                             PYINS_W_SEQ_GAP, PYINS_W_SEQ_REPEAT, PYINS_W_SEQ_LOST, PYINS_W_ENCODER_JUMP};
        const size_t n = sizeof codes / sizeof codes[0];
        size_t i, j;
        int distinct = 1;
        for (i = 0; i < n; ++i) {
            for (j = i + 1; j < n; ++j) {
                if (codes[i] == codes[j] || strcmp(pyins_status_str(codes[i]), pyins_status_str(codes[j])) == 0) {
                    distinct = 0;
                }
            }
            check(strstr(pyins_status_str(codes[i]), "unknown") == NULL, "status has a name");
        }
        check(distinct, "status codes and strings distinct");
        check(strstr(pyins_status_str(-999), "unknown") != NULL, "unknown status named");
        /* Pinned values: never renumbered. */
        check(PYINS_E_NULL == -1 && PYINS_E_MISALIGNED == -2 && PYINS_E_MEM_TOO_SMALL == -3 &&
              PYINS_E_NOT_INIT == -4 && PYINS_E_SAMPLE_NONFINITE == -5 && PYINS_E_CONFIG_RATE == -10 &&
              PYINS_E_CONFIG_LAT == -11 && PYINS_E_CONFIG_MODE == -16, "pinned status values");
        check(PYINS_E_SNAPSHOT_CORRUPT == -30 && PYINS_E_SAMPLE_SATURATED == -31 &&
              PYINS_E_CONFIG_SATURATION == -32 && PYINS_E_CONFIG_SEQ == -33 && PYINS_E_CONFIG_INDEX_SUMS == -34 &&
              PYINS_E_CONFIG_LEVER == -35 && PYINS_E_CONFIG_COARSE_METHOD == -36 &&
              PYINS_E_CONFIG_INTEGRITY == -37 && PYINS_FAULT_ALIGN_INCONSISTENT == 256 &&
              PYINS_FAULT_COARSE_UNSETTLED == 512 &&
              PYINS_W_SEQ_GAP == 1 &&
              PYINS_W_SEQ_REPEAT == 2 && PYINS_W_SEQ_LOST == 3 && PYINS_W_ENCODER_JUMP == 4,
              "pinned sample-level status values");
        check(PYINS_FAULT_SAMPLE_NONFINITE == 4 && PYINS_FAULT_SAMPLE_SATURATED == 8 && PYINS_FAULT_SEQ_GAP == 16 &&
              PYINS_FAULT_SEQ_REPEAT == 32 && PYINS_FAULT_SEQ_LOST == 64 && PYINS_FAULT_ENCODER_JUMP == 128,
              "pinned fault bits");
        check(sizeof(pyins_sample) == 64 && offsetof(pyins_sample, seq) == 56 && sizeof(pyins_output) % 8 == 0,
              "sample and output layout");
    }

    /* Config: defaults, zeroed == defaults, each bad field its own status. */
    check_status(pyins_config_default(NULL), PYINS_E_NULL, "config_default(NULL)");
    check_status(pyins_config_check(NULL), PYINS_E_NULL, "config_check(NULL)");
    check_status(pyins_config_default(&cfg), PYINS_OK, "config_default");
    check_status(pyins_config_check(&cfg), PYINS_OK, "default config valid");
    {
        pyins_config z;
        memset(&z, 0, sizeof z);
        check_status(pyins_config_check(&z), PYINS_OK, "zeroed config valid");
    }
#define BAD_CFG(field_stmt, want, what)              \
    do {                                             \
        pyins_config b;                              \
        pyins_config_default(&b);                    \
        field_stmt;                                  \
        check_status(pyins_config_check(&b), want, what); \
        memset(mem, 0xAB, size);                     \
        check_status(pyins_init(mem, size, &b), want, "init " what); \
        check_status(pyins_step((pyins_core *)mem, NULL, &out), PYINS_E_NOT_INIT, "no instance after failed init " what); \
    } while (0)
    BAD_CFG(b.tick_hz = -100, PYINS_E_CONFIG_RATE, "negative tick_hz");
    BAD_CFG(b.tick_hz = 20000, PYINS_E_CONFIG_RATE, "tick_hz too high");
    BAD_CFG(b.lat_rad = 1.6, PYINS_E_CONFIG_LAT, "latitude beyond 90 deg");
    BAD_CFG(b.lat_rad = -1.6, PYINS_E_CONFIG_LAT, "latitude beyond -90 deg");
    BAD_CFG(b.lat_rad = NAN, PYINS_E_CONFIG_LAT, "latitude NaN");
    BAD_CFG(b.lon_rad = INFINITY, PYINS_E_CONFIG_LON, "longitude Inf");
    BAD_CFG(b.height_m = 1e6, PYINS_E_CONFIG_HEIGHT, "height too high");
    BAD_CFG(b.vel_n_mps[1] = NAN, PYINS_E_CONFIG_VEL, "velocity NaN");
    BAD_CFG(b.euler_b_rad[2] = INFINITY, PYINS_E_CONFIG_ATT, "yaw Inf");
    BAD_CFG(b.table_angle_rad = NAN, PYINS_E_CONFIG_ATT, "table angle NaN");
    BAD_CFG(b.vertical_mode = 7, PYINS_E_CONFIG_MODE, "vertical mode unknown");
    BAD_CFG((b.coarse_ticks = 15000, b.coarse_ratio = 1.0), PYINS_E_CONFIG_ALIGN_RATIO, "ratio 1");
    BAD_CFG((b.coarse_ticks = 15000, b.coarse_ratio = -0.25), PYINS_E_CONFIG_ALIGN_RATIO, "ratio negative");
    BAD_CFG((b.coarse_ticks = 15000, b.coarse_ratio = NAN), PYINS_E_CONFIG_ALIGN_RATIO, "ratio NaN");
    BAD_CFG((b.coarse_ticks = 15000, b.coarse_first_output_ticks = 150), PYINS_E_CONFIG_ALIGN_EARLY,
            "first output before enough data");
    BAD_CFG((b.coarse_ticks = 15000, b.coarse_ratio = 0.01), PYINS_E_CONFIG_ALIGN_EARLY,
            "ratio too small for the first output");
    BAD_CFG(b.coarse_ticks = 30000, PYINS_E_CONFIG_ALIGN_LONG, "coarse alignment beyond storage");
    BAD_CFG(b.coarse_ticks = -1, PYINS_E_CONFIG_ALIGN_TICKS, "negative coarse duration");
    BAD_CFG((b.coarse_ticks = 1000, b.coarse_first_output_ticks = 2000), PYINS_E_CONFIG_ALIGN_TICKS,
            "first output after the end");
    BAD_CFG(b.fine_ticks = -5, PYINS_E_CONFIG_ALIGN_TICKS, "negative fine duration");
    BAD_CFG((b.fine_ticks = 1000, b.fine_states = 6), PYINS_E_CONFIG_FINE, "fine_states 6");
    BAD_CFG((b.fine_ticks = 1000, b.fine_meas_every_ticks = -1), PYINS_E_CONFIG_FINE, "negative update interval");
    BAD_CFG((b.fine_ticks = 1000, b.fine_correction = 3), PYINS_E_CONFIG_FINE, "unknown correction");
    BAD_CFG((b.fine_ticks = 1000, b.fine_gyro_arw = -1e-6), PYINS_E_CONFIG_NOISE, "negative gyro ARW");
    BAD_CFG((b.fine_ticks = 1000, b.fine_accel_vrw = NAN), PYINS_E_CONFIG_NOISE, "NaN accel VRW");
    BAD_CFG((b.fine_ticks = 1000, b.fine_sigma0_att_rad[2] = -1.0), PYINS_E_CONFIG_NOISE, "negative sigma0");
    BAD_CFG(b.index_scheme = 9, PYINS_E_CONFIG_INDEX_SCHEME, "unknown indexing scheme");
    BAD_CFG((b.index_scheme = PYINS_INDEX_FLEXIBLE_DERIVED, b.index_delta = -1.0), PYINS_E_CONFIG_INDEX_DELTA,
            "derived flexible scheme with negative delta");
    BAD_CFG((b.index_scheme = PYINS_INDEX_CUSTOM, b.index_n_steps = 0), PYINS_E_CONFIG_INDEX_EMPTY,
            "empty custom scheme");
    BAD_CFG((b.index_scheme = PYINS_INDEX_CUSTOM, b.index_n_steps = 1, b.index_steps[0].stop_ticks = 100,
             b.index_steps[0].kind = PYINS_INDEX_FIXED, b.index_steps[0].angle_rad = 3.14,
             b.index_rate_rad_s = 0.0, b.index_accel_rad_s2 = 1.0, b.index_delta = 0.01),
            PYINS_E_CONFIG_INDEX_RATE, "custom scheme with zero rate");
    BAD_CFG((b.index_scheme = PYINS_INDEX_CUSTOM, b.index_n_steps = 1, b.index_steps[0].stop_ticks = 100,
             b.index_steps[0].kind = PYINS_INDEX_FLEX_COS, b.index_steps[0].angle_rad = 1.0,
             b.index_rate_rad_s = 0.1, b.index_accel_rad_s2 = 1.0, b.index_delta = 0.0),
            PYINS_E_CONFIG_INDEX_DELTA, "flexible custom scheme with delta 0");
    BAD_CFG((b.index_scheme = PYINS_INDEX_FLEXIBLE_TWO, b.index_delta = -0.01), PYINS_E_CONFIG_INDEX_DELTA,
            "negative delta");
    BAD_CFG((b.index_scheme = PYINS_INDEX_TWO_POSITION, b.index_rate_rad_s = -0.1), PYINS_E_CONFIG_INDEX_RATE,
            "negative rate");
    BAD_CFG((b.index_scheme = PYINS_INDEX_CUSTOM, b.index_n_steps = 1, b.index_steps[0].stop_ticks = 0,
             b.index_steps[0].kind = PYINS_INDEX_FIXED, b.index_steps[0].angle_rad = 3.14,
             b.index_rate_rad_s = 0.1, b.index_accel_rad_s2 = 1.0), PYINS_E_CONFIG_INDEX_STEP,
            "custom step with no stop");
    BAD_CFG(b.seq_mode = 2, PYINS_E_CONFIG_SEQ, "unknown seq mode");
    BAD_CFG(b.seq_mode = -1, PYINS_E_CONFIG_SEQ, "negative seq mode");
    BAD_CFG(b.seq_max_gap_ticks = -1, PYINS_E_CONFIG_SEQ, "negative seq gap");
    BAD_CFG(b.seq_max_gap_ticks = 101, PYINS_E_CONFIG_SEQ, "seq gap beyond 100 ticks");
    BAD_CFG(b.index_sums = 2, PYINS_E_CONFIG_INDEX_SUMS, "unknown index_sums");
    BAD_CFG(b.index_sums = -1, PYINS_E_CONFIG_INDEX_SUMS, "negative index_sums");
    BAD_CFG((b.index_scheme = PYINS_INDEX_NONE, b.index_sums = 7), PYINS_E_CONFIG_INDEX_SUMS,
            "unknown index_sums refused even without rotation");
    BAD_CFG(b.sat_gyro_rad = -0.1, PYINS_E_CONFIG_SATURATION, "negative gyro saturation");
    BAD_CFG(b.sat_gyro_rad = NAN, PYINS_E_CONFIG_SATURATION, "NaN gyro saturation");
    BAD_CFG(b.sat_accel_mps = INFINITY, PYINS_E_CONFIG_SATURATION, "Inf accel saturation");
    BAD_CFG(b.sat_accel_mps = -1.0, PYINS_E_CONFIG_SATURATION, "negative accel saturation");
    BAD_CFG(b.lever_b_m[1] = NAN, PYINS_E_CONFIG_LEVER, "NaN lever arm");
    BAD_CFG(b.lever_p_m[2] = INFINITY, PYINS_E_CONFIG_LEVER, "Inf sensor offset");
    BAD_CFG((b.lever_b_m[0] = 60.0, b.lever_b_m[1] = 60.0, b.lever_b_m[2] = 60.0), PYINS_E_CONFIG_LEVER,
            "lever arm of 104 m (60 m per axis)");
    BAD_CFG(b.lever_p_m[0] = -100.5, PYINS_E_CONFIG_LEVER, "sensor offset longer than 100 m");
    {
        /* 98.5 m and exactly 100 m are accepted */
        pyins_config g;
        pyins_config_default(&g);
        g.lever_b_m[0] = 60.0;
        g.lever_b_m[1] = 60.0;
        g.lever_b_m[2] = 50.0;
        check_status(pyins_config_check(&g), PYINS_OK, "lever arm of 98.5 m accepted");
        pyins_config_default(&g);
        g.lever_p_m[2] = -100.0;
        check_status(pyins_config_check(&g), PYINS_OK, "sensor offset of exactly 100 m accepted");
    }
    BAD_CFG(b.coarse_method = 4, PYINS_E_CONFIG_COARSE_METHOD, "unknown coarse method");
    /* under way the navigation filter aligns finely: no static fine filter, no UNDAMPED */
    BAD_CFG((b.coarse_method = PYINS_COARSE_FIT_VEL, b.coarse_ticks = 12000, b.fine_ticks = 6000),
            PYINS_E_CONFIG_COARSE_METHOD, "FIT_VEL with a fine alignment");
    BAD_CFG((b.coarse_method = PYINS_COARSE_FIT_VEL, b.coarse_ticks = 12000, b.fine_ticks = 0,
             b.nav_mode = PYINS_NAV_UNDAMPED),
            PYINS_E_CONFIG_COARSE_METHOD, "FIT_VEL navigating undamped");
    {
        pyins_config g;
        pyins_config_default(&g);
        g.coarse_method = PYINS_COARSE_FIT_VEL;
        g.coarse_ticks = 12000;
        g.fine_ticks = 0;
        check_status(pyins_config_check(&g), PYINS_OK, "FIT_VEL into the navigation filter accepted");
    }
    {
        pyins_config g;
        pyins_config_default(&g);
        g.coarse_method = PYINS_COARSE_EQ8;
        check_status(pyins_config_check(&g), PYINS_OK, "seed 000 eq. 8 as printed accepted");
    }
    BAD_CFG(b.coarse_method = -1, PYINS_E_CONFIG_COARSE_METHOD, "negative coarse method");
    BAD_CFG((b.coarse_method = PYINS_COARSE_FIT, b.coarse_ticks = 3000, b.coarse_first_output_ticks = 700),
            PYINS_E_CONFIG_ALIGN_EARLY, "FIT with fewer than 8 grid intervals at its first output");
    BAD_CFG(b.fine_states = 11, PYINS_E_CONFIG_FINE, "fine_states 11");
    BAD_CFG(b.fine_pos_sigma_m = -0.5, PYINS_E_CONFIG_NOISE, "negative wave displacement sigma");
    BAD_CFG(b.fine_sigma0_vel_mps = NAN, PYINS_E_CONFIG_NOISE, "NaN initial velocity sigma");
    BAD_CFG(b.fine_site_accel = -1e-3, PYINS_E_CONFIG_NOISE, "negative site acceleration density");
    BAD_CFG(b.fine_site_accel = NAN, PYINS_E_CONFIG_NOISE, "NaN site acceleration density");
    BAD_CFG(b.integrity_nis_window = -2, PYINS_E_CONFIG_INTEGRITY, "NIS window below -1");
    BAD_CFG(b.integrity_nis_max = -1.0, PYINS_E_CONFIG_INTEGRITY, "negative NIS bound");
    BAD_CFG(b.integrity_nis_max = NAN, PYINS_E_CONFIG_INTEGRITY, "NaN NIS bound");
    BAD_CFG(b.integrity_coarse_rad = INFINITY, PYINS_E_CONFIG_INTEGRITY, "Inf wander bound");
    BAD_CFG(b.integrity_coarse_rad = -0.01, PYINS_E_CONFIG_INTEGRITY, "negative wander bound");
    {
        /* FIT has no length limit (its grid halves when full); TRIAD keeps it */
        pyins_config g;
        pyins_config_default(&g);
        g.coarse_method = PYINS_COARSE_FIT;
        g.coarse_ticks = 60000;
        check_status(pyins_config_check(&g), PYINS_OK, "FIT of 600 s on 1 s outputs accepted");
        g.coarse_method = PYINS_COARSE_TRIAD;
        check_status(pyins_config_check(&g), PYINS_E_CONFIG_ALIGN_LONG, "TRIAD of 600 s refused");
        pyins_config_default(&g);
        g.integrity_nis_window = -1;
        check_status(pyins_config_check(&g), PYINS_OK, "NIS test off accepted");
        pyins_config_default(&g);
        g.fine_ticks = 1000;
        g.fine_states = 12;
        check_status(pyins_config_check(&g), PYINS_OK, "the moving-base filter accepted");
    }
    {
        pyins_config g;
        pyins_config_default(&g);
        g.seq_mode = PYINS_SEQ_CHECK;
        g.seq_max_gap_ticks = 100;
        g.sat_gyro_rad = 1e-9;
        g.sat_accel_mps = 1e3;
        check_status(pyins_config_check(&g), PYINS_OK, "seq and saturation limits in range");
    }

    /* init: NULL, misaligned, too small. */
    check_status(pyins_init(NULL, size, &cfg), PYINS_E_NULL, "init NULL mem");
    check_status(pyins_init(mem, size, NULL), PYINS_E_NULL, "init NULL config");
    check_status(pyins_init(mem + 1, size, &cfg), PYINS_E_MISALIGNED, "init misaligned");
    check_status(pyins_init(mem, size - 1, &cfg), PYINS_E_MEM_TOO_SMALL, "init too small");
    memset(mem, 0, size);
    check_status(pyins_step((pyins_core *)mem, NULL, &out), PYINS_E_NOT_INIT, "step on zeroed memory");

    /* A good instance. */
    cfg.lat_rad = 0.0;
    check_status(pyins_init(mem, size, &cfg), PYINS_OK, "init");
    {
        pyins_core *core = (pyins_core *)mem;
        pyins_sample s = static_sample();
        pyins_output before, after;
        size_t n_done = 99;
        check_status(pyins_step(NULL, &s, &out), PYINS_E_NULL, "step NULL core");
        check_status(pyins_step((pyins_core *)(mem + 1), &s, &out), PYINS_E_MISALIGNED, "step misaligned core");
        check_status(pyins_step(core, NULL, &out), PYINS_E_NULL, "step NULL sample");
        check_status(pyins_step(core, &s, NULL), PYINS_E_NULL, "step NULL output");
        check_status(pyins_get_output(core, NULL), PYINS_E_NULL, "get_output NULL");
        check_status(pyins_get_output(NULL, &out), PYINS_E_NULL, "get_output NULL core");
        check_status(pyins_get_motor_command(core, NULL), PYINS_E_NULL, "get_motor_command NULL");
        check_status(pyins_get_motor_command(NULL, (pyins_motor_command *)&out), PYINS_E_NULL,
                     "get_motor_command NULL core");
        check_status(pyins_run(core, NULL, 3, NULL, &n_done), PYINS_E_NULL, "run NULL samples");
        check(n_done == 0, "run NULL samples: n_done 0");
        check_status(pyins_run(core, NULL, 0, NULL, NULL), PYINS_OK, "run zero samples");

        check_status(pyins_step(core, &s, &out), PYINS_OK, "step");
        check(out.tick == 1 && out.mode == PYINS_MODE_NAVIGATE && out.fault_flags == 0u, "tick, mode, faults after one step");
        check_status(pyins_get_output(core, &before), PYINS_OK, "get_output");
        /* Each non-finite field rejected; state untouched but for the fault
         * bit and counter. */
        {
            int f;
            for (f = 0; f < 7; ++f) {
                pyins_sample bad = s;
                double *fields[7] = {&bad.dtheta_p_rad[0], &bad.dtheta_p_rad[1], &bad.dtheta_p_rad[2],
                                     &bad.dv_p_mps[0], &bad.dv_p_mps[1], &bad.dv_p_mps[2],
                                     &bad.table_angle_rad};
                *fields[f] = (f % 2) ? NAN : -INFINITY;
                check_status(pyins_step(core, &bad, &out), PYINS_E_SAMPLE_NONFINITE, "non-finite sample rejected");
                check(same_state(&out, &before), "rejected sample: output shows unchanged state");
                check(out.n_nonfinite == (uint32_t)f + 1u && out.fault_flags == PYINS_FAULT_SAMPLE_NONFINITE,
                      "non-finite sample: bit and counter");
            }
        }
        check_status(pyins_get_output(core, &after), PYINS_OK, "get_output after rejects");
        check(same_state(&before, &after), "rejected samples leave the state unchanged");

        /* run stops at a bad sample and says where. */
        {
            pyins_sample batch[5];
            pyins_output outs[5];
            int i;
            for (i = 0; i < 5; ++i) batch[i] = s;
            batch[3].dv_p_mps[0] = NAN;
            check_status(pyins_run(core, batch, 5, outs, &n_done), PYINS_E_SAMPLE_NONFINITE, "run with NaN at 3");
            check(n_done == 3, "run: n_done == 3");
            check(outs[2].tick == 4, "run: outputs before the bad sample written");
        }
    }

    /* Determinism: two instances, same stream: identical bits; run == steps. */
    {
        enum { N = 1000 };
        static pyins_sample samples[N];
        static pyins_output a[N], b[N];
        unsigned char *raw2 = NULL;
        unsigned char *mem2 = aligned_mem(size, &raw2);
        int i;
        uint64_t x = 0x9E3779B97F4A7C15ull;
        for (i = 0; i < N; ++i) {
            int k;
            samples[i] = static_sample();
            for (k = 0; k < 3; ++k) {
                x ^= x << 13; x ^= x >> 7; x ^= x << 17;
                samples[i].dtheta_p_rad[k] += 1e-4 * ((double)(x >> 11) / 9007199254740992.0 - 0.5);
                samples[i].dv_p_mps[k] += 1e-3 * ((double)(x >> 12) / 4503599627370496.0 - 0.5);
            }
            samples[i].table_angle_rad = 0.01 * i - 6.283185307179586 * (double)(int)(0.01 * i / 6.283185307179586);
        }
        pyins_config_default(&cfg);
        cfg.lat_rad = 0.6;
        cfg.euler_b_rad[2] = 1.0;
        check_status(pyins_init(mem, size, &cfg), PYINS_OK, "init A");
        check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "init B");
        check_status(pyins_run((pyins_core *)mem, samples, N, a, NULL), PYINS_OK, "run A");
        for (i = 0; i < N; ++i) {
            if (pyins_step((pyins_core *)mem2, &samples[i], &b[i]) != PYINS_OK) break;
        }
        check(i == N, "step B all accepted");
        check(memcmp(a, b, sizeof a) == 0, "N single steps == one N-sample run, bit for bit");

        /* Snapshot at 400, restore into fresh memory, continue: same bits. */
        {
            const size_t snap = pyins_snapshot_size();
            unsigned char *blob = (unsigned char *)malloc(snap);
            unsigned char *raw3 = NULL;
            unsigned char *mem3 = aligned_mem(size, &raw3);
            static pyins_output c[N];
            pyins_output before3, after3;
            check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "init D");
            check_status(pyins_run((pyins_core *)mem2, samples, 400, c, NULL), PYINS_OK, "run to 400");
            check_status(pyins_snapshot((pyins_core *)mem2, blob, snap - 1), PYINS_E_SNAPSHOT_SIZE, "snapshot buffer too small");
            check_status(pyins_snapshot((pyins_core *)mem2, blob, snap), PYINS_OK, "snapshot");
            memset(mem3, 0, size);
            check_status(pyins_restore(mem3, size, blob, snap), PYINS_OK, "restore");
            check_status(pyins_run((pyins_core *)mem3, samples + 400, N - 400, c + 400, NULL), PYINS_OK, "run on");
            check(memcmp(c + 400, a + 400, (N - 400) * sizeof c[0]) == 0, "restored run == uninterrupted, bit for bit");
            pyins_get_output((pyins_core *)mem3, &before3);
            check_status(pyins_restore(mem3, size, blob, snap - 1), PYINS_E_SNAPSHOT_SIZE, "truncated snapshot");
            blob[8] ^= 0x01u;   /* ABI version field */
            check_status(pyins_restore(mem3, size, blob, snap), PYINS_E_SNAPSHOT_VERSION, "wrong-version snapshot");
            blob[8] ^= 0x01u;
            blob[100] ^= 0x40u; /* a payload byte */
            check_status(pyins_restore(mem3, size, blob, snap), PYINS_E_SNAPSHOT_CORRUPT, "corrupted snapshot");
            blob[100] ^= 0x40u;
            blob[0] = 'X';
            check_status(pyins_restore(mem3, size, blob, snap), PYINS_E_SNAPSHOT_CORRUPT, "bad magic");
            pyins_get_output((pyins_core *)mem3, &after3);
            check(memcmp(&before3, &after3, sizeof before3) == 0, "refused snapshots leave the state untouched");
            check_status(pyins_restore(mem3 + 1, size, blob, snap), PYINS_E_MISALIGNED, "restore misaligned");
            check_status(pyins_restore(mem3, size - 1, blob, snap), PYINS_E_MEM_TOO_SMALL, "restore too small");
            free(raw3);
            free(blob);
        }

        /* Decimated runs: records at ticks that are multiples of out_every,
         * equal to the full run's records, whatever the chunking. */
        {
            static pyins_output d[N / 7 + 2];
            size_t nd = 0, no = 0, total = 0, start = 0;
            const size_t chunks[] = {1, 13, 250, 736};
            size_t c;
            int same = 1;
            check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "init C");
            check_status(pyins_run_decimated((pyins_core *)mem2, samples, 10, 0, d, 10, &nd, &no),
                         PYINS_E_BAD_ARG, "run_decimated out_every 0");
            check_status(pyins_run_decimated((pyins_core *)mem2, samples, 100, 7, d, 14, &nd, &no),
                         PYINS_E_BUFFER_TOO_SMALL, "run_decimated capacity too small");
            check(nd == 0 && no == 0, "refused run_decimated stepped nothing");
            check_status(pyins_run_decimated((pyins_core *)mem2, NULL, 5, 7, d, 14, &nd, &no),
                         PYINS_E_NULL, "run_decimated NULL samples");
            for (c = 0; c < 4; ++c) {
                check_status(pyins_run_decimated((pyins_core *)mem2, samples + start, chunks[c], 7,
                                                 d + total, N / 7 + 2 - total, &nd, &no),
                             PYINS_OK, "run_decimated chunk");
                start += chunks[c];
                total += no;
            }
            check(start == N && total == N / 7, "decimated record count");
            for (c = 0; c < total; ++c) {
                if (memcmp(&d[c], &a[7 * (c + 1) - 1], sizeof d[c]) != 0 || d[c].tick != (int64_t)(7 * (c + 1))) {
                    same = 0;
                }
            }
            check(same, "decimated records equal the full run's at ticks 7, 14, ...");
        }

        /* Compact records (pyins_run_nav): the same ticks as the decimated
         * run, each field the full record's, bit for bit. */
        {
            static pyins_nav v[N / 7 + 2];
            pyins_nav last;
            size_t nd = 0, no = 0, c;
            int same = 1;
            check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "init C (compact)");
            check_status(pyins_run_nav((pyins_core *)mem2, samples, 10, 0, v, 10, &nd, &no),
                         PYINS_E_BAD_ARG, "run_nav out_every 0");
            check_status(pyins_run_nav((pyins_core *)mem2, samples, 100, 7, v, 14, &nd, &no),
                         PYINS_E_BUFFER_TOO_SMALL, "run_nav capacity too small");
            check(nd == 0 && no == 0, "refused run_nav stepped nothing");
            check_status(pyins_run_nav((pyins_core *)mem2, samples, 5, 7, NULL, 14, &nd, &no),
                         PYINS_E_NULL, "run_nav NULL records");
            check_status(pyins_get_nav((const pyins_core *)mem2, NULL), PYINS_E_NULL, "get_nav NULL");
            check_status(pyins_get_nav(NULL, &last), PYINS_E_NULL, "get_nav NULL core");
            check_status(pyins_run_nav((pyins_core *)mem2, samples, N, 7, v, N / 7 + 2, &nd, &no),
                         PYINS_OK, "run_nav");
            check(nd == N && no == N / 7, "compact record count");
            for (c = 0; c < no; ++c) {
                const pyins_output *o = &a[7 * (c + 1) - 1];
                if (v[c].tick != o->tick || v[c].mode != o->mode || v[c].fault_flags != o->fault_flags ||
                    v[c].state_flags != o->state_flags || v[c].index_state != o->index_state ||
                    memcmp(&v[c].lat_rad, &o->lat_rad, 6 * sizeof(double)) != 0 ||
                    memcmp(v[c].quat_nb, o->quat_nb, 8 * sizeof(double)) != 0 ||
                    memcmp(&v[c].table_angle_rad, &o->table_angle_rad, sizeof(double)) != 0 ||
                    memcmp(&v[c].motor_rate_cmd_rad_s, &o->motor_rate_cmd_rad_s, 2 * sizeof(double)) != 0) {
                    same = 0;
                }
            }
            check(same, "compact records are the full records' fields");
            check_status(pyins_get_nav((const pyins_core *)mem2, &last), PYINS_OK, "get_nav");
            check(last.tick == (int64_t)N, "get_nav: the state after the run");
        }
        free(raw2);
    }

    {
        unsigned char *raw2 = NULL;
        unsigned char *mem2 = aligned_mem(size, &raw2);
        sample_faults(mem, mem2, size);
        free(raw2);
    }

    free(raw);
    printf("%d passed, %d failed\n", n_pass, n_fail);
    return n_fail == 0 ? 0 : 1;
}

/* Sample-level faults (docs/core.md): each status, its sticky bit and
 * counter, and the documented behaviour, on a static base at latitude 0
 * (uniform motion: a bridged gap is exact). */
static void sample_faults(unsigned char *mem, unsigned char *mem2, size_t size) {
    pyins_core *core = (pyins_core *)mem;
    pyins_core *full = (pyins_core *)mem2;
    pyins_config cfg;
    pyins_sample s = static_sample();
    pyins_output out, ref, before;
    uint32_t k;
    int i;
    pyins_config_default(&cfg);
    cfg.seq_mode = PYINS_SEQ_CHECK;
    check_status(pyins_init(mem, size, &cfg), PYINS_OK, "faults: init");
    check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "faults: init reference");
    for (k = 1; k <= 10; ++k) {
        s.seq = k;
        pyins_step(core, &s, &out);
        pyins_step(full, &s, &ref);
    }
    check(out.fault_flags == 0u && out.tick == 10 && out.seq == 10u, "faults: clean start");

    /* Saturation: at the limit rejected, just below taken. */
    {
        const double lim = 400.0 * 3.14159265358979323846 / 180.0 / 100.0;   /* default, 100 Hz */
        pyins_sample bad = s;
        pyins_get_output(core, &before);
        bad.seq = 11u;
        bad.dtheta_p_rad[2] = -lim;
        check_status(pyins_step(core, &bad, &out), PYINS_E_SAMPLE_SATURATED, "gyro at the saturation limit rejected");
        check(same_state(&out, &before) && out.n_saturated == 1u && out.fault_flags == PYINS_FAULT_SAMPLE_SATURATED,
              "saturated: state held, bit and counter");
        bad = s;
        bad.seq = 11u;
        bad.dv_p_mps[0] = 20.0 * 9.80665 / 100.0;
        check_status(pyins_step(core, &bad, &out), PYINS_E_SAMPLE_SATURATED, "accel at the saturation limit rejected");
        check(out.n_saturated == 2u && out.tick == 10, "second saturated sample counted, tick held");
        /* the hole left by the rejected seq 11 is bridged by seq 12: uniform motion, exact */
        s.seq = 11u;
        pyins_step(full, &s, &ref);
        s.seq = 12u;
        pyins_step(full, &s, &ref);
        check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_GAP, "sample after a rejected one bridges it");
        check(out.tick == 12 && out.n_seq_gaps == 1u && out.n_seq_bridged == 1u &&
              (out.fault_flags & PYINS_FAULT_SEQ_GAP) && same_state(&out, &ref),
              "bridged rejected sample == full data (uniform motion)");
        bad = s;
        bad.seq = 13u;
        bad.dtheta_p_rad[0] = 0.999 * lim;
        bad.dv_p_mps[1] = -0.999 * 20.0 * 9.80665 / 100.0;
        {
            pyins_output o2;
            check_status(pyins_step(core, &bad, &o2), PYINS_OK, "just below the saturation limits taken");
            check(o2.n_saturated == 2u, "no saturation counted below the limit");
        }
        /* resynchronise the reference with a fresh pair */
        check_status(pyins_init(mem, size, &cfg), PYINS_OK, "faults: re-init");
        check_status(pyins_init(mem2, size, &cfg), PYINS_OK, "faults: re-init reference");
        s = static_sample();
        for (k = 1; k <= 10; ++k) {
            s.seq = k;
            pyins_step(core, &s, &out);
            pyins_step(full, &s, &ref);
        }
    }

    /* Gap of 2 (the default maximum): bridged, time right, exact on uniform motion. */
    for (k = 11; k <= 13; ++k) {
        s.seq = k;
        pyins_step(full, &s, &ref);
    }
    s.seq = 13u;
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_GAP, "gap of 2 ticks");
    check(out.tick == 13 && out.n_seq_gaps == 1u && out.n_seq_bridged == 2u && out.seq == 13u &&
          out.fault_flags == PYINS_FAULT_SEQ_GAP, "gap: tick, counters, bit");
    check(same_state(&out, &ref), "bridged gap == full data (uniform motion)");

    /* Duplicate and a sample up to the maximum gap behind: dropped, state unchanged. */
    pyins_get_output(core, &before);
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_REPEAT, "repeated seq");
    check(same_state(&out, &before) && out.n_seq_repeats == 1u && (out.fault_flags & PYINS_FAULT_SEQ_REPEAT),
          "duplicate dropped: state unchanged, bit and counter");
    s.seq = 11u;
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_REPEAT, "seq 2 behind: a repeat");
    check(same_state(&out, &before) && out.n_seq_repeats == 2u && out.seq == 13u, "older sample dropped");

    /* Beyond the maximum gap: taken without bridging, resynchronised. */
    s.seq = 17u;
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_LOST, "gap of 3 > 2: sequence lost");
    check(out.tick == 17 && out.n_seq_lost == 1u && out.n_seq_bridged == 2u && out.seq == 17u &&
          (out.fault_flags & PYINS_FAULT_SEQ_LOST), "lost: time right, nothing bridged, bit and counter");
    s.seq = 18u;
    check_status(pyins_step(core, &s, &out), PYINS_OK, "resynchronised: next seq clean");
    s.seq = 5u;   /* an IMU restart: far behind */
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_LOST, "backward jump beyond the window: lost");
    check(out.tick == 19 && out.n_seq_lost == 2u, "backward jump: one tick (outage unknown)");

    /* Wrap at 2^32: the next of 0xFFFFFFFF is 0. */
    s.seq = 0xFFFFFFFFu;
    pyins_step(core, &s, &out);
    s.seq = 0u;
    check_status(pyins_step(core, &s, &out), PYINS_OK, "seq wraps from 2^32 - 1 to 0");
    s.seq = 2u;
    check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_GAP, "gap across zero");

    /* Encoder jump: taken, bit and counter. */
    {
        pyins_sample j = s;
        j.seq = 3u;
        j.table_angle_rad = 0.2;   /* > 5 deg in one tick */
        check_status(pyins_step(core, &j, &out), PYINS_W_ENCODER_JUMP, "encoder jump");
        check(out.n_encoder_jumps == 1u && (out.fault_flags & PYINS_FAULT_ENCODER_JUMP) &&
              fabs(out.table_angle_rad - 0.2) < 1e-15, "encoder jump: reading taken, bit and counter");
        j.seq = 4u;
        j.table_angle_rad = 0.2 + 0.08;   /* < 5 deg */
        check_status(pyins_step(core, &j, &out), PYINS_OK, "encoder change within the limit");
        j.seq = 6u;
        j.table_angle_rad = 0.2 + 0.08 + 0.16;   /* < 2 x 5 deg over a gap of one tick */
        check_status(pyins_step(core, &j, &out), PYINS_W_SEQ_GAP, "encoder change scaled by the gap");
        check(out.n_encoder_jumps == 1u, "no jump over a bridged gap within the limit");
    }
    check(out.fault_flags == (PYINS_FAULT_SEQ_GAP | PYINS_FAULT_SEQ_REPEAT | PYINS_FAULT_SEQ_LOST |
                              PYINS_FAULT_ENCODER_JUMP), "sticky bits accumulate");

    /* Batch calls go on through notices and stop at a rejected sample. */
    {
        pyins_sample batch[6];
        pyins_output outs[6];
        size_t n_done = 0;
        for (i = 0; i < 6; ++i) {
            batch[i] = s;
            batch[i].table_angle_rad = out.table_angle_rad;
            batch[i].seq = 7u + (uint32_t)i;
        }
        batch[1].seq = 7u;                 /* duplicate */
        batch[2].seq = 10u;                /* after 7: 8 and 9 missing */
        batch[4].dtheta_p_rad[0] = 1.0;    /* saturated */
        check_status(pyins_run(core, batch, 6, outs, &n_done), PYINS_E_SAMPLE_SATURATED, "run stops at a saturated sample");
        check(n_done == 4 && outs[1].n_seq_repeats == 3u && outs[2].n_seq_bridged == 2u + 1u + 1u + 2u,
              "run went on through the duplicate and the gap");
    }

    /* Decimated runs: a bridged gap passing a multiple writes its record;
     * more multiples than n / out_every + 1 stop before an overflow. */
    {
        pyins_sample batch[8];
        pyins_output outs[8];
        size_t n_done = 0, n_out = 0;
        int64_t t0;
        pyins_config c2 = cfg;
        c2.seq_max_gap_ticks = 100;
        check_status(pyins_init(mem, size, &c2), PYINS_OK, "decimated: init");
        s = static_sample();
        for (i = 0; i < 8; ++i) {
            batch[i] = s;
            batch[i].seq = 1u + 10u * (uint32_t)i;   /* every sample 10 ticks on */
        }
        /* 8 samples, every 10 ticks: capacity 8 / 10 + 1 = 1 suffices without gaps */
        check_status(pyins_run_decimated(core, batch, 8, 10, outs, 1, &n_done, &n_out),
                     PYINS_E_BUFFER_TOO_SMALL, "decimated: gaps need more records than the capacity");
        check(n_done == 2 && n_out == 1 && outs[0].tick == 11, "decimated: stopped before the overflowing step");
        pyins_get_output(core, &out);
        t0 = out.tick;
        check_status(pyins_run_decimated(core, batch + 2, 6, 10, outs, 8, &n_done, &n_out), PYINS_OK,
                     "decimated: go on with room");
        check(t0 == 11 && n_done == 6 && n_out == 6 && outs[0].tick == 21 && outs[5].tick == 71,
              "decimated: one record per multiple passed");
    }

    /* Seq checking off: seq ignored entirely. */
    {
        pyins_config c3;
        pyins_config_default(&c3);
        check_status(pyins_init(mem, size, &c3), PYINS_OK, "seq off: init");
        check_status(pyins_init(mem2, size, &c3), PYINS_OK, "seq off: init reference");
        s = static_sample();
        for (k = 0; k < 20; ++k) {
            s.seq = (k * 2654435761u) ^ 0x5bd1e995u;   /* anything */
            if (pyins_step(core, &s, &out) != PYINS_OK) break;
            s.seq = 0u;
            pyins_step(full, &s, &ref);
        }
        check(k == 20 && out.fault_flags == 0u && same_state(&out, &ref), "seq off: any seq is the next tick");
    }

    /* Absurd but finite angles wrap into range (tests/fuzz found a configured
     * table angle of -2^755 giving an IMU yaw of -2^755). */
    {
        pyins_config c5;
        pyins_sample w = static_sample();
        pyins_config_default(&c5);
        c5.table_angle_rad = -0x1p+755;
        check_status(pyins_init(mem, size, &c5), PYINS_OK, "huge table angle: init");
        pyins_step(core, &w, &out);
        check(out.yaw_p_rad > -3.14159265358979323846 && out.yaw_p_rad <= 3.14159265358979323846,
              "huge configured table angle: IMU yaw in (-pi, pi]");
        w.table_angle_rad = 1e300;
        pyins_step(core, &w, &out);
        check(out.yaw_p_rad > -3.14159265358979323846 && out.yaw_p_rad <= 3.14159265358979323846,
              "huge encoder reading: IMU yaw in (-pi, pi]");
    }

    /* A gap during alignment restarts it (time kept right). */
    {
        pyins_config c4;
        pyins_config_default(&c4);
        c4.seq_mode = PYINS_SEQ_CHECK;
        c4.fine_ticks = 100;
        check_status(pyins_init(mem, size, &c4), PYINS_OK, "alignment gap: init");
        s = static_sample();
        for (k = 1; k <= 30; ++k) {
            s.seq = k;
            pyins_step(core, &s, &out);
        }
        s.seq = 32u;
        check_status(pyins_step(core, &s, &out), PYINS_W_SEQ_GAP, "gap during fine alignment");
        check(out.mode == PYINS_MODE_FINE_ALIGN && out.align_restarts == 1 && out.tick == 32 &&
              out.n_seq_bridged == 0u && (out.fault_flags & PYINS_FAULT_ALIGN_RESTARTED),
              "alignment restarted at the sample after the gap, nothing bridged");
    }
}
