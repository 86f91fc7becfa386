"""The reference engine without the compiled library.

A copy of the pyins source package without any shared library (and the
source tree's csrc/include/pyins_core.h beside it, where pyins.contract
finds it) runs in a subprocess started with ``python -S`` (no site: the
editable install's .pth hook does not run) and PYTHONPATH = the copy, then
the venv's site-packages (NumPy, cffi): ``pyins`` is the copy, importing
``pyins.native`` raises ImportError, ``pyins.reference`` and
``pyins.engine`` import, and the reference engine runs. Its records are
those of the same run in this process, bit for bit: the reference engine
reads nothing from the library (its defaults included).
"""
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import numpy as np
import pytest

import pyins
from pyins import contract, engine, fil, scenario, sim

ROOT = Path(__file__).resolve().parents[2]
SOURCE = next(Path(p) for p in pyins.__path__ if (Path(p) / "__init__.py").is_file())

# a few hundred ticks of a ship at rest, navigating from the true state
SITE = dict(lat_rad=0.6, lon_rad=0.2, height_m=10.0, euler_b_rad=[0.01, -0.02, 1.0])
TICKS = 300

RUN_SIM = textwrap.dedent("""
    import sys
    import numpy as np
    from pyins import contract, engine, sim
    motion = sim.Static(0.6, 0.2, 10.0, 0.01, -0.02, 1.0)
    chunk = next(sim.generate(motion, {ticks}, with_truth=False))
    samples = contract.make_samples(chunk.dtheta_p, chunk.dv_p, chunk.table_angle, seq=chunk.tick)
    fw = engine.firmware("reference", dict(lat_rad=0.6, lon_rad=0.2, height_m=10.0,
                                           euler_b_rad=[0.01, -0.02, 1.0]))
    np.save(sys.argv[1], fw.run(samples))
""").format(ticks=TICKS)


@pytest.fixture(scope="module")
def no_library(tmp_path_factory):
    """(run, root): run(code, *args) runs ``code`` in the library-less copy."""
    root = tmp_path_factory.mktemp("nolib")
    shutil.copytree(SOURCE, root / "pyins",
                    ignore=shutil.ignore_patterns("__pycache__", "*.so", "*.so.*", "*.dylib", "*.pyd"))
    (root / "csrc" / "include").mkdir(parents=True)
    shutil.copy(ROOT / "csrc" / "include" / "pyins_core.h", root / "csrc" / "include")
    assert not list((root / "pyins").rglob("*.so*"))
    paths = [str(root)] + sorted({sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]})
    env = {k: v for k, v in os.environ.items() if k not in ("PYINS_CORE_LIB", "PYTHONPATH")}
    env.update(PYTHONPATH=os.pathsep.join(paths), SKBUILD_EDITABLE_SKIP="1", PYTHONDONTWRITEBYTECODE="1")

    def run(code, *args):
        return subprocess.run([sys.executable, "-S", "-c", code, *args], cwd=root, env=env,
                              capture_output=True, text=True, timeout=600)
    return run, root


def test_the_reference_imports_and_native_does_not(no_library):
    run, root = no_library
    proc = run(textwrap.dedent("""
        import pyins, pyins.reference, pyins.reference.earth, pyins.contract, pyins.engine
        print(pyins.__file__)
        print(pyins.contract.HEADER_PATH)
        print(pyins.engine.native_error() is not None)
        try:
            import pyins.native
        except ImportError as exc:
            print("native: ImportError:", exc)
        try:
            pyins.engine.firmware("native", {})
        except ImportError as exc:
            print("engine native: ImportError:", exc)
        fw = pyins.engine.firmware("reference", {"lat_rad": 0.5})
        print(fw.output()["mode"], fw.config["tick_hz"])
    """))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == str(root / "pyins" / "__init__.py")
    assert lines[1] == str(root / "csrc" / "include" / "pyins_core.h")
    assert lines[2] == "True"
    assert lines[3].startswith("native: ImportError: pyins: the firmware core library libpyins_core.so")
    assert lines[4].startswith("engine native: ImportError: engine 'native' is not available")
    assert lines[5] == "0 100"   # IDLE before the first step; the mirror's default rate


