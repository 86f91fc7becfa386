// indexing.hpp: the indexing-motor state machine of a single-axis rotation-
// modulated INS. Every scheme is data: a cycle of steps, each "stop for
// stop_ticks, then move". Mirrored by pyins/reference/indexing.py.
//
// Move kinds:
//   kFixed:   turn by `angle` (signed, rad; positive = "forward" =
//             counter-clockwise seen from above, the sense of alpha).
//   kFlexCos: seed 002 step 1: turn in the sense of `angle` until, on the
//             first tick, |cos psi + A_c/N_p| < delta and sin psi * A_s <= 0.
//   kFlexSin: seed 002 step 3: ... |sin psi + A_s/N_p| < delta and
//             cos psi * A_c <= 0.
// psi is the IMU yaw psi_p = psi_b + alpha from the firmware's own solution
// (counter-clockwise, docs/design.md §2); A_c, A_s accumulate cos psi,
// sin psi on every tick the table is stopped, are frozen while it turns and
// are never reset (seed 002, sec. 2); N_p is the stop's length in ticks
// (docs/papers.md, seed 002 §6, reading (b)). With `sums` = 1
// (PYINS_INDEX_SUMS_ALL, our extension) they also accumulate while the
// table turns: the drift integrated over the turns (about 9 % of the time at
// 300-s stops) is then cancelled by the flexible stops too, which seed 002's
// rule leaves uncontrolled (docs/indexing.md).
//
// Choices the paper leaves open (docs/indexing.md):
// - "opposite sign" takes zero as either sign (sin psi * A_s <= 0);
// - no heading satisfying the condition within `max_flex` of turning (e.g.
//   |A_c/N_p| > 1 + delta): the table stops after max_flex (default two
//   turns, 720 deg: the ship may turn back) and the fallback is counted;
// - the commanded motion is a trapezoidal rate profile (rate, accel); a
//   flexible stop decelerates from the tick the condition holds, so the table
//   stops v^2/(2 accel) further on (0.6 deg at 6 deg/s and 30 deg/s^2);
// - faults: the encoder lagging the command by more than `tolerance` for
//   `timeout_ticks` (stall, jam, wrong direction), or jumping by more than
//   `jump` in one tick, or drifting off a stop: FAULT, command 0, until reset.
//
// Heading isolation (`isolate` = 1, scheme PYINS_INDEX_HEADING_ISOLATION; the
// scheme seed 002 argues against, its refs. 7-8): on every tick of a stop or
// move the table also turns by minus the ship's yaw change, so that the IMU
// heading psi_p stays where the cycle puts it. The ship's yaw change comes
// from the solution: d psi_b = d psi_p - d alpha, with d alpha the encoder's
// change and d psi_p taken as the sine of the change of psi_p between two
// ticks, s_k c_(k-1) - c_k s_(k-1) (psi_p is held, so it is tiny and the sine
// is exact to its cube). The counter-rotation d = -d psi_b is added to the
// commanded angle (and to a move's target, so the move's own profile is
// unchanged) and d / dt to the commanded rate. The first tick after init or
// reset has no previous heading and turns by 0.
//
// Counters, every scheme: a motor start is a tick whose commanded rate is
// non-zero after a tick whose commanded rate was 0 (a move leaving a stop, or
// the counter-rotation starting); travel is the sum of |change of the
// commanded angle| over the ticks (the angle the motor is asked to turn, the
// counter-rotation included). Both survive a reset.
#pragma once

#include <cstdint>

