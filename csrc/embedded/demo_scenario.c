/* demo_scenario.c: see demo_scenario.h. Only + - * / on exactly
 * representable values: no libm, so every target computes the same bits. */
#include "demo_scenario.h"

#include <math.h>   /* NAN only: a constant, no libm call */
#include <string.h>

/* Increments of a level IMU at yaw 0 at 34.246 N, to double precision
 * (static: dtheta = C_n^b omega_ie^n dt, dv = C_n^b [0 0 g] dt). The
 * decimal constants are exact inputs; what matters is that every platform
 * parses them to the same double, which IEEE guarantees. */
static const double kDthetaN = 6.027874130954723e-07;  /* W cos L dt [rad] */
static const double kDthetaU = 4.103617522881293e-07;  /* W sin L dt [rad] */
static const double kDvU = 0.09796698857772466;        /* g dt [m/s] */

void demo_config(pyins_config *cfg) {
    memset(cfg, 0, sizeof *cfg);
    cfg->lat_rad = 0.5977054556379782;      /* 34.246 deg */
    cfg->lon_rad = 1.9008380883470242;       /* 108.910 deg */
    cfg->coarse_ticks = 6000;
    cfg->fine_ticks = 6000;
    cfg->fine_states = 12;                  /* the moving-base filter (1 Hz position updates) */
    cfg->index_scheme = PYINS_INDEX_TWO_POSITION;
    cfg->index_stop_ticks = 2000;
    cfg->seq_mode = PYINS_SEQ_CHECK;        /* default gap bridging: up to 2 ticks */
    /* a moored ship: the moving-base coarse alignment, a 2 m lever arm and
     * a sensor offset on the table (demo_sample adds a heave) */
    cfg->coarse_method = PYINS_COARSE_FIT;
    cfg->lever_b_m[0] = 0.5;
    cfg->lever_b_m[1] = 1.5;
    cfg->lever_b_m[2] = 1.25;
    cfg->lever_p_m[0] = 0.0625;
    /* ranging on its lines: the site-motion model (moving_align.hpp), 1000 ug/sqrt(Hz)
       (a binary fraction near it, as the lever arms) */
    cfg->fine_site_accel = 0.009765625;
    /* a DVL turned 28.6 deg about z and a little about x and y, 2 m forward
       and 3 m down (exact binary fractions) */
    cfg->dvl_align_rad[0] = 0.0078125;
    cfg->dvl_align_rad[1] = -0.0078125;
    cfg->dvl_align_rad[2] = 0.5;
    cfg->dvl_lever_b_m[0] = 0.25;
    cfg->dvl_lever_b_m[1] = 2.0;
    cfg->dvl_lever_b_m[2] = -3.0;
    /* the GNSS antenna up the mast (its fixes are the reference point's with
       noise: the lever arm's path runs, its ~2 m offset is inside the 3 m
       sigma) */
    cfg->gnss_lever_b_m[0] = 0.5;
    cfg->gnss_lever_b_m[1] = 2.0;
    cfg->gnss_lever_b_m[2] = 12.5;
    /* the navigation filter told a bias random walk and the gyros' scale
       factors and misalignments, on the table's axis and between the level
       gyros (2^-34 rad/s/sqrt(s), 2^-16, 2^-14 rad: exact binary fractions
       near 0.0007 deg/h/sqrt(h), 15 ppm, 12.6 arcsec) */
    cfg->nav_gyro_bias_rw = 5.820766091346741e-11;
    cfg->nav_table_scale_sigma = 1.52587890625e-05;
    cfg->nav_table_mis_sigma = 6.103515625e-05;
    cfg->nav_level_scale_sigma = 1.52587890625e-05;
    cfg->nav_level_mis_sigma = 6.103515625e-05;
}

void demo_config_b(pyins_config *cfg) {
    demo_config(cfg);
    cfg->coarse_method = PYINS_COARSE_FIT_VEL;   /* under way: the GNSS velocity takes out the motion */
    cfg->fine_ticks = 0;                          /* FIT_VEL's rule: the navigation filter aligns on */
    cfg->fine_states = 0;
    cfg->fine_site_accel = 0.0;
}

