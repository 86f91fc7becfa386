"""Where in the file: the positions the readers name (file lines, records,
samples) and what a parser found out about a file before its first rows."""
from pyins.logs.options import _columns


class _Where:
    """Positions in a window of the log (the probe, or a block with the last
    sample before it as row 0): 1-based file lines for text (``numbers``),
    0-based records for binary and 0-based samples for npz, both counted
    from the start of the file (``start`` is the window's row 0)."""

    def __init__(self, kind, columns, start=0, numbers=None, n=0):
        self.kind, self.columns, self.start, self.numbers, self.n = kind, columns, start, numbers, n

    def at(self, k, col=None):
        if self.kind == "lines":
            s = f"line {self.numbers[k]}"
            return s if col is None else f"{s}, column {col + 1} ({self.columns[col]})"
        g = self.start + int(k)
        if self.kind == "records":
            s = f"record {g} (0-based, byte offset {g * 8 * len(self.columns)})"
            return s if col is None else f"{s}, field {col + 1} ({self.columns[col]})"
        return f"sample {g} (0-based)"

    def span(self):
        if self.kind == "lines":
            return f"lines {self.numbers[0]}-{self.numbers[-1]}"
        what = "records" if self.kind == "records" else "samples"
        return f"{what} {self.start}-{self.start + self.n - 1} (0-based)"


class _Layout:
    """What a parser found out about the file before its first rows: the
    columns, whether the table angle is one, the kind of positions; the
    PSINS header; ``project`` for the project's own csv/npz (read by
    `pyins.logs.project`); ``n`` the samples when the size tells (plain binary)."""
    time_col = None
    has_table = False
    columns = None
    kind = "lines"
    header = None
    project = None
    n = None

    def set(self, time_col, has_table, kind="lines"):
        self.time_col, self.has_table, self.kind = time_col, bool(has_table), kind
        self.columns = _columns(time_col, has_table)
