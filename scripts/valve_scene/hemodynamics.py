"""Hemodynamics of an FSI run (issue 7, item 3), from the fluid's probe series and the coupler's
interface series, per cardiac cycle, next to the reference's Table 2.

    cd scripts && /usr/bin/python3 -m valve_scene.hemodynamics RUN_DIR [--cycle 2] \
        [--model FSI-Ogden] [--markdown X.md] [--png X.png]

Inputs (docs/fluid_sph.md, docs/coupling.md): RUN_DIR/fluid_probes.h5 (/time; /pressure/<tap>
in Pa, gauge; /flow_rate/<section> in m^3/s, m^2/s in 2D; /max_velocity/<plane> in m/s;
/wall_force/fixed_walls, samples x D) and RUN_DIR/coupling_series.h5 (/time = window end;
/force_fluid, windows x 3, N or N/m in 2D: the fluid's force on the leaflets).

Definitions (reference Sec. 2.4 and 3.3, after ISO 5840; written in docs/hemodynamics.md):
- transvalvular pressure dP(t) = p(upstream tap) - p(downstream tap);
- flow rate Q(t) = mean over the flow sections;
- forward-flow period [t1, t2]: the interval around the cycle's peak flow where the flow,
  smoothed by a centred moving average of `smoothing_s`, is positive (zero crossings
  interpolated linearly);
- each tap is the mean over its cross-section: the centre probe <tap> and, where the case has
  them, the probes <tap>_section_<k> across the same section (the 2D and 3D cases put four);
- MSPD = mean of dP over [t1, t2]; PSPD = max over [t1, t2] of dP smoothed by the same centred
  moving average as Q (with its time): a single probe's dP has acoustic spikes of a particle
  squeezed or a pressure wave passing (230 mmHg in the 2D xcoarse cycle), not the jet's drop;
  the raw single-probe maximum is kept as pspd_probe_mmHg;
- peak velocity = max over the cycle of the jet-core speed, the flow through the core disk
  (radius JET_CORE_RADIUS_M around the axis; in 2D the segment |y| < it) on the section 15 mm
  downstream over its area, smoothed as Q; the fastest particle on the plane (a single
  particle, 27 m/s spikes) is kept as peak_particle_speed;
- Qrms = sqrt(mean of Q^2 over [t1, t2]); EOA = Qrms / (51.6 sqrt(MSPD)) with Q in mL/s and
  dP in mmHg gives cm^2 (51.6 = sqrt(2 * 1333.2 dyn/cm^2 / 1 g/cm^3): Bernoulli's jet speed
  in cm/s per sqrt(mmHg));
- regurgitant volume = closing + leakage = -integral of Q from t2 to the cycle's end; the
  closing part ends at valve closure: the first time after the backflow peak where the
  smoothed flow has come back 90 % of the way from the peak to the leakage level (the median
  of the smoothed flow over the last half of [t2, cycle end]), unless a closure time is given;
- leak rate (backflow positive): the slope of a line fitted, together with one damped
  oscillation (the blood column ringing between the plates), to the backflow volume after the
  closing (leak_rate below, where the choice is argued); a partial cycle's regurgitant volume
  is closing + the leak rate x (cycle end - closure), labelled extrapolated;
- leak rate through the valve (3D, where the run has fluid particle snapshots, the leaflets'
  snapshots and its particle spacing): the slope of a line fitted to the volume of the fluid
  particles on the ventricle's side of the closed valve (their count x dp^3; valve_side,
  valve_leak), from where the fit above starts to the series' end. Where it is measured it is
  the leak rate the leakage and a partial cycle's regurgitant volume use: in diastole the flow
  sections' velocity sum misses the particle shifting's displacements, which carry 1-5 mL/s
  through the sections next to the valve (docs/fsi-3d.md, session 18, helper 62);
- peak pull-out force: the maximum axial leaflet force over [t1, t2] (downstream positive);
- peak diastolic force: the minimum axial leaflet force after t2; water-hammer ratio = its
  magnitude over the hydrostatic force Pmax * A (Pmax the waveform's largest reverse
  gradient, A the annulus area pi R^2; 2D: per metre of depth, A = 2 R x 1 m).
In 2D every extensive quantity is per unit depth: Q in cm^2/s (mL/s per cm of depth), EOA in
cm (cm^2 per cm: an effective orifice width), volumes in cm^2 (mL per cm), forces in N/m.
"""
from __future__ import annotations

import argparse
import functools
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import waveform
from .tube_case import BLOOD_DENSITY

PA_PER_MMHG = 133.322387415
GORLIN_CONSTANT = 51.6        # cm/s per sqrt(mmHg), with Q in mL/s -> EOA in cm^2
ANNULUS_RADIUS_M = 11.5e-3    # size 23
JET_CORE_RADIUS_M = 0.5 * ANNULUS_RADIUS_M   # the jet core: half the annulus radius around the axis
JET_CORE_PLANE = "jet_core_15mm"              # flow plane of the jet core (radius JET_CORE_RADIUS_M)
SECTION_SUFFIX = "_section_"                  # <tap>_section_<k>: the tap's cross-section probes

# Reference Table 2 and Sec. 3.3 (W. Mao, K. Li, W. Sun, "Fluid-structure interaction study of
# transcatheter aortic valve dynamics using smoothed particle hydrodynamics", Cardiovasc. Eng.
# Technol. 7(4), 2016): times in s where the paper gives them.
REFERENCE_HEMODYNAMICS = {
    "FSI-Ogden": {"mspd_mmHg": 5.3, "pspd_mmHg": 14.5, "pspd_time_s": 0.025, "eoa": 1.22,
                  "regurgitant_volume": 3.2, "peak_flow_L_per_min": 13.1, "peak_velocity_m_per_s": 1.40,
                  "peak_velocity_time_s": 0.080, "pull_out_force": 0.26, "diastolic_force": -6.9,
                  "diastolic_force_time_s": 0.270, "hydrostatic_force": -5.4},
    "FSI-MHGO": {"mspd_mmHg": 5.0, "pspd_mmHg": 11.7, "pspd_time_s": 0.025, "eoa": 1.50,
                 "regurgitant_volume": 3.1, "peak_flow_L_per_min": 14.7, "peak_velocity_m_per_s": 1.36,
                 "peak_velocity_time_s": 0.080, "pull_out_force": 0.20, "diastolic_force": -6.1,
                 "diastolic_force_time_s": 0.270, "hydrostatic_force": -5.4},
}


@dataclass
class ProbeSeries:
    """What the analysis needs, in SI units, on the fluid's sample times (and the coupler's)."""
    time: np.ndarray                        # fluid probe sample times (s)
    upstream_pressure: np.ndarray           # Pa (gauge)
    downstream_pressure: np.ndarray         # Pa
    flow_rates: dict                        # section name -> m^3/s (m^2/s in 2D)
    max_velocity: np.ndarray | None         # m/s on the velocity plane, or None
    dimension: int = 3
    jet_core_flow: np.ndarray | None = None  # m^3/s (m^2/s in 2D) through the jet core, or None
    upstream_centre: np.ndarray | None = None    # the single centre probes (Pa), for the raw PSPD
    downstream_centre: np.ndarray | None = None
    force_time: np.ndarray | None = None    # coupling window ends (s)
    axial_force: np.ndarray | None = None   # N (N/m in 2D), downstream positive
    particle_run: Path | None = None        # 3D: the run whose particle and leaflet snapshots give the
                                            # leak through the valve (valve_leak), or None
    particle_spacing: float | None = None   # m: its particles' spacing (volume dp^3 each), or None
    tip_gap_time: np.ndarray | None = None  # 2D: solid sample times (s) of tip_gap, or None
    tip_gap: np.ndarray | None = None       # 2D: distance between the two leaflets' tips (m), or None
    symmetry_factor: float | None = None    # copies of the fluid that make the whole (6 for a 1/6 sector;
                                            # fluid_probes.h5's attribute; 0: no finite whole), or None
                                            # for a run written before the fluid recorded it
    source: Path | None = None              # the probe file read

    @property
    def mean_flow_rate(self) -> np.ndarray:
        return np.mean(np.stack(list(self.flow_rates.values())), axis=0)

    @property
    def pressure_drop(self) -> np.ndarray:
        return self.upstream_pressure - self.downstream_pressure

    @property
    def centre_pressure_drop(self) -> np.ndarray:
        if self.upstream_centre is None or self.downstream_centre is None:
            return self.pressure_drop
        return self.upstream_centre - self.downstream_centre


