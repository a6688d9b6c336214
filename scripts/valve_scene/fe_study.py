"""The FE-only half of the reference's comparison: FE-Ogden and FE-MHGO over two cycles at two
resolutions (the second cycle analysed), their kinematics, peak strain and stress against the
reference's FE-only columns, and the wall times.

    cd scripts && /usr/bin/python3 -m valve_scene.fe_study [--variant sector] \
        [--resolutions coarse medium] [--build-dir ../build] [--skip-run]

Writes runs/<case>/ (solver output), docs/fe-only-study.md and docs/figures/fe-only-*.png.
"""
from __future__ import annotations

import argparse
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .launch import launch, read_cost
from .analysis import (ROBUST_PEAK_FRACTION, ValveEvents, bisection_profile, geometric_orifice_area,
                       peak_with_location, robust_peak, triangle_areas, valve_events)
from .valve_geometry import ValveParameters
from .valve_mesh import build_valve_mesh
from .report import REFERENCE_KINEMATICS_MS, REFERENCE_PEAKS, plot_kinematics, plot_profiles
from .solid_results import SolidFields, read_series
from .waveform import PERIOD_S
from .write_cases import CASES_DIR, CaseSpec, case_text, write_cases, write_meshes

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
    peaks: dict = field(default_factory=dict)      # name -> (FieldPeak, time in cycle)
    robust_peaks: dict = field(default_factory=dict)   # name -> (area percentile value, time in cycle)
    profiles: dict = field(default_factory=dict)   # time in cycle -> polyline
    energy_error_max: float = float("nan")
    label: str = ""
    cpu_time_s: float | None = None
    mesh_label: str = ""

    def __post_init__(self):
        self.label = self.label or self.spec.name


def run_case(spec: CaseSpec, build_dir: Path, log_dir: Path, runs_dir: Path = REPO / "runs") -> float:
    """Runs one FE-only case through the launcher; returns its wall time (s)."""
    out = runs_dir / spec.name
    log = log_dir / f"{spec.name}.log"
    cost = launch(CASES_DIR / f"{spec.name}.textproto", out, build_dir, log, fe_only=True)
    if cost.exit_code != 0:
        raise RuntimeError(f"{spec.name}: run_case.py exited with {cost.exit_code}; see {log}")
    return cost.wall_time_s


# The cheap faithful study (--windows): the FE-only valve follows the pressure with no flow to
# remember, so the opening and the closing can be run as two short windows from the stress-free
# closed leaflet. The closing window starts while the valve is open and settles (open in ~3 ms,
# flutter damped) before the analysed part begins.
OPENING_WINDOW = (0.0, 0.06)
CLOSING_WINDOW = (0.15, 0.32)
CLOSING_SETTLE_S = 0.03
WINDOW_RAMP_S = 0.005   # the closing window's gradient (~2.8 mmHg) ramps up instead of stepping


def window_case_text(spec: CaseSpec, start_s: float, end_s: float) -> str:
    """The case of `spec` run from cycle time start_s to end_s: the waveform table rotated so the
    run's t = 0 is cycle time start_s, the mesh path absolute (the file lives in the runs folder)."""
    from . import waveform
    text = case_text(spec)
    t, p_lv, p_ao = waveform.sampled_table()
    shifted_lv = np.interp((t + start_s) % waveform.PERIOD_S, t, p_lv, period=waveform.PERIOD_S)
    shifted_ao = np.interp((t + start_s) % waveform.PERIOD_S, t, p_ao, period=waveform.PERIOD_S)
    fmt = waveform._format_list
    block = ("waveform {\n"
             f"  # rotated: t = 0 here is cycle time {start_s:g} s\n"
             f"  period_s: {waveform.PERIOD_S:g}\n"
             f"  time_s: {fmt(t, '{:.3f}')}\n"
             f"  ventricular_pressure_mmHg: {fmt(shifted_lv, '{:.3f}')}\n"
             f"  aortic_pressure_mmHg: {fmt(shifted_ao, '{:.3f}')}\n"
             + (f"  ramp_time: {WINDOW_RAMP_S:g}\n" if start_s > 0 else "") +
             "}\n")
    text = text.replace(waveform.waveform_textproto(), block)
    text = re.sub(r"end_time: [0-9.]+", f"end_time: {end_s - start_s:.6g}", text, count=1)
    return text.replace(f'mesh_file: "meshes/{spec.mesh_name}"', f'mesh_file: "{CASES_DIR / "meshes" / spec.mesh_name}"')


