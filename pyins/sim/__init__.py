"""The simulator: ship and turntable motion, exact IMU increments, sensor
errors, files. One room per concept:

- `pyins.sim.exact_time`: times as exact (hi, lo) pairs and phases reduced
  without losing bits (`split_times`, `frac_cycles`), what keeps a 72-h run
  exact.
- `pyins.sim.motion`: the ship's base motions (`Static`, `Swing` and the
  seed 000 sea states, `HeadingSwing` of seed 002, `Manoeuvre`).
- `pyins.sim.ship`: the sea around a real ship at the pier: heave, surge and
  sway (`LinearMotion`), lever arms (`ShipAtSea`), wave spectra
  (`sea_spectrum_motion`, `SEA_STATE_SPECTRA`) and the built-in moored ship
  (`moored`, `MOORED_SHIP`), and a ship swinging at anchor (`at_anchor`).
- `pyins.sim.voyage`: a ship under way at sea (`Voyage`: a `Manoeuvre`
  track with the heel of its turns, the sea-state swing and heave;
  `default_voyage`, a multi-hour transit).
- `pyins.sim.references`: the external reference sensors (GNSS with its
  bias, outages, outliers, frozen and offset receivers; EM speed log; DVL;
  zero velocity; the water current) as the firmware's pyins_ref records,
  and their CSV files on the IMU's clock.
- `pyins.sim.turntable`: the table's profiles (`TableMotion`, `Fixed`,
  `ConstantRate`) and the NumPy mirror of the compiled firmware-in-the-loop
  plant (csrc/plant/plant.cpp).
- `pyins.sim.imu`: exact per-tick increments by Gauss-Legendre quadrature of
  the body rate and specific force (`exact_increments`), the true state at the
  sample instants (`truth`), and a chunked run generator (`generate`).
- `pyins.sim.sensors`: bias, scale factor, misalignment, random walk and
  quantisation (`SensorErrors`, `SensorModel`, `preset`).
- `pyins.sim.io`: .npz and CSV sample files (the format is
  `pyins.logs.project`'s; the names stay importable from here).

Frames and units as in ``pyins`` (docs/design.md §2): n = ENU, b = x
starboard / y bow / z up, p = IMU on the turntable with C_p^b = Rz(alpha);
Euler [pitch, roll, yaw], C_b^n = Rz(yaw) Rx(pitch) Ry(roll); SI inside;
the tick and the unit constants are `pyins.units`'. The Earth model is
``pyins.reference.earth``, the same as the firmware's.
"""
from pyins.sim.imu import (Chunk, Truth, body_rate_and_force, euler_to_mat, euler_to_quat,
                           exact_increments, generate, nb_rate_and_derivative, node_rates, node_sums, truth,
                           truth_at)
from pyins.sim.io import (CSV_COLUMNS, CSV_HEADER, ImuData, load_csv, load_npz, save_csv,
                          save_npz)
from pyins.sim.motion import (SEA_STATES, HeadingSwing, Manoeuvre, Motion, MotionState, NarrowbandYaw, Segment,
                              Static, Swing, default_segments, periodic_ticks, sea_state)
from pyins.sim.sensors import PRESETS, SensorErrors, SensorModel, preset
from pyins.sim.ship import (AT_ANCHOR, MOORED_SHIP, SEA_STATE_SPECTRA, LinearMotion, ShipAtSea, anchor_linear,
                            anchor_swing, at_anchor, dnv_gamma, heave_response, jonswap, moored, named_sea_spectrum,
                            pierson_moskowitz, sea_spectrum_motion)
from pyins.sim.turntable import ConstantRate, Fixed, TableMotion
from pyins.sim.voyage import Voyage, default_voyage

__all__ = [
    "Chunk", "Truth", "body_rate_and_force", "euler_to_mat", "euler_to_quat",
    "exact_increments", "generate", "nb_rate_and_derivative", "node_rates", "node_sums", "truth", "truth_at",
    "CSV_COLUMNS", "CSV_HEADER", "ImuData", "load_csv", "load_npz", "save_csv", "save_npz",
    "SEA_STATES", "HeadingSwing", "Manoeuvre", "Motion", "MotionState", "NarrowbandYaw", "Segment", "Static",
    "Swing", "default_segments", "sea_state",
    "PRESETS", "SensorErrors", "SensorModel", "preset",
    "Voyage", "default_voyage",
    "AT_ANCHOR", "anchor_linear", "anchor_swing", "at_anchor",
    "MOORED_SHIP", "SEA_STATE_SPECTRA", "LinearMotion", "ShipAtSea", "dnv_gamma", "heave_response",
    "jonswap", "moored", "named_sea_spectrum", "pierson_moskowitz", "sea_spectrum_motion",
    "ConstantRate", "Fixed", "TableMotion",
]
