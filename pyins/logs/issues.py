"""What the log readers say: `LogError` (a log that cannot be used as
declared) and `LogIssue` (one finding of `pyins.logs.check_log`), both worded
"<file>: <where>: <reason>"."""
from dataclasses import dataclass


class LogError(ValueError):
    """A log that cannot be used as declared: "<file>: <where>: <reason>"."""


@dataclass(frozen=True)
class LogIssue:
    """One finding of `check_log`."""
    level: str      #: "error" or "warning"
    message: str    #: one line, "<file>: <where>: <reason>"

    def __str__(self):
        return f"{self.level}: {self.message}"


def _plural(n, words):
    return f"{n} {words}" if n == 1 else f"{n} {words}s"
