"""The reference's comparison (issue 7, item 4): FE-only against FSI, Ogden against MHGO, at one
resolution and dimension, in one Markdown report with the reference's values beside ours.

    cd scripts && /usr/bin/python3 -m valve_scene.comparison --dimension 2 --resolution xcoarse \
        [--variant sector] [--cycles 2] [--end-time S] [--runs-dir /work/runs/comparison] \
        [--build-dir ../build] [--reuse] [--out ../docs/comparison.md]

Runs the four cases (cases/{fe,fsi}-{ogden,mhgo}-<2d|variant>-<resolution>.textproto) through
scripts/run_case.py, one after the other, timing each; --reuse keeps a finished run (its
wall_time.json) instead of running it again; --end-time shortens every run (a plumbing check).
The report holds: the wall times; the kinematics against the reference's Table 3; the
hemodynamics against its Table 2 (2D: per metre of depth, docs/hemodynamics.md); peak stress and
strain; the interface balance of each FSI run (issue 7, item 5); the findings of issue 7, item 6,
each checked with its numbers; figures like the reference's Figs. 5, 6, 11 and 12.
Reference: W. Mao, K. Li, W. Sun, Cardiovasc. Eng. Technol. 7(4), 2016 (values in report.py,
hemodynamics.py and REFERENCE_FINDINGS below).
"""
from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import hemodynamics as hd
from .analysis import ValveEvents, robust_peak, triangle_areas, valve_events
from .launch import launch, read_cost
from .report import kinematics_table
from .run_report import free_edge_kinematics
from .waveform import PERIOD_S

REPO = Path(__file__).resolve().parents[2]
CASES_DIR = REPO / "cases"
KINDS = ("FE", "FSI")
MATERIALS = ("Ogden", "MHGO")
STRIP_DEPTH_2D = 1.0e-3           # m; the 2D cases' solid.strip_depth (valve2d.STRIP_DEPTH)
OPENING_WINDOW_S = 0.05           # opening peaks: the first 50 ms of the cycle
CLOSED_FROM_S = 0.27              # closed peaks: from the reference's FSI coaptation (270 ms) on
PEAK_WINDOWS = {"opening": (0.0, OPENING_WINDOW_S), "closed": (CLOSED_FROM_S, PERIOD_S)}
SEVERAL_TIMES = 2.0               # "takes several times longer": at least this ratio of RVOTs
CYCLE_TOLERANCE = 0.10            # "the second cycle differs from the first by less than 10 %"
BALANCE_TOLERANCE = 1e-6          # interface work, fluid vs solid, relative over the cycle
INTEGRATOR_TOLERANCE = 1e-3       # the solid's booked external work vs the loads' work (sampled series)

# Section 3.1-3.3 of the reference: the findings issue 7 item 6 asks to reproduce.
REFERENCE_FINDINGS = {
    "opening": "FSI opening starts ~20 ms later and takes 40 ms against 5-6 ms FE-only (Table 3)",
    "wider": "FE-only opens wider: larger radial excursion and GOA (Fig. 5)",
    "water_hammer": "FSI peak diastolic force -6.9/-6.1 N exceeds the hydrostatic -5.4 N (Table 2)",
    "stress": "closed peak stress Ogden 1.42 MPa > MHGO 1.13 MPa (FSI, Sec. 3.2)",
    "leaks": "no fluid passes a closed leaflet (SPH-FE contact)",
    "cycles": "cycles differ by less than 10 % (Sec. 2.4)",
}


@dataclass(frozen=True)
class RunSpec:
    kind: str          # "FE" or "FSI"
    material: str      # "Ogden" or "MHGO"
    dimension: int     # 2 or 3
    resolution: str
    variant: str = "sector"   # 3D only: "sector" or "full"

    @property
    def label(self) -> str:
        return f"{self.kind}-{self.material}"

    @property
    def name(self) -> str:
        shape = "2d" if self.dimension == 2 else self.variant
        return f"{self.kind.lower()}-{self.material.lower()}-{shape}-{self.resolution}"

    @property
    def symmetry_factor(self) -> float:
        return 6.0 if (self.dimension == 3 and self.variant == "sector") else 1.0


@dataclass
class RunResult:
    spec: RunSpec
    run_dir: Path
    wall_time_s: float | None = None
    exit_code: int | None = None
    simulated_s: float = 0.0
    events: ValveEvents | None = None
    events_error: str = ""
    kinematics: dict = field(default_factory=dict)        # t, radial, width of the analysed cycle
    peaks: dict = field(default_factory=dict)             # "opening"/"closed" -> (stress Pa, strain)
    hemodynamics: hd.CycleHemodynamics | None = None
    hemodynamics_error: str = ""
    balance: dict = field(default_factory=dict)
    leaks: int | None = None
    cycle_difference: dict = field(default_factory=dict)  # metric -> relative difference, cycle 1 vs 2
    cycle_values: tuple = ()                              # (previous cycle's, analysed cycle's) metrics
    partial: bool = False                                 # the run ends before the analysed cycle does


# ---------------------------------------------------------------------------------------------
# Running


def prepare_case(spec: RunSpec, work_dir: Path, end_time: float | None = None, cases_dir: Path = CASES_DIR) -> Path:
    """A copy of the case with an absolute mesh path and, when given, a shorter end time."""
    source = cases_dir / f"{spec.name}.textproto"
    if not source.exists():
        raise FileNotFoundError(f"{source}: no such case (write it with `python -m valve_scene.write_cases`)")
    text = source.read_text()
    text = re.sub(r'mesh_file: "([^"/][^"]*)"', lambda m: f'mesh_file: "{(source.parent / m.group(1)).resolve()}"', text)
    if end_time is not None:
        text, n = re.subn(r"end_time: [0-9.eE+-]+", f"end_time: {end_time:g}", text, count=1)
        if n != 1:
            raise ValueError(f"{source}: no run.end_time to shorten")
    work_dir.mkdir(parents=True, exist_ok=True)
    case = work_dir / f"{spec.name}.textproto"
    case.write_text(text)
    return case


