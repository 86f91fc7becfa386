// config.hpp: the configuration contract, apart from the instance.
//
// Mirrored by pyins/reference/config.py. A pyins_config field left 0 means
// "the default": (1) the defaults, one table; (2) config_default, the
// zeroed struct; (3) config_resolved, the defaults put in; (4) config_check,
// PYINS_OK or the first PYINS_E_CONFIG_* status that applies. pyins_init
// checks everything before it changes any state (c_api.cpp); the instance
// (firmware.hpp) takes a checked configuration and resolves it.
#pragma once

#include <cstdint>

#include "pyins_core.h"
#include "units.hpp"

namespace pyins::config {

// --- 1. the defaults, and the limits the checks hold a configuration to ------
inline constexpr int32_t kDefaultTickHz = 100;
inline constexpr int32_t kMaxTickHz = 10000;
/// The ENU frame is singular at the poles: latitudes beyond this are refused.
inline constexpr double kMaxLatRad = 89.9 * kPi / 180.0;
/// Coarse alignment defaults, in seconds (seed 000: first output 20 s, then 1 s).
inline constexpr int32_t kDefaultCoarseFirstS = 20;
inline constexpr int32_t kDefaultCoarseEveryS = 1;
inline constexpr double kDefaultCoarseRatio = 0.5;
/// Fine alignment defaults (seed 001 sec. 3.3; docs/papers.md, seed 001 §3).
inline constexpr int32_t kDefaultFineStates = 5;
inline constexpr int32_t kDefaultFineMeasEvery = 10;             ///< 10 Hz updates at 100 Hz
inline constexpr int32_t kDefaultMovingMeasEverySecond = 1;      ///< moving base: 1 Hz position updates
inline constexpr double kDefaultPosSigma = 0.5;                  ///< [m]: a moored ship's surge and sway
inline constexpr double kDefaultSigma0Vel = 0.5;                 ///< [m/s]: its wave velocity at the start
inline constexpr double kDefaultFineArw = 0.001 * kDegToRad / 60.0;  ///< 0.001 deg/sqrt(h)
inline constexpr double kDefaultFineVrw = 10.0e-6 * kG0;   ///< 10 ug/sqrt(Hz)
inline constexpr double kDefaultFineSigmaAtt[3] = {100.0 * kArcminToRad, 100.0 * kArcminToRad,
                                                   600.0 * kArcminToRad};  ///< 10 x [10', 10', 60']
// (without a coarse phase; after one the static filters fit the attitude
// sigmas to the coarse result, capped at these: fine_align::sigma0_after_coarse)
/// Moving base: the initial attitude sigma is what FIT leaves after 120 s or
/// more on a navigation-grade IMU, with margin: 1', 1', 10' (seed 001's 600'
/// of heading lets the wave noise swing the early heading; docs/concepts.md,
/// "Alignment on a moving base").
inline constexpr double kDefaultMovingSigmaAtt[3] = {1.0 * kArcminToRad, 1.0 * kArcminToRad,
                                                     10.0 * kArcminToRad};
inline constexpr double kDefaultFineSigmaGyro = 0.01 * kDegToRad / 3600.0;
inline constexpr double kDefaultFineSigmaAccel = 100.0e-6 * kG0;  ///< 100 ug (not in seed 001)
/// Indexing defaults (seeds 002, 003: 6 deg/s; stops 60 s in seed 003, 300 s in seed 002).
inline constexpr double kDefaultIndexRate = 6.0 * kDegToRad;
inline constexpr double kDefaultIndexAccel = 30.0 * kDegToRad;     ///< not in the papers
inline constexpr double kDefaultIndexDelta = 0.01;            ///< seed 002, at 100 Hz
inline constexpr double kDefaultIndexMaxFlex = 720.0 * kDegToRad;  ///< two turns: the ship may turn back
inline constexpr double kDefaultIndexTolerance = 0.5 * kDegToRad;
inline constexpr double kDefaultIndexJump = 5.0 * kDegToRad;
inline constexpr int32_t kDefaultIndexTimeoutS = 2;
inline constexpr int32_t kDefaultStopSeed003S = 60;
inline constexpr int32_t kDefaultStopS = 300;
/// Sample-level faults (docs/core.md, "Sample-level faults", which says why
/// a ship stays far below them). Saturation defaults: 400 deg/s and 20 g per
/// axis, the order of a navigation-grade RLG IMU's range: only a saturated
/// sensor (a shock) or a corrupted word reaches them.
inline constexpr double kDefaultSatGyroRate = 400.0 * kDegToRad;      ///< [rad/s]
inline constexpr double kDefaultSatAccel = 20.0 * kG0;       ///< [m/s^2]
/// Longest gap bridged by interpolation [ticks]; see docs/core.md for the
/// error it leaves on seed 000's bad sea state.
inline constexpr int32_t kDefaultSeqMaxGap = 2;
/// Upper bound of seq_max_gap_ticks: one step call bridges at most this many
/// ticks (its worst-case run time is that many strapdown updates).
inline constexpr int32_t kMaxSeqGap = 100;
/// Longest lever arm accepted [m]: a ship's IMU is metres from its reference
/// point; beyond 100 m the number is a unit mistake (mm or inches).
inline constexpr double kMaxLeverM = 100.0;
/// Integrity defaults (docs/concepts.md, "Integrity", which holds what FIT
/// and TRIAD wander on the moored ship): 100 updates (10 s at 10 Hz) per NIS
/// window and a bound of 4 on its mean (10 sigma of a consistent window);
/// the coarse solution may wander 30' over its last fifth.
inline constexpr int32_t kDefaultNisWindow = 100;
inline constexpr double kDefaultNisMax = 4.0;
inline constexpr double kDefaultCoarseWander = 30.0 * kArcminToRad;

/// Navigation at sea (docs/concepts.md, "At sea"): the filter's time update
/// once a second (the Schuler period is 84 min: the linearisation's error
/// over 1 s is 1e-6 of the state's); the gate at chi-square(2) 99.9 % (a
/// consistent filter rejects one good pair in 1,000); 10 rejections in a
/// row put a kind out of use (10 s of GNSS: a multipath jump lasts one or
/// two fixes, a frozen or offset receiver stays); a reference may arrive up
/// to 1 s after its tick (a receiver's latency is 20-200 ms) and be pushed
/// up to 10 s before it (the queue holds 8).
inline constexpr int32_t kDefaultNavEveryS = 1;
inline constexpr int32_t kMaxNavEveryS = 10;
inline constexpr double kDefaultNavGate = 13.8155;   ///< -2 ln(0.001)
inline constexpr int32_t kDefaultNavRejectLimit = 10;
inline constexpr int32_t kDefaultRefLatencyS = 1;
inline constexpr int32_t kRefHorizonS = 10;
/// Bounds on the navigation filter's model beyond its bias states
/// (pyins_core.h): a random walk of 0.2 deg/h per sqrt(s), a scale factor
/// or misalignment of 1 % (far beyond any gyro a ship's INS carries; the
/// bound catches a value in the wrong unit).
inline constexpr double kMaxNavGyroBiasRw = 1e-6;
inline constexpr double kMaxNavTableSigma = 0.01;
/// The fastest a site may move during an alignment [m/s], beyond a
/// reference velocity's noise (3 sigma) and its lever arm's rotation: the
/// waves move a moored ship's reference point by at most ~0.25 m/s (seed
/// 000's sea states with 0.3 m of surge and sway), and a ship making 0.5 m/s
/// over ground turns the frame the coarse alignment takes for fixed by its
/// transport rate, a heading bias of v / (R Omega cos L): 4.5' at 34 deg,
/// 10' at 70 deg. Faster, the alignment cannot be right.
inline constexpr double kAlignMaxSpeed = 0.5;
/// The longest an alignment under way (PYINS_COARSE_FIT_VEL) goes without a
/// GNSS velocity [s]: its integral of the velocity is linear in between, off
/// by a' h^2 / 8 in a turn of acceleration a' (0.04 m at 0.16 m/s^2 and 1 s,
/// 0.4 m at 3 s: 0.3' and 3' of heading against the 132 m of the Earth's
/// rate over 120 s), and a gap of seconds is a receiver that is not tracking.
inline constexpr int32_t kCoarseRefGapS = 3;
/// Initial sigmas of the navigation filter's position and velocity when
/// navigation starts from an alignment at the site [m, m/s] (the site's
/// survey; the alignment's velocity residual), and of its attitude when no
/// fine alignment ran [rad].
inline constexpr double kNavSigma0Pos = 10.0;
inline constexpr double kNavSigma0Vel = 0.1;

/// 2. Fill *cfg with the defaults (equal to a zeroed config).
void config_default(pyins_config* cfg);

/// 3. The configuration with every zero-means-default field resolved.
pyins_config config_resolved(const pyins_config& cfg);

/// 4. PYINS_OK or the first PYINS_E_CONFIG_* that applies.
int config_check(const pyins_config& cfg);

}  // namespace pyins::config