@dataclass
class FittedRate:
    """A rate fitted over a span of the cycle, with its halves: whole valve, backflow positive, in
    the volume units of CycleHemodynamics per second (mL/s; 2D cm^2/s)."""
    rate: float
    uncertainty: float              # half the difference between the two halves' rates
    first_half_rate: float
    second_half_rate: float
    start_s: float                  # the fitted span, s within the cycle
    end_s: float


@dataclass
class LeakRate(FittedRate):
    """The closed valve's leak rate through the flow sections (leak_rate)."""
    period_s: float | None          # the ringing's period (None: no ringing found)
    decay_time_s: float | None      # e-folding time of its amplitude (inf: steady; < 0: it grows)
    ringing_volume: float           # its amplitude in the backflow volume at start_s (mL; 2D cm^2)
    section_rates: dict             # section -> its leak rate with the same ringing's period and decay


@dataclass
class ValveLeak(FittedRate):
    """The leak through the closed valve by mass (valve_leak)."""
    snapshots: int                  # particle snapshots in the span
    volume_change: float            # the ventricle side's particle volume, last minus first snapshot (mL)


@dataclass
class CycleHemodynamics:
    """One cycle's metrics in the reference's units (2D: per depth, see the module doc)."""
    cycle: int
    dimension: int
    forward_start_s: float          # t1, within the cycle (s from its start)
    forward_end_s: float            # t2
    mspd_mmHg: float
    pspd_mmHg: float                # smoothed, section-averaged
    pspd_time_s: float
    q_rms: float                    # mL/s (2D: cm^2/s)
    eoa: float                      # cm^2 (2D: cm)
    stroke_volume: float            # mL (2D: cm^2), forward-flow period
    closing_volume: float           # mL (2D: cm^2)
    leakage_volume: float
    regurgitant_volume: float
    closure_time_s: float
    peak_flow: float                # mL/s (2D: cm^2/s)
    peak_flow_L_per_min: float      # 3D only meaningful; 2D: L/min per metre... kept for the table
    peak_velocity_m_per_s: float | None
    peak_velocity_time_s: float | None
    pull_out_force: float | None    # N (2D: N/m)
    diastolic_force: float | None
    diastolic_force_time_s: float | None
    hydrostatic_force: float        # -Pmax * A, N (2D: N/m)
    water_hammer_ratio: float | None
    section_stroke_volumes: dict    # section -> forward volume over [t1, t2], mL (2D: cm^2)
    pspd_probe_mmHg: float = float("nan")          # raw: the centre probes' largest dP over [t1, t2]
    peak_particle_speed: float | None = None       # raw: fastest particle on the velocity plane (m/s)
    series_end_s: float | None = None              # partial cycle: the series ends here (s in the cycle);
                                                   # leakage_volume and the diastolic force then cover
                                                   # only [t2, series_end_s]
    symmetry_factor: float = 1.0                   # the flows and forces above are the part's x this
    leak: LeakRate | None = None                   # the closed valve's leak rate (None: see leak_refusal)
    leak_refusal: str = ""                         # why there is no leak rate
    leakage_from_rate: float | None = None         # leak.rate x (cycle end - closure), mL (2D: cm^2)
    leakage_from_rate_uncertainty: float | None = None   # leak.uncertainty x (cycle end - closure)
    regurgitant_extrapolated: bool = False         # regurgitant_volume = closing + leakage_from_rate
                                                   # (a partial cycle), not closing + leakage_volume
    valve_leak: ValveLeak | None = None            # the leak through the valve by particle count (3D)
    valve_leak_refusal: str = ""                   # why there is none (empty: not attempted or measured)
    leakage_rate_source: str = ""                  # "particles" (valve_leak) or "flow sections" (leak)
    tip_gap_mm: float | None = None                # 2D: the tips' mean distance from the closure to the
                                                   # series' end (mm), or None
    tip_gap_orifice_leakage: float | None = None   # 2D: the orifice law's backflow through that gap
                                                   # over the same span (cm^2 per cm; tip_gap_orifice_flow)


def read_run(run_dir: Path, upstream: str = "upstream_tap", downstream: str = "downstream_tap",
             velocity_plane: str | None = None, sections: list[str] | None = None,
             particles: bool = True) -> ProbeSeries:
    """Reads RUN_DIR/fluid_probes.h5 and, if present, RUN_DIR/coupling_series.h5. `sections`
    chooses the flow sections averaged (default: all). particles: a 3D run with the leaflets'
    snapshots (solid_fields.h5) and fluid particle snapshots (its own or its segments') is marked
    for the leak through the valve by particle count (valve_leak; read when a cycle is analysed),
    with the particle spacing from the fluid's log (None if no log says it)."""
    import h5py
    run_dir = Path(run_dir)
    path = run_dir / "fluid_probes.h5"
    if not path.exists():
        raise FileNotFoundError(f"{path}: no fluid probe series (fluid_sph writes it in its output folder)")
    with h5py.File(path, "r") as f:
        for group, field in (("pressure", "pressure_points"), ("flow_rate", "flow_planes")):
            if group not in f:
                raise ValueError(f"{path}: no group '/{group}': the case needs fluid.probes.{field}")
        for name in (upstream, downstream):
            if name not in f["pressure"]:
                raise ValueError(f"{path}: no dataset '/pressure/{name}': have {', '.join(f['pressure'])}")
        names = sections or [name for name in f["flow_rate"] if name != JET_CORE_PLANE]
        missing = [name for name in names if name not in f["flow_rate"]]
        if missing:
            raise ValueError(f"{path}: no dataset '/flow_rate/{missing[0]}': have {', '.join(f['flow_rate'])}")
        flows = {name: f["flow_rate"][name][()].reshape(-1) for name in names}
        if not flows:
            raise ValueError(f"{path}: '/flow_rate' holds no section")
        velocity = None
        if "max_velocity" in f and len(f["max_velocity"]):
            names = list(f["max_velocity"])
            name = velocity_plane or names[0]
            if name not in names:
                raise ValueError(f"{path}: no dataset '/max_velocity/{name}': have {', '.join(names)}")
            velocity = f["max_velocity"][name][()].reshape(-1)
        dimension = 3
        if "wall_force" in f and "fixed_walls" in f["wall_force"]:
            dimension = int(f["wall_force"]["fixed_walls"].shape[1])
        def section_mean(tap):
            probes = [tap] + sorted(n for n in f["pressure"] if n.startswith(tap + SECTION_SUFFIX))
            return np.mean([f["pressure"][n][()].reshape(-1) for n in probes], axis=0)

        series = ProbeSeries(time=f["time"][()].reshape(-1),
                             upstream_pressure=section_mean(upstream),
                             downstream_pressure=section_mean(downstream),
                             flow_rates=flows, max_velocity=velocity, dimension=dimension,
                             jet_core_flow=(f["flow_rate"][JET_CORE_PLANE][()].reshape(-1)
                                            if JET_CORE_PLANE in f["flow_rate"] else None),
                             upstream_centre=f["pressure"][upstream][()].reshape(-1),
                             downstream_centre=f["pressure"][downstream][()].reshape(-1),
                             symmetry_factor=(float(f.attrs["symmetry_factor"]) if "symmetry_factor" in f.attrs else None),
                             source=path)
    coupling = run_dir / "coupling_series.h5"
    if coupling.exists():
        with h5py.File(coupling, "r") as f:
            if "force_fluid" in f and len(f["time"]):
                axis = 2 if series.dimension == 3 else 0
                series.force_time = f["time"][()].reshape(-1)
                series.axial_force = f["force_fluid"][()][:, axis]
    solid_series = run_dir / "solid_series.h5"
    if series.dimension == 2 and solid_series.exists():
        with h5py.File(solid_series, "r") as f:
            key = "monitor/free_edge_midpoints/position"
            if key in f and f[key].ndim == 3 and f[key].shape[1] == 2 and len(f["time"]):
                tips = f[key][()]
                series.tip_gap_time = f["time"][()].reshape(-1)
                series.tip_gap = np.linalg.norm(tips[:, 0, :2] - tips[:, 1, :2], axis=1)
    if particles and series.dimension == 3 and (run_dir / "solid_fields.h5").exists() and particle_snapshots(run_dir):
        series.particle_run = run_dir
        series.particle_spacing = particle_spacing_of(run_dir)
    return series


