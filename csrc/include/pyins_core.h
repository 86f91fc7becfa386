/*
 * pyins_core.h: the one public C ABI of the pyins firmware core (C99).
 *
 * The core is a marine strapdown INS stepping at a fixed rate (100 Hz by
 * default). The caller owns all memory: pyins_core_size() says how many bytes
 * an instance needs, pyins_init() builds it there, and the core never
 * allocates, throws, prints or keeps global state.
 *
 * Frames and units (docs/design.md §2): n = East-North-Up, b = ship body
 * (x starboard, y bow, z up), p = IMU frame on the turntable, C_p^b = Rz(alpha).
 * SI units: rad, m, s, m/s. Euler angles [pitch, roll, yaw], C_b^n =
 * Rz(yaw) Rx(pitch) Ry(roll), yaw counter-clockwise from North; heading is the
 * marine one, clockwise from North in [0, 2 pi).
 *
 * Every function that can fail returns PYINS_OK (0) or a negative
 * pyins_status with a fixed value; pyins_step() may also return a positive
 * PYINS_W_* notice (a sample-level fault it handled: docs/core.md,
 * "Sample-level faults"); pyins_status_str() names them all.
 *
 * The block between CDEF-BEGIN and CDEF-END is read verbatim by Python's
 * cffi (pyins/native.py), so it holds no preprocessor lines.
 */
#ifndef PYINS_CORE_H
#define PYINS_CORE_H

#include <stddef.h>
#include <stdint.h>

/* ABI version: (major << 16) | minor. A major change breaks callers. */
#define PYINS_ABI_VERSION_MAJOR 0
#define PYINS_ABI_VERSION_MINOR 20

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#pragma GCC visibility push(default)
#endif

/* CDEF-BEGIN */

/* Status codes. The values are fixed: never renumber, only append.
 * Negative: an error; a rejected sample leaves the state as it was and
 * stops a batch call. Positive (PYINS_W_*): a sample-level notice; the sample
 * was handled as docs/core.md says (taken with a remedy, or dropped as a
 * duplicate), the sticky fault bit and counter record it, and batch calls
 * go on. */
enum pyins_status {
    PYINS_OK = 0,
    PYINS_E_NULL = -1,              /* a required pointer argument is NULL */
    PYINS_E_MISALIGNED = -2,        /* instance memory not aligned to pyins_core_align() */
    PYINS_E_MEM_TOO_SMALL = -3,     /* mem_size < pyins_core_size() */
    PYINS_E_NOT_INIT = -4,          /* the memory does not hold an initialised instance */
    PYINS_E_SAMPLE_NONFINITE = -5,  /* a sample field is NaN or Inf; the sample was rejected */
    PYINS_E_BAD_ARG = -6,           /* an argument is out of range (e.g. out_every == 0) */
    PYINS_E_BUFFER_TOO_SMALL = -7,  /* an output buffer cannot hold the records asked for */
    PYINS_E_CONFIG_RATE = -10,      /* tick_hz out of range (must be 0 = default, or 1..10000) */
    PYINS_E_CONFIG_LAT = -11,       /* latitude not finite or beyond +-90 deg */
    PYINS_E_CONFIG_LON = -12,       /* longitude not finite or beyond +-360 deg */
    PYINS_E_CONFIG_HEIGHT = -13,    /* height not finite or outside -1e4..1e5 m */
    PYINS_E_CONFIG_VEL = -14,       /* velocity not finite or faster than 1e4 m/s */
    PYINS_E_CONFIG_ATT = -15,       /* attitude, table angle or DVL alignment not finite (the DVL's
                                       rotation beyond pi) */
    PYINS_E_CONFIG_MODE = -16,      /* unknown vertical-channel mode */
    PYINS_E_CONFIG_ALIGN_RATIO = -17, /* coarse_ratio not in (0, 1) */
    PYINS_E_CONFIG_ALIGN_EARLY = -18, /* first coarse output before enough data: ratio * first < every */
    PYINS_E_CONFIG_ALIGN_LONG = -19,  /* TRIAD coarse alignment longer than its fixed storage allows (FIT: no limit) */
    PYINS_E_CONFIG_ALIGN_TICKS = -20, /* an alignment duration negative, or first output after its end */
    PYINS_E_CONFIG_FINE = -21,        /* fine_states not 5, 8 or 12, negative update interval, unknown correction or noise source */
    PYINS_E_CONFIG_NOISE = -22,       /* a noise density or initial sigma negative or not finite */
    PYINS_E_CONFIG_INDEX_SCHEME = -23, /* unknown indexing scheme */
    PYINS_E_CONFIG_INDEX_EMPTY = -24, /* custom scheme with no steps (or more than 8) */
    PYINS_E_CONFIG_INDEX_RATE = -25,  /* indexing rate or acceleration not positive (custom) or negative */
    PYINS_E_CONFIG_INDEX_DELTA = -26, /* flexible threshold delta not positive (custom) or negative */
    PYINS_E_CONFIG_INDEX_STEP = -27,  /* a custom step, stop length, tolerance or timeout out of range */
    PYINS_E_SNAPSHOT_SIZE = -28,      /* snapshot blob truncated, too long, or its buffer too small */
    PYINS_E_SNAPSHOT_VERSION = -29,   /* snapshot of another format or ABI version */
    PYINS_E_SNAPSHOT_CORRUPT = -30,   /* snapshot magic or checksum wrong */
    PYINS_E_SAMPLE_SATURATED = -31,   /* an increment at or beyond its saturation limit; the sample was rejected */
    PYINS_E_CONFIG_SATURATION = -32,  /* a saturation limit negative or not finite */
    PYINS_E_CONFIG_SEQ = -33,         /* unknown seq_mode, or seq_max_gap_ticks outside 0..100 */
    PYINS_E_CONFIG_INDEX_SUMS = -34,  /* unknown index_sums */
    PYINS_E_CONFIG_LEVER = -35,       /* a lever-arm component not finite, or a lever arm longer than 100 m
                                         (lever_b_m, lever_p_m, dvl_lever_b_m) */
    PYINS_E_CONFIG_COARSE_METHOD = -36, /* unknown coarse_method */
    PYINS_E_CONFIG_INTEGRITY = -37,   /* integrity_nis_window below -1, or a bound negative or not finite */
    PYINS_E_CONFIG_NAV = -38,         /* unknown nav_mode, or a navigation filter setting out of range */
    PYINS_E_REF_KIND = -39,           /* a reference of an unknown kind (or one this build does not use yet:
                                         a DVL's water track, reserved != 0) */
    PYINS_E_REF_VALUE = -40,          /* a reference value not finite, or a sigma it uses not finite and > 0 */
    PYINS_E_REF_ORDER = -41,          /* a reference older than the last one pushed, or older than
                                         ref_max_latency_ticks before the current tick */
    PYINS_E_REF_FUTURE = -42,         /* a reference more than 10 s ahead of the current tick */
    PYINS_E_REF_FULL = -43,           /* the reference queue is full (step the samples it waits for first) */
    PYINS_E_REF_UNUSED = -44,         /* nav_mode UNDAMPED: the firmware takes no references; DAMPED: no
                                         GNSS position (ABI 0.17) */
    PYINS_W_SEQ_GAP = 1,              /* seq skipped 1..seq_max_gap_ticks ticks: bridged (navigation) or alignment restarted */
    PYINS_W_SEQ_REPEAT = 2,           /* seq repeated (or up to seq_max_gap_ticks behind): duplicate dropped, state unchanged */
    PYINS_W_SEQ_LOST = 3,             /* seq jumped beyond the bridgeable gap: taken without bridging, sequence resynchronised */
    PYINS_W_ENCODER_JUMP = 4          /* the encoder changed by more than index_jump_rad per tick; sample taken */
};

