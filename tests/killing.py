"""Helpers of the tests that kill a run and resume it."""
import json
import os
import signal
import subprocess
import sys
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


def kill_after_checkpoint(code, record_dir, checkpoint, min_done, settle_s):
    """Run ``code`` (a Python script taking ``record_dir`` as argv[1]) in a
    subprocess, wait for its checkpoint file ``checkpoint`` to say
    ``min_done`` ticks, let it run ``settle_s`` more seconds (a chunk past
    the checkpoint) and kill it with SIGKILL."""
    proc = subprocess.Popen([sys.executable, "-c", code, str(record_dir)])
    try:
        wait_for_checkpoint(str(checkpoint), proc, min_done)
        time.sleep(settle_s)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
