"""Error analysis: the theoretical limits of static-base alignment.

Seed 001 (Yan Gongmin, Qin Yongyuan 2006), sec. 3.2 and eq. 21: on a static
base three combinations are unobservable, so even a perfect filter leaves

    phi_N = nabla_E / g,          phi_E = -nabla_N / g,
    phi_U = -eps_E / w_N + tan(L) nabla_E / g,
    eps_N: (nabla_N / g) w_U,     eps_U: -(nabla_N / g) w_N     (true - estimate)

with w_N = W cos L, w_U = W sin L and nabla, eps the n-frame projections of
the body-frame accelerometer biases and gyro drifts. The 8-state filter
cannot estimate eps_E, nabla_E, nabla_N at all (their limit is their own
value); the reduced 5-state filter estimates the transformed states of eq. 21
exactly in the limit, i.e. ``reduced_truth`` below.
"""
from dataclasses import dataclass

import numpy as np

from pyins.reference import attitude, earth


@dataclass
class AlignmentLimits:
    """Limits as true minus estimate (attitude: phi in n, C' = (I - phi x) C)."""
    phi_n: np.ndarray          #: [phi_E, phi_N, phi_U] [rad]
    eps_n_limit: np.ndarray    #: [eps_E, eps_N, eps_U] limit [rad/s]; eps_E: its own value
    nabla_n: np.ndarray        #: [nabla_E, nabla_N] [m/s^2], never estimated (8-state)
    eps_n: np.ndarray          #: the drifts projected into n [rad/s]


def alignment_limits(lat, euler_b, gyro_bias_b, accel_bias_b, height=0.0):
    """Theoretical limiting accuracies for a static IMU at ``euler_b``.

    ``gyro_bias_b`` [rad/s] and ``accel_bias_b`` [m/s^2] are in the IMU frame.
    """
    mat_nb = attitude.euler_to_mat(np.asarray(euler_b, dtype=float))
    nabla = mat_nb @ np.asarray(accel_bias_b, dtype=float)
    eps = mat_nb @ np.asarray(gyro_bias_b, dtype=float)
    g = earth.normal_gravity(np.sin(lat), height)
    w_n = earth.OMEGA_IE * np.cos(lat)
    w_u = earth.OMEGA_IE * np.sin(lat)
    phi = np.array([-nabla[1] / g, nabla[0] / g, -eps[0] / w_n + np.tan(lat) * nabla[0] / g])
    eps_lim = np.array([eps[0], nabla[1] / g * w_u, -nabla[1] / g * w_n])
    return AlignmentLimits(phi_n=phi, eps_n_limit=eps_lim, nabla_n=nabla[:2], eps_n=eps)


def reduced_truth(limits, phi_true=np.zeros(3)):
    """True values of the 5 transformed states of seed 001 eq. 21, for an
    attitude error ``phi_true`` [rad] (with feedback: the residual error).

    [phi_E + nabla_N/g, phi_N - nabla_E/g, phi_U + eps_E/w_N - tanL nabla_E/g,
     eps_N - (nabla_N/g) w_U, eps_U + (nabla_N/g) w_N]
    = [phi - phi_limit, eps_N - eps_N_limit, eps_U - eps_U_limit].
    """
    phi_hat = np.asarray(phi_true, dtype=float) - limits.phi_n
    eps_hat = limits.eps_n[1:] - limits.eps_n_limit[1:]
    return np.concatenate([phi_hat, eps_hat])


# ---------------------------------------------------------------------------
# Linear error model of a static INS (an error-budget tool)
# ---------------------------------------------------------------------------
@dataclass
class StaticErrors:
    """Errors predicted by the linear model at the times asked for."""
    time_s: np.ndarray
    att_n_rad: np.ndarray    #: phi (E, N, U), (N, 3), same sign as metrics.NavErrors
    vel_n_mps: np.ndarray    #: (N, 2) east, north
    north_m: np.ndarray
    east_m: np.ndarray
    horizontal_m: np.ndarray


