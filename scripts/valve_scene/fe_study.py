"""The FE-only half of the reference's comparison: FE-Ogden and FE-MHGO over two cycles at two
resolutions (the second cycle analysed), their kinematics, peak strain and stress against the
reference's FE-only columns, and the wall times.

    cd scripts && /usr/bin/python3 -m valve_scene.fe_study [--variant sector] \
        [--resolutions coarse medium] [--build-dir ../build] [--skip-run]

Writes runs/<case>/ (solver output), docs/fe-only-study.md and docs/figures/fe-only-*.png.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .analysis import (ValveEvents, bisection_profile, geometric_orifice_area, peak_with_location,
                       valve_events)
from .valve_mesh import build_valve_mesh
from .report import REFERENCE_KINEMATICS_MS, REFERENCE_PEAKS, plot_kinematics, plot_profiles
from .solid_results import SolidFields, read_series
from .waveform import PERIOD_S
from .write_cases import CASES_DIR, CaseSpec, write_cases, write_meshes

REPO = Path(__file__).resolve().parents[2]
OPENING_WINDOW_S = 0.05           # opening peaks are searched over the first 50 ms of the cycle
CLOSED_TIME_S = 0.30              # the reference's fully closed snapshot (its Fig. 10)
PROFILE_TIMES_S = (0.0, 0.002, 0.005, 0.010, 0.020, 0.100, 0.220, 0.230, 0.235, 0.240, 0.250, 0.300)


@dataclass
class ModelResult:
    spec: CaseSpec
    wall_time_s: float | None
    events: ValveEvents | None
    events_error: str = ""
    series: dict = field(default_factory=dict)
    peaks: dict = field(default_factory=dict)      # name -> FieldPeak
    profiles: dict = field(default_factory=dict)   # time in cycle -> polyline
    energy_error_max: float = float("nan")


def run_case(spec: CaseSpec, build_dir: Path, log_dir: Path, runs_dir: Path = REPO / "runs") -> float:
    """Runs one FE-only case through the launcher; returns its wall time (s)."""
    out = runs_dir / spec.name
    cmd = [sys.executable, str(REPO / "scripts" / "run_case.py"), str(CASES_DIR / f"{spec.name}.textproto"),
           "--output", str(out), "--fe-only", "--build-dir", str(build_dir)]
    log_dir.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    with open(log_dir / f"{spec.name}.log", "w") as log:
        result = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, cwd=REPO)
    wall = time.monotonic() - start
    if result.returncode != 0:
        raise RuntimeError(f"{spec.name}: run_case.py exited with {result.returncode}; see {log_dir / (spec.name + '.log')}")
    return wall


def analyse(spec: CaseSpec, run_dir: Path, cycle: int = 2, wall_time_s: float | None = None) -> ModelResult:
    """Kinematics, peaks and profiles of cycle `cycle` (1-based) of a finished run."""
    t0 = (cycle - 1) * PERIOD_S
    mesh = build_valve_mesh(spec.variant, spec.resolution, "triangles")   # the case's mesh, rebuilt
    R = float(mesh.description["param_annulus_radius"])
    sector = spec.variant == "sector"
    series = read_series(run_dir)
    in_cycle = (series.time >= t0 - 1e-12) & (series.time <= t0 + PERIOD_S + 1e-12)
    t = series.time[in_cycle] - t0
    x = series.midpoint_positions[in_cycle]
    radial = np.hypot(x[..., 0], x[..., 1]).mean(axis=1)
    result = ModelResult(spec, wall_time_s, None)
    result.energy_error_max = float(np.nanmax(np.abs(series.energy_balance_error))) if len(series.time) else float("nan")
    try:
        result.events = valve_events(t, radial)
    except ValueError as error:
        result.events_error = str(error)

    fields = SolidFields(run_dir)
    snap = np.flatnonzero((fields.times >= t0 - 1e-12) & (fields.times <= t0 + PERIOD_S + 1e-12))
    wedge = (0.0, 60.0) if sector else None
    goa, goa_t = [], []
    for k in snap:
        position = fields.snapshot(int(k))["position"]
        goa.append(geometric_orifice_area(position, fields.triangles, R, wedge, pixels_across=600))
        goa_t.append(fields.times[k] - t0)
    result.series = {"time_s": t, "free_edge_radial_position_m": radial,
                     "goa_time_s": np.array(goa_t), "goa_m2": np.array(goa)}

    leaflet0 = mesh.triangles[mesh.element_sets["leaflet_0_triangles"][1]]
    for tp in PROFILE_TIMES_S:
        k = fields.nearest(t0 + tp)
        result.profiles[round(fields.times[k] - t0, 6)] = bisection_profile(fields.snapshot(k)["position"], leaflet0, 0.0)

    opening = snap[(fields.times[snap] - t0) <= OPENING_WINDOW_S]
    for name, indices in (("opening", opening), ("closed", [fields.nearest(t0 + CLOSED_TIME_S)])):
        best = {}
        for k in indices:
            snapshot = fields.snapshot(int(k))
            for quantity in ("max_principal_log_strain", "max_principal_stress"):
                if quantity not in snapshot:
                    continue
                peak = peak_with_location(snapshot[quantity], fields.reference_nodes, fields.triangles, mesh.node_sets)
                if quantity not in best or peak.value > best[quantity][0].value:
                    best[quantity] = (peak, fields.times[k] - t0)
        for quantity, (peak, when) in best.items():
            result.peaks[f"{name}/{quantity}"] = (peak, when)
    return result


def _ms(value) -> str:
    return "–" if value is None else f"{value * 1e3:.1f}"


def opening_table(opening: dict) -> list[str]:
    """Markdown rows: name -> opening_metrics(...) (or an error string)."""
    lines = ["## Opening: resolution and sector against full (first 60 ms)", "",
             "| run | opening start (ms) | RVOT 10-90 % (ms) | open free-edge r (mm) | peak log strain | peak stress (MPa) |",
             "|---|---|---|---|---|---|"]
    for name, m in opening.items():
        if isinstance(m, str):
            lines.append(f"| {name} | {m} | | | | |")
            continue
        lines.append(f"| {name} | {m['opening_start_s'] * 1e3:.2f} | {m['rvot_s'] * 1e3:.2f} | {m['r_open_m'] * 1e3:.2f} | "
                     f"{m['peak_log_strain']:.3f} | {m['peak_stress_Pa'] * 1e-6:.2f} |")
    lines += ["| reference FE-MHGO | – | 6 | – | ≈ 0.22 (5 ms) | – |", ""]
    return lines


def write_report(results: list[ModelResult], path: Path, figures_dir: Path, cycle: int = 2,
                 opening: dict | None = None, notes: str = "") -> None:
    figures_dir.mkdir(parents=True, exist_ok=True)
    lines = ["# FE-only study: the reference's FE columns", "",
             f"Generated by `cd scripts && /usr/bin/python3 -m valve_scene.fe_study`; cycle {cycle} "
             "is analysed. Definitions: docs/valve-scene.md (\"Analysis\").", "",
             "## Kinematics (reference Table 3, FE-only columns)", "",
             "| case | RVOT (ms) | RVCT (ms) | ET (ms) | opening start (ms) | closing end (ms) | wall time (s) | max energy-balance error |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        e = r.events
        lines.append(f"| {r.spec.name} | {_ms(e and e.rvot)} | {_ms(e and e.rvct)} | {_ms(e and e.et)} | "
                     f"{_ms(e and e.opening_start)} | {_ms(e and e.closing_end)} | "
                     f"{'–' if r.wall_time_s is None else f'{r.wall_time_s:.0f}'} | {r.energy_error_max:.2g} |"
                     + (f" {r.events_error}" if r.events_error else ""))
    for model in ("FE-Ogden", "FE-MHGO"):
        ref = REFERENCE_KINEMATICS_MS[model]
        lines.append(f"| reference {model} | {ref['RVOT']} | {ref['RVCT']} | {ref['ET']} | | | | |")
    lines += ["", "## Peak max-principal log strain and stress (reference Sec. 3.2)", "",
              "| case | when | log strain | at (ms) | where | stress (MPa) | at (ms) | where |", "|---|---|---|---|---|---|---|---|"]
    for r in results:
        for when in ("opening", "closed"):
            strain = r.peaks.get(f"{when}/max_principal_log_strain")
            stress = r.peaks.get(f"{when}/max_principal_stress")
            cells = []
            for item, scale, digits in ((strain, 1.0, 3), (stress, 1e-6, 2)):
                if item is None:
                    cells += ["–", "–", "–"]
                else:
                    peak, at = item
                    cells += [f"{peak.value * scale:.{digits}f}", f"{at * 1e3:.0f}", peak.region]
            lines.append(f"| {r.spec.name} | {when} | " + " | ".join(cells) + " |")
    ref = REFERENCE_PEAKS["FE-MHGO"]
    lines += [f"| reference FE-MHGO | opening | {ref['strain_opening']} | 5 | below the commissures, along the attachment | | | |",
              f"| reference MHGO | closed | {ref['strain_closed']} | | attachment hinge | 1.13 (FSI-MHGO) | 300 | commissure |", ""]
    by_material = {}
    for r in results:
        by_material.setdefault((r.spec.material, r.spec.variant), []).append(r)
    for (material, variant), group in by_material.items():
        name = f"fe-{material.lower()}-{variant}"
        series = {f"{r.spec.resolution}": {"time_s": r.series["time_s"], "free_edge_radial_position_m": r.series["free_edge_radial_position_m"],
                                            "goa_m2": np.interp(r.series["time_s"], r.series["goa_time_s"], r.series["goa_m2"])
                                            if len(r.series.get("goa_m2", [])) else np.zeros_like(r.series["time_s"])}
                  for r in group}
        plot_kinematics(series, figures_dir / f"fe-only-{name}-kinematics.png")
        finest = group[-1]
        plot_profiles(finest.profiles, figures_dir / f"fe-only-{name}-profiles.png", closing_from_s=0.2,
                      title=f"FE-{material}, {variant}, {finest.spec.resolution}: bisection profiles")
        lines += [f"![{name} kinematics](figures/fe-only-{name}-kinematics.png)",
                  f"![{name} profiles](figures/fe-only-{name}-profiles.png)", ""]
    if opening:
        lines += opening_table(opening)
    if notes:
        lines += [notes, ""]
    path.write_text("\n".join(lines) + "\n")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", choices=("full", "sector"), default="sector")
    parser.add_argument("--resolutions", nargs="+", default=["coarse", "medium"])
    parser.add_argument("--materials", nargs="+", default=["Ogden", "MHGO"])
    parser.add_argument("--build-dir", type=Path, default=REPO / "build")
    parser.add_argument("--skip-run", action="store_true", help="analyse existing runs/ folders only")
    parser.add_argument("--report", type=Path, default=REPO / "docs" / "fe-only-study.md")
    parser.add_argument("--cycle", type=int, default=2, help="cycle analysed (1 when the runs stopped in the second)")
    parser.add_argument("--opening-runs", nargs="*", type=Path, default=[],
                        help="run folders whose first 60 ms give the opening table (other resolutions, the full valve)")
    parser.add_argument("--notes", type=Path, help="Markdown appended to the report (the discussion)")
    parser.add_argument("--runs-dir", type=Path, default=REPO / "runs", help="where the runs are (RUNS/<case>)")
    args = parser.parse_args(argv)
    write_cases(CASES_DIR)
    if not all((CASES_DIR / "meshes" / f"valve-{args.variant}-{r}.mesh.h5").exists() for r in args.resolutions):
        write_meshes(CASES_DIR)
    results = []
    for material in args.materials:
        for resolution in args.resolutions:
            spec = CaseSpec("FE", material, args.variant, resolution)
            wall = None if args.skip_run else run_case(spec, args.build_dir, args.runs_dir / "logs", args.runs_dir)
            results.append(analyse(spec, args.runs_dir / spec.name, cycle=args.cycle, wall_time_s=wall))
            e = results[-1].events
            print(f"{spec.name}: wall {wall} s, " + (f"RVOT {e.rvot * 1e3:.1f} ms, RVCT {e.rvct * 1e3:.1f} ms, ET {e.et * 1e3:.1f} ms"
                                                      if e else results[-1].events_error))
    opening = {}
    for run_dir in [args.runs_dir / r.spec.name for r in results] + list(args.opening_runs):
        try:
            opening[run_dir.name] = opening_metrics(run_dir)
        except (FileNotFoundError, KeyError, ValueError, IndexError) as error:
            opening[run_dir.name] = f"not measured: {error}"
    notes = args.notes.read_text() if args.notes else ""
    write_report(results, args.report, args.report.parent / "figures", args.cycle, opening, notes)
    print(args.report)



def opening_metrics(run_dir: Path, end_s: float = 0.06, plateau_from_s: float = 0.03) -> dict:
    """The opening alone (a run stopped at end_s, or the first end_s of a longer one), for the
    resolution and sector-vs-full checks: the 10 %/90 % crossings of the free-edge radial
    position between its start and its open plateau (the median over [plateau_from_s, end_s]),
    and the peak max-principal log strain and stress of the solid's snapshots up to end_s."""
    import h5py
    series = read_series(run_dir)
    keep = series.time <= end_s + 1e-12
    t = series.time[keep]
    r = np.hypot(series.midpoint_positions[keep, :, 0], series.midpoint_positions[keep, :, 1]).mean(axis=1)
    if t[-1] < end_s - 1e-9:
        raise ValueError(f"{run_dir}: the series ends at {t[-1]:g} s, before {end_s:g} s")
    r0, r_open = float(r[0]), float(np.median(r[t >= plateau_from_s]))

    def first_crossing(level):
        i = int(np.flatnonzero(r >= level)[0])
        return float(t[i - 1] + (level - r[i - 1]) / (r[i] - r[i - 1]) * (t[i] - t[i - 1])) if i > 0 else float(t[0])

    t10, t90 = first_crossing(r0 + 0.1 * (r_open - r0)), first_crossing(r0 + 0.9 * (r_open - r0))
    with h5py.File(Path(run_dir) / "solid_series.h5", "r") as f:
        ts = f["snapshots/time"][()]
        sel = ts <= end_s + 1e-12
        strain = float(f["snapshots/peak_max_principal_log_strain"][()][sel].max())
        stress = float(f["snapshots/peak_max_principal_stress"][()][sel].max())
    return {"opening_start_s": t10, "opening_end_s": t90, "rvot_s": t90 - t10, "r_open_m": r_open,
            "peak_log_strain": strain, "peak_stress_Pa": stress}


if __name__ == "__main__":
    main()