def run_window(spec: CaseSpec, window: tuple[float, float], build_dir: Path, runs_dir: Path) -> tuple[Path, float]:
    """Runs one window of an FE-only case; returns (run folder, wall time)."""
    name = f"{spec.name}-window-{window[0] * 1e3:.0f}-{window[1] * 1e3:.0f}ms"
    runs_dir.mkdir(parents=True, exist_ok=True)
    case_file = runs_dir / f"{name}.textproto"
    case_file.write_text(window_case_text(spec, *window))
    out = runs_dir / name
    cost = launch(case_file, out, build_dir, runs_dir / f"{name}.log", fe_only=True)
    if cost.exit_code != 0:
        raise RuntimeError(f"{name}: run_case.py exited with {cost.exit_code}; see {runs_dir / (name + '.log')}")
    return out, cost.wall_time_s


def recorded_times(run_dirs) -> tuple[float | None, float | None]:
    """Summed (wall, CPU) seconds of runs that recorded them (RUN/wall_time.json)."""
    costs = [read_cost(run_dir) for run_dir in run_dirs]
    walls = [c.wall_time_s if c else None for c in costs]
    cpus = [c.cpu_time_s if c else None for c in costs]
    return (None if None in walls else sum(walls)), (None if None in walls + cpus else sum(cpus))


def analyse_windows(spec: CaseSpec, opening_dir: Path, closing_dir: Path, wall_time_s: float | None = None) -> ModelResult:
    """RVOT, RVCT, ET and the peaks from the two windows: the free-edge curve of the opening window
    (cycle time 0-60 ms) joined to the closing window's after it settled (from 180 ms), the
    opening peaks from the first, the closed ones (300 ms) from the second."""
    mesh = run_mesh(spec, opening_dir)
    R = float(mesh.description["param_annulus_radius"])
    result = ModelResult(spec, wall_time_s, None)
    result.mesh_label = mesh_label(mesh)
    parts, errors = [], []
    for run_dir, offset, keep_from in ((opening_dir, OPENING_WINDOW[0], OPENING_WINDOW[0]),
                                       (closing_dir, CLOSING_WINDOW[0], CLOSING_WINDOW[0] + CLOSING_SETTLE_S)):
        series = read_series(run_dir)
        t = series.time + offset
        keep = t >= keep_from - 1e-12
        radial = np.hypot(series.midpoint_positions[keep, :, 0], series.midpoint_positions[keep, :, 1]).mean(axis=1)
        parts.append((t[keep], radial))
        errors.append(float(np.nanmax(np.abs(series.energy_balance_error))))
    t = np.concatenate([p[0] for p in parts])
    radial = np.concatenate([p[1] for p in parts])
    result.energy_error_max = max(errors)
    try:
        result.events = valve_events(t, radial)
    except ValueError as error:
        result.events_error = str(error)
    goa, goa_t = [], []
    for run_dir, offset, keep_from in ((opening_dir, OPENING_WINDOW[0], 0.0),
                                       (closing_dir, CLOSING_WINDOW[0], CLOSING_WINDOW[0] + CLOSING_SETTLE_S)):
        fields = SolidFields(run_dir)
        for k in np.flatnonzero(fields.times + offset >= keep_from - 1e-12):
            goa.append(geometric_orifice_area(fields.snapshot(int(k))["position"], fields.triangles, R,
                                              (0.0, 60.0) if spec.variant == "sector" else None, pixels_across=600))
            goa_t.append(fields.times[k] + offset)
    result.series = {"time_s": t, "free_edge_radial_position_m": radial, "goa_time_s": np.array(goa_t), "goa_m2": np.array(goa)}
    leaflet0 = mesh.triangles[mesh.element_sets["leaflet_0_triangles"][1]]
    for window, run_dir, names in ((OPENING_WINDOW, opening_dir, ("opening",)), (CLOSING_WINDOW, closing_dir, ("closed",))):
        fields = SolidFields(run_dir)
        areas = triangle_areas(fields.reference_nodes, fields.triangles)
        for tp in PROFILE_TIMES_S:
            if window[0] + (CLOSING_SETTLE_S if window[0] > 0 else 0) <= tp <= window[1]:
                k = fields.nearest(tp - window[0])
                result.profiles[round(fields.times[k] + window[0], 6)] = bisection_profile(fields.snapshot(k)["position"], leaflet0, 0.0)
        indices = (np.flatnonzero(fields.times <= OPENING_WINDOW_S + 1e-12) if window[0] == 0
                   else [fields.nearest(CLOSED_TIME_S - window[0])])
        _window_peaks(result, names[0], fields, indices, window[0], areas, mesh)
    return result


