"""FE-only against FSI: the 2D valve's opening side by side (the README's main command,
scripts/run-default.sh). Reads the two runs' series, writes one PNG and a short Markdown
summary with each run's wall time and its opening against the reference study's.

    cd scripts && /usr/bin/python3 -m valve_scene.opening_2d FE_RUN FSI_RUN --out DIR

The opening time is the 10-90 % rise of the free-edge midpoints' mean distance from the axis
(from its start to its largest value in the run); the reference's RVOT (Table 3: FE-MHGO 6 ms,
FSI-MHGO 40 ms) is the time from the start of opening to fully open, the same quantity on a 3D
valve. The 2D numbers are per metre of depth where extensive (flow, force).
"""
from __future__ import annotations

import argparse
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import hemodynamics, waveform
from .quick_look import opening_time_10_90

REFERENCE_OPENING_MS = {"FE-only": 6.0, "FSI": 40.0}   # reference Table 3, MHGO
REFERENCE_OPENING_START_MS = {"FSI": 20.0}           # reference Sec. 3.1: FSI leaflets start to move ~20 ms
WALL_LINE = re.compile(r"run_case: finished in ([0-9.]+) s wall time")


@dataclass
class Opening:
    time: np.ndarray           # s
    distance: np.ndarray       # mean distance of the free-edge midpoints from the axis (m)
    start: float               # s, 10 % of the rise
    duration: float            # s, 10 % -> 90 % of the rise
    wall_s: float | None       # the launcher's wall time, if its log is there


def opening_of(time: np.ndarray, distance: np.ndarray) -> tuple[float, float]:
    """(start, duration): the time of 10 % of the rise from the first to the largest value, and
    the 10-90 % rise time (quick_look's measure of the FE-only opening)."""
    time, distance = np.asarray(time, float), np.asarray(distance, float)
    rise = distance.max() - distance[0]
    if not rise > 0:
        raise ValueError("the free edge never moves away from its start: no opening in this run")
    start = float(time[np.argmax(distance >= distance[0] + 0.1 * rise)])
    return start, opening_time_10_90(time, distance)


def wall_time(run_dir: Path) -> float | None:
    """The launcher's 'finished in ... s wall time' from RUN_DIR/../launcher.log or RUN_DIR/launcher.log."""
    for log in (run_dir / "launcher.log", run_dir.parent / f"{run_dir.name}.log"):
        if log.exists():
            found = WALL_LINE.findall(log.read_text(errors="replace"))
            if found:
                return float(found[-1])
    return None


def read_opening(run_dir: Path) -> Opening:
    import h5py
    path = run_dir / "solid_series.h5"
    if not path.exists():
        raise FileNotFoundError(f"{path}: no solid series (did the run start?)")
    with h5py.File(path, "r") as f:
        name = "monitor/free_edge_midpoints/position"
        if name not in f:
            raise KeyError(f"{path}: no dataset '/{name}' (the case must monitor 'free_edge_midpoints')")
        time = f["time"][()]
        # 2D: x along the channel, y across it; the axis is y = 0
        distance = np.abs(f[name][()][..., 1]).mean(axis=1)
    start, duration = opening_of(time, distance)
    return Opening(time, distance, start, duration, wall_time(run_dir))


def relative_error(measured: float, reference: float) -> str:
    return f"{(measured - reference) / reference:+.0%}"