namespace pyins::indexing {

enum class Kind : int32_t { kFixed = 1, kFlexCos = 2, kFlexSin = 3 };
enum class State : int32_t { kIdle = 0, kStop = 1, kMove = 2, kFault = 3 };
enum class Fault : int32_t { kNone = 0, kLag = 1, kJump = 2, kDrift = 3 };

inline constexpr int kMaxSteps = 8;
inline constexpr int32_t kSumsStops = 0;   ///< PYINS_INDEX_SUMS_STOPS (seed 002)
inline constexpr int32_t kSumsAll = 1;     ///< PYINS_INDEX_SUMS_ALL (turns too)

struct Step {
    int32_t stop_ticks;
    Kind kind;
    double angle;          ///< fixed: signed turn [rad]; flexible: its sign is the sense
};

struct Params {
    Step steps[kMaxSteps];
    int32_t n_steps;       ///< 0: no rotation (the table stays put)
    int32_t isolate;       ///< 1: heading isolation (counter-rotate against the ship's yaw)
    double rate;           ///< cruise rate [rad/s] > 0
    double accel;          ///< acceleration [rad/s^2] > 0
    double delta;          ///< flexible threshold (0.01 at 100 Hz, seed 002)
    double max_flex;       ///< longest flexible turn [rad]
    double tolerance;      ///< position tolerance [rad]
    double jump;           ///< largest believable encoder change in one tick [rad]
    int32_t timeout_ticks; ///< how long the encoder may lag
    int32_t sums;          ///< kSumsStops: A_c, A_s over stopped ticks (seed 002); kSumsAll: every tick
    double dt;             ///< tick [s]
};
// Every int32 beside another: no padding, so a Params copied from a stack
// local (Indexer::prm) carries no undefined bytes into a snapshot.
static_assert(sizeof(Step) == 2 * sizeof(int32_t) + sizeof(double), "indexing::Step has no padding");
static_assert(sizeof(Params) == kMaxSteps * sizeof(Step) + 7 * sizeof(double) + 4 * sizeof(int32_t),
              "indexing::Params has no padding");

struct Indexer {
    Params prm;
    State state;
    Fault fault;
    int32_t step;          ///< current step of the cycle
    int32_t stop_count;    ///< ticks stopped in this step
    int32_t lag_ticks;     ///< consecutive ticks the encoder is off the command
    int32_t fallbacks;     ///< flexible turns that ended at max_flex
    double a_c;            ///< sum of cos psi over stopped ticks (every tick with sums = 1)
    double a_s;            ///< sum of sin psi over the same ticks
    double cmd_angle;      ///< commanded (unwrapped) table angle [rad]
    double cmd_rate;       ///< commanded rate [rad/s] (signed)
    double target;         ///< where the current move ends [rad]
    double move_start;     ///< commanded angle at the start of the move [rad]
    double prev_meas;      ///< last encoder reading (unwrapped) [rad]
    bool target_known;     ///< fixed move, or flexible condition met / fallback
    bool have_heading;     ///< prev_sin, prev_cos hold the last tick's heading (isolate)
    int32_t motor_starts;  ///< ticks whose commanded rate left 0
    double travel;         ///< sum of |change of the commanded angle| [rad]
    double hold_rate;      ///< this tick's counter-rotation rate [rad/s] (0 without isolate)
    double prev_sin;       ///< sin psi_p of the last tick (isolate)
    double prev_cos;       ///< cos psi_p of the last tick (isolate)
};

/// Preset schemes (enum pyins_index_scheme): 0 none, 1 single-position
/// forward/reverse (seed 003), 2 traditional two-position (seed 002),
/// 3 four-position, 4 flexible two-position (seed 002), 6 the flexible scheme
/// of seed 002's derivation without the fixed 180-deg moves, 7 heading
/// isolation (a two-position cycle, +180 and -180, at the held heading). Writes the cycle into
/// steps (room for kMaxSteps) and returns its length, or -1 if unknown.
int32_t preset_steps(int32_t scheme, int32_t stop_ticks, Step* steps);

/// Start at the measured (unwrapped) table angle, first step, stopped.
void init(Indexer& ix, const Params& prm, double meas);

/// Whether this tick's update reads the IMU heading: a stop sums it, a move
/// tests it while its flexible target is open or when the turn's ticks are
/// summed too. The caller computes sin/cos psi_p only then.
bool wants_heading(const Indexer& ix);

/// One tick, after the navigation update: meas = unwrapped encoder angle at
/// t_k [rad]; sin_yaw_p, cos_yaw_p = sine and cosine of the IMU yaw psi_p
/// from the solution (read only where wants_heading says; 0 otherwise).
void update(Indexer& ix, double meas, double sin_yaw_p, double cos_yaw_p);

/// Leave FAULT: start the cycle again at the measured angle, keeping A_c, A_s
/// and the counters.
void reset(Indexer& ix, double meas);

}  // namespace pyins::indexing