def run_mesh(spec: CaseSpec, run_dir: Path):
    """The run's mesh rebuilt with its node sets: the generator's default, the sharp commissure
    (its top row doubled, or uniform rows as before session 12) or the measured 2 mm rounded one,
    whichever has the run's reference nodes."""
    reference = SolidFields(run_dir).reference_nodes
    for params, top_row in ((ValveParameters(), None), (ValveParameters(commissure_fillet_radius=0.0), None),
                            (ValveParameters(commissure_fillet_radius=0.0), (1.0, 1)),
                            (ValveParameters(commissure_fillet_radius=2e-3), None)):
        mesh = build_valve_mesh(spec.variant, spec.resolution, "triangles", params, commissure_top_row=top_row)
        if mesh.nodes.shape == reference.shape and np.allclose(mesh.nodes, reference, rtol=0, atol=1e-12):
            return mesh
    raise ValueError(f"{run_dir}: its mesh is neither the generator's {spec.variant} {spec.resolution} mesh "
                     "with the default rounded commissure nor the sharp one")


def mesh_label(mesh) -> str:
    radius = float(mesh.description.get("param_commissure_fillet_radius", 0.0))
    return f"commissure fillet {radius * 1e3:g} mm" if radius > 0 else "sharp commissure"


def _window_peaks(result: ModelResult, name: str, fields: SolidFields, indices, t0: float, areas, mesh) -> None:
    """Element maximum (with its region) and robust peak of strain and stress over the snapshots
    `indices`, stored under `name`; a snapshot's cycle time is its run time + `t0`."""
    best, history = {}, {}
    for k in indices:
        snapshot = fields.snapshot(int(k))
        for quantity in ("max_principal_log_strain", "max_principal_stress"):
            if quantity not in snapshot:
                continue
            history.setdefault(quantity, []).append(snapshot[quantity])
            peak = peak_with_location(snapshot[quantity], fields.reference_nodes, fields.triangles, mesh.node_sets)
            if quantity not in best or peak.value > best[quantity][0].value:
                best[quantity] = (peak, fields.times[k] + t0)
    for quantity, (peak, when) in best.items():
        result.peaks[f"{name}/{quantity}"] = (peak, when)
        value, j = robust_peak(history[quantity], areas)
        result.robust_peaks[f"{name}/{quantity}"] = (value, fields.times[indices[j]] + t0)