def summary(fe: Opening, fsi: Opening, probes: hemodynamics.ProbeSeries | None, leaks: int | None) -> str:
    wall = lambda o: f"{o.wall_s:.0f} s" if o.wall_s is not None else "–"
    lines = ["# The 2D valve's opening: FE-only against FSI", "",
             "Coarse 2D MHGO valve (cases/default-fe-2d-opening, cases/default-fsi-2d-opening); reference: "
             "Mao et al. 2016, Table 3 (a 3D valve: read the 2D numbers as bands).", "",
             "| run | opening starts (ms) | opening time 10-90 % (ms) | reference (ms) | error | "
             "free edge from the axis (mm) | wall time |",
             "|---|---|---|---|---|---|---|"]
    for label, o in (("FE-only", fe), ("FSI", fsi)):
        ref = REFERENCE_OPENING_MS[label]
        lines.append(f"| {label} | {o.start * 1e3:.1f} | {o.duration * 1e3:.1f} | {ref:g} | "
                     f"{relative_error(o.duration * 1e3, ref)} | {o.distance[0] * 1e3:.2f} -> "
                     f"{o.distance.max() * 1e3:.2f} | {wall(o)} |")
    lines += ["", f"FSI opens {fsi.duration / fe.duration:.1f}x slower than FE-only and starts "
              f"{(fsi.start - fe.start) * 1e3:.0f} ms later (reference: about 40 vs 5-6 ms, FSI starting near "
              f"{REFERENCE_OPENING_START_MS['FSI']:g} ms): the blood's inertia."]
    if probes is not None:
        q = hemodynamics.moving_average(probes.time, probes.mean_flow_rate, 0.002)
        dp = hemodynamics.moving_average(probes.time, probes.pressure_drop, 0.002) / hemodynamics.PA_PER_MMHG
        lines += [f"FSI: peak flow rate {q.max() * 1e4:.1f} cm²/s per cm of depth at {probes.time[np.argmax(q)] * 1e3:.0f} ms; "
                  f"largest transvalvular pressure drop (2 ms average) {dp.max():.1f} mmHg."]
    if leaks is not None:
        lines.append(f"Particles through a leaflet: {leaks}.")
    return "\n".join(lines) + "\n"


def plot(fe: Opening, fsi: Opening, probes, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = 3 if probes is not None else 1
    fig, axes = plt.subplots(panels, 1, sharex=True, figsize=(7, 2.6 * panels + 0.6), squeeze=False)
    ax = axes[0, 0]
    ax.plot(fe.time * 1e3, fe.distance * 1e3, label="FE-only (uniform pressure)")
    ax.plot(fsi.time * 1e3, fsi.distance * 1e3, label="FSI (SPH blood)")
    ax.set_ylabel("free edge from axis (mm)")
    ax.legend(loc="lower right")
    ax.set_title("2D MHGO valve opening")
    if probes is not None:
        t = probes.time * 1e3
        axes[1, 0].plot(t, hemodynamics.moving_average(probes.time, probes.mean_flow_rate, 0.002) * 1e4)
        axes[1, 0].set_ylabel("flow (cm²/s per cm)")
        axes[2, 0].plot(t, hemodynamics.moving_average(probes.time, probes.pressure_drop, 0.002)
                        / hemodynamics.PA_PER_MMHG, label="taps (2 ms average)")
        tw = np.linspace(0, probes.time[-1], 400)
        axes[2, 0].plot(tw * 1e3, waveform.transvalvular_pressure_mmHg(tw), "k--", label="prescribed (Wiggers)")
        axes[2, 0].set_ylabel("ΔP (mmHg)")
        axes[2, 0].legend(loc="upper right")
    axes[-1, 0].set_xlabel("time (ms)")
    for row in axes:
        row[0].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def leak_count(run_dir: Path) -> int | None:
    import h5py
    path = run_dir / "fluid_probes.h5"
    if not path.exists():
        return None
    with h5py.File(path, "r") as f:
        if "interface" in f and "leaks" in f["interface"] and len(f["interface"]["leaks"]):
            return int(np.max(f["interface"]["leaks"][()]))
    return None


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fe_run", type=Path)
    parser.add_argument("fsi_run", type=Path)
    parser.add_argument("--out", type=Path, help="folder for opening.png and opening.md (default: FSI_RUN/..)")
    args = parser.parse_args(argv)
    out = args.out or args.fsi_run.parent
    out.mkdir(parents=True, exist_ok=True)
    fe, fsi = read_opening(args.fe_run), read_opening(args.fsi_run)
    try:
        probes = hemodynamics.read_run(args.fsi_run)
    except (FileNotFoundError, ValueError) as error:
        print(f"opening_2d: no hemodynamics: {error}")
        probes = None
    text = summary(fe, fsi, probes, leak_count(args.fsi_run))
    (out / "opening.md").write_text(text)
    plot(fe, fsi, probes, out / "opening.png")
    print(text, end="")
    print(f"opening_2d: {out / 'opening.md'}, {out / 'opening.png'}")


if __name__ == "__main__":
    main()
