"""Command line entry point: ``pyins`` / ``python -m pyins``.

For now it holds the main job run by ``tools/setup.sh``:

    pyins demo [--hours 2] [--out runs/demo] [--sensors seed002]

which simulates seed 002's experiment-1 ship (heading swing of 6 deg/s
amplitude, 120 s period, at Xi'an) with a sensor error preset, runs it
through the C++ firmware with the IMU fixed to the ship, prints the
navigation errors and writes a plot. The full CLI comes with the CLI issue.
"""
import argparse
import json
import os
import sys
import time

import numpy as np


def _demo(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pyins import native, runner, sim
    from pyins.reference import earth

    motion = sim.HeadingSwing.experiment(1)
    sensors = sim.SensorModel(sim.preset(args.sensors), seed=args.seed)
    ticks = int(round(args.hours * 3600 * 100))
    t0 = time.perf_counter()

    def progress(done, total):
        if not args.quiet and sys.stdout.isatty():
            print(f"\r  {done / 360000:6.2f} h of {total / 360000:.2f} h ship time", end="", flush=True)

    result = runner.navigate(motion, ticks, every=100, sensors=sensors, progress=progress)
    wall = time.perf_counter() - t0
    if not args.quiet and sys.stdout.isatty():
        print()
    e = runner.nav_errors(result)
    arcsec, arcmin = earth.ARCSEC_TO_RAD, earth.ARCMIN_TO_RAD
    summary = {
        "scenario": "seed 002 experiment 1 heading swing, IMU fixed to the ship",
        "sensors": args.sensors,
        "ship_time_h": args.hours,
        "wall_time_s": wall,
        "final_horizontal_error_m": float(e.horizontal_m[-1]),
        "max_horizontal_error_m": float(e.horizontal_m.max()),
        "max_horizontal_error_nmi": float(e.horizontal_m.max() / earth.NMI_TO_M),
        "max_level_error_arcsec": float(np.abs(e.att_n_rad[:, :2]).max() / arcsec),
        "max_heading_error_arcmin": float(np.abs(e.att_n_rad[:, 2]).max() / arcmin),
        "max_velocity_error_mps": float(np.abs(e.vel_n_mps[:, :2]).max()),
        "core_version": native.version(),
    }
    os.makedirs(args.out, exist_ok=True)
    th = e.time_s / 3600.0
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    ax[0].plot(th, e.north_m, label="north")
    ax[0].plot(th, e.east_m, label="east")
    ax[0].plot(th, e.horizontal_m, "k", label="horizontal")
    ax[0].set_ylabel("position error [m]")
    ax[0].legend()
    ax[1].plot(th, e.att_n_rad[:, 0] / arcsec, label="phi_E")
    ax[1].plot(th, e.att_n_rad[:, 1] / arcsec, label="phi_N")
    ax[1].set_ylabel("level error [arcsec]")
    ax[1].legend()
    ax[2].plot(th, e.att_n_rad[:, 2] / arcmin, label="phi_U (heading)")
    ax[2].set_ylabel("heading error [arcmin]")
    ax[2].set_xlabel("ship time [h]")
    ax[2].legend()
    fig.suptitle(f"pyins demo: {summary['scenario']}, sensors {args.sensors}")
    fig.tight_layout()
    plot = os.path.join(args.out, "navigation_errors.png")
    fig.savefig(plot, dpi=100)
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    print(f"pyins demo: {args.hours:g} h of ship time through the C++ firmware in {wall:.1f} s wall")
    print(f"  max horizontal position error {summary['max_horizontal_error_m']:.1f} m "
          f"({summary['max_horizontal_error_nmi']:.3f} nmi), final {summary['final_horizontal_error_m']:.1f} m")
    print(f"  max level error {summary['max_level_error_arcsec']:.2f} arcsec, "
          f"max heading error {summary['max_heading_error_arcmin']:.3f} arcmin, "
          f"max velocity error {summary['max_velocity_error_mps']:.4f} m/s")
    print(f"  plot: {plot}  figures: {os.path.join(args.out, 'summary.json')}")
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(prog="pyins", description="pyins: marine rotation-modulated INS firmware")
    sub = ap.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the default scenario through the firmware, print and plot errors",
                          description="example: pyins demo --hours 2 --sensors seed002")
    demo.add_argument("--hours", type=float, default=2.0, help="ship time [h] (default 2)")
    demo.add_argument("--sensors", default="seed002",
                      help="sensor error preset: error_free, seed000, seed001, seed002, seed003")
    demo.add_argument("--seed", type=int, default=1, help="noise seed")
    demo.add_argument("--out", default=os.path.join("runs", "demo"), help="output directory")
    demo.add_argument("--quiet", action="store_true", help="no progress line")
    sub.add_parser("version", help="print the package and core versions")
    args = ap.parse_args(argv)
    if args.command == "demo":
        from pyins import sim
        if args.sensors not in sim.PRESETS:
            ap.error(f"--sensors: unknown preset {args.sensors!r} (known: {', '.join(sim.PRESETS)})")
        if not args.hours > 0:
            ap.error("--hours: must be positive")
        return _demo(args)
    if args.command == "version":
        from pyins import __version__, native
        print(f"pyins {__version__}, core {native.version()} (ABI {'.'.join(map(str, native.abi_version()))})")
        return 0
    return 2


if __name__ == "__main__":
    sys.exit(main())
