"""The indexing-motor state machine.

Mirrors ``csrc/src/indexing.{hpp,cpp}`` function by function, in the same
order (the header documents the schemes-as-data design and every choice):
the state changes (``_start_stop``, ``_start_move``, ``_enter_fault``), the
command checks (``_off_command``, ``_flex_condition``), one tick of the
command (``_advance_command``), then the interface: ``preset_steps``,
``init``, ``reset``, ``update``. ``run`` mirrors the test hook.
"""
from dataclasses import dataclass, field

import numpy as np

SUMS_STOPS = 0       #: kSumsStops (PYINS_INDEX_SUMS_STOPS): A_c, A_s over stopped ticks (seed 002)
SUMS_ALL = 1         #: kSumsAll (PYINS_INDEX_SUMS_ALL): over every tick, turns included (our extension)

KIND_FIXED = 1       #: Kind::kFixed
KIND_FLEX_COS = 2    #: Kind::kFlexCos
KIND_FLEX_SIN = 3    #: Kind::kFlexSin

STATE_IDLE = 0       #: State::kIdle
STATE_STOP = 1       #: State::kStop
STATE_MOVE = 2       #: State::kMove
STATE_FAULT = 3      #: State::kFault

FAULT_NONE = 0       #: Fault::kNone
FAULT_LAG = 1        #: Fault::kLag
FAULT_JUMP = 2       #: Fault::kJump
FAULT_DRIFT = 3      #: Fault::kDrift

MAX_STEPS = 8        #: kMaxSteps


@dataclass
class Step:
    stop_ticks: int
    kind: int
    angle: float


@dataclass
class Params:
    steps: list
    rate: float
    accel: float
    delta: float
    max_flex: float
    tolerance: float
    jump: float
    timeout_ticks: int
    dt: float
    sums: int = SUMS_STOPS   # (C++: after timeout_ticks; a default here keeps old callers working)
    isolate: int = 0         # 1: heading isolation (indexing.hpp)

    @property
    def n_steps(self):
        return len(self.steps)


@dataclass
class Indexer:
    prm: Params
    state: int = STATE_IDLE
    fault: int = FAULT_NONE
    step: int = 0
    stop_count: int = 0
    lag_ticks: int = 0
    fallbacks: int = 0
    a_c: float = 0.0
    a_s: float = 0.0
    cmd_angle: float = 0.0
    cmd_rate: float = 0.0
    target: float = 0.0
    move_start: float = 0.0
    prev_meas: float = 0.0
    target_known: bool = True
    have_heading: bool = False
    motor_starts: int = 0
    travel: float = 0.0
    hold_rate: float = 0.0
    prev_sin: float = 0.0
    prev_cos: float = 0.0


def _sense(angle):
    return -1.0 if angle < 0.0 else 1.0


def _start_stop(ix):
    ix.state = STATE_STOP
    ix.stop_count = 0
    ix.cmd_rate = ix.hold_rate   # 0 but while isolating
    ix.lag_ticks = 0


def _start_move(ix):
    s = ix.prm.steps[ix.step]
    ix.state = STATE_MOVE
    ix.move_start = ix.cmd_angle
    ix.lag_ticks = 0
    if s.kind == KIND_FIXED:
        ix.target = ix.cmd_angle + s.angle
        ix.target_known = True
    else:
        ix.target = ix.cmd_angle + _sense(s.angle) * ix.prm.max_flex
        ix.target_known = False


def _enter_fault(ix, f):
    ix.state = STATE_FAULT
    ix.fault = f
    ix.cmd_rate = 0.0


def _off_command(ix, meas, fault):
    """Count ticks off the command; True (and FAULT) past the timeout."""
    if abs(meas - ix.cmd_angle) > ix.prm.tolerance:
        ix.lag_ticks = ix.lag_ticks + 1
        if ix.lag_ticks > ix.prm.timeout_ticks:
            _enter_fault(ix, fault)
            return True
    else:
        ix.lag_ticks = 0
    return False


