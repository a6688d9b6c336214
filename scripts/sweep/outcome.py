"""How a run ended, from its exit code, the programs' logs and its series.

Kinds (docs/stability-map.md), first match wins:
- `completed`: exit 0 and the series reach the end time, with no leak and bounded energy;
- `nan`: a program or the transport reported a non-finite value;
- `time-step collapse`: the fluid's time-step guard stopped the run (but when its message shows
  a leaflet node faster than `speed_bound`, the solid's motion ran away first: `coupling
  divergence`, detected by the guard);
- `solid failure`: the solid could not evaluate its material (inverted element, overflow);
- `coupling divergence`: implicit windows left unconverged, or a step collapse behind a
  runaway leaflet (below);
- `leaks`: particles crossed a leaflet (fluid_probes.h5 interface/leaks > 0); the fluid stops
  above fluid.max_leak_fraction, below it a completed run can end in this class;
- `energy growth`: the coupler stopped a runaway interface (coupling.max_interface_speed, or
  its slow-runaway watch, coupling.runaway_oscillation_speed: both say "running away"), or
  the interface force beyond any physical bound (|F| > `force_bound`; an
  explicit coupling instability and a fluid instability next to the leaflet look alike here:
  the stability map's "window only" group tells them apart), or a leaflet's free edge faster
  than `speed_bound` (10 m/s, 6x the Bernoulli jet speed of the waveform's peak gradient,
  1.57 m/s; sound 2D runs stay below 3 m/s over 0-30 ms, measured), or the solid's own
  energy-growth stop (solid.max_energy_balance_error; the post-mortem does not re-judge the
  balance error);
- `timeout`: stopped at the sweep's wall-time limit;
- `other`: any other failure (the first error line is kept).
Detection by the programs is recorded apart from the class: `detected_by` names the program
whose message stopped the run, or is empty when the class comes only from this post-mortem.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FORCE_BOUND_N_PER_M = 500.0   # 2D: ~10x the largest transvalvular load (97 mmHg over 23 mm = 298 N/m)
SPEED_BOUND_M_PER_S = 10.0

PATTERNS = [  # (kind, regex on a log line), checked on error lines first
    ("nan", re.compile(r"\bnan\b|not finite|non-finite|infinit", re.IGNORECASE)),
    ("time-step collapse", re.compile(r"time step collapsed", re.IGNORECASE)),
    # the solid's material errors (MaterialStateError: inverted element, exponent overflow, a
    # non-positive eigenvalue); not the word 'material', which run folders' names carry
    ("solid failure", re.compile(r"inverted|overflow|eigenvalue", re.IGNORECASE)),
    ("coupling divergence", re.compile(r"diverg|not converged", re.IGNORECASE)),
    # the coupler's runaway checks (coupling.max_interface_speed, runaway_oscillation_speed), and the
    # solid's own energy-growth stop (solid.max_energy_balance_error)
    ("energy growth", re.compile(r"interface is running away|energy growth at t =", re.IGNORECASE)),
    # the fluid's leak stop (fluid.max_leak_fraction)
    ("leaks", re.compile(r"fluid leaks through the leaflets", re.IGNORECASE)),
]
LEAFLET_SPEED = re.compile(r"leaflet node speed ([0-9.eE+-]+) m/s")
# "[error]" (spdlog's default pattern: fluid_sph, solid_fe) or "12:00:00.000 error" (the coupler's)
# "[solid] solid: ..." / "[fluid] fluid_sph: ...": a program's own stop message, as the launcher prefixes it
ERROR_LINE = re.compile(r"\[(error|critical)\]|^[0-9:.]+ (error|critical) |run_case: .*failed|error:"
                        r"|^\[\w+\] (solid|fluid_sph|coupler): ", re.IGNORECASE)


@dataclass
class Outcome:
    kind: str
    detail: str          # the message (first error line) or the measured quantity
    detected_by: str     # program whose message stopped the run ('' = not stopped by a program)
    reached_s: float | None
    unconverged_windows: int = 0


def shortened(line: str, keep: int = 400) -> str:
    """An error line for the table: its start (what failed) and its end (the remedy)."""
    line = line.strip()
    if len(line) <= keep:
        return line
    return line[: keep // 2] + " ... " + line[-(keep // 2 - 5):]


def _lines(path: Path) -> list[str]:
    try:
        return path.read_text(errors="replace").splitlines()
    except OSError:
        return []


def _reached(run_dir: Path) -> float | None:
    import h5py
    for name, key in (("coupling_series.h5", "time"), ("solid_series.h5", "time"), ("fluid_probes.h5", "time")):
        try:
            with h5py.File(run_dir / name, "r") as f:
                t = f[key][...]
                if len(t):
                    return float(np.max(t))
        except (OSError, KeyError):
            continue
    return None


# what each program left on disk, in the order a reader of a failed run looks for it: (label, file,
# where the times are: a dataset, or the "time" attribute of the file's snapshot groups)
WRITTEN = (("interface series", "coupling_series.h5", "time"),
           ("solid series", "solid_series.h5", "time"),
           ("solid snapshot", "solid_fields.h5", "snapshots"),
           ("fluid probes", "fluid_probes.h5", "time"),
           ("fluid snapshot", "fluid_particles.h5", ""))


def last_written(run_dir: Path) -> dict:
    """{label: the latest time (s) in that file, or None when the file is missing, unreadable or
    empty}: the last state a failed run left behind, per program and kind (WRITTEN)."""
    import h5py
    out = {}
    for label, name, where in WRITTEN:
        latest = None
        try:
            with h5py.File(Path(run_dir) / name, "r") as f:
                if where == "time":
                    t = f["time"][...]
                    latest = float(np.max(t)) if len(t) else None
                else:
                    groups = f[where] if where else f
                    times = [float(g.attrs["time"]) for g in groups.values()
                             if isinstance(g, h5py.Group) and "time" in g.attrs]
                    latest = max(times) if times else None
        except (OSError, KeyError):
            latest = None
        out[label] = latest
    return out


def last_written_text(written: dict | None) -> str:
    """'interface series 11.93 ms, ..., fluid probes missing' for the table."""
    if not written:
        return "–"
    return ", ".join(f"{label} " + ("missing" if t is None else f"{t * 1e3:.2f} ms") for label, t in written.items())


def _coupling_series(run_dir: Path):
    import h5py
    try:
        with h5py.File(run_dir / "coupling_series.h5", "r") as f:
            return {k: f[k][...] for k in ("time", "force_fluid", "iterations", "relative_residual") if k in f}
    except OSError:
        return {}


# what to change when the post-mortem finds a runaway no program stopped (the levers of the
# stability map, docs/stability-map.md)
RUNAWAY_REMEDY = ("not stopped by any program; lower time_step_factor (the coupling window and the fluid CFL), "
                  "make the leaflet heavier (a smaller added-mass number mu) or couple implicitly (IQN-ILS)")


def _force_where(series: dict, bound: float) -> str:
    """When the interface force first passed `bound` and when it peaked (the post-mortem's 'where')."""
    t, force = series.get("time"), series.get("force_fluid")
    if t is None or force is None or not len(t):
        return ""
    size = np.abs(np.nan_to_num(force, nan=np.inf)).max(axis=-1) if force.ndim > 1 else np.abs(force)
    over = np.flatnonzero(size > bound)
    if not len(over):
        return ""
    return (f"first above {bound:g} N/m in the window ending at t = {t[over[0]] * 1e3:.2f} ms, "
            f"largest at t = {t[int(np.argmax(size))] * 1e3:.2f} ms")


def _edge_where(edge_speed_at) -> str:
    if not edge_speed_at:
        return ""
    time_s, where_mm = edge_speed_at
    return (f"fastest free edge at t = {time_s * 1e3:.2f} ms, at ("
            + ", ".join(f"{v:.2f}" for v in where_mm) + ") mm")


def classify(run_dir: Path, exit_code: int, end_time: float, timed_out: bool = False,
             launcher_log: Path | None = None, leaks: int | None = None, max_edge_speed: float | None = None,
             force_bound: float = FORCE_BOUND_N_PER_M, speed_bound: float = SPEED_BOUND_M_PER_S,
             edge_speed_at: tuple | None = None) -> Outcome:
    """`edge_speed_at` = (time s, position mm) of `max_edge_speed`: with the force series it says
    where a runaway that no program stopped happened."""
    run_dir = Path(run_dir)
    reached = _reached(run_dir)
    logs = {role: _lines(run_dir / f"{role}.log") for role in ("fluid", "solid", "coupler")}
    if launcher_log is not None:
        logs["launcher"] = _lines(launcher_log)
    unconverged = sum(1 for line in logs["coupler"] if re.search(r"not converged after \d+ iterations", line))
    series = _coupling_series(run_dir)
    force_max = None
    if "force_fluid" in series and len(series["force_fluid"]):
        finite = np.isfinite(series["force_fluid"]).all()
        force_max = float(np.abs(series["force_fluid"]).max()) if finite else float("inf")

    if exit_code != 0:
        # the program that failed first is named by the launcher; its error lines say why
        first = next((m.group(1) for line in logs.get("launcher", [])
                      for m in [re.search(r"run_case: (\w+) failed with exit code", line)] if m), "")
        ordered = ([first] if first in logs else []) + [r for r in ("fluid", "solid", "coupler") if r != first]
        errors = [(role, line) for role in ordered for line in logs[role] if ERROR_LINE.search(line)]
        for kind, pattern in PATTERNS:
            for role, line in errors:
                if pattern.search(line):
                    speed = LEAFLET_SPEED.search(line)
                    if kind == "time-step collapse" and speed and float(speed.group(1)) > speed_bound:
                        # the step collapsed because the solid's motion ran away (an implicit
                        # iterate, an explicit blow-up): the coupling diverged, the guard caught it
                        return Outcome("coupling divergence", shortened(line), f"{role} (time-step guard)",
                                       reached, unconverged)
                    return Outcome(kind, shortened(line), role, reached, unconverged)
        if timed_out:
            return Outcome("timeout", f"stopped at the wall-time limit at t = {reached}", "", reached, unconverged)
        if force_max is not None and force_max > force_bound:
            return Outcome("energy growth", f"|interface force| reached {force_max:.3g} N/m "
                           f"({_force_where(series, force_bound)}; exit code {exit_code}, no program named it); "
                           f"{RUNAWAY_REMEDY}", "", reached, unconverged)
        detail = shortened(errors[0][1]) if errors else f"exit code {exit_code}, no error line in the logs"
        return Outcome("other", detail, errors[0][0] if errors else "", reached, unconverged)

    if reached is None or reached < end_time - 1e-9:
        return Outcome("other", f"exit 0 but the series end at t = {reached}", "", reached, unconverged)
    if unconverged:
        return Outcome("coupling divergence", f"completed with {unconverged} unconverged implicit windows (warnings only)",
                       "", reached, unconverged)
    if leaks:
        return Outcome("leaks", f"completed with {leaks} particle(s) through a leaflet (counted, not stopped)",
                       "", reached, unconverged)
    if force_max is not None and force_max > force_bound:
        where = "; ".join(w for w in (_force_where(series, force_bound), _edge_where(edge_speed_at)) if w)
        return Outcome("energy growth", f"completed, but the interface force reached {force_max:.3g} N/m "
                       f"({where}); {RUNAWAY_REMEDY}", "", reached, unconverged)
    if max_edge_speed is not None and max_edge_speed > speed_bound:
        return Outcome("energy growth", f"completed, but a free edge reached {max_edge_speed:.3g} m/s "
                       f"({_edge_where(edge_speed_at)}); {RUNAWAY_REMEDY}", "", reached, unconverged)
    return Outcome("completed", "", "", reached, unconverged)