/* Indexing schemes (pyins_config.index_scheme). */
enum pyins_index_scheme {
    PYINS_INDEX_NONE = 0,             /* the IMU stays fixed to the ship */
    PYINS_INDEX_SINGLE_FWD_REV = 1,   /* seed 003: stop, +360, stop, -360 (stops at zero) */
    PYINS_INDEX_TWO_POSITION = 2,     /* seed 002 traditional: stop, +180, stop, +180, stop, -180, stop, -180 */
    PYINS_INDEX_FOUR_POSITION = 3,    /* stops at 0, 180, 90, 270: +180, -90, +180, -270 (no slip ring) */
    PYINS_INDEX_FLEXIBLE_TWO = 4,     /* seed 002 flexible: flex-cos fwd, +180, flex-sin rev, -180 */
    PYINS_INDEX_CUSTOM = 5,           /* index_steps[0 .. index_n_steps-1] */
    PYINS_INDEX_FLEXIBLE_DERIVED = 6, /* seed 002's three-stop derivation: flex-cos fwd, flex-sin rev,
                                         without the fixed 180-deg moves (docs/papers.md, seed 002 §6, note 3) */
    PYINS_INDEX_HEADING_ISOLATION = 7 /* the table counter-rotates against the ship's yaw (holds the IMU
                                         heading), plus a two-position cycle +180, -180 at the held heading
                                         (docs/indexing.md) */
};

/* Which ticks add cos psi, sin psi to A_c, A_s (pyins_config.index_sums). */
enum pyins_index_sums {
    PYINS_INDEX_SUMS_STOPS = 0,       /* seed 002: stopped ticks only; frozen while turning */
    PYINS_INDEX_SUMS_ALL = 1          /* every tick of the cycle, turns included: the flexible
                                         stops then also cancel the drift integrated while
                                         turning (docs/indexing.md, "What the turns leave") */
};

/* Move kinds of an indexing step. */
enum pyins_index_kind {
    PYINS_INDEX_FIXED = 1,            /* turn by angle_rad (signed; + = counter-clockwise from above) */
    PYINS_INDEX_FLEX_COS = 2,         /* turn in the sense of angle_rad until seed 002's cos condition */
    PYINS_INDEX_FLEX_SIN = 3          /* ... until seed 002's sin condition */
};

/* Indexing machine states (pyins_output.index_state). */
enum pyins_index_state {
    PYINS_INDEX_IDLE = 0, PYINS_INDEX_STOP = 1, PYINS_INDEX_MOVE = 2, PYINS_INDEX_FAULT = 3
};

/* One step of an indexing cycle: stop for stop_ticks, then move. */
typedef struct pyins_index_step {
    int32_t stop_ticks;
    int32_t kind;                 /* enum pyins_index_kind */
    double angle_rad;
} pyins_index_step;

/* How the coarse alignment solves C_ib0^i (pyins_config.coarse_method). */
enum pyins_coarse_method {
    PYINS_COARSE_TRIAD = 0,       /* seed 000: the velocity integrals at t_k1 = r t_k2 and t_k2 (TRIAD);
                                     assumes the IMU at rest at t0 and no linear motion */
    PYINS_COARSE_FIT = 1,         /* moving base: the integrals of the velocity integrals weighted by two
                                     smooth functions that ignore an unknown initial velocity and
                                     position offset and suppress bounded wave motion
                                     (docs/concepts.md, "Alignment on a moving base") */
    PYINS_COARSE_EQ8 = 2,         /* seed 000 eq. 8 as printed: the same vectors as TRIAD, C_ib0^i =
                                     A^-1 B, not orthonormalised (docs/core.md) */
    PYINS_COARSE_FIT_VEL = 3      /* under way: FIT with the ship's motion taken out by the GNSS velocity
                                     references pushed during the alignment (ABI 0.20); navigation
                                     starts where they carried the ship, at their velocity. Needs
                                     fine_ticks 0 and a navigation filter (nav_mode not UNDAMPED), which
                                     then aligns finely (docs/concepts.md, "Alignment under way") */
};