def _flex_condition(ix, kind, s, c):
    n_p = float(ix.prm.steps[ix.step].stop_ticks)
    if kind == KIND_FLEX_COS:
        return abs(c + ix.a_c / n_p) < ix.prm.delta and s * ix.a_s <= 0.0
    return abs(s + ix.a_s / n_p) < ix.prm.delta and c * ix.a_c <= 0.0


def _advance_command(ix):
    remaining = ix.target - ix.cmd_angle
    direction = _sense(remaining)
    dist = abs(remaining)
    dt = ix.prm.dt
    v = abs(ix.cmd_rate) + ix.prm.accel * dt
    if v > ix.prm.rate:
        v = ix.prm.rate
    v_brake = np.sqrt(2.0 * ix.prm.accel * dist)
    if v > v_brake:
        v = v_brake
    if v * dt >= dist:
        ix.cmd_angle = ix.target
        ix.cmd_rate = 0.0
        return True
    ix.cmd_angle = ix.cmd_angle + direction * v * dt
    ix.cmd_rate = direction * v
    return False


def preset_steps(scheme, stop_ticks):
    """Steps of a preset scheme (mirrors ``indexing::preset_steps``); None if unknown."""
    fx = KIND_FIXED
    pi = np.pi
    table = {
        0: [],
        1: [(fx, 2.0 * pi), (fx, -2.0 * pi)],
        2: [(fx, pi), (fx, pi), (fx, -pi), (fx, -pi)],
        3: [(fx, pi), (fx, -0.5 * pi), (fx, pi), (fx, -1.5 * pi)],
        4: [(KIND_FLEX_COS, 1.0), (fx, pi), (KIND_FLEX_SIN, -1.0), (fx, -pi)],
        6: [(KIND_FLEX_COS, 1.0), (KIND_FLEX_SIN, -1.0)],
        7: [(fx, pi), (fx, -pi)],    # heading isolation: two positions at the held heading
    }
    if scheme not in table:
        return None
    return [Step(stop_ticks, kind, angle) for kind, angle in table[scheme]]


def init(prm, meas):
    ix = Indexer(prm=prm, cmd_angle=meas, target=meas, move_start=meas, prev_meas=meas)
    if prm.n_steps == 0:
        ix.state = STATE_IDLE
    else:
        _start_stop(ix)
    return ix


def reset(ix, meas):
    """Leave FAULT: start the cycle again at ``meas``, keeping A_c, A_s."""
    new = init(ix.prm, meas)
    new.a_c, new.a_s, new.fallbacks = ix.a_c, ix.a_s, ix.fallbacks
    new.motor_starts, new.travel = ix.motor_starts, ix.travel
    return new


def wants_heading(ix):
    """Whether this tick's update reads the IMU heading (mirrors
    ``indexing::wants_heading``)."""
    if ix.state == STATE_STOP:
        return True
    return ix.state == STATE_MOVE and (ix.prm.sums == SUMS_ALL or not ix.target_known
                                       or ix.prm.isolate != 0)


def update(ix, meas, sin_yaw_p, cos_yaw_p):
    """One tick (mirrors ``indexing::update``); the heading as its sine and
    cosine, read only where ``wants_heading`` says. Counts the motor starts
    (commanded rate from 0 to non-zero) and the commanded travel."""
    rate0, angle0 = ix.cmd_rate, ix.cmd_angle
    _step_machine(ix, meas, sin_yaw_p, cos_yaw_p)
    if rate0 == 0.0 and ix.cmd_rate != 0.0:
        ix.motor_starts = ix.motor_starts + 1
    ix.travel = ix.travel + abs(ix.cmd_angle - angle0)


