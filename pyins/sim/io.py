"""The project's IMU sample files, .npz and CSV: the format lives in
`pyins.logs.project` (with the other log formats, docs/log-formats.md);
these names stay importable from here for the simulator's users."""
from pyins.logs.project import (CSV_COLUMNS, CSV_HEADER, ImuData, load_csv, load_npz, save_csv,
                                save_npz)

__all__ = ["CSV_COLUMNS", "CSV_HEADER", "ImuData", "load_csv", "load_npz", "save_csv", "save_npz"]