def analyse(spec: CaseSpec, run_dir: Path, cycle: int = 2, wall_time_s: float | None = None) -> ModelResult:
    """Kinematics, peaks and profiles of cycle `cycle` (1-based) of a finished run."""
    t0 = (cycle - 1) * PERIOD_S
    mesh = run_mesh(spec, run_dir)   # the case's mesh, rebuilt
    R = float(mesh.description["param_annulus_radius"])
    sector = spec.variant == "sector"
    series = read_series(run_dir)
    in_cycle = (series.time >= t0 - 1e-12) & (series.time <= t0 + PERIOD_S + 1e-12)
    t = series.time[in_cycle] - t0
    x = series.midpoint_positions[in_cycle]
    radial = np.hypot(x[..., 0], x[..., 1]).mean(axis=1)
    result = ModelResult(spec, wall_time_s, None, mesh_label=mesh_label(mesh))
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
    areas = triangle_areas(fields.reference_nodes, fields.triangles)
    _window_peaks(result, "opening", fields, opening, -t0, areas, mesh)
    _window_peaks(result, "closed", fields, [fields.nearest(t0 + CLOSED_TIME_S)], -t0, areas, mesh)
    return result


def _ms(value) -> str:
    return "–" if value is None else f"{value * 1e3:.1f}"


def opening_table(opening: dict) -> list[str]:
    """Markdown rows: name -> opening_metrics(...) (or an error string)."""
    lines = ["## Opening: resolution and sector against full (first 60 ms)", "",
             "| run | opening start (ms) | RVOT 10-90 % (ms) | open free-edge r (mm) | log strain p99 | peak log strain | peak stress (MPa) |",
             "|---|---|---|---|---|---|---|"]
    for name, m in opening.items():
        if isinstance(m, str):
            lines.append(f"| {name} | {m} | | | | | |")
            continue
        lines.append(f"| {name} | {m['opening_start_s'] * 1e3:.2f} | {m['rvot_s'] * 1e3:.2f} | {m['r_open_m'] * 1e3:.2f} | "
                     f"{m.get('robust_log_strain', float('nan')):.3f} | {m['peak_log_strain']:.3f} | {m['peak_stress_Pa'] * 1e-6:.2f} |")
    lines += ["| reference FE-MHGO | – | 6 | – | – | ≈ 0.22 (5 ms) | – |", ""]
    return lines