def _step_machine(ix, meas, sin_yaw_p, cos_yaw_p):
    dmeas = meas - ix.prev_meas
    jumped = abs(dmeas)
    ix.prev_meas = meas
    if ix.state in (STATE_IDLE, STATE_FAULT):
        return
    if jumped > ix.prm.jump:
        _enter_fault(ix, FAULT_JUMP)
        return
    # heading isolation: d = -d psi_b = d alpha - d psi_p (indexing.hpp)
    hold_prev = ix.hold_rate
    d = 0.0
    if ix.prm.isolate != 0:
        if ix.have_heading:
            d = dmeas - (sin_yaw_p * ix.prev_cos - cos_yaw_p * ix.prev_sin)
        ix.prev_sin, ix.prev_cos, ix.have_heading = sin_yaw_p, cos_yaw_p, True
        ix.hold_rate = d / ix.prm.dt
    if ix.state == STATE_STOP:
        # A_c, A_s accumulate cos and sin of psi_p while stopped (seed 002 sec. 2)
        ix.a_c = ix.a_c + cos_yaw_p
        ix.a_s = ix.a_s + sin_yaw_p
        ix.stop_count = ix.stop_count + 1
        if ix.prm.isolate != 0:
            ix.cmd_angle = ix.cmd_angle + d
            ix.cmd_rate = ix.hold_rate
        if _off_command(ix, meas, FAULT_DRIFT):
            return
        if ix.stop_count == ix.prm.steps[ix.step].stop_ticks:
            _start_move(ix)
        return
    # kMove
    s = ix.prm.steps[ix.step]
    if ix.prm.sums == SUMS_ALL:
        # our extension: the turn's ticks count too (before the test)
        ix.a_c = ix.a_c + cos_yaw_p
        ix.a_s = ix.a_s + sin_yaw_p
    if not ix.target_known:
        if _flex_condition(ix, s.kind, sin_yaw_p, cos_yaw_p):
            v = abs(ix.cmd_rate)
            ix.target = ix.cmd_angle + _sense(s.angle) * (v * v / (2.0 * ix.prm.accel))
            ix.target_known = True
        elif abs(ix.cmd_angle - ix.move_start) >= ix.prm.max_flex:
            ix.target_known = True
            ix.fallbacks = ix.fallbacks + 1
    if ix.prm.isolate != 0:
        # the profile's own rate, then the counter-rotation on angle and target
        ix.cmd_rate = ix.cmd_rate - hold_prev
        ix.cmd_angle = ix.cmd_angle + d
        ix.target = ix.target + d
    before = ix.cmd_angle
    arrived = _advance_command(ix)
    # isolating, the rate is the command's change, a move's partial last step included
    rate_iso = (ix.cmd_angle - before) / ix.prm.dt + ix.hold_rate
    if _off_command(ix, meas, FAULT_LAG):
        return
    if arrived and not ix.target_known:
        # the provisional end (max_flex) reached without the condition: the
        # fallback, taken on this tick (mirrors step_machine)
        ix.target_known = True
        ix.fallbacks = ix.fallbacks + 1
    if arrived and ix.target_known:
        ix.step = (ix.step + 1) % ix.prm.n_steps
        _start_stop(ix)
    if ix.prm.isolate != 0:
        ix.cmd_rate = rate_iso


def run(prm, meas0, meas, yaw_b):
    """Per-tick records of a whole run (mirrors the test hook
    pyins_t_indexing_run of c_api_testing.cpp)."""
    ix = init(prm, meas0)
    out = []
    for k in range(len(yaw_b)):
        m = meas[k] if meas is not None else ix.cmd_angle
        sn = cs = 0.0
        if wants_heading(ix):
            sn, cs = np.sin(yaw_b[k] + m), np.cos(yaw_b[k] + m)
        update(ix, m, sn, cs)
        out.append((ix.state, ix.step, ix.fault, ix.fallbacks, ix.cmd_angle, ix.cmd_rate,
                    ix.a_c, ix.a_s, ix.motor_starts, 0, ix.travel))
    return out
