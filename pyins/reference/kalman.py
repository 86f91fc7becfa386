"""Fixed-size linear Kalman filter steps. Mirrors ``csrc/src/kalman.hpp``:
time update, Joseph-form measurement update for two measurements,
symmetrisation, diagonal positive-definiteness check."""
import numpy as np


def predict(x, p, phi, qd):
    """x <- Phi x; P <- Phi P Phi^T + Qd, symmetrised. Returns (x, P)."""
    x = phi @ x
    pp = phi @ p @ phi.T + qd
    return x, 0.5 * (pp + pp.T)


def update2(x, p, h, z, r):
    """Joseph-form update with z = H x + v (2 measurements).

    Returns (x, P, nis) with nis = nu^T S^-1 nu the normalised innovation
    squared (mirrors update2).
    """
    s = h @ p @ h.T + r
    det = s[0, 0] * s[1, 1] - s[0, 1] * s[1, 0]
    s_inv = np.array([[s[1, 1] / det, -s[0, 1] / det],
                      [-s[1, 0] / det, s[0, 0] / det]])
    k = p @ h.T @ s_inv
    nu = z - h @ x
    nis = float(nu @ (s_inv @ nu))
    x = x + k @ nu
    ikh = np.eye(len(x)) - k @ h
    pj = ikh @ p @ ikh.T + k @ r @ k.T
    return x, 0.5 * (pj + pj.T), nis


def diagonal_positive(p):
    d = np.diag(p)
    return bool(np.all(d > 0.0) and np.all(np.isfinite(d)))
