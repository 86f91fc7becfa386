"""The report loads a variant's timeseries.npz with only the record fields
it reads (`pyins.report.run.load_series`), 5,000 records at a time: the
same values as np.load of the whole file, a fraction of the memory; a
damaged file is an error the report names, not a short series."""
import zipfile

import numpy as np
import pytest

from pyins import run_scenario, scenario
from pyins.report import run as report_run


@pytest.fixture(scope="module")
def npz(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    scn = scenario.load("voyage_gnss_outages").with_overrides({"duration": "700 s", "record_every": "0.1 s"})
    run_scenario.execute(scn, str(d))
    (path,) = d.glob("*/timeseries.npz")
    return path


def test_the_series_are_the_files_values_with_the_fields_the_report_reads(npz, monkeypatch):
    monkeypatch.setattr(report_run, "_READ_RECORDS", 997)     # many reads, the last one short
    s = report_run.load_series(npz)
    with np.load(npz) as z:
        whole = {k: z[k] for k in z.files}
    assert len(whole["outputs"]) == 7000
    assert set(s) == set(whole) - {"plant"}
    for k in s:
        if k != "outputs":
            assert s[k].tobytes() == whole[k].tobytes(), k
    assert s["outputs"].dtype.names == report_run._REPORT_FIELDS
    for n in report_run._REPORT_FIELDS:
        assert s["outputs"][n].tobytes() == whole["outputs"][n].tobytes(), n
    assert s["outputs"].dtype.itemsize < 0.3 * whole["outputs"].dtype.itemsize


def test_a_cut_file_is_an_error(npz, tmp_path):
    cut = tmp_path / "cut.npz"
    data = npz.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises((zipfile.BadZipFile, ValueError, OSError)):   # the report names it damaged
        #                                                             (tests/cli/test_run_defects.py)
        report_run.load_series(cut)


def test_a_newer_npy_layout_is_read_whole_and_kept_to_the_fields(npz, tmp_path):
    """A member written in .npy format 3.0 (utf-8 field names) is read with
    NumPy's own reader, then kept to the report's fields: the same values."""
    with np.load(npz) as z:
        whole = {k: z[k] for k in z.files}
    v3 = tmp_path / "v3.npz"
    with zipfile.ZipFile(v3, "w") as zf:
        for k, arr in whole.items():
            with zf.open(k + ".npy", "w", force_zip64=True) as f:
                np.lib.format.write_array(f, arr, version=(3, 0) if k == "outputs" else None)
    s = report_run.load_series(v3)
    assert s["outputs"].dtype.names == report_run._REPORT_FIELDS
    for n in report_run._REPORT_FIELDS:
        assert s["outputs"][n].tobytes() == whole["outputs"][n].tobytes(), n