int demo_fault(uint32_t k) {
    if (k == 3000u) return DEMO_REPEAT;                    /* coarse alignment: dropped, no restart */
    if (k == 14000u) return DEMO_DROP;                     /* navigation: 1 tick bridged */
    if (k == 15000u || k == 15001u) return DEMO_DROP;      /* 2 ticks bridged */
    if (k == 16000u) return DEMO_NAN;                      /* rejected, then bridged */
    if (k == 17000u) return DEMO_SATURATE;                 /* rejected, then bridged */
    if (k >= 18000u && k < 18005u) return DEMO_DROP;       /* 5 ticks: beyond the gap, resync */
    if (k == 19001u) return DEMO_REPEAT;                   /* duplicate in navigation */
    if (k == 23000u) return DEMO_ENCODER_GLITCH;           /* a jump, indexing FAULT, reset */
    return DEMO_NONE;
}

static double lcg_unit(uint64_t *state) {
    /* Knuth's MMIX LCG; the top 21 bits as an integer in [-2^20, 2^20) */
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)((int64_t)(*state >> 43) - (int64_t)(1 << 20));
}

void demo_sample(uint64_t *state, uint32_t k, int fault, double encoder_rad, double table_step_rad,
                 pyins_sample *s) {
    const double k_ang = 1.0 / 1099511627776.0 / 1048576.0;  /* 2^-60 rad per LCG unit */
    const double k_vel = 1.0 / 1073741824.0 / 1048576.0;     /* 2^-50 m/s per LCG unit */
    /* the IMU turns with the table: its z increment gains the table's step,
       and the Earth rate's north component reads -1 x at the 180 deg stop
       (nearer pi than 0; exact; off during a move only) */
    const double side = encoder_rad > 1.5707963267948966 && encoder_rad < 4.71238898038469 ? -1.0 : 1.0;
    s->dtheta_p_rad[0] = lcg_unit(state) * k_ang;
    s->dtheta_p_rad[1] = side * kDthetaN + lcg_unit(state) * k_ang;
    s->dtheta_p_rad[2] = kDthetaU + table_step_rad + lcg_unit(state) * k_ang;
    s->dv_p_mps[0] = lcg_unit(state) * k_vel;
    s->dv_p_mps[1] = lcg_unit(state) * k_vel;
    /* heave: a zero-mean sawtooth acceleration of period 8 s (800 ticks),
     * odd integers -799..799 times 2^-22 m/s per tick (up to 2 mg) */
    s->dv_p_mps[2] = kDvU + lcg_unit(state) * k_vel +
                     (double)(2 * (int32_t)(k % 800u) - 799) * (1.0 / 4194304.0);
    s->table_angle_rad = encoder_rad;
    s->seq = k + 1u;
    s->reserved = 0u;
    if (fault == DEMO_NAN) {
        s->dv_p_mps[0] = NAN;
    } else if (fault == DEMO_SATURATE) {
        s->dtheta_p_rad[0] = 1.0;
    } else if (fault == DEMO_ENCODER_GLITCH) {
        s->table_angle_rad = encoder_rad + 0.25;   /* 14 deg: beyond index_jump_rad (5 deg) */
    }
}

/* Navigation starts at tick 12000 (coarse 6000 + fine 6000 ticks). */
#define DEMO_NAV_TICK 12000u
#define DEMO_GNSS_END 18500u      /* the last GNSS second */
#define DEMO_OUTLIER_TICK 16500u  /* a multipath jump of 1e-4 rad (637 m) north */
#define DEMO_LOG_TICK 14000u      /* the speed log from here on */
#define DEMO_DVL_FROM 20500u      /* a DVL in bottom track over (from, to] */
#define DEMO_DVL_TO 22000u

static void demo_ref(pyins_ref *r, int32_t kind, int64_t tick, double v0, double v1, double v2,
                     double s0, double s1, double s2) {
    memset(r, 0, sizeof *r);
    r->kind = kind;
    r->tick = tick;
    r->value[0] = v0;
    r->value[1] = v1;
    r->value[2] = v2;
    r->sigma[0] = s0;
    r->sigma[1] = s1;
    r->sigma[2] = s2;
}

