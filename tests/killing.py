"""Helpers of the tests that kill a run and resume it."""
import json
import os
import time


def wait_for_checkpoint(path, proc, min_done, timeout=120.0):
    """Wait until the checkpoint file ``path`` of the subprocess ``proc``
    says at least ``min_done`` ticks are done (AssertionError if the run ends
    first or nothing comes within ``timeout`` seconds)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        assert proc.poll() is None, "the run ended before it could be killed"
        if os.path.exists(path):
            try:
                with open(path) as f:
                    if json.load(f)["done_ticks"] >= min_done:
                        return
            except (ValueError, KeyError):
                pass                      # never happens with the atomic rename; keep polling
        time.sleep(0.02)
    raise AssertionError("no checkpoint appeared")
