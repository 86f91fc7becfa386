"""A variant scored from its records on disk chunk by chunk
(`pyins.records.score_variant`, what `pyins run` and campaigns do) gives
what the whole records in memory give (`metrics.run_metrics`,
`metrics.aligned`, `records.write_timeseries`): the same metrics, the same
alignment line and the same timeseries.npz arrays and CSV, bit for bit,
whatever the chunk, on the motions the metrics treat differently (a static
alignment, a swinging ship with its table indexed, a voyage with GNSS
outages, a ship at anchor aligning with GNSS)."""
import os

import numpy as np
import pytest

from pyins import metrics, records, run_scenario, scenario

CASES = [("seed001_fine8", "1200 s", {}),                               # alignment only, static
         ("seed002_exp1", "1200 s", {"indexing.scheme": "flexible", "compare": None, "paper": None}),
         ("voyage_gnss_outages", "1200 s", {}),                        # references, outage windows
         ("at_anchor", "300 s", {})]                                    # aligns, then navigates


def _whole(vdir, spec):
    res, _ = records.load_variant(os.path.join(vdir, "records"), spec.motion, spec.dt)
    records.write_timeseries(vdir, res)
    with np.load(os.path.join(vdir, "timeseries.npz")) as z:
        arrays = {k: z[k] for k in z.files}
    with open(os.path.join(vdir, "timeseries.csv")) as f:
        csv = f.read()
    return (metrics.run_metrics(spec, res), metrics.aligned(spec.config, 1.0 / spec.dt, res.outputs),
            arrays, csv)


@pytest.mark.parametrize("name,duration,over", CASES, ids=[c[0] for c in CASES])
def test_scored_in_chunks_equals_the_whole_records(tmp_path, name, duration, over):
    scn = scenario.load(name).with_overrides({"duration": duration, **over})
    spec = list(scn.runs())[0]
    vdir = str(tmp_path)
    assert run_scenario.run(spec, record_dir=os.path.join(vdir, "records"), keep_result=False) is None
    m_whole, al_whole, arrays, csv = _whole(vdir, spec)
    assert m_whole, "the case scores something"
    for chunk in (7, 256, records.CHUNK_RECORDS):
        m, al, info = records.score_variant(vdir, spec, chunk=chunk)
        assert info["complete"]
        assert m.keys() == m_whole.keys()
        for k in m:     # the same float: max and last exactly, the RMS sums exactly rounded
            assert m[k] == m_whole[k] or (np.isnan(m[k]) and np.isnan(m_whole[k])), (chunk, k)
        assert al == al_whole
        with np.load(os.path.join(vdir, "timeseries.npz")) as z:
            assert list(z.files) == list(arrays)
            for k in arrays:
                assert z[k].dtype == arrays[k].dtype and z[k].shape == arrays[k].shape, (chunk, k)
                assert z[k].tobytes() == arrays[k].tobytes(), (chunk, k)      # bit for bit
        with open(os.path.join(vdir, "timeseries.csv")) as f:
            assert f.read() == csv
        assert not [p for p in os.listdir(vdir) if ".part" in p], "no temporary file left"


def test_a_run_that_wrote_nothing_scores_nothing(tmp_path):
    spec = list(scenario.load("demo").runs())[0]
    assert records.score_variant(str(tmp_path), spec) == ({}, None, None)


def test_the_outage_windows_see_every_chunk():
    """An outage's largest error is the largest over the records in it, also
    when the outage spans chunks (the voyage with outages, 7-record chunks,
    above); here the fold itself: the RMS sum does not depend on the chunks."""
    rng = np.random.default_rng(3)
    x = rng.standard_normal(10_001) * 1e3
    a, b = [0.0, 0.0], [0.0, 0.0]
    metrics._fold(a, x * x)
    for i in range(0, len(x), 97):
        metrics._fold(b, x[i:i + 97] ** 2)
    assert a[0] == b[0]


@pytest.mark.parametrize("values, want", [([1.0, np.inf, 2.0], np.inf), ([1.0, np.nan], np.nan),
                                          ([1e308] * 4, np.inf), ([np.inf, np.nan], np.nan)])
def test_a_sum_that_is_not_finite_is_what_the_mean_of_the_whole_gives(values, want):
    """A diverged run (an inf or NaN error, or squares past the largest
    double) scores inf or NaN as np.mean over the whole records did, in any
    chunking, and never raises (math.fsum alone raises on inf - inf and on
    overflow)."""
    for chunk in (1, 2, len(values)):
        acc = [0.0, 0.0]
        for i in range(0, len(values), chunk):
            metrics._fold(acc, np.array(values[i:i + chunk]))
        with np.errstate(over="ignore", invalid="ignore"):
            whole = np.mean(np.array(values))
        assert (np.isnan(acc[0]) and np.isnan(want) and np.isnan(whole)) or acc[0] == want == whole