int demo_refs(uint64_t *lcg, uint32_t k, pyins_ref *refs) {
    /* the references' own noise (a receiver never repeats a fix bit for bit:
       the core reads that as frozen), exact multiples of powers of two */
    const double k_pos = 1.0 / 1099511627776.0;     /* 2^-40 rad per unit: up to 6 m */
    const double k_vel = 1.0 / 16777216.0;          /* 2^-24 m/s per unit: up to 0.0625 m/s */
    const uint32_t t = k + 1u;     /* the tick sample k ends */
    int n = 0;
    if (t <= DEMO_NAV_TICK + 100u) return 0;
    if (t % 100u == 0u && t <= DEMO_GNSS_END) {
        /* the velocity of second t, pushed ahead: queued, applied at its tick */
        const double ve = lcg_unit(lcg) * k_vel;
        const double vn = lcg_unit(lcg) * k_vel;
        demo_ref(&refs[n++], PYINS_REF_GNSS_VEL, (int64_t)t, ve, vn, 0.0, 0.0625, 0.0625, 0.0625);
    }
    if (t % 100u == 20u && t <= DEMO_GNSS_END + 20u) {
        /* the fix of 20 ticks ago, pushed late: carried forward by the velocity */
        const uint32_t tf = t - 20u;
        const double dlat = (tf == DEMO_OUTLIER_TICK ? 1e-4 : 0.0) + lcg_unit(lcg) * k_pos;
        const double dlon = lcg_unit(lcg) * k_pos;
        demo_ref(&refs[n++], PYINS_REF_GNSS_POS, (int64_t)tf, 0.5977054556379782 + dlat,
                 1.9008380883470242 + dlon, 0.0, 3.0, 3.0, 5.0);
    }
    if (t % 100u == 50u && t > DEMO_LOG_TICK) {
        /* moored: the log reads no speed through water, and its noise; it
           learns the current under GNSS and damps alone after it */
        demo_ref(&refs[n++], PYINS_REF_SPEED_LOG, (int64_t)t, lcg_unit(lcg) * k_vel, 0.0, 0.0, 0.0625, 0.0,
                 0.0);
    }
    if (t % 100u == 70u && t > DEMO_DVL_FROM && t <= DEMO_DVL_TO) {
        /* moored: the DVL reads no velocity over ground, and its noise, in
           its own axes (turned into n by the mounting, the lever arm's
           w x r taken out) */
        const double vx = lcg_unit(lcg) * k_vel;
        const double vy = lcg_unit(lcg) * k_vel;
        const double vz = lcg_unit(lcg) * k_vel;
        demo_ref(&refs[n++], PYINS_REF_DVL, (int64_t)t, vx, vy, vz, 0.0625, 0.0625, 0.0625);
    }
    return n;
}

int demo_refs_b(uint64_t *lcg, uint32_t k, pyins_ref *refs) {
    const double k_pos = 1.0 / 1099511627776.0;     /* 2^-40 rad per unit: up to 6 m */
    const double k_vel = 1.0 / 16777216.0;          /* 2^-24 m/s per unit: up to 0.0625 m/s */
    const uint32_t t = k + 1u;
    int n = 0;
    if (t % 100u == 0u) {
        const double ve = lcg_unit(lcg) * k_vel;
        const double vn = lcg_unit(lcg) * k_vel;
        const double vu = lcg_unit(lcg) * k_vel;
        demo_ref(&refs[n++], PYINS_REF_GNSS_VEL, (int64_t)t, ve, vn, vu, 0.0625, 0.0625, 0.0625);
    }
    if (t % 100u == 20u && t > 100u) {
        const uint32_t tf = t - 20u;
        const double dlat = lcg_unit(lcg) * k_pos;
        const double dlon = lcg_unit(lcg) * k_pos;
        demo_ref(&refs[n++], PYINS_REF_GNSS_POS, (int64_t)tf, 0.5977054556379782 + dlat,
                 1.9008380883470242 + dlon, 0.0, 3.0, 3.0, 5.0);
    }
    return n;
}
