"""The scripts under tools/ as modules, for the tests that check what they
compute (a script is not a package: it is loaded from its file)."""
import importlib.util
import pathlib

TOOLS = pathlib.Path(__file__).resolve().parents[1] / "tools"


def load_tool(relpath):
    """tools/<relpath> (e.g. "nees_gnss.py", "papers/seed000.py") as a
    module, run once per call."""
    path = TOOLS / relpath
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
