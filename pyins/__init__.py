"""pyins: firmware of a marine rotation-modulated RLG strapdown INS.

The firmware core is C++17/Eigen (``csrc/``), stepping at a fixed 100 Hz
behind a plain C ABI (``csrc/include/pyins_core.h``). This package holds:

- ``pyins.native``: the cffi binding of the built core (``Firmware``) and
  of the compiled closed-loop plant (``Plant``);
- ``pyins.reference``: the same algorithms written plainly in NumPy, module
  for module, which the C++ is tested against;
- ``pyins.engine``: the choice between the two ("native", "reference");
- ``pyins.sim``: the plant: ship motion, turntable, exact IMU increments,
  sensor errors, IMU sample files;
- ``pyins.units``: the unit constants and the tick, defined once;
- ``pyins.scenario``: scenario files, checked and resolved to SI, and what a
  run of one is built from (its initial state included);
- ``pyins.open_loop`` and ``pyins.fil`` (the closed loop through the
  turntable) run the firmware against the truth; ``pyins.run_scenario``
  runs a scenario into a run directory, ``pyins.rundir`` is that
  directory (its layout, reading it back, the interrupt guard);
  ``pyins.replay`` replays logs; ``pyins.records`` holds the record files
  and checkpoints; ``pyins.metrics`` every metric; ``pyins.campaign`` and
  ``pyins.report`` sets of runs and their reports; ``pyins.logs`` IMU log
  files; ``pyins.analysis`` the error theory, ``pyins.budget`` the error
  budget of a run.

Conventions (shared by C++ and Python)
--------------------------------------
Frames: n = East-North-Up; b = ship body (x starboard, y bow, z up);
p = IMU frame on the turntable, C_p^b = Rz(alpha), alpha counter-clockwise
seen from above; i = inertial; e = Earth-fixed.

Names carry frames as suffixes: ``vel_n`` (velocity in n), ``mat_nb``
(C_b^n, maps b to n), ``quat_np`` (C_p^n), ``omega_ib_b``.

Euler angles ``[pitch, roll, yaw]`` with C_b^n = Rz(yaw) Rx(pitch) Ry(roll);
yaw counter-clockwise from North. ``heading`` is the marine heading,
clockwise from North in [0, 2 pi): heading = (-yaw) mod 2 pi. Every field says
which of the two it is.

Units: SI inside (rad, m, s, m/s); degrees, arc-seconds, deg/h, micro-g only
at the edges, through the named conversions of ``pyins.units``.
Time inside the firmware is an integer tick count (``pyins.units.TICK_HZ``).

Note: nmayorov's ``pyins`` (distributed as ``python-ins``) uses the same
import name; the two cannot share one environment.
"""
__version__ = "0.1.0"
