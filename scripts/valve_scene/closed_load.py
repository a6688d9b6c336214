"""The closed valve under its peak diastolic load, FSI against FE-only (issue 7): the sector valve
starts at rest in its stress-free, nearly closed shape and the transvalvular pressure is ramped
from 0 to the cycle's largest reverse difference (97.2 mmHg at 0.361 s of the 75 bpm Wiggers
table), then held.

Why this scene: a whole 3D cycle reaches the closed valve only after ~275 ms of simulated systole
(~2 h of wall time on two cores), and the sector's run went wrong after its closing (particles
removed from 279 ms, an interface runaway at 297 ms; docs/fsi-3d.md). This scene puts the
closed valve under diastolic load in ~30 ms of simulated time, so the closed phase can be
studied (and re-run) on its own: with the fluid at rest, the closed leaflets' equilibrium must be
the FE-only one under the same uniform pressure, and the blood's net force on the leaflets must
come to dp * A (the sector's share).

    cd scripts && /usr/bin/python3 -m valve_scene.closed_load compare FE_RUN FSI_RUN [--times 0.04 0.05 0.06]
"""
from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

import h5py
import numpy as np

from . import waveform
from .tube_case import FSI_3D_PLATE_PRESSURE_RESERVE_MMHG

RAMP_S = 0.030        # cosine ramp of the load: slower than the leaflet's closed period, faster than the cycle's 0.245 -> 0.36 s
END_TIME_S = 0.060    # the ramp and 30 ms held
# the cycle's largest reverse transvalvular difference (p_Ao - p_LV) and when it occurs
PEAK_REVERSE_TIME_S = 0.361
PASCAL_PER_MMHG = 133.322387415


def load_end_pressures_mmHg() -> tuple[float, float]:
    """(p_LV, p_Ao) at the cycle's largest reverse difference."""
    t = np.array([PEAK_REVERSE_TIME_S])
    return float(waveform.ventricular_pressure_mmHg()(t)[0]), float(waveform.aortic_pressure_mmHg()(t)[0])


def load_start_pressures_mmHg() -> tuple[float, float]:
    """(p_LV, p_Ao) at t = 0 of the cycle: both ~80.73 mmHg, so the blood starts at gauge 0."""
    t = np.array([0.0])
    return float(waveform.ventricular_pressure_mmHg()(t)[0]), float(waveform.aortic_pressure_mmHg()(t)[0])