# ---------------------------------------------------------------------------------------------
# The leak through the valve by particle count


VALVE_SIDE_MARGIN_M = 3e-3        # within this of the leaflets' extent the side is the leaflets'
VALVE_SIDE_RADIAL_MARGIN_M = 1e-4  # beyond the attachment radius by this: the sinus or under the gasket
VALVE_SNAPSHOT_TOLERANCE_S = 5e-4  # a fluid snapshot takes the leaflet snapshot this close in time
VALVE_LEAK_FALLBACK_DELAY_S = 0.032  # without the flow sections' fit: the span starts this long after the closure
VALVE_LEAK_MIN_SNAPSHOTS = 6
PARTICLE_FLUID, PARTICLE_LOST = 0, 2   # fluid_particles.h5 /kind (fluid_sph Kind)
SPACING_IN_LOG = re.compile(r"\bdp = ([0-9.eE+-]+) m\b")


def _segments(run_dir: Path) -> list[Path]:
    from .join_segments import segments_of
    return segments_of(run_dir)


def particle_snapshots(run_dir: Path) -> list[tuple[float, Path, str]]:
    """(time, file, group) of the fluid particle snapshots of a run, in time order: its own
    fluid_particles.h5, or, for a run joined from restart segments (join_segments, which does not
    copy them), its segments': segment k contributes its snapshots before the first of the next
    segment that has any (the later segment wins, as in the join)."""
    import h5py
    run_dir = Path(run_dir)
    files = [d / "fluid_particles.h5" for d in [run_dir] + _segments(run_dir) if (d / "fluid_particles.h5").exists()]
    per_file = []
    for path in files:
        with h5py.File(path, "r") as f:
            found = sorted((float(f[n].attrs["time"]), path, n) for n in f if n.startswith("snapshot_"))
        if found:
            per_file.append(found)
    out = []
    for k, found in enumerate(per_file):
        limit = per_file[k + 1][0][0] if k + 1 < len(per_file) else math.inf
        out += [entry for entry in found if entry[0] < limit]
    return out


def particle_spacing_of(run_dir: Path) -> float | None:
    """The fluid's particle spacing (m) as its log (fluid.log: "dp = ... m") states it, from the run
    folder or its segments; None if none does."""
    for folder in [Path(run_dir)] + _segments(run_dir):
        log = folder / "fluid.log"
        if log.is_file():
            with open(log, errors="replace") as f:
                for line in f:
                    found = SPACING_IN_LOG.search(line)
                    if found:
                        return float(found.group(1))
    return None


def _surface_samples(nodes: np.ndarray, triangles: np.ndarray, level: int = 5) -> tuple[np.ndarray, np.ndarray]:
    """Points on every triangle (a barycentric grid, level + 1 per edge) and their triangle's unit
    normal, oriented so that the mesh's area-weighted normal points along +z (downstream)."""
    a, b, c = nodes[triangles[:, 0]], nodes[triangles[:, 1]], nodes[triangles[:, 2]]
    n = np.cross(b - a, c - a)
    if np.sum(n[:, 2]) < 0:
        n = -n
    n = n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    points, normals = [], []
    for i in range(level + 1):
        for j in range(level + 1 - i):
            points.append(a + (i / level) * (b - a) + (j / level) * (c - a))
            normals.append(n)
    return np.concatenate(points), np.concatenate(normals)


def valve_side(points: np.ndarray, nodes: np.ndarray, triangles: np.ndarray, base_z: float, top_z: float,
               radius: float, margin: float = VALVE_SIDE_MARGIN_M,
               radial_margin: float = VALVE_SIDE_RADIAL_MARGIN_M) -> np.ndarray:
    """+1 (aorta's side) or -1 (ventricle's side) of the closed valve for each point [n, 3], the
    flow along +z: within radius + radial_margin of the axis and between base_z - margin and
    top_z + margin (the leaflets' extent: annulus plane to commissure tops), the side of the
    leaflets' mid-surface (nodes, triangles, consistently oriented) nearest the point; outside
    that radius, above base_z is the sinus (aorta), below it the gasket's underside (ventricle);
    below and above the leaflets' extent, the ventricle and the aorta. A point's side is the
    leaflet's only while the valve is closed."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    z, r = points[:, 2], np.hypot(points[:, 0], points[:, 1])
    side = np.where(z > base_z, 1, -1)
    near = (r <= radius + radial_margin) & (z > base_z - margin) & (z < top_z + margin)
    if np.any(near):
        samples, normals = _surface_samples(np.asarray(nodes, dtype=float), np.asarray(triangles))
        q = points[near]
        nearest = np.empty(len(q), dtype=int)
        s2 = np.sum(samples ** 2, axis=1)
        for i0 in range(0, len(q), 2000):
            block = q[i0:i0 + 2000]
            nearest[i0:i0 + 2000] = np.argmin(s2[None, :] - 2.0 * block @ samples.T, axis=1)
        signed = np.einsum("ij,ij->i", q - samples[nearest], normals[nearest])
        side[near] = np.where(signed > 0, 1, -1)
    return side


@functools.lru_cache(maxsize=8)
def _ventricle_side_counts(run_dir: Path, start: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, fluid particles on the ventricle's side) at the particle snapshots in [start, end]
    that have a leaflet snapshot within VALVE_SNAPSHOT_TOLERANCE_S. Particles the fluid took out
    (kind lost: their density left the allowed band, most of them squeezed in the coaptation
    zone) count where they stay, so that a loss is not read as a leak."""
    import h5py
    with h5py.File(run_dir / "solid_fields.h5", "r") as f:
        reference = f["mesh/nodes"][()]
        triangles = f["mesh/triangles"][()]
        names = sorted(f["snapshots"])
        solid_times = np.array([float(f["snapshots"][n].attrs["time"]) for n in names])
    base_z, top_z = float(reference[:, 2].min()), float(reference[:, 2].max())
    radius = float(np.max(np.hypot(reference[:, 0], reference[:, 1])))
    times, counts = [], []
    for t, path, group in particle_snapshots(run_dir):
        if not (start - 1e-9 <= t <= end + 1e-9) or len(solid_times) == 0:
            continue
        k = int(np.argmin(np.abs(solid_times - t)))
        if abs(solid_times[k] - t) > VALVE_SNAPSHOT_TOLERANCE_S:
            continue
        with h5py.File(run_dir / "solid_fields.h5", "r") as f:
            nodes = f["snapshots"][names[k]]["position"][()]
        with h5py.File(path, "r") as f:
            kind = f[group]["kind"][()].reshape(-1)
            x = f[group]["position"][()][(kind == PARTICLE_FLUID) | (kind == PARTICLE_LOST)]
        times.append(t)
        counts.append(int(np.count_nonzero(valve_side(x, nodes, triangles, base_z, top_z, radius) < 0)))
    return np.array(times), np.array(counts, dtype=float)