/* How the fine alignment uses its attitude estimate. */
enum pyins_fine_correction {
    PYINS_FINE_FEEDBACK = 0,      /* correct the attitude after every update (seed 001's advice) */
    PYINS_FINE_OPEN_LOOP = 1      /* leave it; report the corrected attitude */
};

/* Where the static fine filters' measurement noise R comes from
 * (pyins_config.fine_noise). */
enum pyins_fine_noise {
    PYINS_FINE_NOISE_MEASURED = 0,   /* the larger of fine_accel_vrw and the horizontal specific-force noise
                                        the coarse phase measured on the update interval (pyins_output.
                                        coarse_vrw; sensor noise plus vibration); fine_accel_vrw without a
                                        coarse phase (docs/core.md, "Measurement noise") */
    PYINS_FINE_NOISE_CONFIGURED = 1  /* fine_accel_vrw as configured */
};

/* Bits of pyins_output.fault_flags (sticky: set once, never cleared). */
enum pyins_fault_flag {
    PYINS_FAULT_KF_NOT_PD = 1,    /* the fine-alignment covariance lost positive definiteness */
    PYINS_FAULT_ALIGN_RESTARTED = 2, /* a sample was rejected or missing during alignment, which restarted */
    PYINS_FAULT_SAMPLE_NONFINITE = 4, /* a sample with NaN/Inf was rejected (n_nonfinite) */
    PYINS_FAULT_SAMPLE_SATURATED = 8, /* a sample at/beyond a saturation limit was rejected (n_saturated) */
    PYINS_FAULT_SEQ_GAP = 16,     /* ticks were missing from the sequence (n_seq_gaps, n_seq_bridged) */
    PYINS_FAULT_SEQ_REPEAT = 32,  /* a duplicate sample was dropped (n_seq_repeats) */
    PYINS_FAULT_SEQ_LOST = 64,    /* the sequence broke beyond the bridgeable gap (n_seq_lost) */
    PYINS_FAULT_ENCODER_JUMP = 128, /* the encoder jumped (n_encoder_jumps) */
    PYINS_FAULT_ALIGN_INCONSISTENT = 256, /* the alignment's measurements do not fit its model: the
                                             fine alignment's window mean normalised innovation squared
                                             (align_nis) beyond integrity_nis_max, or a reference
                                             velocity during an alignment says the site moves (more
                                             than 0.5 m/s beyond its noise and lever arm: a ship under
                                             way, ABI 0.18), or an alignment under way
                                             (PYINS_COARSE_FIT_VEL) that went more than 3 s without a
                                             GNSS velocity (ABI 0.20); the attitude is not valid */
    PYINS_FAULT_COARSE_UNSETTLED = 512, /* the coarse solution kept moving over the last fifth of the
                                          coarse alignment by more than integrity_coarse_rad
                                          (coarse_wander_rad); the attitude is not valid */
    PYINS_FAULT_REF_REJECTED = 1024 /* a reference kind failed its innovation gate nav_reject_limit times
                                       in a row (n_ref_rejected): it is out of use (ref_in_use) until
                                       one of its measurements fits again */
};

/* Navigation modes (pyins_config.nav_mode; pyins_output.nav_mode reports the
 * one in effect, never AUTO). docs/concepts.md, "At sea". */
enum pyins_nav_mode {
    PYINS_NAV_AUTO = 0,           /* config: INTEGRATED while a reference is in use, else UNDAMPED,
                                     the filter's covariance running throughout */
    PYINS_NAV_UNDAMPED = 1,       /* free inertial navigation (the firmware of ABI 0.14): no filter,
                                     references refused (PYINS_E_REF_UNUSED) */
    PYINS_NAV_DAMPED = 2,         /* reported (AUTO, INTEGRATED): the speed log the only reference in
                                     use, on a straight course: the horizontal channels damped by it;
                                     the position is dead reckoning. As config (ABI 0.17): level
                                     damping only, never a filter correction, by the first reference
                                     velocity in use in the order GNSS velocity, log (on a straight
                                     course), DVL, zero velocity; GNSS position refused
                                     (PYINS_E_REF_UNUSED); UNDAMPED reported while none is in use */
    PYINS_NAV_INTEGRATED = 3      /* the error-state Kalman filter corrects attitude, velocity,
                                     position and the IMU biases from the references */
};

/* Kinds of external reference (pyins_ref.kind; the slot kind - 1 of the
 * per-kind record arrays). Values on the IMU's clock, at the reference
 * point, or of the antenna at gnss_lever_b_m and the DVL at dvl_lever_b_m. */