def _cpu_time(run_dir: Path) -> float | None:
    """CPU seconds of a run (all programs), when its wall_time.json recorded them."""
    cost = read_cost(run_dir)
    return cost.cpu_time_s if cost else None


def run_one(spec: RunSpec, case: Path, run_dir: Path, build_dir: Path) -> tuple[float, int]:
    """Runs the case through the launcher (one thread per program); returns (wall s, exit code),
    which the launcher records in RUN_DIR/wall_time.json."""
    cost = launch(case, run_dir, build_dir, run_dir.parent / f"{spec.name}.log", fe_only=spec.kind == "FE", one_thread=True)
    return cost.wall_time_s, cost.exit_code


# ---------------------------------------------------------------------------------------------
# Analysis of one run


def _series_end(run_dir: Path) -> float:
    import h5py
    path = run_dir / "solid_series.h5"
    if not path.exists():
        return 0.0
    with h5py.File(path, "r") as f:
        return float(f["time"][-1]) if len(f["time"]) else 0.0


def solid_peaks(run_dir: Path, cycle: int) -> dict:
    """Peak max-principal stress (Pa) and log strain of the cycle while opening (first 50 ms)
    and closed (from 270 ms): the element maximum, from the solid's per-snapshot peaks in
    solid_series.h5, and the robust peak (the largest over the window's field snapshots of the
    value exceeded on 1 % of the leaflet area, analysis.robust_peak), which one element at a
    mesh corner cannot set."""
    import h5py
    path = run_dir / "solid_series.h5"
    peaks = {}
    with h5py.File(path, "r") as f:
        if "snapshots/time" not in f:
            return peaks
        t = f["snapshots/time"][()] - (cycle - 1) * PERIOD_S
        stress = f["snapshots/peak_max_principal_stress"][()]
        strain = f["snapshots/peak_max_principal_log_strain"][()]
    for name, (a, b) in PEAK_WINDOWS.items():
        sel = (t >= a - 1e-12) & (t < b)
        if np.any(sel):
            i, j = np.argmax(np.where(sel, stress, -np.inf)), np.argmax(np.where(sel, strain, -np.inf))
            peaks[name] = {"stress_Pa": float(stress[i]), "stress_time_s": float(t[i]),
                           "strain": float(strain[j]), "strain_time_s": float(t[j])}
    if (run_dir / "solid_fields.h5").exists():
        try:
            for name, robust in robust_solid_peaks(run_dir, cycle).items():
                peaks.setdefault(name, {}).update(robust)
        except (KeyError, ValueError):
            pass  # fields without a triangle mesh: the element maxima only
    return peaks


def robust_solid_peaks(run_dir: Path, cycle: int) -> dict:
    """Per window of PEAK_WINDOWS: the robust peak (analysis.robust_peak) of the max-principal
    stress ("stress_p99_Pa") and log strain ("strain_p99") over the field snapshots in it, with
    their cycle times."""
    from .solid_results import SolidFields
    fields = SolidFields(run_dir)
    areas = triangle_areas(fields.reference_nodes, fields.triangles)
    t = fields.times - (cycle - 1) * PERIOD_S
    peaks = {}
    for name, (a, b) in PEAK_WINDOWS.items():
        indices = np.flatnonzero((t >= a - 1e-12) & (t < b))
        snapshots = [fields.snapshot(int(k)) for k in indices]
        entry = {}
        for quantity, key in (("max_principal_stress", "stress_p99_Pa"), ("max_principal_log_strain", "strain_p99")):
            history = [s[quantity] for s in snapshots if quantity in s]
            if len(history) == len(indices) and history:
                value, k = robust_peak(history, areas)
                entry[key], entry[key.replace("_Pa", "") + "_time_s"] = value, float(t[indices[k]])
        if entry:
            peaks[name] = entry
    return peaks


def booked_over_windows(series_time, cumulative, window_end, window_size) -> float:
    """The increase of a cumulative series (the solid's external work) summed over the given
    coupling windows only, each (end - size, end], the series interpolated linearly. Over
    contiguous windows this telescopes to the increase from the first window's start to the last
    one's end; across a span without windows (a segment killed before its coupling series was
    flushed, then continued from a later restart point) it leaves that span's work out, as the
    windows' own sum does, so the two stay comparable."""
    window_end = np.asarray(window_end, dtype=float)
    start = window_end - np.asarray(window_size, dtype=float)
    return float(np.sum(np.interp(window_end, series_time, cumulative) - np.interp(start, series_time, cumulative)))


def window_gap(window_end, window_size) -> float:
    """Time (s) between the first window's start and the last one's end that no window covers."""
    window_end = np.asarray(window_end, dtype=float)
    if window_end.size == 0:
        return 0.0
    covered = float(np.sum(window_size))
    return max(0.0, float(window_end[-1] - (window_end[0] - window_size[0])) - covered)


