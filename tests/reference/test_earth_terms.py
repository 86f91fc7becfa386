"""The Earth terms a navigation tick keeps (pyins.reference.earth.PositionTerms,
mirrored by csrc/src/earth.hpp): computed at latitude L0 and height h0,
carried to the tick's latitude L0 + d to first order, against the same
quantities computed at (L0 + d, h) exactly (earth_at, position_rate).

The strapdown moves the terms when |d| > TERMS_LAT_STEP (1e-6 rad) or the
height has moved 0.01 m (TERMS_HEIGHT_STEP). Its header states what
staleness within those steps can cost: the latitude-carried terms 1e-10 of
themselves below 80 deg of latitude, the radii (not carried) 1e-8 of
themselves; this holds the code to those statements."""
import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from pyins.reference import earth, strapdown

STEP = strapdown.TERMS_LAT_STEP
H_STEP = strapdown.TERMS_HEIGHT_STEP


@given(lat0=st.floats(-80.0, 80.0), frac=st.floats(-1.0, 1.0), h0=st.floats(-100.0, 3000.0),
       dh=st.floats(-1.0, 1.0), ve=st.floats(-30.0, 30.0), vn=st.floats(-30.0, 30.0))
def test_kept_terms_are_the_exact_ones_to_the_stated_bounds(lat0, frac, h0, dh, ve, vn):
    lat0 = np.radians(lat0)
    d = frac * STEP
    h = h0 + dh * H_STEP
    p = earth.position_terms(lat0, np.sin(lat0), np.cos(lat0), h0)
    lat = lat0 + d
    vel = np.array([ve, vn, 0.0])
    e = earth.earth_at(np.sin(lat), np.cos(lat), h, vel)
    # Earth rate: carried to first order, the d^2 / 2 term left out is
    # 5e-13 of Omega at d = 1e-6: 1e-10 of Omega bounds it with rounding room
    assert np.max(np.abs(earth.earth_rate(p, d) - e.omega_ie_n)) <= 1e-10 * earth.OMEGA_IE
    # transport rate: its tan L part carried (1e-10), the radii stale in
    # latitude and height (R_M moves 3 e^2 sin L cos L = 1e-2 of itself per
    # radian, 1e-8 at d = 1e-6; 0.01 m of height is 1.6e-9): 1e-8 of the
    # largest component
    w = earth.transport_rate(p, d, vel)
    assert np.max(np.abs(w - e.omega_en_n)) <= 1e-8 * max(np.max(np.abs(e.omega_en_n)), 1e-300)
    # position rate likewise (its 1 / cos L carried, the radii stale)
    r = earth.position_rate_of_terms(p, d, vel)[:2]
    exact = earth.position_rate(e, vel)[:2]
    assert np.max(np.abs(r - exact)) <= 1e-8 * max(np.max(np.abs(exact)), 1e-300)
    # and the bounds are not slack by orders of magnitude: a latitude step of
    # 1e-6 rad without the first-order carry moves the Earth rate by ~1e-6 of
    # Omega at mid latitudes, what the carry is there to remove
    if abs(frac) > 0.5 and 0.2 < abs(lat0) < 1.2:
        stale = p.omega_ie_n
        assert np.max(np.abs(stale - e.omega_ie_n)) > 1e-7 * earth.OMEGA_IE
