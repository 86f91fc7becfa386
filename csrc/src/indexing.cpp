// indexing.cpp: see indexing.hpp. Mirrored by pyins/reference/indexing.py.
#include "indexing.hpp"

#include <cmath>

#include "math_portable.hpp"
#include "units.hpp"

namespace pyins::indexing {

namespace {

double sense(double angle) { return angle < 0.0 ? -1.0 : 1.0; }

void start_stop(Indexer& ix) {
    ix.state = State::kStop;
    ix.stop_count = 0;
    ix.cmd_rate = ix.hold_rate;   // 0 but while isolating
    ix.lag_ticks = 0;
}

void start_move(Indexer& ix) {
    const Step& s = ix.prm.steps[ix.step];
    ix.state = State::kMove;
    ix.move_start = ix.cmd_angle;
    ix.lag_ticks = 0;
    if (s.kind == Kind::kFixed) {
        ix.target = ix.cmd_angle + s.angle;
        ix.target_known = true;
    } else {
        // provisional: the fallback end of the turn
        ix.target = ix.cmd_angle + sense(s.angle) * ix.prm.max_flex;
        ix.target_known = false;
    }
}

void enter_fault(Indexer& ix, Fault f) {
    ix.state = State::kFault;
    ix.fault = f;
    ix.cmd_rate = 0.0;
}

/// Count the ticks the encoder is off the command; true (and FAULT) once
/// that lasts longer than the timeout.
bool off_command(Indexer& ix, double meas, Fault f) {
    if (std::fabs(meas - ix.cmd_angle) > ix.prm.tolerance) {
        ix.lag_ticks = ix.lag_ticks + 1;
        if (ix.lag_ticks > ix.prm.timeout_ticks) {
            enter_fault(ix, f);
            return true;
        }
    } else {
        ix.lag_ticks = 0;
    }
    return false;
}

/// The flexible stop condition of seed 002 on this tick's heading (s, c =
/// its sin and cos).
bool flex_condition(const Indexer& ix, Kind kind, double s, double c) {
    const double n_p = static_cast<double>(ix.prm.steps[ix.step].stop_ticks);
    if (kind == Kind::kFlexCos) {
        return std::fabs(c + ix.a_c / n_p) < ix.prm.delta && s * ix.a_s <= 0.0;
    }
    return std::fabs(s + ix.a_s / n_p) < ix.prm.delta && c * ix.a_c <= 0.0;
}

/// Advance the commanded angle one tick along a trapezoidal profile to
/// target; returns true once the command has arrived.
bool advance_command(Indexer& ix) {
    const double remaining = ix.target - ix.cmd_angle;
    const double dir = sense(remaining);
    const double dist = std::fabs(remaining);
    const double dt = ix.prm.dt;
    double v = std::fabs(ix.cmd_rate) + ix.prm.accel * dt;
    if (v > ix.prm.rate) {
        v = ix.prm.rate;
    }
    const double v_brake = pmath::sqrt(2.0 * ix.prm.accel * dist);
    if (v > v_brake) {
        v = v_brake;
    }
    if (v * dt >= dist) {
        ix.cmd_angle = ix.target;
        ix.cmd_rate = 0.0;
        return true;
    }
    ix.cmd_angle = ix.cmd_angle + dir * v * dt;
    ix.cmd_rate = dir * v;
    return false;
}

}  // namespace

int32_t preset_steps(int32_t scheme, int32_t stop_ticks, Step* steps) {
    const Kind fx = Kind::kFixed;
    switch (scheme) {
        case 0:  // none: the IMU stays fixed to the ship
            return 0;
        case 1:  // seed 003: stop at zero, +360 (counter-clockwise), stop, -360
            steps[0] = Step{stop_ticks, fx, 2.0 * kPi};
            steps[1] = Step{stop_ticks, fx, -2.0 * kPi};
            return 2;
        case 2:  // seed 002 traditional: stops at 0, 180, 0 (360), 180, back to 0
            steps[0] = Step{stop_ticks, fx, kPi};
            steps[1] = Step{stop_ticks, fx, kPi};
            steps[2] = Step{stop_ticks, fx, -kPi};
            steps[3] = Step{stop_ticks, fx, -kPi};
            return 4;
        case 3:  // four-position 0, 180, 90, 270 within 0..270 deg (no slip ring)
            steps[0] = Step{stop_ticks, fx, kPi};
            steps[1] = Step{stop_ticks, fx, -0.5 * kPi};
            steps[2] = Step{stop_ticks, fx, kPi};
            steps[3] = Step{stop_ticks, fx, -1.5 * kPi};
            return 4;
        case 4:  // seed 002 flexible: flex-cos forward, +180, flex-sin reverse, -180
            steps[0] = Step{stop_ticks, Kind::kFlexCos, 1.0};
            steps[1] = Step{stop_ticks, fx, kPi};
            steps[2] = Step{stop_ticks, Kind::kFlexSin, -1.0};
            steps[3] = Step{stop_ticks, fx, -kPi};
            return 4;
        case 6:  // seed 002's derivation (eqs. 9-13): conditional stops only
            steps[0] = Step{stop_ticks, Kind::kFlexCos, 1.0};
            steps[1] = Step{stop_ticks, Kind::kFlexSin, -1.0};
            return 2;
        case 7:  // heading isolation (seed 002, refs. 7-8): two positions at the held heading
            steps[0] = Step{stop_ticks, fx, kPi};
            steps[1] = Step{stop_ticks, fx, -kPi};
            return 2;
        default:
            return -1;
    }
}

void init(Indexer& ix, const Params& prm, double meas) {
    ix.prm = prm;
    ix.fault = Fault::kNone;
    ix.step = 0;
    ix.fallbacks = 0;
    ix.a_c = 0.0;
    ix.a_s = 0.0;
    ix.cmd_angle = meas;
    ix.target = meas;
    ix.move_start = meas;
    ix.prev_meas = meas;
    ix.target_known = true;
    ix.have_heading = false;
    ix.motor_starts = 0;
    ix.travel = 0.0;
    ix.hold_rate = 0.0;
    ix.prev_sin = 0.0;
    ix.prev_cos = 0.0;
    if (prm.n_steps == 0) {
        ix.state = State::kIdle;
        ix.stop_count = 0;
        ix.cmd_rate = 0.0;
        ix.lag_ticks = 0;
    } else {
        start_stop(ix);
    }
}

void reset(Indexer& ix, double meas) {
    const double a_c = ix.a_c;
    const double a_s = ix.a_s;
    const int32_t fallbacks = ix.fallbacks;
    const int32_t starts = ix.motor_starts;
    const double travel = ix.travel;
    init(ix, ix.prm, meas);
    ix.a_c = a_c;
    ix.a_s = a_s;
    ix.fallbacks = fallbacks;
    ix.motor_starts = starts;
    ix.travel = travel;
}

bool wants_heading(const Indexer& ix) {
    if (ix.state == State::kStop) {
        return true;
    }
    return ix.state == State::kMove && (ix.prm.sums == kSumsAll || !ix.target_known || ix.prm.isolate != 0);
}

namespace {

void step_machine(Indexer& ix, double meas, double sin_yaw_p, double cos_yaw_p) {
    const double dmeas = meas - ix.prev_meas;
    const double jumped = std::fabs(dmeas);
    ix.prev_meas = meas;
    if (ix.state == State::kIdle || ix.state == State::kFault) {
        return;
    }
    if (jumped > ix.prm.jump) {
        enter_fault(ix, Fault::kJump);
        return;
    }
    // heading isolation: d = -d psi_b = d alpha - d psi_p (see the header)
    const double hold_prev = ix.hold_rate;
    double d = 0.0;
    if (ix.prm.isolate != 0) {
        if (ix.have_heading) {
            d = dmeas - (sin_yaw_p * ix.prev_cos - cos_yaw_p * ix.prev_sin);
        }
        ix.prev_sin = sin_yaw_p;
        ix.prev_cos = cos_yaw_p;
        ix.have_heading = true;
        ix.hold_rate = d / ix.prm.dt;
    }
    if (ix.state == State::kStop) {
        // A_c, A_s accumulate cos and sin of psi_p while stopped (seed 002 sec. 2)
        ix.a_c = ix.a_c + cos_yaw_p;
        ix.a_s = ix.a_s + sin_yaw_p;
        ix.stop_count = ix.stop_count + 1;
        if (ix.prm.isolate != 0) {
            ix.cmd_angle = ix.cmd_angle + d;
            ix.cmd_rate = ix.hold_rate;
        }
        if (off_command(ix, meas, Fault::kDrift)) {
            return;
        }
        if (ix.stop_count == ix.prm.steps[ix.step].stop_ticks) {
            start_move(ix);
        }
        return;
    }
    // kMove
    const Step& s = ix.prm.steps[ix.step];
    if (ix.prm.sums == kSumsAll) {
        // our extension: the turn's ticks count too (before the test, as a
        // stopped tick's heading counts before its stop may end)
        ix.a_c = ix.a_c + cos_yaw_p;
        ix.a_s = ix.a_s + sin_yaw_p;
    }
    if (!ix.target_known) {
        if (flex_condition(ix, s.kind, sin_yaw_p, cos_yaw_p)) {
            // stop as soon as the profile allows: brake from here
            const double v = std::fabs(ix.cmd_rate);
            ix.target = ix.cmd_angle + sense(s.angle) * (v * v / (2.0 * ix.prm.accel));
            ix.target_known = true;
        } else if (std::fabs(ix.cmd_angle - ix.move_start) >= ix.prm.max_flex) {
            ix.target_known = true;   // no heading met the condition: give up here
            ix.fallbacks = ix.fallbacks + 1;
        }
    }
    if (ix.prm.isolate != 0) {
        // the profile's own rate, then the counter-rotation on angle and target
        ix.cmd_rate = ix.cmd_rate - hold_prev;
        ix.cmd_angle = ix.cmd_angle + d;
        ix.target = ix.target + d;
    }
    const double before = ix.cmd_angle;
    const bool arrived = advance_command(ix);
    // isolating, the rate is the command's change (the last, partial step of a
    // move included, which the profile leaves at rate 0): a rate-following
    // table then keeps the held heading over any number of moves
    const double rate_iso = (ix.cmd_angle - before) / ix.prm.dt + ix.hold_rate;
    if (off_command(ix, meas, Fault::kLag)) {
        return;
    }
    if (arrived && !ix.target_known) {
        // the provisional end (max_flex from the start) reached on this
        // tick without the condition met: the fallback, taken now (the test
        // above sees it only on the next tick, which stood the table still
        // one tick as part of the move)
        ix.target_known = true;
        ix.fallbacks = ix.fallbacks + 1;
    }
    if (arrived && ix.target_known) {
        ix.step = (ix.step + 1) % ix.prm.n_steps;
        start_stop(ix);
    }
    if (ix.prm.isolate != 0) {
        ix.cmd_rate = rate_iso;
    }
}

}  // namespace

void update(Indexer& ix, double meas, double sin_yaw_p, double cos_yaw_p) {
    const double rate0 = ix.cmd_rate;
    const double angle0 = ix.cmd_angle;
    step_machine(ix, meas, sin_yaw_p, cos_yaw_p);
    if (rate0 == 0.0 && ix.cmd_rate != 0.0) {
        ix.motor_starts = ix.motor_starts + 1;   // the motor leaves rest
    }
    ix.travel = ix.travel + std::fabs(ix.cmd_angle - angle0);
}

}  // namespace pyins::indexing