enum pyins_ref_kind {
    PYINS_REF_GNSS_POS = 1,       /* value: [lat rad, lon rad, height m]; sigma: [E, N, U] m (U unused:
                                     the vertical channel is held) */
    PYINS_REF_GNSS_VEL = 2,       /* value: ENU velocity m/s; sigma: per axis m/s (U read only by the
                                     coarse alignment under way, where sigma[2] > 0: 0 = none) */
    PYINS_REF_SPEED_LOG = 3,      /* EM log: value[0] speed through water along the bow [m/s]; sigma[0]
                                     [m/s] (components 1, 2 not used): damps the horizontal channels */
    PYINS_REF_DVL = 4,            /* Doppler velocity log, bottom track (ABI 0.16): value: the velocity
                                     over ground in the DVL's frame d [m/s], x, y, z; sigma: per axis
                                     [m/s], all three used (rotated into n). The mounting is the
                                     configuration's dvl_align_rad, dvl_lever_b_m. pyins_ref.reserved
                                     must be 0 (bottom track): water track (through water) is not
                                     used and a non-zero reserved is refused (PYINS_E_REF_KIND) */
    PYINS_REF_ZERO_VEL = 5        /* the ship at rest: value 0; sigma: per axis m/s (U unused) */
};

/* One external reference measurement, valid at the end of IMU tick `tick`
 * (the record's tick numbering). Pushed ahead of its tick it waits in the
 * instance's queue (8 deep) and is applied when that tick is stepped; pushed
 * late (up to ref_max_latency_ticks) it is applied at once, the position
 * carried forward by the velocity over the latency. */
typedef struct pyins_ref {
    int32_t kind;                 /* enum pyins_ref_kind */
    int32_t reserved;             /* keep 0; ignored, but for a DVL: 0 = bottom track, anything else
                                     (water track) refused with PYINS_E_REF_KIND (ABI 0.16) */
    int64_t tick;                 /* tick at whose end the value holds */
    double value[3];
    double sigma[3];
} pyins_ref;

/* Sequence checking (pyins_config.seq_mode). */
enum pyins_seq_mode {
    PYINS_SEQ_OFF = 0,            /* pyins_sample.seq is ignored: every sample is the next tick (old logs) */
    PYINS_SEQ_CHECK = 1           /* seq must count up by one per tick (wrapping at 2^32) */
};

/* Firmware modes, in pyins_output.mode. */
enum pyins_mode {
    PYINS_MODE_IDLE = 0,          /* initialised, no sample yet */
    PYINS_MODE_COARSE_ALIGN = 1,  /* inertial-frame coarse alignment (seed 000) */
    PYINS_MODE_FINE_ALIGN = 2,    /* Kalman fine alignment (seed 001) */
    PYINS_MODE_NAVIGATE = 3
};

/* Bits of pyins_output.state_flags. */
enum pyins_state_flag {
    PYINS_STATE_ATT_VALID = 1,    /* the attitude is a solution, not the configured guess nor a
                                     provisional one (coarse solutions until the coarse alignment
                                     has ended and passed its wander test; a fine estimate before
                                     the first NIS window has passed or while the filter's heading
                                     sigma exceeds 10'; a fine alignment that ended with a larger
                                     one), and no
                                     integrity test failed (PYINS_FAULT_ALIGN_INCONSISTENT,
                                     PYINS_FAULT_COARSE_UNSETTLED: once set, never valid again) */
    PYINS_STATE_POS_AIDED = 2     /* a position reference was applied within the last 10 s */
};

/* Vertical channel: a marine INS holds height at the reference (external
 * height aiding); FREE integrates it (diverges within hours). */
enum pyins_vertical_mode {
    PYINS_VERTICAL_HOLD = 0,
    PYINS_VERTICAL_FREE = 1
};

/* Firmware configuration. A zeroed struct means the defaults, which
 * pyins_config_default() also writes. */