def valve_leak(series: ProbeSeries, closure: float, end: float, start: float, to_volume: float,
               symmetry_factor: float = 1.0, cycle_start: float = 0.0,
               particle_spacing: float | None = None) -> tuple[ValveLeak | None, str]:
    """The leak through the closed valve by mass, from the run's particle snapshots: the volume of
    the fluid particles on the ventricle's side (count x dp^3 x symmetry_factor, in to_volume
    units), fitted by a line over [start, end] (s; start after the closure); uncertainty half the
    difference between the rates of the span's two halves. Returns (ValveLeak, "") or (None, why).

    Why: the flow sections' rates sum the particles' velocities over a slab, and in diastole the
    particle shifting (which moves particles without velocity, towards the closed leaflets from
    both sides) carries 1-5 mL/s through the sections next to the valve that the velocities do
    not (docs/fsi-3d.md, session 18, helper 62). A particle's mass crosses the valve only through
    it; the count on the ventricle's side changes by nothing else (lost particles aside), does not
    ring with the blood columns and is blind to the leaflets' bulging."""
    if series.particle_run is None:
        return None, ""
    spacing = particle_spacing or series.particle_spacing
    if not spacing:
        return None, "the particle spacing is unknown (no fluid.log states 'dp = ... m'; pass particle_spacing)"
    if start < closure:
        start = closure
    times, counts = _ventricle_side_counts(Path(series.particle_run), float(start), float(end))
    if len(times) < VALVE_LEAK_MIN_SNAPSHOTS:
        return None, (f"{len(times)} particle snapshots with the leaflets' between {(start - cycle_start) * 1e3:.0f} and "
                      f"{(end - cycle_start) * 1e3:.0f} ms, fewer than {VALVE_LEAK_MIN_SNAPSHOTS}")
    volume = counts * spacing ** 3 * symmetry_factor * to_volume
    tau = times - times[0]
    rate = float(np.polyfit(tau, volume, 1)[0])
    half = len(tau) // 2
    halves = [float(np.polyfit(tau[part], volume[part], 1)[0]) for part in (slice(0, half + 1), slice(half, None))]
    return ValveLeak(rate=rate, uncertainty=0.5 * abs(halves[0] - halves[1]), first_half_rate=halves[0],
                     second_half_rate=halves[1], start_s=float(times[0] - cycle_start), end_s=float(times[-1] - cycle_start),
                     snapshots=len(times), volume_change=float(volume[-1] - volume[0])), ""


# ---------------------------------------------------------------------------------------------
# The 2D valve's tips' gap as an orifice


SLIT_DISCHARGE_COEFFICIENT = 0.6   # a sharp-edged slit's (0.6-0.62); the coarse 2D valve's SPH
                                   # leakage follows it at gaps of 0.16-0.49 mm (docs/fsi-2d.md, session 20)


def tip_gap_orifice_flow(t: np.ndarray, pressure_drop_Pa: np.ndarray, gap_time: np.ndarray, gap_m: np.ndarray,
                         density: float = BLOOD_DENSITY,
                         discharge: float = SLIT_DISCHARGE_COEFFICIENT) -> np.ndarray:
    """Flow per depth (m^2/s, forward positive) that the orifice law passes through a slit as wide
    as the 2D valve's tips are apart, Q = C_d g sqrt(2 |dp| / rho) sign(dp), on the probe times t
    (the gap interpolated onto them). Compared with the flow sections, it says how much of a
    closed 2D valve's leakage is flow through the gap its tips leave."""
    gap = np.interp(t, gap_time, gap_m)
    return discharge * gap * np.sqrt(2.0 * np.abs(pressure_drop_Pa) / density) * np.sign(pressure_drop_Pa)


def moving_average(t: np.ndarray, y: np.ndarray, width_s: float) -> np.ndarray:
    """Centred moving average over about width_s (uniform sampling assumed; none if shorter)."""
    if len(t) < 3 or width_s <= 0:
        return y.copy()
    dt = float(np.median(np.diff(t)))
    n = int(round(width_s / dt))
    if n < 2:
        return y.copy()
    kernel = np.ones(n) / n
    padded = np.concatenate([np.full(n, y[0]), y, np.full(n, y[-1])])
    return np.convolve(padded, kernel, mode="same")[n:-n]


def _crossing(t, y, i0, i1) -> float:
    """Zero of the line through (t[i0], y[i0]) and (t[i1], y[i1])."""
    if y[i1] == y[i0]:
        return float(t[i1])
    return float(t[i0] + (t[i1] - t[i0]) * (0.0 - y[i0]) / (y[i1] - y[i0]))


def integral(t: np.ndarray, y: np.ndarray, a: float, b: float) -> float:
    """Trapezoidal integral of the piecewise-linear y(t) over [a, b] (ends interpolated)."""
    if b <= a:
        return 0.0
    inside = (t > a) & (t < b)
    tt = np.concatenate([[a], t[inside], [b]])
    yy = np.concatenate([[np.interp(a, t, y)], y[inside], [np.interp(b, t, y)]])
    return float(np.sum(0.5 * (yy[1:] + yy[:-1]) * np.diff(tt)))


def forward_flow_period(t: np.ndarray, q_smooth: np.ndarray) -> tuple[float, float]:
    """[t1, t2] around the peak flow where the smoothed flow is positive."""
    peak = int(np.argmax(q_smooth))
    if q_smooth[peak] <= 0:
        raise ValueError("no forward flow in the analysed cycle (flow rate never positive)")
    i = peak
    while i > 0 and q_smooth[i - 1] > 0:
        i -= 1
    t1 = float(t[0]) if i == 0 else _crossing(t, q_smooth, i - 1, i)
    j = peak
    while j < len(t) - 1 and q_smooth[j + 1] > 0:
        j += 1
    t2 = float(t[-1]) if j == len(t) - 1 else _crossing(t, q_smooth, j, j + 1)
    return t1, t2


def closure_time(t: np.ndarray, q_smooth: np.ndarray, t2: float) -> float:
    """End of the closing backflow (module doc): 90 % back from the backflow peak to the
    leakage level."""
    after = t >= t2
    ta, qa = t[after], q_smooth[after]
    if len(ta) < 4:
        return float(t[-1])
    late = ta >= t2 + 0.5 * (ta[-1] - t2)
    leak_level = float(np.median(qa[late]))
    k = int(np.argmin(qa))
    if qa[k] >= leak_level:   # no backflow peak below the leakage level
        return float(t2)
    target = qa[k] + 0.9 * (leak_level - qa[k])
    for m in range(k, len(ta)):
        if qa[m] >= target:
            if m == k:
                return float(ta[m])
            return float(ta[m - 1] + (ta[m] - ta[m - 1]) * (target - qa[m - 1]) / (qa[m] - qa[m - 1]))
    return float(ta[-1])


LEAK_SHORTEST_PERIOD_S = 0.004   # the column's ringing is 30 ms; faster modes carry little volume
LEAK_SEARCH_SAMPLES = 600        # the (period, decay) search runs on this many samples of the smooth volume
LEAK_RINGING_SHARE = 0.75        # "ringing": the oscillation removes this share of the line's residual
LEAK_LINE_FIT = 0.01             # without ringing, a line must fit the volume to this share of its range


def _line_and_mode(tau: np.ndarray, volume: np.ndarray, period: float | None,
                   decay_rate: float = 0.0) -> tuple[float, np.ndarray]:
    """Least squares of volume ~ a + r tau + exp(-decay_rate tau) (b cos + c sin)(2 pi tau / period)
    (period None: the line alone): (residual sum of squares, [a, r, b, c])."""
    columns = [np.ones_like(tau), tau]
    if period is not None:
        envelope, phase = np.exp(-decay_rate * tau), 2.0 * math.pi * tau / period
        columns += [envelope * np.cos(phase), envelope * np.sin(phase)]
    basis = np.column_stack(columns)
    coefficients, *_ = np.linalg.lstsq(basis, volume, rcond=None)
    residual = volume - basis @ coefficients
    return float(residual @ residual), coefficients