def static_error_model(lat, times_s, eps_n, nabla_n=None, height=0.0, step_s=0.5):
    """Propagate the linear phi-angle error equations of a static INS.

    Qin Yongyuan, "Inertial Navigation" (2014), sec. 4.2 (ENU, psi = 0 ship
    at rest, vertical channel held):

        phi'  = -omega_ie x phi + d_omega_in - eps^n
                d_omega_in = [-dvN/RM, dvE/RN - W sinL dL, dvE tanL/RN + W cosL dL]
        dvE'  = -g phi_N + 2 W sinL dvN + nabla_E
        dvN'  =  g phi_E - 2 W sinL dvE + nabla_N
        dL'   = dvN / RM,   dlambda' = dvE / (RN cosL)

    with its Schuler (84 min), Earth-rate (24 h) and Foucault couplings.
    ``eps_n`` is the gyro drift in n [rad/s]: a 3-vector, or a function that
    maps an array of times (N,) to drifts (N, 3) (a rotating IMU:
    C_p^n(t) eps^p); ``nabla_n`` likewise for the accelerometer bias (E, N
    used). Integrated by fourth-order Runge-Kutta with ``step_s`` (the
    inputs are sampled on the half-step grid); returns StaticErrors at
    ``times_s``.
    """
    times_s = np.asarray(times_s, dtype=float)
    half = 0.5 * step_s
    grid = np.arange(0.0, times_s.max() + 2 * step_s, half)

    def sampled(src):
        if src is None:
            return np.zeros((len(grid), 3))
        if callable(src):
            return np.asarray(src(grid), dtype=float).reshape(len(grid), 3)
        return np.tile(np.asarray(src, dtype=float), (len(grid), 1))

    eps_grid = sampled(eps_n)
    nab_grid = sampled(nabla_n)

    def eps_f(t):
        return eps_grid[int(round(t / half))]

    def nab_f(t):
        return nab_grid[int(round(t / half))]
    sin_lat, cos_lat = np.sin(lat), np.cos(lat)
    rm, rn = earth.principal_radii(sin_lat)
    rm_h, rn_h = rm + height, rn + height
    g = earth.normal_gravity(sin_lat, height)
    w = earth.OMEGA_IE
    w_n, w_u = w * cos_lat, w * sin_lat

    def f(t, x):
        phi_e, phi_n, phi_u, dve, dvn, dlat, _ = x
        eps = eps_f(t)
        nab = nab_f(t)
        return np.array([
            w_u * phi_n - w_n * phi_u - dvn / rm_h - eps[0],
            -w_u * phi_e + dve / rn_h - w_u * dlat - eps[1],
            w_n * phi_e + dve * np.tan(lat) / rn_h + w_n * dlat - eps[2],
            -g * phi_n + 2.0 * w_u * dvn + nab[0],
            g * phi_e - 2.0 * w_u * dve + nab[1],
            dvn / rm_h,
            dve / (rn_h * cos_lat),
        ])

    x = np.zeros(7)
    t = 0.0
    out = np.zeros((len(times_s), 7))
    for i, target in enumerate(times_s):
        while t < target - 1e-9:
            h = step_s
            if target - t < step_s - 1e-9:
                raise ValueError(f"times_s must be multiples of step_s ({step_s} s); got {target}")
            k1 = f(t, x)
            k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
            k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
            k4 = f(t + h, x + h * k3)
            x = x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            t = t + h
        out[i] = x
    north = out[:, 5] * rm_h
    east = out[:, 6] * rn_h * cos_lat
    return StaticErrors(time_s=times_s, att_n_rad=out[:, :3], vel_n_mps=out[:, 3:5], north_m=north,
                        east_m=east, horizontal_m=np.hypot(north, east))


def table_projected(bias_p, euler_b, rec_time_s, rec_alpha_rad, alpha0=0.0):
    """The IMU-frame constant ``bias_p`` (3,) seen in n on a static ship at
    ``euler_b`` whose table turned as recorded (times [s], angles [rad],
    unwrapped; ``alpha0`` at t = 0): a function of time for
    ``static_error_model``.

    C_p^n(t) = C_b^n Rz(alpha(t)) (docs/design.md §2); alpha is interpolated
    linearly between records, exact while the table turns at constant rate
    or stands still.
    """
    mat_nb = attitude.euler_to_mat(np.asarray(euler_b, dtype=float))
    b = np.asarray(bias_p, dtype=float)
    t_rec = np.concatenate([[0.0], np.asarray(rec_time_s, dtype=float)])
    a_rec = np.concatenate([[alpha0], np.asarray(rec_alpha_rad, dtype=float)])

    def in_n(t):
        alpha = np.interp(t, t_rec, a_rec)
        c, s = np.cos(alpha), np.sin(alpha)
        in_b = np.column_stack([c * b[0] - s * b[1], s * b[0] + c * b[1], np.full_like(t, b[2])])
        return in_b @ mat_nb.T
    return in_n


def predict_static_fil(result, lat, euler_b, gyro_bias_p, accel_bias_p, times_s, alpha0=0.0,
                       step_s=0.5):
    """What the linear error model says a static FIL run should show.

    ``result`` is a ``pyins.records.FilResult`` (its plant records give the table
    angle); the constant gyro drifts and accelerometer biases of the IMU
    frame are projected through the table angle and propagated by
    ``static_error_model``. Scale-factor, installation and random errors are
    left out: for a static ship they are second order.
    """
    t_rec = result.plant["tick"] * result.dt
    alpha = result.plant["alpha_rad"]
    return static_error_model(lat, times_s, table_projected(gyro_bias_p, euler_b, t_rec, alpha, alpha0),
                              table_projected(accel_bias_p, euler_b, t_rec, alpha, alpha0),
                              step_s=step_s)


def drift_surviving(yaw_p, mask=None):
    """The fraction of a constant x/y drift of the IMU that survives the
    modulation (the proxy of docs/papers.md, seed 002 §10): |sum of [cos psi,
    sin psi]| / number of samples, psi the IMU yaw sampled uniformly (e.g.
    an output record every second). With ``mask`` only the masked samples
    are summed (still divided by all of them), e.g. the stopped ones: the
    parts add up as vectors."""
    psi = np.asarray(yaw_p, dtype=float)
    sel = psi if mask is None else psi[np.asarray(mask, dtype=bool)]
    return float(np.hypot(np.cos(sel).sum(), np.sin(sel).sum()) / len(psi))