def interface_balance(run_dir: Path, cycle: int, dimension: int) -> dict:
    """Issue 7, item 5, over the cycle (or the part of it the run covers), from the coupler's
    series and the solid's:
    - the work the fluid gives at the velocity its points move with, sum of power_fluid * dt, and
      the same through the mapping on the solid's side (power_solid): equal when the mapping
      conserves power, and so the total forces;
    - the work the loads do on the solid, sum of load_work_solid = F . (x_end - x_start), and the
      external work the solid's own integrator books over the same span (in 2D per strip depth,
      so divided by it): equal when the solid takes exactly the loads it was sent;
    - their difference, load work - fluid's work = F . (dx - v dt): what a staggered (explicit)
      coupling's lag creates at the interface (the fluid's points move with the velocity of the
      window before and are put back on the solid at the next window); zero under implicit
      coupling at convergence. Reported, not judged: it is the scheme's energy error."""
    import h5py
    with h5py.File(run_dir / "coupling_series.h5", "r") as f:
        t = f["time"][()].reshape(-1)
        dt = f["window_size"][()].reshape(-1)
        pf, ps = f["power_fluid"][()].reshape(-1), f["power_solid"][()].reshape(-1)
        ff, fs = f["force_fluid"][()], f["force_solid"][()]
        lw = f["load_work_solid"][()].reshape(-1) if "load_work_solid" in f else None
    a, b = (cycle - 1) * PERIOD_S, cycle * PERIOD_S
    solid_series = run_dir / "solid_series.h5"
    ts = we = None
    if solid_series.exists():
        with h5py.File(solid_series, "r") as f:
            if "energy/external_work" in f:
                ts, we = f["time"][()], f["energy/external_work"][()]
                b = min(b, float(ts[-1]))   # a stopped run's series may end before its last window
    sel = (t > a + 1e-12) & (t <= b + 1e-12)
    if not np.any(sel):
        raise ValueError(f"{run_dir}/coupling_series.h5: no window in cycle {cycle}")
    work_fluid, work_solid = float(np.sum(pf[sel] * dt[sel])), float(np.sum(ps[sel] * dt[sel]))
    scale = max(float(np.sum(np.abs(pf[sel]) * dt[sel])), 1e-300)
    force_scale = max(float(np.abs(ff[sel]).max()), 1e-300)
    result = {"work_fluid": work_fluid, "work_solid": work_solid,
              "work_relative_difference": abs(work_fluid - work_solid) / scale,
              "force_relative_difference": float(np.abs(ff[sel] - fs[sel]).max()) / force_scale,
              "power_scale": scale, "windows": int(np.count_nonzero(sel)),
              "t_first": float(t[sel][0] - dt[sel][0]), "t_last": float(t[sel][-1])}
    if lw is not None:
        load_work = float(np.sum(lw[sel]))
        load_scale = max(float(np.sum(np.abs(lw[sel]))), 1e-300)
        result.update({"load_work": load_work, "load_work_scale": load_scale, "lag_work": load_work - work_fluid})
    result["window_gap_s"] = window_gap(t[sel], dt[sel])
    if ts is not None:
        depth = STRIP_DEPTH_2D if dimension == 2 else 1.0
        booked = booked_over_windows(ts, we, t[sel], dt[sel]) / depth
        result["work_solid_integrator"] = booked
        if lw is not None:
            result["integrator_relative_difference"] = abs(booked - result["load_work"]) / result["load_work_scale"]
    return result


def leak_count(run_dir: Path) -> int | None:
    import h5py
    path = run_dir / "fluid_probes.h5"
    if not path.exists():
        return None
    with h5py.File(path, "r") as f:
        return int(f["interface/leaks"][()].max()) if "interface/leaks" in f else None


def _cycle_metrics(run: RunResult, cycle: int) -> dict:
    t, radial, width = free_edge_kinematics(run.run_dir, run.spec.dimension, cycle)
    events = valve_events(t, radial)
    metrics = {"RVOT": events.rvot, "RVCT": events.rvct, "ET": events.et, "peak radial position": float(radial.max())}
    if run.spec.kind == "FSI":
        series = hd.read_run(run.run_dir)
        h = hd.analyse_cycle(series, cycle, closure_time_s=events.closing_end, symmetry_factor=run.spec.symmetry_factor)
        metrics.update({"MSPD": h.mspd_mmHg, "PSPD": h.pspd_mmHg, "EOA": h.eoa, "peak flow": h.peak_flow,
                        "stroke volume": h.stroke_volume})
        if h.water_hammer_ratio is not None:
            metrics["water-hammer ratio"] = h.water_hammer_ratio
    return metrics


# Units and scale of each cycle metric in the cycle table (2D: per depth, as in Table 2's rows).
CYCLE_METRIC_UNITS = {"RVOT": ("ms", 1e3), "RVCT": ("ms", 1e3), "ET": ("ms", 1e3), "peak radial position": ("mm", 1e3),
                      "MSPD": ("mmHg", 1.0), "PSPD": ("mmHg", 1.0), "EOA": ("cm²; 2D cm", 1.0),
                      "peak flow": ("mL/s; 2D cm²/s", 1.0), "stroke volume": ("mL; 2D cm²", 1.0),
                      "water-hammer ratio": ("", 1.0)}


def cycles_table(runs: dict, cycle: int) -> str:
    """Each run's metrics in the previous and the analysed cycle, with their relative difference
    |c_n - c_(n-1)| / |c_n| (the "cycles" finding's measure)."""
    labels = [label for label, r in runs.items() if r.cycle_values]
    if not labels:
        return ""
    lines = [f"| metric | {' | '.join(f'{l} c{cycle - 1} / c{cycle} (diff.)' for l in labels)} |",
             "|---|" + "---|" * len(labels)]
    for key, (unit, scale) in CYCLE_METRIC_UNITS.items():
        cells = []
        for label in labels:
            first, second = runs[label].cycle_values
            if key in first and key in second:
                d = runs[label].cycle_difference[key]
                cells.append(f"{first[key] * scale:.3g} / {second[key] * scale:.3g} ({'**' if d >= CYCLE_TOLERANCE else ''}{d:.0%}{'**' if d >= CYCLE_TOLERANCE else ''})")
            else:
                cells.append("–")
        if any(c != "–" for c in cells):
            lines.append(f"| {key}{f' ({unit})' if unit else ''} | {' | '.join(cells)} |")
    return "\n".join(lines) + "\n"


def _closure_time(events: ValveEvents | None) -> float | None:
    """The closing end, when the run saw it (a partial cycle's is NaN)."""
    return events.closing_end if events is not None and np.isfinite(events.closing_end) else None


