"""The command line, one module a group of subcommands: `run` (run, report,
demo), `replay`, `simulate`, `study` (campaign, budget), `info` (list,
bench, version); `common` what they share (exit codes, `InputError`, the
progress and summary lines); `parser` the grammar. ``pyins`` and ``python -m
pyins`` enter through `pyins.__main__.main`."""