def _mode_residuals(tau: np.ndarray, volume: np.ndarray, periods: np.ndarray, decays: np.ndarray) -> np.ndarray:
    """_line_and_mode's residual sum of squares for each (periods[k], decays[k]) at once: the
    oscillation's two columns, with the line projected out, fitted to the line's residual."""
    line_basis, _ = np.linalg.qr(np.column_stack([np.ones_like(tau), tau]))
    def without_line(y):   # y (..., n) minus its least-squares line
        return y - (y @ line_basis) @ line_basis.T
    residual = without_line(volume)
    envelope = np.exp(-np.outer(decays, tau))
    phase = 2.0 * math.pi * np.outer(1.0 / periods, tau)
    c, s = without_line(envelope * np.cos(phase)), without_line(envelope * np.sin(phase))
    cc, cs, ss = np.sum(c * c, axis=1), np.sum(c * s, axis=1), np.sum(s * s, axis=1)
    cr, sr = c @ residual, s @ residual
    determinant = np.maximum(cc * ss - cs * cs, 1e-300)
    explained = (ss * cr * cr - 2.0 * cs * cr * sr + cc * sr * sr) / determinant
    return residual @ residual - explained


def _ringing(tau: np.ndarray, volume: np.ndarray) -> tuple[float, float] | None:
    """(period, decay rate) of the damped oscillation that, with a line, fits volume(tau) best;
    periods from LEAK_SHORTEST_PERIOD_S to half the span (a longer one is the trend's curvature),
    decays from e-folding in span/30 to growth by e^3 over the span. None when the best
    oscillation removes less than LEAK_RINGING_SHARE of the line's residual (no ringing)."""
    span = float(tau[-1])
    longest = 0.5 * span
    if longest <= LEAK_SHORTEST_PERIOD_S:
        return None
    step = max(1, len(tau) // LEAK_SEARCH_SAMPLES)
    ts, vs = tau[::step], volume[::step]
    line = _line_and_mode(ts, vs, None)[0]
    if line <= (1e-9 * float(np.ptp(vs))) ** 2 * len(vs):   # a line to round-off
        return None
    periods = np.geomspace(LEAK_SHORTEST_PERIOD_S, longest, 80)
    decays = np.concatenate([-np.geomspace(0.1, 3.0, 6)[::-1], [0.0], np.geomspace(0.1, 30.0, 16)]) / span
    grid_p, grid_d = (a.ravel() for a in np.meshgrid(periods, decays))
    k = int(np.argmin(_mode_residuals(ts, vs, grid_p, grid_d)))
    period, decay = float(grid_p[k]), float(grid_d[k])
    # refine around the grid's best: halving steps in log(period) and decay
    log_step, decay_step = math.log(periods[1] / periods[0]), 0.5 / span
    for _ in range(8):
        near_p = np.clip(period * np.exp(log_step * np.array([-1.0, 0.0, 1.0])), LEAK_SHORTEST_PERIOD_S, longest)
        near_d = decay + decay_step * np.array([-1.0, 0.0, 1.0])
        trial_p, trial_d = (a.ravel() for a in np.meshgrid(near_p, near_d))
        k = int(np.argmin(_mode_residuals(ts, vs, trial_p, trial_d)))
        period, decay = float(trial_p[k]), float(trial_d[k])
        log_step, decay_step = 0.5 * log_step, 0.5 * decay_step
    if _line_and_mode(ts, vs, period, decay)[0] > (1.0 - LEAK_RINGING_SHARE) * line:
        return None
    return period, decay


def leak_rate(t: np.ndarray, flow: np.ndarray, closure: float, to_volume: float, sections: dict | None = None,
              cycle_start: float = 0.0) -> tuple[LeakRate | None, str]:
    """The closed valve's leak rate from the whole valve's flow (m^3/s; 2D m^2/s) on t after
    `closure` (s); to_volume converts m^3 to the result's volume unit. sections (name -> flow on
    t) are each fitted with the flow's ringing. Returns (LeakRate, "") or (None, why).

    Why a fit of the volume: after the closing the blood column between the two plates rings
    (3D sector: a period of ~32 ms whose amplitude falls by e in ~180 ms), so -integral of Q to
    wherever the series stops swings by the ringing's volume (+-0.4 mL against a leak of
    ~1 mL/s). The other candidate, the mean of Q over whole periods between upward zero
    crossings of its oscillation, finds the periods well (31-33 ms) but is biased when the
    ringing decays: its window starts and ends at minima of the oscillating volume of unequal
    depth (on a synthetic 2 mL/s leak with a 130 ms decay it read 0.3-0.7 mL/s; on the 3D
    MHGO run ~1 mL/s of forward flow where the fit reads 1.3 mL/s of backflow). Between flow
    peaks instead it moved by up to 0.4 mL/s with the stop on synthetic series and read 2.6-4.6
    mL/s on the MHGO run (its ends follow the waveform's shape, not the oscillation's mean). A
    least-squares fit of the backflow volume V(t) (smooth: an integral) to a line plus one
    damped oscillation uses every sample and needs no zero crossing, and gives the period and
    decay as well; on synthetic series (tests: LeakRate) it recovers a 2 mL/s leak within
    0.001 mL/s at any stop three periods or more after the closure.

    Procedure: a first fit from the closure finds the period P; the fitted span starts one period
    later, since the closing's water hammer is not one damped mode (on the 3D runs its residual
    is 0.2 mL against 0.05-0.1 mL later, and it moves the rate by 0.4-0.7 mL/s); the span must then
    hold two periods (three from the closure), else None. The uncertainty is half the
    difference between the rates of the span's two halves (each fitted with the whole span's
    period and decay): a leak rate that changes over the diastole shows there. A series
    without ringing gets the line's slope from the closure on (period None), if the line fits
    (LEAK_LINE_FIT; else the ringing may just be slower than the span shows: None)."""
    after = t >= closure
    if np.count_nonzero(after) < 8:
        return None, f"{np.count_nonzero(after)} samples after the closure"
    ta = t[after]

    def backflow_volume(q):   # -integral of q from the first sample after the closure
        q = -q[after] * to_volume
        return np.concatenate([[0.0], np.cumsum(0.5 * (q[1:] + q[:-1]) * np.diff(ta))])

    volume = backflow_volume(flow)
    first = _ringing(ta - ta[0], volume)
    after_closure_ms = (ta[-1] - closure) * 1e3
    if first is None:
        # no ringing, or one too slow for the span to show: only a line that fits settles which
        line_rms = math.sqrt(_line_and_mode(ta - ta[0], volume, None)[0] / len(ta))
        if line_rms > LEAK_LINE_FIT * float(np.ptp(volume)):
            return None, (f"no ringing period within half of the {after_closure_ms:.0f} ms after the closure, and a "
                          f"line leaves {line_rms / float(np.ptp(volume)):.0%} of the volume's range: too short a span")
        period = decay = None
        fitted = np.ones_like(ta, dtype=bool)
    else:
        skip = ta >= ta[0] + first[0]
        if ta[-1] - ta[0] < 3.0 * first[0] or np.count_nonzero(skip) < 8:
            return None, (f"the series holds {after_closure_ms:.0f} ms after the closure, less than three "
                          f"ringing periods ({first[0] * 1e3:.1f} ms): one skipped, two fitted")
        fitted = skip
        found = _ringing(ta[fitted] - ta[fitted][0], volume[fitted])
        if found is None:
            return None, (f"no ringing shorter than half the {(ta[-1] - ta[fitted][0]) * 1e3:.0f} ms after the "
                          f"closing's first period ({first[0] * 1e3:.1f} ms)")
        period, decay = found
    tf = ta[fitted]
    tau = tf - tf[0]
    _, coefficients = _line_and_mode(tau, volume[fitted], period, decay or 0.0)
    half = len(tf) // 2
    halves = [_line_and_mode(tau[part] - tau[part][0], volume[fitted][part], period, decay or 0.0)[1][1]
              for part in (slice(0, half + 1), slice(half, None))]
    section_rates = {name: _line_and_mode(tau, backflow_volume(q)[fitted], period, decay or 0.0)[1][1]
                     for name, q in (sections or {}).items()}
    decay_time = None if period is None else (math.inf if decay == 0 else 1.0 / decay)
    return LeakRate(rate=float(coefficients[1]), uncertainty=0.5 * abs(halves[0] - halves[1]),
                    first_half_rate=float(halves[0]), second_half_rate=float(halves[1]),
                    start_s=float(tf[0] - cycle_start), end_s=float(tf[-1] - cycle_start),
                    period_s=period, decay_time_s=decay_time,
                    ringing_volume=0.0 if period is None else float(math.hypot(coefficients[2], coefficients[3])),
                    section_rates={k: float(v) for k, v in section_rates.items()}), ""


@functools.lru_cache(maxsize=None)
def hydrostatic_pressure_Pa() -> float:
    """The waveform's largest reverse transvalvular gradient (Pa, positive): 97.2 mmHg."""
    t = np.linspace(0.0, waveform.PERIOD_S, 8001)
    return -float(np.min(waveform.transvalvular_pressure_mmHg(t))) * PA_PER_MMHG


def annulus_area(dimension: int, radius: float = ANNULUS_RADIUS_M) -> float:
    """m^2 (3D: pi R^2) or m^2 per metre of depth (2D: the orifice width 2R)."""
    return math.pi * radius ** 2 if dimension == 3 else 2.0 * radius


def whole_valve_factor(series: ProbeSeries, requested: float | None = None) -> float:
    """The factor from the series' flows and forces to the whole valve's: the fluid's record,
    or `requested` where the run has none. Refuses a request that contradicts the record, and a
    fluid with no finite whole (parallel mirror planes), whose flows no factor makes a valve's."""
    recorded = series.symmetry_factor
    where = series.source or "the probe series"
    if recorded is not None and recorded <= 0:
        raise ValueError(f"{where}: symmetry_factor = {recorded:g}: the fluid's mirror planes are parallel, "
                         "no number of copies makes a whole valve")
    if recorded is not None and requested is not None and abs(requested - recorded) > 1e-9 * recorded:
        raise ValueError(f"{where}: symmetry factor {requested:g} requested, but the fluid recorded {recorded:g} "
                         f"(its mirror planes make {recorded:g} copies of it the whole): leave the option out")
    return float(recorded if recorded is not None else (requested if requested is not None else 1.0))


def analyse_cycle(series: ProbeSeries, cycle: int = 2, period: float = waveform.PERIOD_S,
                  smoothing_s: float = 0.002, closure_time_s: float | None = None,
                  hydrostatic_Pa: float | None = None, annulus_radius: float = ANNULUS_RADIUS_M,
                  symmetry_factor: float | None = None, allow_partial: bool = False,
                  particle_spacing: float | None = None) -> CycleHemodynamics:
    """Metrics of cycle `cycle` (1-based: [(cycle-1) T, cycle T)). closure_time_s, if given, is
    the valve's closure within the cycle (e.g. from the kinematics) and splits closing from
    leakage volume. symmetry_factor multiplies the flows and forces of a symmetric part (6 for
    the 1/6 sector) into the whole valve's: by default the one the fluid recorded (1 for a run
    written before it did); a given one that contradicts the record is refused. allow_partial
    accepts a series that ends before the cycle does, once the forward flow has ended in it (a
    run that covers only the parts of the cycle the metrics need): the result's series_end_s
    says where the diastolic quantities stop,
    and its regurgitant volume is closing + the leak rate x (cycle end - closure) when the leak
    rate is measured (regurgitant_extrapolated; leakage_volume stays the integral to the end).
    Where the series has particle snapshots (read_run) the leak through the valve by particle
    count (valve_leak; particle_spacing overrides the log's) is the leak rate the leakage from
    the rate uses; else the flow sections' fit (leak_rate)."""
    symmetry_factor = whole_valve_factor(series, symmetry_factor)
    start, end = (cycle - 1) * period, cycle * period
    t_all = series.time
    sel = (t_all >= start - 1e-12) & (t_all <= end + 1e-12)
    if np.count_nonzero(sel) < 4:
        raise ValueError(f"cycle {cycle} ([{start:g}, {end:g}] s) has {np.count_nonzero(sel)} probe samples: "
                         f"the series covers [{t_all[0]:g}, {t_all[-1]:g}] s")
    t = t_all[sel]
    partial = t[-1] < end - 0.05 * period
    if partial and not allow_partial:
        raise ValueError(f"cycle {cycle} is incomplete: the series ends at {t[-1]:g} s, the cycle at {end:g} s")
    q = series.mean_flow_rate[sel] * symmetry_factor
    dp = series.pressure_drop[sel]
    q_s = moving_average(t, q, smoothing_s)
    t1, t2 = forward_flow_period(t, q_s)
    if partial and t2 >= t[-1]:
        raise ValueError(f"cycle {cycle} is incomplete and its forward flow has not ended: the series ends at "
                         f"{t[-1]:g} s with the flow still positive")
    duration = t2 - t1
    # Volumes: m^3 -> mL is 1e6 (3D); m^2 -> cm^2 is 1e4 (2D, per depth). Rates likewise.
    to_volume = 1e6 if series.dimension == 3 else 1e4
    mspd = integral(t, dp, t1, t2) / duration / PA_PER_MMHG
    in_forward = (t >= t1) & (t <= t2)
    k = int(np.argmax(np.where(in_forward, moving_average(t, dp, smoothing_s), -np.inf)))
    dp_smooth_peak = float(moving_average(t, dp, smoothing_s)[k])
    pspd_probe = float(np.max(np.where(in_forward, series.centre_pressure_drop[sel], -np.inf))) / PA_PER_MMHG
    q_rms = math.sqrt(integral(t, q * q, t1, t2) / duration) * to_volume
    eoa = q_rms / (GORLIN_CONSTANT * math.sqrt(mspd)) if mspd > 0 else float("nan")
    t_close = closure_time(t, q_s, t2) if closure_time_s is None else start + closure_time_s
    closing = -integral(t, q, t2, t_close) * to_volume
    leakage = -integral(t, q, t_close, t[-1]) * to_volume
    leak, leak_refusal = leak_rate(t, q, t_close, to_volume, cycle_start=start,
                                   sections={name: rate[sel] * symmetry_factor for name, rate in series.flow_rates.items()})
    valve_start = start + leak.start_s if leak is not None else t_close + VALVE_LEAK_FALLBACK_DELAY_S
    valve, valve_refusal = valve_leak(series, t_close, float(t[-1]), valve_start, to_volume,
                                      symmetry_factor=symmetry_factor, cycle_start=start,
                                      particle_spacing=particle_spacing)
    chosen = valve if valve is not None else leak
    source = "" if chosen is None else ("particles" if valve is not None else "flow sections")
    leakage_from_rate = None if chosen is None else chosen.rate * (end - t_close)
    leakage_from_rate_uncertainty = None if chosen is None else chosen.uncertainty * (end - t_close)
    extrapolated = partial and leakage_from_rate is not None
    peak_q = float(np.max(q)) * to_volume
    tip_gap_mm = tip_gap_leakage = None
    if series.tip_gap is not None and series.tip_gap_time is not None and t[-1] > t_close:
        closed = (series.tip_gap_time >= t_close) & (series.tip_gap_time <= t[-1])
        if np.any(closed):
            tip_gap_mm = float(np.mean(series.tip_gap[closed])) * 1e3
            orifice = tip_gap_orifice_flow(t, dp, series.tip_gap_time, series.tip_gap)
            tip_gap_leakage = -integral(t, orifice, t_close, t[-1]) * to_volume
    sections = {name: integral(t, rate[sel] * symmetry_factor, t1, t2) * to_volume for name, rate in series.flow_rates.items()}

    velocity = velocity_time = particle_speed = None
    if series.max_velocity is not None:
        particle_speed = float(np.max(series.max_velocity[sel]))
    if series.jet_core_flow is not None:
        core_area = math.pi * JET_CORE_RADIUS_M ** 2 if series.dimension == 3 else 2 * JET_CORE_RADIUS_M
        v = moving_average(t, series.jet_core_flow[sel] * symmetry_factor / core_area, smoothing_s)
        kv = int(np.argmax(v))
        velocity, velocity_time = float(v[kv]), float(t[kv] - start)
    elif series.max_velocity is not None:   # older runs without a jet-core plane: the smoothed fastest particle
        v = moving_average(t, series.max_velocity[sel], smoothing_s)
        kv = int(np.argmax(v))
        velocity, velocity_time = float(v[kv]), float(t[kv] - start)
    p_max = hydrostatic_Pa if hydrostatic_Pa is not None else hydrostatic_pressure_Pa()
    hydrostatic_force = -p_max * annulus_area(series.dimension, annulus_radius)
    pull_out = diastolic = diastolic_time = ratio = None
    if series.axial_force is not None and series.force_time is not None:
        tf, f = series.force_time, series.axial_force * symmetry_factor
        systole = (tf >= t1) & (tf <= t2)
        diastole = (tf > t2) & (tf <= end + 1e-12)
        if np.any(systole):
            pull_out = float(np.max(f[systole]))
        if np.any(diastole):
            kd = int(np.argmin(np.where(diastole, f, np.inf)))
            diastolic, diastolic_time = float(f[kd]), float(tf[kd] - start)
            ratio = diastolic / hydrostatic_force
    return CycleHemodynamics(
        cycle=cycle, dimension=series.dimension, forward_start_s=t1 - start, forward_end_s=t2 - start,
        mspd_mmHg=mspd, pspd_mmHg=dp_smooth_peak / PA_PER_MMHG, pspd_time_s=float(t[k] - start),
        q_rms=q_rms, eoa=eoa, stroke_volume=integral(t, q, t1, t2) * to_volume,
        closing_volume=closing, leakage_volume=leakage,
        regurgitant_volume=closing + (leakage_from_rate if extrapolated else leakage),
        closure_time_s=t_close - start, peak_flow=peak_q, peak_flow_L_per_min=peak_q * 60.0 / 1000.0,
        peak_velocity_m_per_s=velocity, peak_velocity_time_s=velocity_time,
        pull_out_force=pull_out, diastolic_force=diastolic, diastolic_force_time_s=diastolic_time,
        hydrostatic_force=hydrostatic_force, water_hammer_ratio=ratio, section_stroke_volumes=sections,
        pspd_probe_mmHg=pspd_probe, peak_particle_speed=particle_speed,
        series_end_s=float(t[-1] - start) if partial else None, symmetry_factor=symmetry_factor,
        leak=leak, leak_refusal=leak_refusal, leakage_from_rate=leakage_from_rate,
        leakage_from_rate_uncertainty=leakage_from_rate_uncertainty,
        regurgitant_extrapolated=extrapolated, valve_leak=valve, valve_leak_refusal=valve_refusal,
        leakage_rate_source=source, tip_gap_mm=tip_gap_mm, tip_gap_orifice_leakage=tip_gap_leakage)


# ---------------------------------------------------------------------------------------------
# Report


def _units(dimension: int) -> dict:
    if dimension == 3:
        return {"eoa": "cm²", "volume": "mL", "flow": "mL/s", "force": "N", "flow_min": "L/min"}
    return {"eoa": "cm per cm depth", "volume": "cm² (mL per cm depth)", "flow": "cm²/s",
            "force": "N/m", "flow_min": "L/min per cm depth"}


def _f(value, digits=2, scale=1.0) -> str:
    return "–" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value * scale:.{digits}f}"


