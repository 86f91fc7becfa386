#!/usr/bin/env python3
"""Regenerate the golden regression records of tests/regression (on purpose only).

    .venv/bin/python tools/regenerate_golden.py [CASE ...]

For each case of tests/regression/cases.py: its configuration and input
stream and, from the installed firmware, every tick's output record;
tests/regression/data/<case>.npz keeps the configuration (JSON) and the
inputs, the records every cases.EVERY ticks bit for bit, and a
SHA-256 over all the records. Run it only when a change of the firmware's
bits is meant, and say why in the commit: tests/regression/test_golden.py
fails on any bit that moves.
"""
import hashlib
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "regression"))
import cases  # noqa: E402

from pyins import native  # noqa: E402


def _plain(v):
    """A configuration value as JSON keeps it (ints stay ints: index_steps)."""
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    return v


def main(argv=None):
    names = (argv if argv is not None else sys.argv[1:]) or list(cases.CASES)
    out_dir = os.path.join(ROOT, "tests", "regression", "data")
    os.makedirs(out_dir, exist_ok=True)
    for name in names:
        if name not in cases.CASES:
            print(f"regenerate_golden: unknown case {name!r} (known: {', '.join(cases.CASES)})",
                  file=sys.stderr)
            return 2
        cfg, dtheta, dv, table, seq = cases.inputs(name)
        rec = cases.run(cfg, dtheta, dv, seq, turn=name in cases.TURNS)
        digest = hashlib.sha256(rec.tobytes()).hexdigest()
        config = json.dumps({k: _plain(v) for k, v in cfg.items()}, sort_keys=True)
        np.savez_compressed(os.path.join(out_dir, f"{name}.npz"), dtheta=dtheta, dv=dv, seq=seq,
                            config=np.array(config),
                            records=np.ascontiguousarray(rec[cases.EVERY - 1::cases.EVERY]).view(np.uint8),
                            sha256=np.array(digest), abi=np.array(native.abi_version()))
        modes = sorted(set(int(m) for m in rec["mode"]))
        print(f"{name}: {len(rec)} ticks, modes {modes}, faults {int(rec['fault_flags'][-1]):#x}, "
              f"sha256 {digest[:16]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