typedef struct pyins_config {
    int32_t tick_hz;              /* step rate [Hz]; 0 = 100 */
    int32_t vertical_mode;        /* enum pyins_vertical_mode */
    double lat_rad;               /* initial geodetic latitude [rad] */
    double lon_rad;               /* initial longitude [rad] */
    double height_m;              /* initial height [m]; the HOLD reference */
    double vel_n_mps[3];          /* initial velocity, ENU [m/s] */
    double euler_b_rad[3];        /* initial ship attitude [pitch, roll, yaw] [rad] */
    double table_angle_rad;       /* turntable angle alpha at the initial time [rad] */
    /* Alignment. With coarse_ticks = 0 the firmware navigates from the
     * configured attitude; the position above is the alignment site. */
    int32_t coarse_ticks;         /* COARSE_ALIGN duration [ticks]; 0 = none */
    int32_t coarse_first_output_ticks; /* first coarse solution [ticks]; 0 = 20 s */
    int32_t coarse_output_every_ticks; /* then one every [ticks]; 0 = 1 s */
    int32_t reserved0;            /* padding, ignored; keep 0 */
    double coarse_ratio;          /* r = t_k1 / t_k2 in (0, 1); 0 = 1/2 */
    int32_t fine_ticks;           /* FINE_ALIGN duration [ticks]; 0 = none */
    int32_t fine_states;          /* 5 (reduced filter) or 8 (full): seed 001's static filters;
                                     12: the moving-base filter (position matching on a moored
                                     ship, docs/concepts.md); 0 = 5 */
    int32_t fine_meas_every_ticks; /* ticks per measurement update; 0 = 10 (static), 100 (moving base) */
    int32_t fine_correction;      /* enum pyins_fine_correction */
    double fine_gyro_arw;         /* Q: gyro angle random walk [rad/sqrt(s)]; 0 = 0.001 deg/sqrt(h) */
    double fine_accel_vrw;        /* R: accelerometer velocity random walk [(m/s)/sqrt(s)]; 0 = 10 ug/sqrt(Hz) */
    double fine_sigma0_att_rad[3]; /* initial sigma of phi E, N, U [rad]; 0 = 100', 100', 600'
                                      without a coarse phase; after one (coarse_ticks > 0) the fit
                                      to its result: 3 x the expected error and wander, 1' to the
                                      above (docs/core.md); moving base (fine_states 12): 1', 1', 10' */
    double fine_sigma0_gyro;      /* initial sigma of the gyro drifts [rad/s]; 0 = 0.01 deg/h */
    double fine_sigma0_accel;     /* initial sigma of the accelerometer biases [m/s^2]; 0 = 100 ug */
    /* Indexing (rotation modulation), active in NAVIGATE. For preset schemes
     * 0 means the default; a custom scheme states rate, accel and delta. */
    int32_t index_scheme;         /* enum pyins_index_scheme */
    int32_t index_stop_ticks;     /* presets: stop length [ticks]; 0 = 60 s (seed 003), 300 s (others) */
    int32_t index_timeout_ticks;  /* how long the encoder may lag the command [ticks]; 0 = 2 s */
    int32_t index_n_steps;        /* custom scheme: steps used, 1..8 */
    double index_rate_rad_s;      /* cruise rate; 0 = 6 deg/s */
    double index_accel_rad_s2;    /* acceleration; 0 = 30 deg/s^2 */
    double index_delta;           /* flexible threshold; 0 = 0.01 */
    double index_max_flex_rad;    /* longest flexible turn before giving up; 0 = 720 deg */
    double index_tolerance_rad;   /* encoder vs command tolerance; 0 = 0.5 deg */
    double index_jump_rad;        /* largest believable encoder change per tick; 0 = 5 deg */
    pyins_index_step index_steps[8]; /* custom scheme */
    /* Sample-level faults (docs/core.md, "Sample-level faults"). */
    int32_t seq_mode;             /* enum pyins_seq_mode; 0 = off */
    int32_t seq_max_gap_ticks;    /* longest gap bridged [ticks], 1..100; 0 = 2 */
    double sat_gyro_rad;          /* angle increment saturation per axis per tick [rad]; 0 = 400 deg/s x tick */
    double sat_accel_mps;         /* velocity increment saturation per axis per tick [m/s]; 0 = 20 g x tick */
    int32_t index_sums;           /* enum pyins_index_sums; 0 = stops only (seed 002) */
    int32_t reserved1;            /* padding, ignored; keep 0 */
    /* Lever arms (docs/concepts.md, "Lever arms"). The firmware navigates the
     * accelerometer triad and reports the reference point: position, velocity
     * and the initial state above are those of the ship's reference point. */
    double lever_b_m[3];          /* reference point -> turntable centre, in b [m]; |r| <= 100 m */
    double lever_p_m[3];          /* turntable centre -> accelerometer triad, in p [m]; |r| <= 100 m */
    int32_t coarse_method;        /* enum pyins_coarse_method; 0 = seed 000's TRIAD, 2 = its eq. 8 */
    int32_t reserved2;            /* padding, ignored; keep 0 */
    /* Integrity tests of the alignment (docs/concepts.md, "Integrity"). */
    int32_t integrity_nis_window; /* fine-alignment updates per NIS window; 0 = 100, -1 = no test */
    int32_t fine_noise;           /* enum pyins_fine_noise; 0 = MEASURED */
    double integrity_nis_max;     /* bound on a window's mean NIS (2 when the model holds); 0 = 4 */
    double integrity_coarse_rad;  /* bound on the coarse solution's wander over its last fifth [rad];
                                     0 = 30 arcmin */
    /* The moving-base fine alignment (fine_states = 12). */
    double fine_pos_sigma_m;      /* R: the waves' horizontal displacement [m]; 0 = 0.5 m */
    double fine_sigma0_vel_mps;   /* initial sigma of the velocity error [m/s]; 0 = 0.5 m/s */
    double fine_site_accel;       /* the site's slow horizontal motion (a ship ranging on its lines):
                                     white acceleration density [m/s^2/sqrt(Hz)], its displacement an
                                     integrated random walk in the filter's Q and in the prior it
                                     takes from the coarse result (moving_align.hpp); >= 0,
                                     0 = a rigid site */
    /* Navigation at sea (ABI 0.15; docs/concepts.md, "At sea"). */
    int32_t nav_mode;             /* enum pyins_nav_mode; 0 = AUTO */
    int32_t nav_every_ticks;      /* the navigation filter's time-update interval [ticks]; 0 = 1 s */
    double nav_gate;              /* innovation gate on a 2-D reference's normalised innovation squared
                                     (chi-square, 2 degrees of freedom); 0 = 13.8 (99.9 %) */
    int32_t nav_reject_limit;     /* rejections in a row that put a kind out of use; 0 = 10 */
    int32_t ref_max_latency_ticks; /* latest a reference may be pushed after its tick [ticks]; 0 = 1 s */
    /* The DVL's mounting (ABI 0.16; PYINS_REF_DVL; docs/concepts.md, "At sea"). */
    double dvl_align_rad[3];      /* rotation vector m of the DVL frame d from the ship's b: C_d^b =
                                     exp([m x]) (the d axes are b's turned by m); 0 = aligned with
                                     the ship's axes; finite, |m| <= pi (else PYINS_E_CONFIG_ATT) */
    double dvl_lever_b_m[3];      /* reference point -> DVL, in b [m]; |r| <= 100 m (else
                                     PYINS_E_CONFIG_LEVER) */
    /* The GNSS antenna (ABI 0.16; PYINS_REF_GNSS_POS, PYINS_REF_GNSS_VEL). */
    double gnss_lever_b_m[3];     /* reference point -> the antenna's phase centre, in b [m]: the
                                     fixes are the antenna's, the firmware compares them with the
                                     antenna's position and velocity by its own attitude and rates;
                                     0 = fixes of the reference point; |r| <= 100 m (else
                                     PYINS_E_CONFIG_LEVER) */
    /* The navigation filter's model of the IMU beyond its bias states (ABI 0.18, the table's errors
     * as states since 0.19; docs/concepts.md, "At sea", the filter's consistency). Each 0 = not
     * modelled (0 is 0 here, not a default); finite, >= 0 and within the bound given (else
     * PYINS_E_CONFIG_NAV). */
    double nav_gyro_bias_rw;      /* the gyro biases' random walk, their instability [rad/s/sqrt(s)];
                                     <= 1e-6 (0.2 deg/h/sqrt(s)) */
    double nav_table_scale_sigma; /* prior sigma of the scale factor of the gyro on the table's axis
                                     [-], a state of the filter (a table move by a turns the heading
                                     by that fraction of a); <= 0.01 */
    double nav_table_mis_sigma;   /* prior sigma of the other two gyros' misalignments to the table's
                                     axis [rad], two states (a tilt of that fraction of a move);
                                     <= 0.01 rad */
    double nav_level_scale_sigma; /* prior sigma of the x and y gyros' scale factors [-], two states
                                     (with the misalignments below, the Earth's rate through them is
                                     a heading error no indexing removes); <= 0.01 */
    double nav_level_mis_sigma;   /* prior sigma of the x and y gyros' misalignments to each other
                                     [rad], two states; <= 0.01 rad */
} pyins_config;