def hemodynamics_table(results: dict) -> str:
    """Markdown table: one column per model (name -> CycleHemodynamics), then the reference's
    FSI columns (3D values; in 2D only the dimensionless rows and the times compare)."""
    models = list(results)
    dims = {r.dimension for r in results.values()}
    u = _units(dims.pop() if len(dims) == 1 else 3)
    refs = list(REFERENCE_HEMODYNAMICS)
    header = "| quantity | " + " | ".join(f"{m} (ours)" for m in models) + " | " + " | ".join(f"{r} (ref.)" for r in refs) + " |"
    rows = [header, "|---" * (1 + len(models) + len(refs)) + "|"]

    def ref(key, digits=2, scale=1.0):
        return [_f(REFERENCE_HEMODYNAMICS[r].get(key), digits, scale) for r in refs]

    def ref_ratio(r):
        d = REFERENCE_HEMODYNAMICS[r]
        return f"{d['diastolic_force'] / d['hydrostatic_force']:.2f}"

    def regurgitant(r):
        return _f(r.regurgitant_volume, 2) + (" (extrap.)" if r.regurgitant_extrapolated else "")

    def leak_rate_cell(r):
        k = r.leak
        if k is None:
            return "–"
        return f"{k.rate:.2f} ± {k.uncertainty:.2f} (halves {k.first_half_rate:.2f}, {k.second_half_rate:.2f})"

    def leakage_from_rate_cell(r):
        if r.leakage_from_rate is None:
            return "–"
        cell = f"{r.leakage_from_rate:.2f} ± {r.leakage_from_rate_uncertainty:.2f}"
        cell += " (extrap.)" if r.series_end_s is not None else ""
        return cell + (" (particles)" if r.leakage_rate_source == "particles" else "")

    def valve_leak_cell(r):
        k = r.valve_leak
        if k is None:
            return "–"
        return (f"{k.rate:.2f} ± {k.uncertainty:.2f} (halves {k.first_half_rate:.2f}, {k.second_half_rate:.2f}; "
                f"{k.start_s * 1e3:.0f}–{k.end_s * 1e3:.0f} ms, {k.snapshots} snapshots)")

    def section_rates_cell(r):
        rates = list(r.leak.section_rates.values()) if r.leak is not None else []
        return f"{min(rates):.2f} to {max(rates):.2f}" if rates else "–"

    def leak_fit_cell(r):
        k = r.leak
        if k is None:
            return "–"
        span = f"{k.start_s * 1e3:.0f}–{k.end_s * 1e3:.0f}"
        if k.period_s is None:
            return span + "; no ringing"
        return f"{span}; {k.period_s * 1e3:.1f}, {_f(k.decay_time_s, 0, 1e3) if math.isfinite(k.decay_time_s) else '∞'}"

    partial = any(r.series_end_s is not None for r in results.values())
    none = ["–"] * len(refs)

    spec = [
        ("MSPD (mmHg)", lambda r: _f(r.mspd_mmHg, 1), ref("mspd_mmHg", 1)),
        ("PSPD, section mean, 2 ms smoothed (mmHg)", lambda r: _f(r.pspd_mmHg, 1), ref("pspd_mmHg", 1)),
        ("PSPD time (ms)", lambda r: _f(r.pspd_time_s, 0, 1e3), ref("pspd_time_s", 0, 1e3)),
        ("— raw: centre probes' largest ΔP (mmHg)", lambda r: _f(r.pspd_probe_mmHg, 1), ["–"] * len(refs)),
        (f"EOA ({u['eoa']})", lambda r: _f(r.eoa, 2), ref("eoa", 2)),
        (f"regurgitant volume ({u['volume']})" + ("; a partial cycle's: closing + the leakage extrapolated from "
                                                  "the leak rate (extrap.)" if partial else ""),
         regurgitant, ref("regurgitant_volume", 1)),
        (f"— closing ({u['volume']})", lambda r: _f(r.closing_volume, 2), none),
        (f"— leakage to the series' end, −∫Q ({u['volume']})", lambda r: _f(r.leakage_volume, 2), none),
        (f"— leak rate, backflow, fitted ± half its halves' difference ({u['volume']}/s)", leak_rate_cell, none),
        (f"— leak rate through the valve, particles on the ventricle's side, ± half its halves' difference "
         f"({u['volume']}/s)", valve_leak_cell, none),
        (f"— leakage from the leak rate (through the valve where measured: particles), closure to cycle end "
         f"({u['volume']})", leakage_from_rate_cell, none),
        (f"— leak rate by flow section, lowest to highest ({u['volume']}/s)", section_rates_cell, none),
        ("— leak-rate fit: span (ms in the cycle); ringing period, e-folding time (ms)", leak_fit_cell, none),
        (f"peak flow rate ({u['flow_min']})", lambda r: _f(r.peak_flow_L_per_min, 2), ref("peak_flow_L_per_min", 1)),
        ("peak velocity 15 mm downstream, jet core (m/s)", lambda r: _f(r.peak_velocity_m_per_s, 2), ref("peak_velocity_m_per_s", 2)),
        ("peak velocity time (ms)", lambda r: _f(r.peak_velocity_time_s, 0, 1e3), ref("peak_velocity_time_s", 0, 1e3)),
        ("— raw: fastest particle on the plane (m/s)", lambda r: _f(r.peak_particle_speed, 2), ["–"] * len(refs)),
        (f"peak pull-out force, systole ({u['force']})", lambda r: _f(r.pull_out_force, 3), ref("pull_out_force", 2)),
        (f"peak diastolic force ({u['force']})", lambda r: _f(r.diastolic_force, 2), ref("diastolic_force", 1)),
        ("diastolic force time (ms)", lambda r: _f(r.diastolic_force_time_s, 0, 1e3), ref("diastolic_force_time_s", 0, 1e3)),
        (f"hydrostatic force Pmax·A ({u['force']})", lambda r: _f(r.hydrostatic_force, 2), ref("hydrostatic_force", 1)),
        ("water-hammer ratio", lambda r: _f(r.water_hammer_ratio, 2), [ref_ratio(r) for r in refs]),
        ("forward flow (ms)", lambda r: f"{r.forward_start_s * 1e3:.0f}–{r.forward_end_s * 1e3:.0f}", ["–"] * len(refs)),
    ]
    if any(r.tip_gap_mm is not None for r in results.values()):
        at = next(i for i, row in enumerate(spec) if row[0].startswith("— leak rate, backflow"))
        spec[at:at] = [
            ("— 2D: the tips' gap, mean from the closure to the series' end (mm)", lambda r: _f(r.tip_gap_mm, 3), none),
            (f"— 2D: the orifice law through that gap, C_d {SLIT_DISCHARGE_COEFFICIENT:g}, over the same span "
             f"({u['volume']})", lambda r: _f(r.tip_gap_orifice_leakage, 2), none)]
    if partial:
        spec.append(("partial cycle: series ends at (ms); leakage to it, diastolic force up to it",
                     lambda r: _f(r.series_end_s, 0, 1e3), none))
    for label, ours, theirs in spec:
        rows.append(f"| {label} | " + " | ".join(ours(results[m]) for m in models) + " | " + " | ".join(theirs) + " |")
    refusals = [f"{m}: {r.leak_refusal}" for m, r in results.items() if r.leak_refusal]
    if refusals:
        rows += ["", "No leak rate: " + "; ".join(refusals) + "."]
    refusals = [f"{m}: {r.valve_leak_refusal}" for m, r in results.items() if r.valve_leak_refusal]
    if refusals:
        rows += ["", "No leak rate through the valve by particle count: " + "; ".join(refusals) + "."]
    return "\n".join(rows) + "\n"