def analyse_run(run: RunResult, cycle: int, allow_partial: bool = False) -> RunResult:
    """The run's metrics over the cycle. allow_partial: a run that ends inside the cycle (a long
    coupled run stopped, or still going) is analysed up to its end: the opening's events without
    the closing's, the hemodynamics up to the end (hemodynamics.analyse_cycle), the peaks and the
    balance over what exists; run.partial says so and the report marks it."""
    d = run.spec.dimension
    run.partial = allow_partial and run.simulated_s < cycle * PERIOD_S - 1e-9
    try:
        t, radial, width = free_edge_kinematics(run.run_dir, d, cycle)
        run.kinematics = {"t": t, "radial": radial, "width": width}
        run.events = valve_events(t, radial, allow_open_end=run.partial)
    except (FileNotFoundError, KeyError, ValueError) as error:
        run.events_error = str(error)
    try:
        run.peaks = solid_peaks(run.run_dir, cycle)
    except (FileNotFoundError, KeyError):
        run.peaks = {}
    if run.spec.kind == "FSI":
        try:
            series = hd.read_run(run.run_dir)
            run.hemodynamics = hd.analyse_cycle(series, cycle, closure_time_s=_closure_time(run.events),
                                                symmetry_factor=run.spec.symmetry_factor, allow_partial=run.partial)
        except (FileNotFoundError, KeyError, ValueError, IndexError) as error:
            run.hemodynamics_error = str(error)
        try:
            run.balance = interface_balance(run.run_dir, cycle, d)
        except (FileNotFoundError, KeyError, ValueError) as error:
            run.balance = {"error": str(error)}
        run.leaks = leak_count(run.run_dir)
    if cycle >= 2:
        try:
            first, second = _cycle_metrics(run, cycle - 1), _cycle_metrics(run, cycle)
            run.cycle_difference = {k: abs(second[k] - first[k]) / max(abs(second[k]), 1e-300) for k in second if k in first}
            run.cycle_values = (first, second)
        except (FileNotFoundError, KeyError, ValueError, IndexError):
            run.cycle_difference = {}
            run.cycle_values = ()
    return run


# ---------------------------------------------------------------------------------------------
# Findings (issue 7, item 6)


@dataclass(frozen=True)
class Finding:
    key: str
    holds: bool | None     # None: not measurable from these runs
    evidence: str


def check_findings(runs: dict) -> list[Finding]:
    """runs: label ('FE-Ogden', ...) -> RunResult of the analysed cycle."""
    findings = []
    pairs = [(runs.get(f"FE-{m}"), runs.get(f"FSI-{m}")) for m in MATERIALS]

    # FSI opening starts later and takes several times longer than FE-only
    parts, verdicts = [], []
    for fe, fsi in pairs:
        if fe and fsi and fe.events and fsi.events:
            later = fsi.events.opening_start > fe.events.opening_start
            longer = fsi.events.rvot >= SEVERAL_TIMES * fe.events.rvot
            verdicts.append(later and longer)
            parts.append(f"{fsi.spec.material}: opening starts {fsi.events.opening_start * 1e3:.1f} vs "
                         f"{fe.events.opening_start * 1e3:.1f} ms, RVOT {fsi.events.rvot * 1e3:.1f} vs "
                         f"{fe.events.rvot * 1e3:.1f} ms (x{fsi.events.rvot / max(fe.events.rvot, 1e-12):.1f})")
    findings.append(Finding("opening", all(verdicts) if verdicts else None,
                            "; ".join(parts) or "no pair with valve events"))

    # FE-only opens wider (peak free-edge radial position; 2D: the peak orifice width)
    parts, verdicts = [], []
    for fe, fsi in pairs:
        if fe and fsi and fe.events and fsi.events:   # both opened and closed: the whole excursion is seen
            key = "width" if fe.kinematics.get("width") is not None and fsi.kinematics.get("width") is not None else "radial"
            a, b = float(np.max(fe.kinematics[key])), float(np.max(fsi.kinematics[key]))
            verdicts.append(a > b)
            parts.append(f"{fe.spec.material}: peak {'orifice width' if key == 'width' else 'free-edge radial position'} "
                         f"FE {a * 1e3:.2f} mm vs FSI {b * 1e3:.2f} mm")
    findings.append(Finding("wider", all(verdicts) if verdicts else None, "; ".join(parts) or "no pair with valve events"))

    # water hammer: FSI peak diastolic force beyond the hydrostatic one
    parts, verdicts = [], []
    for m in MATERIALS:
        fsi = runs.get(f"FSI-{m}")
        h = fsi.hemodynamics if fsi else None
        if h and h.water_hammer_ratio is not None:
            verdicts.append(h.water_hammer_ratio > 1.0)
            parts.append(f"{m}: {h.diastolic_force:.3g} vs hydrostatic {h.hydrostatic_force:.3g} (ratio {h.water_hammer_ratio:.2f})")
    findings.append(Finding("water_hammer", all(verdicts) if len(verdicts) == len(MATERIALS) else None,
                            "; ".join(parts) or "no FSI diastole measured"))

    # Ogden's closed peak stress exceeds MHGO's (FSI; FE-only beside it)
    parts, verdict = [], None
    for kind in ("FSI", "FE"):
        o, h = runs.get(f"{kind}-Ogden"), runs.get(f"{kind}-MHGO")
        if o and h and "stress_Pa" in o.peaks.get("closed", {}) and "stress_Pa" in h.peaks.get("closed", {}):
            co, ch = o.peaks["closed"], h.peaks["closed"]
            # judged on the robust peak where both runs have field snapshots: the element maximum
            # sits at the fixed commissure corner, where the mesh sets its value (docs/comparison-3d.md)
            robust = "stress_p99_Pa" in co and "stress_p99_Pa" in ch
            so, sh = (co["stress_p99_Pa"], ch["stress_p99_Pa"]) if robust else (co["stress_Pa"], ch["stress_Pa"])
            text = f"{kind}: Ogden {so * 1e-6:.3g} MPa vs MHGO {sh * 1e-6:.3g} MPa"
            if robust:
                text += f" (1 % area peak; element maximum {co['stress_Pa'] * 1e-6:.3g} vs {ch['stress_Pa'] * 1e-6:.3g})"
            parts.append(text)
            if kind == "FSI":
                verdict = so > sh
    if any(r.spec.dimension == 2 for r in runs.values()):
        # the closed 2D leaflet lies on its support (docs/fsi-2d.md): its stress is not the
        # commissures' closed stress the finding is about
        verdict = None
        parts.insert(0, "2D: not comparable (the closed strip lies on the annulus support)")
    findings.append(Finding("stress", verdict, "; ".join(parts) or "no closed state reached"))

    # no particle leaks through a leaflet
    counts = {m: runs[f"FSI-{m}"].leaks for m in MATERIALS if runs.get(f"FSI-{m}") and runs[f"FSI-{m}"].leaks is not None}
    findings.append(Finding("leaks", all(v == 0 for v in counts.values()) if len(counts) == len(MATERIALS) else None,
                            ", ".join(f"{m}: {v}" for m, v in counts.items()) or "no FSI leak counter"))

    # second cycle within 10 % of the first
    parts, verdicts = [], []
    for label, run in runs.items():
        if run.cycle_difference:
            worst = max(run.cycle_difference, key=run.cycle_difference.get)
            verdicts.append(run.cycle_difference[worst] < CYCLE_TOLERANCE)
            parts.append(f"{label}: largest {worst} {run.cycle_difference[worst]:.1%}")
    findings.append(Finding("cycles", all(verdicts) if verdicts else None, "; ".join(parts) or "one cycle only"))
    return findings