/* One IMU sample: what the IMU delivers for one tick [t_{k-1}, t_k]. */
typedef struct pyins_sample {
    double dtheta_p_rad[3];       /* angle increment in p [rad] */
    double dv_p_mps[3];           /* velocity increment in p [m/s] */
    double table_angle_rad;       /* encoder angle alpha at t_k, wrapped to [0, 2 pi) [rad] */
    uint32_t seq;                 /* the IMU's sample counter, +1 per tick, wrapping; read only with PYINS_SEQ_CHECK */
    uint32_t reserved;            /* ignored; keep 0 */
} pyins_sample;

/* One output record per step, the state at t_k. */
typedef struct pyins_output {
    int64_t tick;                 /* ticks since init: samples taken plus ticks a seq gap skipped */
    int32_t mode;                 /* enum pyins_mode */
    uint32_t fault_flags;         /* bit field, 0 = healthy */
    uint32_t state_flags;         /* enum pyins_state_flag bits */
    int32_t reserved0;
    double lat_rad;               /* geodetic latitude of the reference point [rad] */
    double lon_rad;               /* longitude of the reference point [rad] */
    double height_m;              /* height of the reference point [m] */
    double vel_n_mps[3];          /* velocity of the reference point, ENU [m/s] */
    double quat_nb[4];            /* ship attitude C_b^n as [w, x, y, z], w >= 0 */
    double quat_np[4];            /* IMU attitude C_p^n as [w, x, y, z], w >= 0 */
    double euler_b_rad[3];        /* ship [pitch, roll, yaw] [rad], yaw CCW from North */
    double heading_b_rad;         /* ship heading, clockwise from North, [0, 2 pi) [rad] */
    double yaw_p_rad;             /* IMU yaw psi_p = psi_b + alpha, CCW, (-pi, pi] [rad] */
    double table_angle_rad;       /* unwrapped turntable angle alpha [rad] */
    int32_t kf_states;            /* 0 before fine alignment, else 5, 8 or 12 (its last values stay) */
    int32_t align_restarts;       /* alignments restarted after a rejected sample */
    double kf_x[8];               /* fine-alignment state, fine_align.hpp layout [rad, rad/s, m/s^2];
                                     12 states: [phi, eps, nabla_E, nabla_N] as the 8-state filter */
    double kf_sigma[8];           /* its standard deviations, same units */
    int32_t index_state;          /* enum pyins_index_state */
    int32_t index_step;           /* step of the cycle */
    int32_t index_fault;          /* 0 none, 1 encoder lags the command, 2 encoder jump, 3 drift off a stop */
    int32_t index_fallbacks;      /* flexible turns that found no heading and stopped at the maximum */
    double motor_rate_cmd_rad_s;  /* commanded table rate */
    double table_angle_cmd_rad;   /* commanded (unwrapped) table angle */
    double index_a_c;             /* seed 002's cos accumulator A_c (index_sums says over which ticks) */
    double index_a_s;             /* seed 002's sin accumulator A_s */
    /* Sample-level fault counters since init (saturating at 2^32 - 1), one
     * per pyins_fault_flag bit of the same name. */
    uint32_t n_nonfinite;         /* samples rejected for NaN/Inf */
    uint32_t n_saturated;         /* samples rejected at/beyond a saturation limit */
    uint32_t n_seq_gaps;          /* gaps of 1..seq_max_gap_ticks missing ticks */
    uint32_t n_seq_bridged;       /* missing ticks bridged by interpolation (navigation) */
    uint32_t n_seq_repeats;       /* duplicate samples dropped */
    uint32_t n_seq_lost;          /* sequence breaks beyond the bridgeable gap */
    uint32_t n_encoder_jumps;     /* encoder jumps */
    uint32_t seq;                 /* seq of the last sample taken (0 before any) */
    double align_nis;             /* mean NIS of the last complete window of fine-alignment updates
                                     (0 before the first); 2 when the filter's model holds */
    double coarse_wander_rad;     /* sine of the largest rotation of the coarse solution from its
                                     value at the start of the coarse alignment's last fifth
                                     (1 for 90 deg or more) */
    double coarse_vrw;            /* horizontal specific-force noise density the coarse phase measured on the
                                     fine alignment's update interval [(m/s)/sqrt(s)]; 0 before 5 s of it,
                                     or when no static fine alignment follows or fine_noise is CONFIGURED */
    double fine_vrw;              /* the noise density the static fine filter's R is built from
                                     [(m/s)/sqrt(s)] (fine_noise); 0 before it starts and for fine_states 12 */
    double index_travel_rad;      /* angle the motor was commanded to turn since init: sum of |change of
                                     table_angle_cmd_rad| per tick (ABI 0.13) */
    int32_t index_motor_starts;   /* motor starts since init: ticks whose commanded rate is non-zero
                                     after a tick whose commanded rate was 0 (ABI 0.13) */
    int32_t reserved1;
    /* Navigation at sea (ABI 0.15). Per-kind arrays: slot kind - 1 (enum pyins_ref_kind). */
    int32_t nav_mode;             /* enum pyins_nav_mode in effect (0 before NAVIGATE) */
    uint32_t ref_in_use;          /* bit 1 << (kind - 1): a reference of that kind was applied within
                                     the last 10 s and the kind is not out of use */
    uint32_t n_ref_used[5];       /* references applied (passed their gate) */
    uint32_t n_ref_rejected[5];   /* references that failed the innovation gate */
    uint32_t n_ref_skipped[5];    /* references whose tick passed before navigation (alignment) */
    uint32_t n_ref_stale[5];      /* references not used because they repeat the last one of their kind
                                     bit for bit (a frozen receiver: no new information); those while the
                                     ship moved more than 3 sigma since the first copy (position: at the
                                     speed now; velocity: its change) count as rejected too */
    double nav_nis[5];            /* the latest normalised innovation squared per kind (gated or not) */
    double nav_sigma_pos_m;       /* the filter's horizontal position sigma sqrt(P_EE + P_NN) [m]
                                     (0 without the filter) */
    double nav_sigma_heading_rad; /* its heading sigma sqrt(P(phi_U)) [rad] */
    double nav_gyro_bias_rad_s[3]; /* gyro biases estimated and compensated, in p [rad/s] */
    double nav_accel_bias_mps2[3]; /* accelerometer biases estimated and compensated, in p (z: not
                                     estimated, 0) [m/s^2] */
    double nav_table_err[3];      /* the table-axis errors estimated and compensated (ABI 0.19): the x
                                     and y gyros' misalignments to the table's axis m_xz, m_yz [rad]
                                     and the z gyro's scale factor k_z [-]; 0 while not modelled */
    double nav_level_err[4];      /* the level gyros' errors estimated and compensated (ABI 0.19): the
                                     scale factors k_x, k_y [-] and the misalignments m_xy (x's to
                                     the y rate), m_yx [rad]; 0 while not modelled */
} pyins_output;

