"""The shipped real laser-gyro log's parked site (tests/data/README.md) and
GNSS fixes of it, for the replay tests with references (tests/cli)."""
import numpy as np

from pyins import contract
from pyins.reference import earth
from pyins.units import DEG_TO_RAD

LAT, LON, H = 34.246048, 108.909664, 380.0        # the log's header (tests/data/README.md)


def fixes(ticks, noise_m, seed=0, up_velocity=True):
    """GNSS position fixes of the parked site, white noise ``noise_m`` per
    axis, and velocity fixes of white noise 0.05 m/s at the same ticks,
    merged by tick (a receiver's: one repeating an exact 0 would read as
    frozen, its repeats unused). ``up_velocity`` False: the up velocity 0,
    as NMEA's RMC carries none (the draws then 2 an epoch, not 3)."""
    rng = np.random.default_rng(seed)
    lat, lon = LAT * DEG_TO_RAD, LON * DEG_TO_RAD
    rm, rn = earth.principal_radii(np.sin(lat))
    d = rng.normal(0.0, noise_m, (len(ticks), 2))
    pos = np.column_stack([lat + d[:, 1] / (rm + H), lon + d[:, 0] / ((rn + H) * np.cos(lat)),
                           np.full(len(ticks), H)])
    p = contract.make_refs("gnss_pos", ticks, pos, np.tile([noise_m, noise_m, 5.0], (len(ticks), 1)))
    vel = (rng.normal(0.0, 0.05, (len(ticks), 3)) if up_velocity else
           np.column_stack([rng.normal(0.0, 0.05, (len(ticks), 2)), np.zeros(len(ticks))]))
    v = contract.make_refs("gnss_vel", ticks, vel, np.full((len(ticks), 3), 0.05))
    both = np.concatenate([p, v])
    return both[np.argsort(both["tick"], kind="stable")]
