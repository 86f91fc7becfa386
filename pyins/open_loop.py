"""Open-loop runs: simulated IMU data through the firmware, against the truth.

``navigate`` generates the samples of a motion profile chunk by chunk (memory
stays bounded for any duration), steps them through the firmware of the
engine (`pyins.engine`: the C++ core or its NumPy mirror) keeping one record
every ``every`` ticks, and returns those records beside the true state at
the same ticks. The closed loop with the turntable is `pyins.fil`.

The firmware starts from `pyins.scenario.initial_config` (the truth at
t = 0 as a firmware configuration); the errors in physical units are
`pyins.metrics.nav_errors`.
"""
from dataclasses import dataclass

import numpy as np

from pyins import engine as engines
from pyins import contract, sim
from pyins.aiding import Aider
from pyins.scenario.build import initial_config
from pyins.units import DT

__all__ = ["RunResult", "navigate"]


@dataclass
class RunResult:
    outputs: np.ndarray      #: OUTPUT_DTYPE records at the kept ticks
    truth: sim.Truth         #: true state at the same ticks
    dt: float


def navigate(motion, duration_ticks, every=100, sensors=None, table=None, config=None,
             chunk_ticks=100_000, dt=DT, progress=None, engine="native", refs=None, avail_tick=None):
    """Run ``duration_ticks`` of ``motion`` through the firmware.

    ``sensors`` is a ``pyins.sim.SensorModel`` (None: error-free), ``table`` a
    turntable profile, ``config`` overrides of the firmware configuration
    (default: the true initial state), ``engine`` "native" or "reference".
    Returns a RunResult with one record and one truth row every ``every``
    ticks. ``refs`` (REF_DTYPE, sorted by tick) are external references
    pushed as they become available (`pyins.aiding.Aider`; ``avail_tick``
    their availability, None: ahead of their tick).
    """
    fw = engines.firmware(engine, initial_config(motion, table, **(config or {})))
    aider = Aider(refs, avail_tick, tick_hz=int(round(1.0 / dt))) if refs is not None else None
    outs = []
    for chunk in sim.generate(motion, duration_ticks, chunk_ticks=chunk_ticks, dt=dt, table=table,
                              sensors=sensors, with_truth=False):
        # seq: the tick number each sample ends, as an IMU's packet counter
        # (read only when the configuration sets seq_mode = 1)
        samples = contract.make_samples(chunk.dtheta_p, chunk.dv_p, chunk.table_angle, seq=chunk.tick)
        outs.append(aider.run(fw, samples, every) if aider is not None else fw.run(samples, every=every))
        if progress is not None:
            progress(int(chunk.tick[-1]), duration_ticks)
    outputs = np.concatenate(outs) if outs else np.zeros(0, dtype=contract.OUTPUT_DTYPE)
    truth = sim.truth_at(motion, outputs["tick"], dt=dt, table=table)
    return RunResult(outputs=outputs, truth=truth, dt=dt)