/* What the turntable's motor controller reads after every step, without
 * the cost of a record (pyins_get_motor_command): the same values as the
 * record's fields of the same meaning. */
typedef struct pyins_motor_command {
    double rate_rad_s;            /* = pyins_output.motor_rate_cmd_rad_s: commanded table rate */
    double angle_rad;             /* = pyins_output.table_angle_cmd_rad: commanded (unwrapped) angle */
    int32_t index_state;          /* = pyins_output.index_state (enum pyins_index_state) */
    int32_t index_fault;          /* = pyins_output.index_fault */
} pyins_motor_command;

/* The navigation solution alone, for a caller that wants it often (a
 * replay or a closed loop at the full rate): the fields of pyins_output of
 * the same names, bit for bit, without the Euler angles, the heading, the
 * alignment filter's state and the counters, whose derivation costs as much
 * as the navigation tick (pyins_run_nav, pyins_get_nav). 168 bytes against
 * pyins_output's 696. */
typedef struct pyins_nav {
    int64_t tick;                 /* = pyins_output.tick */
    int32_t mode;                 /* = pyins_output.mode (enum pyins_mode) */
    uint32_t fault_flags;         /* = pyins_output.fault_flags */
    uint32_t state_flags;         /* = pyins_output.state_flags */
    int32_t index_state;          /* = pyins_output.index_state */
    int32_t nav_mode;             /* = pyins_output.nav_mode (ABI 0.15) */
    uint32_t ref_in_use;          /* = pyins_output.ref_in_use (ABI 0.15) */
    double lat_rad;               /* = pyins_output.lat_rad: the reference point's */
    double lon_rad;               /* = pyins_output.lon_rad */
    double height_m;              /* = pyins_output.height_m */
    double vel_n_mps[3];          /* = pyins_output.vel_n_mps, ENU [m/s] */
    double quat_nb[4];            /* = pyins_output.quat_nb: ship attitude C_b^n, w >= 0 */
    double quat_np[4];            /* = pyins_output.quat_np: IMU attitude C_p^n, w >= 0 */
    double table_angle_rad;       /* = pyins_output.table_angle_rad */
    double motor_rate_cmd_rad_s;  /* = pyins_output.motor_rate_cmd_rad_s */
    double table_angle_cmd_rad;   /* = pyins_output.table_angle_cmd_rad */
} pyins_nav;

/* The firmware instance. Opaque: it lives in caller memory of
 * pyins_core_size() bytes aligned to pyins_core_align(). */
typedef struct pyins_core pyins_core;

/* (PYINS_ABI_VERSION_MAJOR << 16) | PYINS_ABI_VERSION_MINOR of the built library. */
uint32_t pyins_abi_version(void);

/* Library version as a static string, e.g. "0.1.0". Never NULL. */
const char *pyins_version_string(void);

/* Bytes and alignment a firmware instance needs. */
size_t pyins_core_size(void);
size_t pyins_core_align(void);

