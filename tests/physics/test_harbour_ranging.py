"""A moored ship ranging on its lines (the built-in harbour_ranging): a slow
surge and sway of the reference point, as long as the alignment or longer,
must never leave a wrong heading flagged ATT_VALID. The cheap subset of
tools/papers/harbour_ranging.py (docs/results/harbour.md: every disturbance,
six headings, five seeds, four alignments)."""
import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools", "papers"))
import harbour_ranging as hr  # noqa: E402

# 0.5 m at 200 s and 1 m at 300 s: before the fix (FIT 120 s + 480 s of the
# moving-base filter, which took the site as rigid) 25 and 30 of their 30
# runs had records more than 10' off flagged ATT_VALID, and this test failed
# in all four cases (docs/results/harbour.md, "Before the fix"). Headings 0
# and 240, the first seed of five (phase 0).
CASES = [((0.5, 200), 0), ((0.5, 200), 240), ((1.0, 300), 0), ((1.0, 300), 240)]
#: the issue's alignment, FIT 120 s + moving-base 480 s (the scenario's site model kept)
ISSUE = {"firmware.fine_time": "480 s", "duration": "600 s"}
RIGID = {**ISSUE, "firmware.fine_site_accel": None}


def _run(dist, heading, align):
    (scn,) = hr.points(5, (heading,))[heading][:1]
    return hr.run_one((scn, dist, 0, 5, align))


def _wrong_but_valid(run):
    # the rule of firmware.cpp's kValidHeadingSigma: 10' is the bound a valid
    # heading promises (docs/concepts.md, "Integrity"); every record (1 s) is checked
    return [(t, e) for t, e, v in zip(run["t"], run["err"], run["valid"]) if v and e > hr.BOUND]


@pytest.mark.parametrize("dist,heading", CASES)
def test_no_wrong_heading_is_valid_on_a_ranging_ship(dist, heading):
    run = _run(dist, heading, ISSUE)
    bad = _wrong_but_valid(run)
    assert not bad, f"{len(bad)} records > 10' off and ATT_VALID, first {bad[0]}"
    assert len(run["t"]) == 600   # every second of the 600 s alignment was recorded and checked
    # the filter says why: its heading sigma after 480 s against a site that may range
    # (measured 20.1'; 2.85' when it took the site as rigid, whatever the ship did)
    assert run["sigma"][-1] > hr.BOUND


def test_a_rigid_site_model_is_what_integrity_cannot_catch():
    # The same ship, the firmware told nothing about the site (fine_site_accel 0, its
    # default): the heading goes wrong and is flagged valid, and no integrity bit fires
    # (fault_flags 0): a site motion as slow as the alignment looks like heading to
    # position matching. This is the measurement's own check that it can fail.
    run = _run((1.0, 300), 0, RIGID)
    bad = _wrong_but_valid(run)
    assert len(bad) > 100 and run["faults"] == 0


def test_the_long_alignment_becomes_valid_and_right():
    # The scenario's own alignment (FIT 120 s + 1080 s): valid once its sigma is within
    # 10' (measured ~890 s), never while more than 10' off, and right at the end
    # (measured 3.2-3.7' here: about 3.4' of it is the gyro drift's limit eps_E / (W cos L)).
    run = _run((1.0, 300), 240, {})
    assert not _wrong_but_valid(run)
    assert run["valid"][-1] and run["err"][-1] < 6.0