def ramp_fraction(t) -> np.ndarray:
    """0 -> 1 over RAMP_S with zero slope at both ends (no step in the load's rate either)."""
    s = np.clip(np.asarray(t, dtype=float) / RAMP_S, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(math.pi * s)


def pressures_mmHg(t) -> tuple[np.ndarray, np.ndarray]:
    """The plates' drives: the ventricle ramps from the start to the start + the cycle's pressure
    reserve (tube_case.FSI_3D_PLATE_PRESSURE_RESERVE_MMHG), the aorta to that + the largest reverse
    difference, which is where the cycle's plates stand then (its reserve engaged in ejection)."""
    (lv0, ao0), (lv1, ao1) = load_start_pressures_mmHg(), load_end_pressures_mmHg()
    f = ramp_fraction(t)
    reserve = FSI_3D_PLATE_PRESSURE_RESERVE_MMHG
    return lv0 + f * reserve, ao0 + f * (reserve + ao1 - lv1)


def waveform_textproto() -> str:
    """The `waveform { ... }` block: the ramp sampled every 1 ms over one period (the table is
    periodic; the run ends long before the period does)."""
    count = int(round(waveform.PERIOD_S / waveform.SAMPLE_INTERVAL_S))
    t = np.arange(count) * waveform.SAMPLE_INTERVAL_S
    p_lv, p_ao = pressures_mmHg(t)
    fmt = waveform._format_list  # the cycle table's layout
    return ("waveform {\n"
            f"  period_s: {waveform.PERIOD_S:g}\n"
            f"  time_s: {fmt(t, '{:.3f}')}\n"
            f"  ventricular_pressure_mmHg: {fmt(p_lv, '{:.3f}')}\n"
            f"  aortic_pressure_mmHg: {fmt(p_ao, '{:.3f}')}\n"
            "}\n")


def case_name(kind: str) -> str:
    return f"{kind.lower()}-mhgo-sector-coarse-closed-load"


def case_text(kind: str, base_text: str) -> str:
    """The closed-load variant of the coarse MHGO sector case `base_text` (FE or FSI, as
    write_cases writes it): a new header, run block and waveform; solid, fluid and coupling as
    the cycle case has them."""
    lv1, ao1 = load_end_pressures_mmHg()
    name = case_name(kind)
    fe = kind == "FE"
    header = [
        f"# {kind}-MHGO, sector valve, coarse, closed-valve load.",
        "#",
        "# What it models: the coarse 1/6 sector of the size-23 TAV (as "
        f"{'fe' if fe else 'fsi'}-mhgo-sector-coarse), starting at rest in its stress-free, nearly closed shape; "
        f"the transvalvular pressure is ramped over {RAMP_S * 1e3:g} ms (cosine) from 0 to the cycle's largest reverse "
        f"difference, {ao1 - lv1:.1f} mmHg (LV {lv1:.2f}, Ao {ao1:.2f} mmHg, at {PEAK_REVERSE_TIME_S:g} s of the Wiggers table), "
        f"then held to {END_TIME_S * 1e3:g} ms" + (" (uniform pressure on the leaflets, no fluid)." if fe else
                                                   " (the two plates; the blood starts at rest at gauge 0; both plates "
                                                   f"rise by the cycle's {FSI_3D_PLATE_PRESSURE_RESERVE_MMHG:g} mmHg pressure reserve "
                                                   "as the cycle's stand then)."),
        "# What it should show: the closed valve's equilibrium under peak diastolic load"
        + (", against which the FSI variant is compared." if fe else
           ": the leaflets' strain and shape as the FE-only variant's, the blood's force on the leaflets "
           "dp * A / 6, no leak (valve_scene.closed_load compare FE_RUN FSI_RUN)."),
        "# Run (from the repository root; the meshes are written by",
        "#   `cd scripts && /usr/bin/python3 -m valve_scene.write_cases`):",
        f"#   /usr/bin/python3 scripts/run_case.py cases/{name}.textproto --output runs/{name}" + (" --fe-only" if fe else ""),
        "# Generated by scripts/valve_scene/write_cases.py (docs/valve-scene.md); edit that, not this file.",
    ]
    from .write_cases import _wrap_comment
    body = base_text[base_text.index("title: "):]
    title_end = body.index("\n") + 1
    run_start, waveform_start, solid_start = body.index("run {"), body.index("waveform {"), body.index("solid {")
    title = body[:title_end].replace('"\n', ', closed-valve load"\n', 1)
    run = re.sub(r"  end_time: [^\n]*\n", f"  end_time: {END_TIME_S:g}\n", body[run_start:waveform_start], count=1)
    run = re.sub(r"  output_dir: [^\n]*\n", f"  output_dir: \"runs/{name}\"\n", run, count=1)
    rest = body[solid_start:]   # the solid, fluid and coupling as the cycle case (an FSI solid: implicit)
    return ("\n".join(_wrap_comment(line) for line in header) + "\n" + title + run + waveform_textproto() + rest)


# --- analysis ----------------------------------------------------------------------------------

def axial_leaflet_force(run: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(window end times, the blood's axial force on the sector's leaflets, N, downstream
    positive) from the coupler's series; None for an FE-only run."""
    path = Path(run) / "coupling_series.h5"
    if not path.exists():
        return None
    with h5py.File(path, "r") as f:
        return f["time"][()].reshape(-1), f["force_fluid"][()][:, 2]


def force_at(fsi_run: Path, times: list[float], window_s: float = 0.002) -> list[float | None]:
    """The blood's axial force on the leaflets averaged over the `window_s` before each time
    (the closed leaflet rings)."""
    series = axial_leaflet_force(fsi_run)
    if series is None:
        return [None for _ in times]
    t_force, force = series
    out = []
    for t in times:
        pick = (t_force > t - window_s) & (t_force <= t)
        out.append(float(np.mean(force[pick])) if pick.any() else None)
    return out


STATE_KEYS = ("time", "strain_p99", "stress_p99_MPa", "strain_energy_mJ", "kinetic_mJ", "node_speed_rms")


def compare(fe_run: Path, fsi_run: Path, times: list[float], mesh_file: Path) -> dict:
    """Closed state of both runs at each time, and the FSI leaflet force against dp * A / 6."""
    from .closed_state import closed_state
    from .hemodynamics import ANNULUS_RADIUS_M
    from .write_cases import MHGO
    lv1, ao1 = load_end_pressures_mmHg()
    dp_Pa = (ao1 - lv1) * PASCAL_PER_MMHG
    expected = -dp_Pa * math.pi * ANNULUS_RADIUS_M ** 2 / 6.0
    forces = force_at(fsi_run, times)
    rows = []
    for t, force in zip(times, forces):
        fe = closed_state(fe_run, mesh_file, t, MHGO["fibre_angle_deg"], full=False)
        fsi = closed_state(fsi_run, mesh_file, t, MHGO["fibre_angle_deg"], full=False)
        rows.append({"fe": {k: fe[k] for k in STATE_KEYS}, "fsi": {k: fsi[k] for k in STATE_KEYS},
                     "fsi_leaflet_force_N": force,
                     "force_over_dp_area": None if force is None else force / expected})
    return {"dp_mmHg": ao1 - lv1, "dp_area_sector_N": expected, "rows": rows}


def kinetic_energy_series(run: Path) -> tuple[np.ndarray, np.ndarray]:
    """(time, the leaflet's kinetic energy, J) from the solid's series."""
    with h5py.File(Path(run) / "solid_series.h5", "r") as f:
        return f["time"][()], f["energy/kinetic"][()]


def growth_rate_per_ms(time: np.ndarray, kinetic: np.ndarray, t0: float, t1: float) -> float:
    """Exponential growth rate of the kinetic energy over [t0, t1] (least squares on its log)."""
    pick = (time >= t0) & (time <= t1) & (kinetic > 0)
    slope = np.polyfit(time[pick] * 1e3, np.log(kinetic[pick]), 1)[0]
    return float(slope)


def plot(runs: dict[str, Path], path: Path) -> None:
    """The leaflet's kinetic energy (log) and, for coupled runs, the blood's force on it over dp*A."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .hemodynamics import ANNULUS_RADIUS_M
    lv1, ao1 = load_end_pressures_mmHg()
    expected = -(ao1 - lv1) * PASCAL_PER_MMHG * math.pi * ANNULUS_RADIUS_M ** 2 / 6.0
    fig, (ax_k, ax_f) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True)
    for index, (label, run) in enumerate(runs.items()):
        colour = f"C{index}"   # the same run in the same colour in both panels
        t, k = kinetic_energy_series(run)
        ax_k.semilogy(t * 1e3, np.maximum(k, 1e-12) * 1e3, color=colour, label=label)
        force = axial_leaflet_force(run)
        if force is not None:
            ax_f.plot(force[0] * 1e3, force[1] / expected, color=colour, lw=0.6, label=label)
    ax_f.plot(np.linspace(0, END_TIME_S * 1e3, 200), ramp_fraction(np.linspace(0, END_TIME_S, 200)), "k--", lw=1,
              label="applied load (ramp)")
    ax_k.set_ylabel("leaflet kinetic energy (mJ, sector)")
    ax_k.legend(fontsize=8)
    ax_f.set_ylabel("blood's force on the leaflet / (dp A / 6)")
    ax_f.set_ylim(-0.5, 2.5)
    ax_f.set_xlabel("time (ms)")
    ax_f.legend(fontsize=8)
    fig.suptitle(f"Closed valve under {ao1 - lv1:.1f} mmHg, coarse MHGO sector")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    c = sub.add_parser("compare", help="closed state of an FE-only and an FSI closed-load run at given times")
    c.add_argument("fe_run", type=Path)
    c.add_argument("fsi_run", type=Path)
    c.add_argument("--times", type=float, nargs="+", default=[0.03, 0.04, 0.05, 0.06])
    c.add_argument("--mesh", type=Path, default=Path(__file__).resolve().parents[2] / "cases/meshes/valve-sector-coarse.mesh.h5")
    g = sub.add_parser("plot", help="kinetic energy and leaflet force of several runs: LABEL=RUN ...")
    g.add_argument("runs", nargs="+")
    g.add_argument("--png", type=Path, required=True)
    args = parser.parse_args(argv)
    if args.command == "compare":
        print(json.dumps(compare(args.fe_run, args.fsi_run, args.times, args.mesh), indent=1))
    else:
        plot({r.split("=", 1)[0]: Path(r.split("=", 1)[1]) for r in args.runs}, args.png)


if __name__ == "__main__":
    main()