def test_a_reference_run_without_the_library_is_the_same_run_with_it(no_library, tmp_path):
    run, _ = no_library
    out = tmp_path / "records.npy"
    proc = run(RUN_SIM, str(out))
    assert proc.returncode == 0, proc.stderr
    away = np.load(out)
    motion = sim.Static(0.6, 0.2, 10.0, 0.01, -0.02, 1.0)
    chunk = next(sim.generate(motion, TICKS, with_truth=False))
    samples = contract.make_samples(chunk.dtheta_p, chunk.dv_p, chunk.table_angle, seq=chunk.tick)
    here = engine.firmware("reference", SITE).run(samples)
    assert away.dtype == contract.OUTPUT_DTYPE and away.shape == (TICKS,)
    assert away.tobytes() == here.tobytes()
    assert (away["mode"] == 3).all() and (away["fault_flags"] == 0).all()
    assert abs(away["lat_rad"][-1] - SITE["lat_rad"]) < 1e-9


RUN_SCENARIO = textwrap.dedent("""
    import sys
    import numpy as np
    from pyins import scenario
    spec = next(iter(scenario.load("demo").runs()))
    from pyins import fil
    res = fil.run_fil(spec.motion, 300, config=spec.config, errors=spec.errors, seed=spec.seed,
                      table=spec.table, every=100, dt=spec.dt, engine="reference")
    np.save(sys.argv[1], res.outputs)
""")


def _blocking_chain(stderr):
    """The pyins import lines of a traceback, outermost first."""
    chain = []
    lines = stderr.splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith("File ") and "/pyins/" in line and i + 1 < len(lines):
            where = line.split("/pyins/", 1)[1].split('"')[0]
            chain.append(f"pyins/{where}: {lines[i + 1].strip()}")
            if where.startswith("native.py"):
                break
    return " -> ".join(chain)


def test_a_builtin_scenario_runs_on_the_reference_engine_without_the_library(no_library, tmp_path):
    """300 ticks of the built-in 'demo' through pyins.fil.run_fil(engine='reference')
    (the closed loop over the NumPy plant, what a scenario run calls): the
    scenario's build checks the configuration with the reference's mirror
    of pyins_config_check (engine.config_check), and the records are those
    of the same run here, bit for bit."""
    run, _ = no_library
    out = tmp_path / "records.npy"
    proc = run(RUN_SCENARIO, str(out))
    assert proc.returncode == 0, "a module on the run path needs the library: " + _blocking_chain(proc.stderr)
    away = np.load(out)
    spec = next(iter(scenario.load("demo").runs()))
    here = fil.run_fil(spec.motion, 300, config=spec.config, errors=spec.errors, seed=spec.seed,
                       table=spec.table, every=100, dt=spec.dt, engine="reference").outputs
    assert away.shape == (3,) and away.tobytes() == here.tobytes()


def test_the_cli_runs_a_builtin_scenario_on_the_reference_engine_without_the_library(no_library, tmp_path):
    """`pyins run demo --engine reference` as a user without a build runs it:
    exit 0, a summary that says no compiled core was there; `pyins version`
    says the same; the native engine is refused with the loader's reason."""
    run, _ = no_library
    out = tmp_path / "demo"
    proc = run("import sys; from pyins.__main__ import main; sys.exit(main(sys.argv[1:]))",
               "run", "demo", "--engine", "reference", "--hours", "0.001", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["core_version"].startswith("none (no compiled library")
    proc = run("import sys; from pyins.__main__ import main; sys.exit(main(sys.argv[1:]))", "version")
    assert proc.returncode == 0 and "core none (no compiled library" in proc.stdout, proc.stdout + proc.stderr
    proc = run("import sys; from pyins.__main__ import main; sys.exit(main(sys.argv[1:]))",
               "run", "demo", "--hours", "0.001", "--out", str(tmp_path / "native"))
    assert proc.returncode != 0 and "engine 'native' is not available" in proc.stderr, proc.stderr
