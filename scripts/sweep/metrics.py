"""Headline metrics of one run over the span it covers, and the reference's values.

A run may cover only part of the cycle (the opening, 0-120 ms): each metric is computed only
when the span holds it, and says which span it came from.
- peak_velocity (m/s): maximum of the velocity plane 15 mm downstream (2 ms moving average,
  SPH probes are noisy sample to sample);
- peak_flow (m^3/s; m^2/s in 2D): maximum of the mean flow over the sections (2 ms average);
- pspd_mmHg: peak pressure drop between the taps (2 ms average), over the span;
- rvot (s): rapid valve opening time, from the free-edge curve: 10 % to 90 % of the way from
  the closed position r(0) to the open plateau (the median of the samples above half the
  excursion); needs the curve to pass 90 %;
- opening_start (s): the 10 % crossing;
- and, when the span covers a whole first cycle: eoa, rvct, diastolic_force
  (valve_scene.hemodynamics.analyse_cycle and analysis.valve_events);
- peak_strain, peak_stress (3D, from the solid's field snapshots): the robust peak of the max
  principal log strain and stress (the value exceeded on 1 % of the leaflet's reference area,
  the largest over the span's snapshots: valve_scene.analysis.robust_peak), so that one corner
  element cannot decide a comparison between meshes.
In 2D, extensive quantities are per metre of depth and the radial position is |y|.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

SMOOTHING_S = 2.0e-3   # as valve_scene.hemodynamics.analyse_cycle smooths the flow
# The reference study (W. Mao, K. Li, W. Sun, Cardiovasc. Eng. Technol. 7(4), 2016; Tables 2
# and 3; docs/hemodynamics.md): values comparable in kind with a 2D run are the velocity, the
# pressure drop and the kinematic times; flows, areas and forces are 3D quantities.
REFERENCE = {
    "MHGO": {"peak_velocity": 1.36, "pspd_mmHg": 11.7, "rvot": 0.040, "rvct": 0.035},
    "Ogden": {"peak_velocity": 1.40, "pspd_mmHg": 14.5, "rvot": 0.040, "rvct": 0.035},
}
REFERENCE_3D_ONLY = {
    "MHGO": {"peak_flow": 14.7e-3 / 60.0, "eoa": 1.50e-4, "diastolic_force": -6.1},
    "Ogden": {"peak_flow": 13.1e-3 / 60.0, "eoa": 1.22e-4, "diastolic_force": -6.9},
}
UNITS = {"peak_strain": "1", "peak_stress": "Pa", "peak_velocity": "m/s", "peak_flow": "m^2/s (2D) or m^3/s", "pspd_mmHg": "mmHg", "rvot": "s",
         "opening_start": "s", "eoa": "cm (2D) or cm^2", "rvct": "s", "diastolic_force": "N/m (2D) or N"}
HEADLINE = ("peak_velocity", "peak_flow", "pspd_mmHg", "rvot", "eoa", "rvct", "diastolic_force", "peak_strain",
            "peak_stress")


def _smooth(t, y):
    from valve_scene.hemodynamics import moving_average
    return moving_average(np.asarray(t, float), np.asarray(y, float), SMOOTHING_S)


def opening_events(t: np.ndarray, r: np.ndarray, low: float = 0.1, high: float = 0.9) -> dict:
    """{'opening_start', 'opening_end', 'rvot'} (s) of a free-edge curve that starts closed;
    an entry is missing when the curve does not reach its level."""
    t, r = np.asarray(t, float), np.asarray(r, float)
    out = {}
    if len(t) < 3:
        return out
    r0, r_max = r[0], r.max()
    if not r_max > r0:
        return out
    r_open = float(np.median(r[r > r0 + 0.5 * (r_max - r0)]))

    def first_up(level, after=-np.inf):
        idx = np.flatnonzero((r[:-1] < level) & (r[1:] >= level) & (t[1:] > after))
        if len(idx) == 0:
            return None
        i = idx[0]
        return float(t[i] + (level - r[i]) / (r[i + 1] - r[i]) * (t[i + 1] - t[i]))

    start = first_up(r0 + low * (r_open - r0))
    if start is None:
        return out
    out["opening_start"] = start
    end = first_up(r0 + high * (r_open - r0), after=start)
    if end is not None:
        out["opening_end"] = end
        out["rvot"] = end - start
    return out


def run_metrics(run_dir: Path, dimension: int = 2, material: str = "MHGO") -> dict:
    """Headline metrics of the run in `run_dir` (a run_case.py output folder) over the span its
    series cover; {'span_s': [t0, t1], name: value, ...}. Missing files give fewer metrics."""
    import h5py
    from valve_scene import hemodynamics as hd
    from valve_scene.solid_results import read_series

    run_dir = Path(run_dir)
    out: dict = {}
    probes = run_dir / "fluid_probes.h5"
    series = None
    if probes.exists():
        try:
            series = hd.read_run(run_dir)
        except (OSError, KeyError, ValueError):
            series = None
    if series is not None and len(series.time) >= 3:
        t = series.time
        out["span_s"] = [float(t[0]), float(t[-1])]
        if series.max_velocity is not None:
            v = _smooth(t, series.max_velocity)
            out["peak_velocity"] = float(v.max())
            out["peak_velocity_time"] = float(t[int(np.argmax(v))])
        q = _smooth(t, series.mean_flow_rate)
        out["peak_flow"] = float(q.max())
        out["peak_flow_time"] = float(t[int(np.argmax(q))])
        dp = _smooth(t, series.pressure_drop) / hd.PA_PER_MMHG
        out["pspd_mmHg"] = float(dp.max())
    try:
        with h5py.File(probes, "r") as f:
            if "interface/leaks" in f:
                out["leaks"] = int(np.max(f["interface/leaks"][...], initial=0))
    except OSError:
        pass
    try:
        with h5py.File(run_dir / "coupling_series.h5", "r") as f:
            force = f["force_fluid"][...]
            if len(force):
                out["max_interface_force"] = float(np.abs(force).max())
    except (OSError, KeyError):
        pass
    events = None
    try:
        solid = read_series(run_dir)
        x = solid.midpoint_positions
        radial = (np.abs(x[..., 1]).mean(axis=1) if dimension == 2 else np.hypot(x[..., 0], x[..., 1]).mean(axis=1))
        out.update(opening_events(solid.time, radial))
        out["solid_span_s"] = [float(solid.time[0]), float(solid.time[-1])]
        if len(solid.time) > 1:
            speed = np.linalg.norm(np.diff(x, axis=0), axis=-1) / np.diff(solid.time)[:, None]
            out["max_edge_speed"] = float(np.max(speed))
            # where and when: the free-edge midpoint at the end of the fastest sample interval
            sample, midpoint = np.unravel_index(int(np.argmax(speed)), speed.shape)
            out["max_edge_speed_time"] = float(solid.time[sample + 1])
            out["max_edge_speed_where_mm"] = [float(v) * 1e3 for v in x[sample + 1, midpoint]]
        energy = solid.energy_balance_error
        if np.any(np.isfinite(energy)):
            out["max_energy_error"] = float(np.nanmax(np.abs(energy)))
        from valve_scene.analysis import valve_events
        from valve_scene.waveform import PERIOD_S
        if solid.time[-1] >= PERIOD_S * 0.95:
            first = solid.time <= PERIOD_S + 1e-12
            try:
                events = valve_events(solid.time[first], radial[first])
                out["rvct"] = events.rvct
            except ValueError:
                events = None
    except (OSError, KeyError, FileNotFoundError):
        pass
    if dimension == 3:
        out.update(field_peaks(run_dir))
    if series is not None and out.get("span_s", [0, 0])[1] >= 0.95 * 0.8:
        try:
            cycle = hd.analyse_cycle(series, 1, closure_time_s=events.closing_end if events else None)
            out["eoa"] = cycle.eoa
            if cycle.diastolic_force is not None:
                out["diastolic_force"] = cycle.diastolic_force
        except ValueError:
            pass
    return out


def field_peaks(run_dir: Path) -> dict:
    """{'peak_strain', 'peak_stress'}: robust peaks over the run's field snapshots (none without
    snapshots)."""
    import h5py
    from valve_scene.analysis import robust_peak, triangle_areas
    path = Path(run_dir) / "solid_fields.h5"
    names = ("max_principal_log_strain", "max_principal_stress")
    try:
        with h5py.File(path, "r") as f:
            nodes = f["mesh/nodes"][()]
            if "triangles" in f["mesh"]:
                areas = triangle_areas(nodes, f["mesh/triangles"][()])
            else:
                areas = hexahedron_mid_areas(nodes, f["mesh/hexahedra"][()])
            snapshots = [f["snapshots"][n] for n in sorted(f["snapshots"])]
            times = [float(g.attrs["time"]) for g in snapshots]
            history = {name: [g[name][()] for g in snapshots if name in g and len(g[name]) == len(areas)]
                       for name in names}
    except (OSError, KeyError):
        return {}
    out = {}
    for metric, name in (("peak_strain", names[0]), ("peak_stress", names[1])):
        if history.get(name) and len(history[name]) == len(times):
            value, k = robust_peak(history[name], areas)
            out[metric], out[metric + "_time"] = value, times[k]
    return out


def hexahedron_mid_areas(nodes: np.ndarray, hexahedra: np.ndarray) -> np.ndarray:
    """A one-brick-thick leaflet's area per brick: the mean of its two faces 0-1-2-3 and 4-5-6-7
    (the leaflet's two surfaces; a quadrilateral's area is half its diagonals' cross product)."""
    x = np.asarray(nodes, float)[np.asarray(hexahedra)]
    def quad(a, b, c, d):
        return 0.5 * np.linalg.norm(np.cross(x[:, c] - x[:, a], x[:, d] - x[:, b]), axis=1)
    return 0.5 * (quad(0, 1, 2, 3) + quad(4, 5, 6, 7))


def reference_errors(metrics: dict, material: str) -> dict:
    """Relative error of each metric against the reference's value of the same kind."""
    ref = REFERENCE.get(material, {})
    return {name: (metrics[name] - value) / abs(value) for name, value in ref.items()
            if metrics.get(name) is not None}


def errors_against(metrics: dict, finest: dict, names=HEADLINE) -> dict:
    """Relative error of each headline metric against the finest run's (both must have it)."""
    errors = {}
    for name in names:
        a, b = metrics.get(name), finest.get(name)
        if a is None or b is None or b == 0:
            continue
        errors[name] = (a - b) / abs(b)
    return errors