def write_report(results: list[ModelResult], path: Path, figures_dir: Path, cycle: int = 2,
                 opening: dict | None = None, notes: str = "", mode: str = "cycles") -> None:
    figures_dir.mkdir(parents=True, exist_ok=True)
    how = (f"rows \"(windows)\": the opening ({OPENING_WINDOW[0] * 1e3:.0f}–{OPENING_WINDOW[1] * 1e3:.0f} ms) and closing "
           f"({CLOSING_WINDOW[0] * 1e3:.0f}–{CLOSING_WINDOW[1] * 1e3:.0f} ms, analysed from "
           f"{(CLOSING_WINDOW[0] + CLOSING_SETTLE_S) * 1e3:.0f} ms) windows, each started from the stress-free leaflet; "
           f"rows \"(cycle {cycle})\": cycle {cycle} of a two-cycle run" if mode == "windows" else f"cycle {cycle} is analysed")
    lines = ["# FE-only study: the reference's FE columns", "",
             f"Generated by `cd scripts && /usr/bin/python3 -m valve_scene.fe_study` (--mode {mode}); {how}. "
             "Definitions: docs/valve-scene.md (\"Analysis\").", "",
             "## Kinematics (reference Table 3, FE-only columns)", "",
             "| case | RVOT (ms) | RVCT (ms) | ET (ms) | opening start (ms) | closing end (ms) | wall / CPU time (s) | max energy-balance error |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        e = r.events
        lines.append(f"| {r.label} | {_ms(e and e.rvot)} | {_ms(e and e.rvct)} | {_ms(e and e.et)} | "
                     f"{_ms(e and e.opening_start)} | {_ms(e and e.closing_end)} | "
                     f"{'–' if r.wall_time_s is None else f'{r.wall_time_s:.0f}'}"
                     f"{'' if r.cpu_time_s is None else f' / {r.cpu_time_s:.0f}'} | {r.energy_error_max:.2g} |"
                     + (f" {r.events_error}" if r.events_error else ""))
    for model in ("FE-Ogden", "FE-MHGO"):
        ref = REFERENCE_KINEMATICS_MS[model]
        lines.append(f"| reference {model} | {ref['RVOT']} | {ref['RVCT']} | {ref['ET']} | | | | |")
    percent = f"{100 * (1 - ROBUST_PEAK_FRACTION):g}"
    lines += ["", "## Peak max-principal log strain and stress (reference Sec. 3.2)", "",
              f"Robust peak (p{percent}): the value exceeded on {100 * ROBUST_PEAK_FRACTION:g} % of the leaflet's reference area, "
              "largest over the window's snapshots (definition: docs/valve-scene.md); the element maximum beside it.", "",
              f"| case | when | log strain p{percent} | max | at (ms) | where | stress p{percent} (MPa) | max (MPa) | at (ms) | where |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for when in ("opening", "closed"):
            cells = []
            for quantity, scale, digits in (("max_principal_log_strain", 1.0, 3), ("max_principal_stress", 1e-6, 2)):
                item = r.peaks.get(f"{when}/{quantity}")
                robust = r.robust_peaks.get(f"{when}/{quantity}")
                if item is None:
                    cells += ["–", "–", "–", "–"]
                else:
                    peak, at = item
                    cells += [f"{robust[0] * scale:.{digits}f}" if robust else "–", f"{peak.value * scale:.{digits}f}",
                              f"{at * 1e3:.0f}", peak.region]
            lines.append(f"| {r.label} | {when} | " + " | ".join(cells) + " |")
    ref = REFERENCE_PEAKS["FE-MHGO"]
    lines += [f"| reference FE-MHGO | opening | | {ref['strain_opening']} | 5 | below the commissures, along the attachment | | | | |",
              f"| reference MHGO | closed | | {ref['strain_closed']} | | attachment hinge | | 1.13 (FSI-MHGO) | 300 | commissure |", ""]
    by_material = {}
    for r in results:
        by_material.setdefault((r.spec.material, r.spec.variant), []).append(r)
    for (material, variant), group in by_material.items():
        name = f"fe-{material.lower()}-{variant}"
        series = {(f"{r.spec.resolution}" if len(group) == 1 or r.label == r.spec.name else r.label.split(" (")[1].rstrip(")")): {"time_s": r.series["time_s"], "free_edge_radial_position_m": r.series["free_edge_radial_position_m"],
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
    parser.add_argument("--mode", choices=("windows", "cycles"), default="windows",
                        help="windows (default, minutes): the opening (0-60 ms) and closing (150-320 ms) windows of "
                             "each model; cycles: two whole cycles, the second analysed (~25 min CPU per model, coarse)")
    parser.add_argument("--variant", choices=("full", "sector"), default="sector")
    parser.add_argument("--resolutions", nargs="+", default=["coarse"])
    parser.add_argument("--materials", nargs="+", default=["Ogden", "MHGO"])
    parser.add_argument("--build-dir", type=Path, default=REPO / "build")
    parser.add_argument("--skip-run", action="store_true", help="analyse existing runs/ folders only")
    parser.add_argument("--report", type=Path, default=REPO / "docs" / "fe-only-study.md")
    parser.add_argument("--cycle", type=int, default=2, help="cycle analysed (1 when the runs stopped in the second)")
    parser.add_argument("--also-cycles", nargs="*", type=int, default=[],
                        help="cycles mode: rows for these cycles too (e.g. 1, to show the cycle repeats)")
    parser.add_argument("--cycle-runs-dir", type=Path,
                        help="windows mode: also analyse the two-cycle runs in this folder (rows next to the windows')")
    parser.add_argument("--opening-runs", nargs="*", type=Path, default=[],
                        help="run folders whose first 60 ms give the opening table (other resolutions, the full valve)")
    parser.add_argument("--notes", type=Path, help="Markdown appended to the report (the discussion)")
    parser.add_argument("--runs-dir", type=Path, default=REPO / "runs", help="where the runs are (RUNS/<case>)")
    args = parser.parse_args(argv)
    if not args.skip_run:   # analysing existing runs needs no case files (the mesh is rebuilt)
        write_cases(CASES_DIR)
    if not args.skip_run and not all((CASES_DIR / "meshes" / f"valve-{args.variant}-{r}.mesh.h5").exists() for r in args.resolutions):
        write_meshes(CASES_DIR)
    results, opening_dirs = [], []
    for material in args.materials:
        for resolution in args.resolutions:
            spec = CaseSpec("FE", material, args.variant, resolution)
            if args.mode == "windows":
                dirs, walls = [], []
                for window in (OPENING_WINDOW, CLOSING_WINDOW):
                    name = f"{spec.name}-window-{window[0] * 1e3:.0f}-{window[1] * 1e3:.0f}ms"
                    if args.skip_run:
                        dirs.append(args.runs_dir / name)
                    else:
                        run_dir, wall = run_window(spec, window, args.build_dir, args.runs_dir)
                        dirs.append(run_dir)
                        walls.append(wall)
                if args.skip_run and not all((d / "solid_series.h5").exists() for d in dirs):
                    print(f"{spec.name}: no window runs in {args.runs_dir}, left out")
                    continue
                wall, cpu = recorded_times(dirs)
                results.append(analyse_windows(spec, *dirs, wall_time_s=wall))
                results[-1].cpu_time_s = cpu
                results[-1].label = f"{spec.name} (windows, {results[-1].mesh_label})"
                opening_dirs.append(dirs[0])
                if args.cycle_runs_dir and (args.cycle_runs_dir / spec.name).exists():
                    cycle_wall, cycle_cpu = recorded_times([args.cycle_runs_dir / spec.name])
                    results.append(analyse(spec, args.cycle_runs_dir / spec.name, cycle=args.cycle, wall_time_s=cycle_wall))
                    results[-1].cpu_time_s = cycle_cpu
                    results[-1].label = f"{spec.name} (cycle {args.cycle}, {results[-1].mesh_label})"
            else:
                if not args.skip_run:
                    run_case(spec, args.build_dir, args.runs_dir / "logs", args.runs_dir)
                wall, cpu = recorded_times([args.runs_dir / spec.name])   # the run's RUN/wall_time.json
                for cycle in [*args.also_cycles, args.cycle]:
                    results.append(analyse(spec, args.runs_dir / spec.name, cycle=cycle, wall_time_s=wall))
                    results[-1].cpu_time_s = cpu
                    results[-1].label = f"{spec.name} (cycle {cycle}, {results[-1].mesh_label})"
                opening_dirs.append(args.runs_dir / spec.name)
            e = results[-1].events
            print(f"{results[-1].label}: wall {results[-1].wall_time_s} s, "
                  + (f"RVOT {e.rvot * 1e3:.1f} ms, RVCT {e.rvct * 1e3:.1f} ms, ET {e.et * 1e3:.1f} ms" if e else results[-1].events_error))
    opening = {}
    for run_dir in opening_dirs + list(args.opening_runs):
        try:
            opening[run_dir.name] = opening_metrics(run_dir)
        except (FileNotFoundError, KeyError, ValueError, IndexError) as error:
            opening[run_dir.name] = f"not measured: {error}"
    notes = args.notes.read_text() if args.notes else ""
    write_report(results, args.report, args.report.parent / "figures", args.cycle, opening, notes, args.mode)
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
    robust = float("nan")
    try:
        fields = SolidFields(run_dir)
        areas = triangle_areas(fields.reference_nodes, fields.triangles)
        indices = np.flatnonzero(fields.times <= end_s + 1e-12)
        robust = robust_peak([fields.snapshot(int(k))["max_principal_log_strain"] for k in indices], areas)[0]
    except (FileNotFoundError, KeyError, ValueError):
        pass
    return {"opening_start_s": t10, "opening_end_s": t90, "rvot_s": t90 - t10, "r_open_m": r_open,
            "peak_log_strain": strain, "peak_stress_Pa": stress, "robust_log_strain": robust}


if __name__ == "__main__":
    main()