def plotted_flow_and_force(series: ProbeSeries, result: CycleHemodynamics, period: float = waveform.PERIOD_S):
    """The plot's flow (mL/s; 2D cm^2/s) on the probe times of the cycle and its axial force
    (times in ms from the cycle's start, N; 2D N/m), both of the whole valve: a sector's are
    multiplied by the result's symmetry factor, as the table's are."""
    start = (result.cycle - 1) * period
    sel = (series.time >= start) & (series.time <= start + period)
    to_volume = 1e6 if series.dimension == 3 else 1e4
    flow = series.mean_flow_rate[sel] * to_volume * result.symmetry_factor
    if series.axial_force is None or series.force_time is None:
        return flow, None, None
    fs = (series.force_time >= start) & (series.force_time <= start + period)
    return flow, (series.force_time[fs] - start) * 1e3, series.axial_force[fs] * result.symmetry_factor


def plot_cycle(series: ProbeSeries, result: CycleHemodynamics, path: Path, period: float = waveform.PERIOD_S) -> None:
    """Like the reference's Fig. 11: pressure drop, flow rate, axial leaflet force and maximum
    velocity over the analysed cycle."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    start = (result.cycle - 1) * period
    sel = (series.time >= start) & (series.time <= start + period)
    t = (series.time[sel] - start) * 1e3
    u = _units(series.dimension)
    flow, force_time, force = plotted_flow_and_force(series, result, period)
    fig, axes = plt.subplots(4, 1, figsize=(7, 9), sharex=True)
    axes[0].plot(t, series.pressure_drop[sel] / PA_PER_MMHG, "k-", lw=0.8)
    axes[0].set_ylabel("ΔP (mmHg)")
    axes[1].plot(t, flow, "b-", lw=0.8)
    axes[1].set_ylabel(f"Q ({u['flow']})")
    if force is not None:
        axes[2].plot(force_time, force, "r-", lw=0.8)
        axes[2].axhline(result.hydrostatic_force, color="0.5", ls="--", lw=0.8, label="hydrostatic Pmax·A")
        axes[2].legend(fontsize=8)
    axes[2].set_ylabel(f"axial force ({u['force']})")
    if series.max_velocity is not None:
        axes[3].plot(t, series.max_velocity[sel], "g-", lw=0.8)
    axes[3].set_ylabel("max speed 15 mm (m/s)")
    axes[3].set_xlabel(f"time in cycle {result.cycle} (ms)")
    for ax in axes:
        ax.axvspan(result.forward_start_s * 1e3, result.forward_end_s * 1e3, color="y", alpha=0.15)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="Hemodynamics of an FSI run (fluid_probes.h5, coupling_series.h5).")
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--cycle", type=int, default=2, help="cycle analysed (1-based; default 2)")
    parser.add_argument("--model", default="this run", help="column name in the table, e.g. FSI-Ogden")
    parser.add_argument("--closure-time", type=float, help="valve closure within the cycle (s), e.g. from the kinematics")
    parser.add_argument("--sections", nargs="+", help="flow sections to average (default: all in the file)")
    parser.add_argument("--symmetry-factor", type=float,
                        help="flows and forces x this for the whole valve (6 for a 1/6-sector run); "
                             "default: what the fluid recorded in fluid_probes.h5, else 1")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    parser.add_argument("--png", type=Path, help="write the Fig. 11-like plot here")
    parser.add_argument("--partial", action="store_true",
                        help="accept a cycle the series does not finish, once its forward flow has ended")
    parser.add_argument("--no-particles", action="store_true",
                        help="do not read the particle snapshots for the leak through the valve")
    parser.add_argument("--particle-spacing", type=float,
                        help="the fluid's particle spacing (m) where no fluid.log states it")
    args = parser.parse_args(argv)
    series = read_run(args.run_dir, sections=args.sections, particles=not args.no_particles)
    result = analyse_cycle(series, args.cycle, closure_time_s=args.closure_time, symmetry_factor=args.symmetry_factor,
                           allow_partial=args.partial, particle_spacing=args.particle_spacing)
    table = hemodynamics_table({args.model: result})
    print(table)
    print("section stroke volumes:", {k: round(v, 3) for k, v in result.section_stroke_volumes.items()})
    if args.markdown:
        args.markdown.write_text(table)
    if args.png:
        plot_cycle(series, result, args.png)


if __name__ == "__main__":
    main()
