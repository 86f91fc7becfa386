"""Hypothesis strategies for the domain, with the edge cases listed first so
shrinking lands on readable values (cf. astropy's time precision tests)."""
import numpy as np
from hypothesis import strategies as st

DEG = np.pi / 180.0


def finite(lo, hi):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


def latitudes():
    """Geodetic latitude [rad], up to +-89 deg, with the equator and near-pole values."""
    simple = [0.0, 45.0 * DEG, -60.0 * DEG, 89.0 * DEG, -89.0 * DEG, 34.246 * DEG]
    return st.one_of(st.sampled_from(simple), finite(-89.0 * DEG, 89.0 * DEG))


def heights():
    return st.one_of(st.sampled_from([0.0, 380.0, -50.0]), finite(-500.0, 10000.0))


def vectors(scale):
    """3-vectors with components in [-scale, scale], including zero and tiny ones."""
    comp = st.one_of(st.sampled_from([0.0, scale, -scale, 1e-12 * scale]), finite(-scale, scale))
    return st.tuples(comp, comp, comp).map(np.array)


def rotation_vectors():
    """Rotation vectors: zero, the small-angle series branch (|v|^2 < 1e-3),
    its boundary, ordinary angles, and angles near pi."""
    def near(angle):
        return unit_vectors().flatmap(
            lambda u: finite(-1e-9, 1e-9).map(lambda d: u * (angle + d)))
    return st.one_of(
        st.just(np.zeros(3)),
        unit_vectors().flatmap(lambda u: finite(0.0, 0.05).map(lambda a: u * a)),
        near(np.sqrt(1e-3)),
        unit_vectors().flatmap(lambda u: finite(0.0, np.pi).map(lambda a: u * a)),
        near(np.pi - 1e-7),
        near(np.pi),
    )


def unit_vectors():
    return vectors(1.0).filter(lambda v: np.linalg.norm(v) > 1e-3).map(
        lambda v: v / np.linalg.norm(v))


def quaternions():
    """Unit quaternions, w >= 0, including identity and 180-degree rotations."""
    raw = st.tuples(*[finite(-1.0, 1.0)] * 4).map(np.array).filter(
        lambda q: np.linalg.norm(q) > 1e-3)
    special = st.sampled_from([np.array([1.0, 0, 0, 0]), np.array([0.0, 1, 0, 0]),
                               np.array([0.0, 0, 0, 1]), np.array([0.5, 0.5, 0.5, 0.5])])
    def unit(q):
        q = q / np.linalg.norm(q)
        return -q if q[0] < 0 else q
    return st.one_of(special, raw.map(unit))


def euler_angles():
    """[pitch, roll, yaw] [rad]: pitch within +-89 deg, roll and yaw full range."""
    simple = st.sampled_from([np.zeros(3), np.array([1.0, -2.0, 15.0]) * DEG,
                              np.array([-5.0, 2.0, 235.0 - 360.0]) * DEG,
                              np.array([0.0, 0.0, np.pi])])
    return st.one_of(simple, st.tuples(finite(-89 * DEG, 89 * DEG), finite(-np.pi, np.pi),
                                       finite(-np.pi, np.pi)).map(np.array))