/* sizeof the public structs as the library was built, for layout checks. */
size_t pyins_sizeof_config(void);
size_t pyins_sizeof_sample(void);
size_t pyins_sizeof_output(void);
size_t pyins_sizeof_nav(void);

/* Write the default configuration into *cfg (a zeroed struct means the same).
 * Returns PYINS_OK or PYINS_E_NULL. */
int pyins_config_default(pyins_config *cfg);

/* Check a configuration without building anything.
 * Returns PYINS_OK or the first negative PYINS_E_CONFIG_* found. */
int pyins_config_check(const pyins_config *cfg);

/* Build a firmware instance inside mem (mem_size bytes, aligned to
 * pyins_core_align()); from then on (pyins_core *)mem is the instance.
 * On failure mem is left as it was. Never allocates.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_init(void *mem, size_t mem_size, const pyins_config *cfg);

/* Advance one tick with one sample and write the output record to *out.
 * A rejected sample (PYINS_E_SAMPLE_NONFINITE, PYINS_E_SAMPLE_SATURATED)
 * leaves the navigation state unchanged (only the fault bits and counters
 * record it); *out then holds that state. With PYINS_SEQ_CHECK a sample may
 * also stand for missing ticks (bridged first) or be a dropped duplicate.
 * Returns PYINS_OK, a positive PYINS_W_* notice (the first that applies of
 * SEQ_REPEAT, SEQ_LOST, SEQ_GAP, ENCODER_JUMP), or a negative pyins_status. */
int pyins_step(pyins_core *core, const pyins_sample *sample, pyins_output *out);

/* Step n samples from an array in one call, writing n output records
 * (outputs may be NULL when only the final state is wanted). Goes on through
 * PYINS_W_* notices (see the records' fault bits and counters) and stops at
 * the first rejected sample; *n_done (if not NULL) receives the number of
 * samples handled, so samples[*n_done] is the one rejected. N single steps
 * and one N-sample call give bit-identical outputs.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_run(pyins_core *core, const pyins_sample *samples, size_t n,
              pyins_output *outputs, size_t *n_done);

/* As pyins_run, but write an output record only after the steps whose tick
 * (pyins_output.tick, counted since init) reaches a multiple of out_every:
 * with out_every = 100 at 100 Hz, one record per second of ship time, in
 * phase whatever the chunking. A step that bridges missing ticks past a
 * multiple writes its record (its tick is then past the multiple).
 * outputs must hold out_capacity records; a capacity below n / out_every + 1
 * is refused up front (nothing stepped); bridged gaps can ask for more, and
 * the call then stops with PYINS_E_BUFFER_TOO_SMALL before the step that
 * would overflow (*n_done says where to go on). *n_out (if not NULL)
 * receives the number written.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_run_decimated(pyins_core *core, const pyins_sample *samples, size_t n,
                        size_t out_every, pyins_output *outputs, size_t out_capacity,
                        size_t *n_done, size_t *n_out);

/* As pyins_run_decimated, with the compact record pyins_nav: a record
 * after the steps whose tick reaches a multiple of out_every (1: after
 * every step that advances the tick), the same rules for the capacity,
 * gaps, rejected samples, *n_done and *n_out. The records are the
 * corresponding fields of pyins_run_decimated's, bit for bit.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_run_nav(pyins_core *core, const pyins_sample *samples, size_t n,
                  size_t out_every, pyins_nav *navs, size_t out_capacity,
                  size_t *n_done, size_t *n_out);

/* Hand the firmware one external reference (struct pyins_ref). Checked
 * whole before anything changes: an unknown kind, a non-finite value or
 * sigma <= 0, a tick out of order, too late or too far ahead, a full queue
 * or an UNDAMPED configuration is refused with its own status and leaves
 * the state as it was. Returns PYINS_OK or a negative pyins_status. */
int pyins_push_ref(pyins_core *core, const pyins_ref *ref);

/* Leave the indexing FAULT state: the cycle starts again at its first step
 * from the measured table angle (A_c, A_s kept). Does nothing otherwise.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_index_reset(pyins_core *core);

/* Bytes of a snapshot blob: a 24-byte header (magic "PYSN", format version,
 * ABI version, payload size, CRC-32 of the payload, reserved) and the whole
 * firmware state. */
size_t pyins_snapshot_size(void);

/* Write the whole state of core into buf (buf_size >= pyins_snapshot_size()).
 * Restoring it and stepping on gives output bit-identical to never stopping.
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_snapshot(const pyins_core *core, void *buf, size_t buf_size);

/* Build an instance in mem from a snapshot blob (like pyins_init). A
 * truncated, corrupted, wrong-version or wrong-size blob is refused and mem
 * is left as it was. Returns PYINS_OK or a negative pyins_status. */
int pyins_restore(void *mem, size_t mem_size, const void *buf, size_t buf_size);

/* Write the current state as an output record (no step).
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_get_output(const pyins_core *core, pyins_output *out);

/* Write the current state as a compact record (no step).
 * Returns PYINS_OK or a negative pyins_status. */
int pyins_get_nav(const pyins_core *core, pyins_nav *nav);

/* Write the indexing motor's command after the last step (no record is
 * built: a closed loop that reads the command every tick and a record every
 * second steps with pyins_run(core, &sample, 1, NULL, NULL), reads this, and
 * takes pyins_get_output only at its record ticks; the same bits as a
 * record every tick). Returns PYINS_OK or a negative pyins_status. */
int pyins_get_motor_command(const pyins_core *core, pyins_motor_command *cmd);

/* Static, human-readable name and meaning of a status code. Never NULL. */
const char *pyins_status_str(int status);

/* CDEF-END */

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#ifdef __cplusplus
}
#endif

#endif /* PYINS_CORE_H */
