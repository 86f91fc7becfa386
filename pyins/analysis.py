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