# ---------------------------------------------------------------------------------------------
# Figures


def plot_fig5(runs: dict, path: Path) -> None:
    """Like the reference's Fig. 5: free-edge radial position (and, in 2D, the orifice width)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    two_d = any(r.kinematics.get("width") is not None for r in runs.values())
    fig, axes = plt.subplots(1, 2 if two_d else 1, figsize=(11 if two_d else 6, 4), squeeze=False)
    styles = {"FE": "--", "FSI": "-"}
    colors = {"Ogden": "tab:red", "MHGO": "tab:blue"}
    for label, r in runs.items():
        if not r.kinematics:
            continue
        t = r.kinematics["t"] * 1e3
        axes[0, 0].plot(t, r.kinematics["radial"] * 1e3, styles[r.spec.kind], color=colors[r.spec.material], lw=1, label=label)
        if two_d and r.kinematics.get("width") is not None:
            axes[0, 1].plot(t, r.kinematics["width"] * 1e3, styles[r.spec.kind], color=colors[r.spec.material], lw=1, label=label)
    axes[0, 0].set_ylabel("free-edge midpoint radial position (mm)")
    if two_d:
        axes[0, 1].set_ylabel("orifice width between the free ends (mm)")
    for ax in axes[0]:
        ax.set_xlabel("time in the cycle (ms)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_fig6_2d(runs: dict, path: Path, cycle: int, times_s=(0.0, 0.01, 0.02, 0.04, 0.06, 0.1, 0.24, 0.25, 0.26, 0.27, 0.3)) -> None:
    """Like the reference's Fig. 6: the upper leaflet's profile at chosen times, one panel per run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .solid_results import SolidFields
    shown = [r for r in runs.values() if (r.run_dir / "solid_fields.h5").exists()]
    if not shown:
        return
    fig, axes = plt.subplots(1, len(shown), figsize=(3.2 * len(shown), 3.6), squeeze=False)
    for ax, r in zip(axes[0], shown):
        fields = SolidFields(r.run_dir)
        ref = fields.reference_nodes
        upper = np.flatnonzero((ref[:, 1] > 0) & (np.abs(ref[:, 2]) < 1e-12))
        upper = upper[np.argsort(-ref[upper, 1])]
        t0 = (cycle - 1) * PERIOD_S
        for tp in times_s:
            if fields.times.size == 0 or t0 + tp > fields.times[-1] + 1e-9:
                continue
            k = fields.nearest(t0 + tp)
            x = fields.snapshot(k)["position"][upper]
            color = "tab:red" if tp < 0.2 else "tab:blue"
            ax.plot(x[:, 0] * 1e3, x[:, 1] * 1e3, color=color, lw=1)
            ax.annotate(f"{tp * 1e3:.0f}", (x[-1, 0] * 1e3, x[-1, 1] * 1e3), fontsize=6, color=color)
        ax.set_title(r.spec.label, fontsize=9)
        ax.set_xlabel("x (mm, downstream)")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("y (mm)")
    fig.suptitle("upper leaflet profiles (red opening, blue closing; labels: ms in the cycle)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def particle_files(run_dir: Path) -> list[Path]:
    """The fluid's particle snapshot files of a run: its own, or, for a run joined from restart
    segments (which does not copy them: too large), its segments' (join_segments.SEGMENTS_FILE)."""
    from .join_segments import segments_of
    return [d / "fluid_particles.h5" for d in [run_dir] + segments_of(run_dir) if (d / "fluid_particles.h5").exists()]


def particle_spacing(x: np.ndarray, samples: int = 400, seed: int = 0) -> float:
    """The median nearest-neighbour distance of a random sample of the particles (the lattice
    spacing of a fluid that has moved off its lattice)."""
    if len(x) < 2:
        return 1e-3
    rng = np.random.default_rng(seed)
    picked = rng.choice(len(x), size=min(samples, len(x)), replace=False)
    nearest = []
    for i in picked:
        d2 = np.sum((x - x[i]) ** 2, axis=1)
        d2[i] = np.inf
        nearest.append(np.sqrt(d2.min()))
    return float(np.median(nearest))


def velocity_slice(run_dir: Path, time_s: float, dimension: int):
    """(positions [n, 2] in the slice plane, speeds) of the fluid snapshot nearest time_s: in 2D
    all fluid particles; in 3D those within half a spacing of the plane y = 0."""
    import h5py
    nearest = None   # (distance in time, file, snapshot name)
    for path in particle_files(run_dir):
        with h5py.File(path, "r") as f:
            for n in f:
                if n.startswith("snapshot_"):
                    d = abs(float(f[n].attrs["time"]) - time_s)
                    if nearest is None or d < nearest[0]:
                        nearest = (d, path, n)
    if nearest is None:
        raise ValueError(f"{run_dir}: no fluid particle snapshot (fluid_particles.h5) in the run or its segments")
    with h5py.File(nearest[1], "r") as f:
        g = f[nearest[2]]
        x, v, kind = g["position"][()], g["velocity"][()], g["kind"][()].reshape(-1)
        when = float(g.attrs["time"])
    fluid = kind == 0
    x, v = x[fluid], v[fluid]
    if dimension == 3:
        # one layer of particles at the plane y = 0 (the sector's mirror plane, which its fluid
        # touches from one side only; a full valve's fluid from both)
        spacing = particle_spacing(x)
        keep = np.abs(x[:, 1]) < (1.0 if x[:, 1].min() > -0.5 * spacing else 0.5) * spacing
        return np.stack([x[keep, 2], x[keep, 0]], axis=1), np.linalg.norm(v[keep], axis=1), when
    return x[:, :2], np.linalg.norm(v[:, :2], axis=1), when


def plot_fig12(runs: dict, path: Path, cycle: int) -> str:
    """Like the reference's Fig. 12: the speed in the axial plane at the peak flow of each FSI
    run (the fluid's HDF5 snapshots). Returns a note on the times shown."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shown = [r for r in runs.values() if r.spec.kind == "FSI" and particle_files(r.run_dir)]
    if not shown:
        return "no fluid snapshot"
    fig, axes = plt.subplots(len(shown), 1, figsize=(10, 3.0 * len(shown)), squeeze=False)
    notes = []
    for ax, r in zip(axes[:, 0], shown):
        h = r.hemodynamics
        # the reference's Fig. 12 instant is its peak velocity (80 ms); ours where measured
        peak_t = h.peak_velocity_time_s if h and h.peak_velocity_time_s is not None else 0.08
        try:
            xy, speed, when = velocity_slice(r.run_dir, (cycle - 1) * PERIOD_S + peak_t, r.spec.dimension)
        except (ValueError, KeyError) as error:
            notes.append(f"{r.spec.label}: {error}")
            continue
        near = (xy[:, 0] > -0.04) & (xy[:, 0] < 0.09)
        art = ax.scatter(xy[near, 0] * 1e3, xy[near, 1] * 1e3, c=speed[near], s=4, cmap="jet", vmin=0)
        fig.colorbar(art, ax=ax, label="speed (m/s)")
        ax.set_aspect("equal")
        ax.set_title(f"{r.spec.label}: t = {when * 1e3:.0f} ms (cycle time {(when - (cycle - 1) * PERIOD_S) * 1e3:.0f} ms)", fontsize=9)
        ax.set_ylabel("y (mm)")
        notes.append(f"{r.spec.label} at {when * 1e3:.0f} ms")
    axes[-1, 0].set_xlabel("x (mm, downstream)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return "; ".join(notes)


# ---------------------------------------------------------------------------------------------
# Report


def _fmt(value, digits=1, scale=1.0) -> str:
    return "–" if value is None or (isinstance(value, float) and not np.isfinite(value)) else f"{value * scale:.{digits}f}"


def write_report(runs: dict, out: Path, command: str, cycle: int, dimension: int, resolution: str) -> str:
    figures = out.parent / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    stem = f"comparison-{dimension}d-{resolution}"
    lines = [f"# FE-only against FSI, Ogden against MHGO ({dimension}D, {resolution})", "",
             f"Generated by `{command}`; cycle {cycle} analysed. Reference: W. Mao, K. Li, W. Sun, "
             "Cardiovasc. Eng. Technol. 7(4), 2016 (Tables 2, 3; Figs. 5, 6, 11, 12). Definitions: "
             "docs/valve-scene.md (\"Analysis\"), docs/hemodynamics.md; the 2D model and what these numbers "
             "mean: docs/fsi-2d.md." +
             (" 2D: the reference's 3D extensive quantities (volumes, flows, forces, EOA) do not compare "
              "with ours per metre of depth; its times, pressures, velocities and ratios do." if dimension == 2 else ""), "",
             "## Runs and wall times", "",
             "| run | simulated (s) | wall time (s) | CPU time (s) | exit code |", "|---|---|---|---|---|"]
    for label, r in runs.items():
        simulated = f"{r.simulated_s:.4g}" + (f" (partial: cycle {cycle} to {(r.simulated_s - (cycle - 1) * PERIOD_S) * 1e3:.0f} ms)"
                                              if r.partial else "")
        lines.append(f"| {r.spec.name} | {simulated} | {_fmt(r.wall_time_s, 0)} | {_fmt(_cpu_time(r.run_dir), 0)} | "
                     f"{'–' if r.exit_code is None else r.exit_code} |")
    partial = [label for label, r in runs.items() if r.partial]
    if partial:
        lines += ["", f"Partial: {', '.join(partial)} end inside cycle {cycle}; their metrics cover what they ran "
                  "(no closing events before the closing, no closed peaks before 270 ms, the hemodynamics to the run's "
                  "end). A dash is a metric the runs do not reach."]
    lines += ["", "## Kinematics (reference Table 3)", "",
              kinematics_table({label: r.events for label, r in runs.items()})]
    errors = [f"{label}: {r.events_error}" for label, r in runs.items() if r.events_error]
    if errors:
        lines += ["No valve events: " + "; ".join(errors), ""]
    lines += ["## Hemodynamics (reference Table 2)", ""]
    hemo = {label: r.hemodynamics for label, r in runs.items() if r.hemodynamics is not None}
    if hemo:
        lines += [hd.hemodynamics_table(hemo)]
    problems = [f"{label}: {r.hemodynamics_error}" for label, r in runs.items() if r.hemodynamics_error]
    if problems:
        lines += ["Not measured: " + "; ".join(problems), ""]
    lines += ["## Peak max-principal stress and log strain (reference Sec. 3.2)", "",
              "| run | opening stress (MPa): max / 1 % area | opening strain: max / 1 % area | "
              "closed stress (MPa): max / 1 % area | closed strain: max / 1 % area |", "|---|---|---|---|---|"]

    def pair(entry: dict, key: str, robust_key: str, scale: float = 1.0) -> str:
        return f"{_fmt(entry.get(key), 3, scale)} / {_fmt(entry.get(robust_key), 3, scale)}"
    for label, r in runs.items():
        o, c = r.peaks.get("opening", {}), r.peaks.get("closed", {})
        lines.append(f"| {label} | {pair(o, 'stress_Pa', 'stress_p99_Pa', 1e-6)} | {pair(o, 'strain', 'strain_p99')} | "
                     f"{pair(c, 'stress_Pa', 'stress_p99_Pa', 1e-6)} | {pair(c, 'strain', 'strain_p99')} |")
    lines += ["| reference | – | FE-MHGO 0.22, FSI-MHGO 0.112 | FSI-Ogden 1.42, FSI-MHGO 1.13 (commissure) | MHGO 0.185, FSI-Ogden 0.144 |", "",
              f"Opening: the first {OPENING_WINDOW_S * 1e3:.0f} ms of the cycle; closed: from {CLOSED_FROM_S * 1e3:.0f} ms "
              "to the cycle's end. Max: the largest element value (the solid's per-snapshot peaks); 1 % area: the "
              "largest over the field snapshots of the value exceeded on 1 % of the leaflet's area, which one "
              "element at a mesh corner cannot set (the \"stress\" finding is judged on it).", ""]
    lines += ["## Interface balance (issue 7, item 5)", "",
              f"Over cycle {cycle} (or the part a partial run covers): the work the fluid gave at the velocity its points "
              "moved with (Σ power_fluid·Δt) and the same through the mapping on the solid's side (Σ power_solid·Δt); "
              "the work the loads did on the solid, Σ F·(x_end − x_start) (the coupler's `load_work_solid`), and the "
              "external work the solid's own integrator booked over the same span; their difference, F·(Δx − vΔt), "
              "is what the explicit coupling's lag created at the interface (the fluid's points move with the "
              "previous window's velocity and are put back on the solid at the next window): the scheme's energy "
              "error, reported, not judged. Conserved: the mapping's power and total force within "
              f"{BALANCE_TOLERANCE:g} of Σ|power_fluid|·Δt (resp. the largest force), the integrator's work within "
              f"{INTEGRATOR_TOLERANCE:g} of Σ|load work| (the solid's series is sampled, not window-aligned)." +
              (" 2D: per metre of depth (the solid's work divided by its strip depth)." if dimension == 2 else ""), "",
              "| run | windows | fluid gave (J) | mapping, relative difference | total force, relative difference | "
              "loads' work on the solid (J) | solid integrator (J) | relative difference | lag created (J) | lag / Σ|load work| | conserved |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in runs.items():
        b = r.balance
        if r.spec.kind != "FSI":
            continue
        if "error" in b or not b:
            lines.append(f"| {label} | {b.get('error', 'not measured')} | | | | | | | | | |")
            continue
        ok = b["work_relative_difference"] < BALANCE_TOLERANCE and b["force_relative_difference"] < BALANCE_TOLERANCE
        if "integrator_relative_difference" in b:
            ok = ok and b["integrator_relative_difference"] < INTEGRATOR_TOLERANCE
        lag_share = b["lag_work"] / b["load_work_scale"] if "lag_work" in b else float("nan")
        lines.append(f"| {label} | {b['windows']} | {b['work_fluid']:.4g} | {b['work_relative_difference']:.1e} | "
                     f"{b['force_relative_difference']:.1e} | {b.get('load_work', float('nan')):.4g} | "
                     f"{b.get('work_solid_integrator', float('nan')):.4g} | {b.get('integrator_relative_difference', float('nan')):.1e} | "
                     f"{b.get('lag_work', float('nan')):.4g} | {lag_share:.2f} | {'yes' if ok else 'NO'} |")
    gaps = [f"{label} {r.balance['window_gap_s'] * 1e3:.3g} ms" for label, r in runs.items()
            if r.spec.kind == "FSI" and r.balance.get("window_gap_s", 0.0) > 1e-9]
    if gaps:
        lines += ["", "Spans without coupling windows (a segment stopped before its series were flushed, continued from a "
                  "later restart point), left out of every sum above, the integrator's included: " + ", ".join(gaps) + "."]
    lines += ["", "## Findings of the reference (issue 7, item 6)", "", "| finding | reference | holds here | evidence |", "|---|---|---|---|"]
    for f in check_findings(runs):
        verdict = {True: "yes", False: "**no**", None: "not measured"}[f.holds]
        lines.append(f"| {f.key} | {REFERENCE_FINDINGS[f.key]} | {verdict} | {f.evidence} |")
    lines += [""]
    table = cycles_table(runs, cycle)
    if table:
        lines += [f"## Cycle {cycle - 1} against cycle {cycle} (the \"cycles\" finding)", "",
                  f"Each metric measured the same way in both cycles; the difference is |c{cycle} − c{cycle - 1}| / |c{cycle}|, "
                  f"in bold where it reaches {CYCLE_TOLERANCE:.0%}.", "", table]
    plot_fig5(runs, figures / f"{stem}-fig5.png")
    lines += ["## Figures", "", "Free-edge motion (like Fig. 5; dashed FE-only, solid FSI):", "",
              f"![fig5](figures/{stem}-fig5.png)", ""]
    if dimension == 2:
        plot_fig6_2d(runs, figures / f"{stem}-fig6.png", cycle)
        if (figures / f"{stem}-fig6.png").exists():
            lines += ["Leaflet profiles (like Fig. 6):", "", f"![fig6](figures/{stem}-fig6.png)", ""]
    for label, r in runs.items():
        if r.hemodynamics is not None:
            png = figures / f"{stem}-fig11-{r.spec.material.lower()}.png"
            hd.plot_cycle(hd.read_run(r.run_dir), r.hemodynamics, png)
            lines += [f"{label} hemodynamics (like Fig. 11):", "", f"![fig11 {label}](figures/{png.name})", ""]
    note = plot_fig12(runs, figures / f"{stem}-fig12.png", cycle)
    if (figures / f"{stem}-fig12.png").exists():
        lines += [f"Speed in the axial plane at the peak velocity (like Fig. 12; {note}):", "",
                  f"![fig12](figures/{stem}-fig12.png)", ""]
    text = "\n".join(lines) + "\n"
    out.write_text(text)
    return text


def compare(dimension: int, resolution: str, variant: str, runs_dir: Path, build_dir: Path, out: Path,
            cycle: int, end_time: float | None, reuse: bool, command: str, cases_dir: Path = CASES_DIR,
            existing: dict | None = None, allow_partial: bool = False) -> dict:
    """existing: label ('FSI-MHGO', ...) -> a run folder to analyse as it is, never run here (a
    long coupled run joined from its segments by join_segments); allow_partial: analyse runs
    that end inside the cycle up to their end (analyse_run)."""
    existing = existing or {}
    unknown = sorted(set(existing) - {f"{k}-{m}" for k in KINDS for m in MATERIALS})
    if unknown:
        raise ValueError(f"--run {unknown[0]}=...: allowed labels are " + ", ".join(f"{k}-{m}" for k in KINDS for m in MATERIALS))
    runs = {}
    for kind in KINDS:
        for material in MATERIALS:
            spec = RunSpec(kind, material, dimension, resolution, variant)
            if spec.label in existing:
                run_dir = Path(existing[spec.label]).resolve()
                if not (run_dir / "solid_series.h5").exists():
                    raise FileNotFoundError(f"--run {spec.label}={run_dir}: no solid_series.h5 there")
                cost = read_cost(run_dir)
                wall, code = (cost.wall_time_s, cost.exit_code) if cost else (None, None)
            elif reuse and (runs_dir / spec.name / "wall_time.json").exists():
                run_dir = runs_dir / spec.name
                cost = read_cost(run_dir)
                wall, code = cost.wall_time_s, cost.exit_code
            else:
                run_dir = runs_dir / spec.name
                case = prepare_case(spec, runs_dir / "cases", end_time, cases_dir)
                wall, code = run_one(spec, case, run_dir, build_dir)
            result = RunResult(spec, run_dir, wall, code, _series_end(run_dir))
            runs[spec.label] = analyse_run(result, cycle, allow_partial)
            print(f"{spec.name}: exit {code}, {result.simulated_s:.4g} s simulated in {_fmt(wall, 0)} s"
                  + (" (partial cycle)" if result.partial else ""), flush=True)
    write_report(runs, out, command, cycle, dimension, resolution)
    return runs


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="FE-only vs FSI, Ogden vs MHGO: run the four cases and write the comparison report.")
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=2)
    parser.add_argument("--resolution", default="coarse",
                        help="case resolution (default coarse; the 2D xcoarse valve does not seal in diastole)")
    parser.add_argument("--variant", choices=("sector", "full"), default="sector", help="3D only")
    parser.add_argument("--cycle", type=int, default=2, help="cycle analysed (the runs last as the case says, 2 cycles)")
    parser.add_argument("--end-time", type=float, help="shorten every run to this (s): a plumbing check")
    parser.add_argument("--runs-dir", type=Path, default=REPO / "runs" / "comparison")
    parser.add_argument("--build-dir", type=Path, default=REPO / "build")
    parser.add_argument("--reuse", action="store_true", help="keep runs that finished before (RUN/wall_time.json)")
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "comparison.md")
    parser.add_argument("--run", action="append", default=[], metavar="LABEL=DIR",
                        help="analyse this run folder for LABEL (FE-Ogden, FE-MHGO, FSI-Ogden, FSI-MHGO) instead of "
                             "running its case, e.g. a long run joined by join_segments; repeatable")
    parser.add_argument("--partial", action="store_true",
                        help="analyse runs that end inside the cycle up to their end (marked in the report)")
    args = parser.parse_args(argv)
    existing = {}
    for item in args.run:
        label, sep, folder = item.partition("=")
        if not sep or not folder:
            parser.error(f"--run {item}: expected LABEL=DIR")
        existing[label] = Path(folder)
    command = "python -m valve_scene.comparison " + " ".join(a for a in (argv if argv is not None else sys.argv[1:]))
    compare(args.dimension, args.resolution, args.variant, args.runs_dir.resolve(), args.build_dir.resolve(),
            args.out.resolve(), args.cycle, args.end_time, args.reuse, command, existing=existing,
            allow_partial=args.partial)
    print(args.out)


if __name__ == "__main__":
    main()
