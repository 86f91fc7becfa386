"""A ship swinging at anchor aligns from nothing (the alignment issue's
acceptance 1, the cheap subset of tools/anchor_alignment.py): with GNSS
no record more than 10' off in heading says ATT_VALID; with no reference
the 12-state alignment told its site moves says it is not aligned while
it is not; told a rigid site it is wrong and valid, the measurement's own
check that it can fail."""
import numpy as np
import pytest

from pyins.units import ARCMIN_TO_RAD
from tools_loader import load_tool

aa = load_tool("anchor_alignment.py")
BOUND = 10.0 * ARCMIN_TO_RAD      # the bound a valid heading promises (firmware.hpp's kValidHeadingSigma)
# heading 0 deg, seed 1: radius 42.5 m, 30 min; the rigid-site alignment is 24.5' off
# at 600 s there (measured), the worst of the grid's first cells
CELL = (0, 1)


def _wrong_but_valid(err, valid):
    return int(np.sum(valid & (np.abs(err) > BOUND)))


def test_gnss_aided_alignment_at_anchor_is_valid_only_when_right():
    t, err, valid, limit, sigma = aa.one(*CELL, "gnss")
    assert len(t) == 600                                  # every record of the 600 s checked
    assert _wrong_but_valid(err, valid) == 0
    # valid only once 3 sigma is within 10' (measured from 454 s; before the fix the
    # navigation filter's heading was valid from its coarse prior, a sigma of 9.8',
    # while 10.0-10.8' off: 132 records)
    assert not np.any(valid & (3.0 * sigma > BOUND * (1 + 1e-12)))
    assert valid[-1]
    # the heading at 600 s within 2' of the static limit's size (measured 0.45' against
    # |limit| 6.56': indexing takes it below); 2' is the acceptance line
    k = int(np.searchsorted(t, 599.0))
    assert abs(err[k]) < abs(limit) + 2.0 * ARCMIN_TO_RAD
    assert abs(err[k]) < 3.0 * sigma[k]                   # inside its own 3 sigma (measured 0.45', sigma 1.36')


def test_unaided_alignment_told_the_site_moves_says_it_is_not_aligned_at_600_s():
    t, err, valid, _, sigma = aa.one(*CELL, "none")
    assert len(t) == 1200
    # 24.5' off at 600 s, its sigma 20.2' (measured): it says so instead of calling it
    # valid. (Later, under the fine alignments' older rule, sigma within 10', it is
    # valid while 10-12' off for 101 records: the open part of acceptance 1,
    # docs/concepts.md "Alignment at anchor".)
    k = int(np.searchsorted(t, 599.0))
    assert abs(err[k]) > BOUND and not valid[k] and sigma[k] > BOUND
    assert abs(err[-1]) < 3.0 * sigma[-1]        # at the end inside its 3 sigma (4.0', sigma 6.3')


def test_unaided_alignment_told_a_rigid_site_is_wrong_and_valid():
    # the firmware's default site model at anchor: the heading goes 24' wrong with a
    # sigma of 2.7' and is flagged valid (measured 405 records); integrity has to catch
    # this (the harbour-ranging issue): the check above can fail
    t, err, valid, _, _ = aa.one(*CELL, "none_rigid")
    assert _wrong_but_valid(err, valid) > 100
