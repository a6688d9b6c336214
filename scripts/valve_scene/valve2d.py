"""The 2D valve scene (issue 7, item 1): two leaflets in a plane channel through the valve axis,
as a strip mesh for solid_fe and FE-only / FSI case files.

    cd scripts && /usr/bin/python3 -m valve_scene.valve2d [--cases-dir ../cases] [--png X.png]

Frame (2D, docs/valve-scene.md "2D valve scene"): x is the axial flow direction (ventricle
x < 0, aorta x > 0), y the radial direction, z out of plane; the leaflets' attached ends are
on the stent's inner faces y = +-R at x = 0 (the 3D leaflet base).

Each leaflet is the radial-axial section of the 3D valve through a leaflet belly (the bisecting
plane s = 0 of valve_geometry): the Bezier curve from the attachment base (r = R, z = 0) to the
free-edge midpoint, mapped (r, z) -> (x = z, y = +-r); leaflet 0 is the upper one (y > 0).
The strip (shared contract, docs/valve-scene.md): the polyline at z = 0 (node set strip_front)
and its copy at z = strip_depth (strip_back), two shell triangles per segment, normals toward
the outflow side as in 3D, circumferential axis +z, radial axis along the polyline.
"""
from __future__ import annotations

import argparse
import dataclasses
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import waveform
from .mesh_io import write_mesh
from .tube import TubeSetup
from .hemodynamics import JET_CORE_PLANE, JET_CORE_RADIUS_M, SECTION_SUFFIX
from .tube_case import SECTION_PROBE_FRACTIONS, aortic_pressure_at_opening_mmHg
from .valve_geometry import ValveParameters
from .valve_mesh import ValveMesh, leaflet_grid

CASES_DIR = Path(__file__).resolve().parents[2] / "cases"
# Segments per leaflet: about one per particle spacing (0.80 mm at coarse).
SEGMENTS = {"xcoarse": 7, "coarse": 14, "medium": 28}
# Fluid particle spacing. xcoarse: 23 mm / 12, so that the 23 mm orifice spans whole spacings
# (both stent faces on lattice planes); the channel's axial faces snap to its lattice.
PARTICLE_SPACING_2D = {"xcoarse": 23.0e-3 / 12.0, "coarse": 1.0e-3, "medium": 0.5e-3}
STRIP_DEPTH = 1.0e-3            # m; solid_case.proto's default strip_depth
LEAFLETS_2D = 2
PA_PER_MMHG = 133.322387415
CYCLES = 2
BLOOD_DENSITY = 1056.0          # kg/m^3 (reference Sec. 2.3)
LEAFLET_DENSITY = 1100.0        # kg/m^3 (reference Sec. 2.2)
# FE-only 2D only (measured, docs/valve-scene.md): mass damping (1/s) in place of the absent fluid,
# and the fraction of the solid's estimated stable step that survives the stent-plane impacts.
FE_ONLY_DAMPING_PER_S = 100.0
FE_ONLY_TIME_STEP_SAFETY = 0.3
LEAFLET_SHAPES = ("flat", "belly")
# The 2D FSI cases start the fluid at gauge 0 without a background pressure. Without it the
# ventricular plate, driven at LV - 80.7 mmHg ~ -75 mmHg gauge in diastole, pulls the blood into
# tension: the blood parts from it and the plate flies off upstream (972 m by 1.6 s in both
# session-4 runs), so diastole has no ventricular pressure and cycle 2 no forward flow
# (docs/fsi-2d.md). With it, the coarse 2D valve's leaflet force reaches 255 N/m within 10 ms
# (fsi.valve2d_first_10ms bounds it at 20 N/m) and the xcoarse taps spike by ~100 mmHg in the
# opening; session 4 ran the xcoarse cycles both ways (docs/fsi-2d.md). Off until one is fixed.
BACKGROUND_PRESSURE_2D = False
# Session 5: without it, fluid.plates_never_pull raises both plates' pressures by one common level
# whenever the ventricular one would go below 0, so no plate pulls on the blood (docs/fluid_sph.md).
# The fluid's CFL number and the coupling window (a multiple of the mu = 1 window), from the
# stability map (docs/stability-map.md, session 5): with the leaflets two-sided along their whole
# length (the sinus behind them), the coarse valve at CFL 0.2 and the mu = 1 window (6.5 us) runs
# away at 25 ms (a free edge at 22 m/s, 1,300 N/m); CFL 0.15 at 28.8 ms; CFL 0.1 reaches 30 ms
# but with 796 N/m. With CFL 0.1 and a window of 2 or 3 x (13 or 19.5 us, the fluid sub-cycling
# twice or three times) the leaflet force stays at 3 N/m and the edge below 0.6 m/s.
FLUID_CFL_2D = 0.1
COUPLING_WINDOW_FACTOR_2D = 2.0
# Session 6: the coupled leaflets are twice as heavy as the tissue (2 x 1100 kg/m^3), so the
# 13 us window has mu = 1 instead of 2, the 1D piston's neutral limit where serial explicit
# coupling neither damps nor grows a leaflet's fastest mode. At mu = 2 the coarse 2D valve's
# leaflet rang in a 10.7 kHz in-plane mode (1 m/s at every node, neighbours in antiphase) from
# ~0.17 s until the solid's energy stop (0.258 s) or the coupler's runaway bound (0.275-0.30 s);
# at mu = 1 the same restart closes at 0.28 s (diastole: docs/fsi-2d.md, "Session 6").
# The leaflet's own inertia (rho_s t = 0.55 kg/m^2) stays ~5 % of the blood's added mass on it
# (~rho_f L = 12 kg/m^2), so the kinematics hardly change; the FE-only cases keep the tissue's.
FSI_LEAFLET_DENSITY_FACTOR_2D = 2.0
# Closed, the heavier leaflets' tips chatter on the annulus plane under the diastolic load (the
# pressed-flap instability of docs/solid_fe.md, which mass damping of 200 /s cures there): from the
# same restart the undamped valve runs away at 0.358 s (tip at 20.6 m/s), the damped one holds
# its tips within 0.7 mm of the axis past the -97 mmHg peak (docs/fsi-2d.md, "Session 6"). The
# damping's force, 200 /s x 0.55 kg/m^2 = 110 Pa per m/s, is below 1 mmHg at the leaflets' speeds.
FSI_MASS_DAMPING_PER_S_2D = 200.0
RESTART_INTERVAL_2D_S = 0.2
# The coaptation tie (solid_fe, docs/solid_fe.md "Coaptation tie"): the touching tips are held
# on the annulus plane until the tie pulls harder than this per metre of depth. A forward
# gradient dp loads the 11.25 mm flap with dp L = 1.5 N/m per mmHg, and a flap held at both ends
# pulls on its tip about 2.8x its load (the solid's test: membrane tension), ~4.2 N/m per mmHg:
# 10 N/m lets go near 2.4 mmHg forward (the waveform passes it ~5 ms into ejection, before the
# FSI valve's inertia lets it move) and holds against the diastolic sloshing dips that lifted
# the untied tips (docs/fsi-2d.md).
# Off in the cases: tried in session 4 (two 2D xcoarse cycles, docs/comparison.md "Reading this
# report"), the fluid pulls the tips at 200-230 N/m, 20x the release force, so the tie caught and
# released them ~1,000-1,800 times per cycle and did not hold the valve shut, while it delayed the
# FE-only opening (6.8 vs 3.7 ms) and broke the FE-only cycle-to-cycle agreement (11 % vs 2 %).
COAPTATION_TIE = False
# Session 8: the leaflet's self-contact (solid.leaflet_self_contact). In cycle 2 of the coarse
# FSI-MHGO run leaflet A crumpled in the jet and passed through itself from 0.87 s (25 crossings
# in 13 snapshots); a wall that crosses itself has no sides, and particles leaked there until the
# leak stop (0.993 s). With the leaflet held apart from itself (session 7's per-column contact
# sets) the same restart ran to 1.6 s with no crossing and no leak (docs/fsi-2d.md, sessions 7-8).
# The FE-only cases carry it too (the same leaflet; their runs are unchanged, the solid's step
# ~35 % dearer: docs/solid_fe.md, "Self-contact").
LEAFLET_SELF_CONTACT_2D = True
# Session 8: the ventricle's plate floor (fluid.plate_pressure_floor_mmHg with
# plate_pressure_floor_once_reached): once the lower plate's drive has first risen to it (~55 ms
# into the first systole), the lower plate is never driven below it, so the diastolic
# ventricle's plate is pushed back to the blood instead of coasting away (docs/fsi-2d.md,
# "Session 6"); before that the start is that of a case without floor (the plain floor from
# t = 0 raised the leaflet force to 88 N/m in the first 10 ms against 1.2 N/m).
PLATE_PRESSURE_FLOOR_2D_MMHG = 20.0
COAPTATION_TIE_RELEASE_N_PER_M = 10.0
# Session 21: the fluid's coaptation bridge (fluid.thin_walls.coaptation_distance). The shells'
# contact keeps the closed tips' mid-lines at least a thickness apart (0.49 mm at rest on the
# annulus plane with the 0.5 mm mesh gap), and the 2D section leaked through that gap as an
# orifice (7.5 cm^2 per cm over diastole; the 3D leaflets meet over millimetres instead). Tips
# within this distance are joined for the fluid (released at 1.25 times it): the regurgitant
# volume of the coarse FSI-MHGO cycle fell from 9.0 to 4.2 cm^2 per cm (docs/fsi-2d.md,
# "Session 21"). Above the mesh gap, so the tips at rest are joined; below the coarse spacing.
COAPTATION_DISTANCE_2D = 0.75e-3  # m
# Contact plane holding the closed 2D valve (docs/fsi-2d.md).
ANNULUS_PLANE = "annulus"


def belly_section(p: ValveParameters, segments: int) -> np.ndarray:
    """(axial, radial) of the leaflet's bisecting-plane section, [segments + 1, 2], uniform in
    arc length, from the attachment base to the free-edge midpoint."""
    column = leaflet_grid(p, 2, segments)[1]   # s = 0: the plane y = 0, x = radial coordinate
    return np.stack([column[:, 2], column[:, 0]], axis=1)


def radial_span(p: ValveParameters, segments: int) -> np.ndarray:
    """(axial, radial) of the 2D leaflet, [segments + 1, 2]: flat across the annulus plane x = 0
    from the attachment (0, R) to half the coaptation gap off the axis; its length R - gap/2
    is the closed 3D leaflet's radial span (docs/fsi-2d.md: why not the belly section)."""
    radial = np.linspace(p.annulus_radius, 0.5 * p.coaptation_gap, segments + 1)
    return np.stack([np.zeros_like(radial), radial], axis=1)


def leaflet_polylines(p: ValveParameters, segments: int, shape: str = "flat") -> list[np.ndarray]:
    """Mid-lines of the two 2D leaflets in the x-y plane, each [segments + 1, 2], attached end
    first: leaflet 0 at y > 0, leaflet 1 its mirror image. shape "flat" (the cases: the radial
    span) or "belly" (the 3D belly section, 16.3 mm: no closed 2D state, docs/fsi-2d.md)."""
    if shape not in LEAFLET_SHAPES:
        raise ValueError(f"2D leaflet shape '{shape}': allowed {', '.join(LEAFLET_SHAPES)}")
    section = radial_span(p, segments) if shape == "flat" else belly_section(p, segments)
    upper = section.copy()
    lower = section * np.array([1.0, -1.0])
    return [upper, lower]


def build_strip_mesh(resolution: str = "coarse", params: ValveParameters | None = None,
                     strip_depth: float = STRIP_DEPTH, segments: int | None = None,
                     shape: str = "flat") -> ValveMesh:
    """The two leaflets as one-element-deep strips (plane strain in solid_fe)."""
    p = params or ValveParameters()
    p.validate()
    if segments is None:
        if resolution not in SEGMENTS:
            raise ValueError(f"2D resolution '{resolution}': allowed {', '.join(SEGMENTS)}")
        segments = SEGMENTS[resolution]
    if segments < 1:
        raise ValueError(f"segments {segments}: allowed >= 1")
    if not strip_depth > 0:
        raise ValueError(f"strip_depth {strip_depth!r}: allowed > 0")
    lines = leaflet_polylines(p, segments, shape)
    leaflets = len(lines)
    n = segments + 1
    front = np.concatenate([np.column_stack([line, np.zeros(n)]) for line in lines])
    back = front + np.array([0.0, 0.0, strip_depth])
    mesh = ValveMesh(nodes=np.concatenate([front, back]))
    count = len(front)   # back node of front node i is i + count

    tris, radial = [], []
    for k, line in enumerate(lines):
        for i in range(segments):
            f0, f1 = k * n + i, k * n + i + 1
            b0, b1 = f0 + count, f1 + count
            # e_z x d points to the outflow side for the upper leaflet, d x e_z for the mirrored lower one
            if k == 0:
                tris += [[f0, b1, f1], [f0, b0, b1]]
            else:
                tris += [[f0, f1, b1], [f0, b1, b0]]
            d = line[i + 1] - line[i]
            d = np.append(d / np.linalg.norm(d), 0.0)
            radial += [d, d]
    mesh.triangles = np.array(tris, dtype=np.int64)
    mesh.triangle_thickness = np.full(len(tris), p.thickness)
    mesh.triangle_circumferential = np.tile([0.0, 0.0, 1.0], (len(tris), 1))
    mesh.triangle_radial = np.array(radial)

    def both_layers(ids) -> np.ndarray:
        ids = np.asarray(ids, dtype=np.int64)
        return np.sort(np.concatenate([ids, ids + count]))

    attached = [k * n for k in range(leaflets)]
    free = [k * n + segments for k in range(leaflets)]
    mesh.node_sets["strip_front"] = np.arange(count, dtype=np.int64)
    mesh.node_sets["strip_back"] = np.arange(count, 2 * count, dtype=np.int64)
    mesh.node_sets["attachment"] = both_layers(attached)
    mesh.node_sets["free_edge"] = both_layers(free)
    mesh.node_sets["free_edge_midpoints"] = np.array(free, dtype=np.int64)
    mesh.node_sets["triangle_nodes"] = np.arange(2 * count, dtype=np.int64)
    # the stent as rigid contact planes for the solid only (the 3D cases' stent cylinder: the face
    # half a thickness outside the attachment, so the mid-surface stays within |y| <= R). The fluid
    # has no wall there (its skirt ends at the annulus), so blood fills the sinus behind the open
    # leaflets and can push them shut; without the stop the open 2D flaps folded back into the
    # sinus, onto the skirt (docs/fsi-2d.md)
    face = p.annulus_radius + 0.5 * p.thickness
    mesh.contact_planes["stent_upper"] = (np.array([0.0, face, 0.0]), np.array([0.0, -1.0, 0.0]))
    mesh.contact_planes["stent_lower"] = (np.array([0.0, -face, 0.0]), np.array([0.0, 1.0, 0.0]))
    # the closed valve's support (docs/fsi-2d.md): the annulus plane x = 0, normal downstream, half
    # a thickness upstream so that mid-surface nodes keep x >= 0; it stands for the circumferential
    # load path to the commissures that a 2D section lacks (no frictionless closed equilibrium
    # exists without it). Opening is untouched: the leaflets move downstream of it.
    mesh.contact_planes[ANNULUS_PLANE] = (np.array([-0.5 * p.thickness, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]))
    per_leaflet = 2 * segments
    for k in range(leaflets):
        mesh.node_sets[f"leaflet_{k}"] = both_layers(np.arange(k * n, (k + 1) * n))
        mesh.element_sets[f"leaflet_{k}_triangles"] = (
            "triangle", np.arange(k * per_leaflet, (k + 1) * per_leaflet, dtype=np.int64))
    mesh.description = {
        "generator": "valve_scene.valve2d",
        "variant": "2d",
        "resolution": resolution if segments == SEGMENTS.get(resolution) else f"{segments}",
        "segments_per_leaflet": segments,
        "leaflet_count_in_file": leaflets,
        "strip_depth": strip_depth,
        **{f"param_{name}": value for name, value in p.__dict__.items()},
    }
    return mesh


def leaflet_length(p: ValveParameters, segments: int = 400, shape: str = "flat") -> float:
    section = leaflet_polylines(p, segments, shape)[0]
    return float(np.linalg.norm(np.diff(section, axis=0), axis=1).sum())


# ---------------------------------------------------------------------------------------------
# The channel and the fluid part of the FSI case


@dataclass(frozen=True)
class Channel2D:
    """The ISO tube's axial section as a channel (m). Defaults from TubeSetup and ValveParameters
    so that the 2D and 3D scenes share their dimensions."""
    width: float = TubeSetup().tube_diameter                   # 36.8 mm
    stent_radius: float = ValveParameters().annulus_radius      # orifice half-width (23 mm orifice)
    stent_start: float = TubeSetup().gasket_z - TubeSetup().gasket_thickness   # -6 mm: gasket's upstream face
    # the skirt ends at the annulus: the stent is not modelled downstream of the leaflet base (as
    # in the reference), so the open leaflets swing into the sinus, the 36.8 mm channel, and the
    # backflow can get behind them (against a stent face they stayed open, docs/fsi-2d.md)
    stent_end: float = 0.0
    # the fluid's gasket blocks reach this far past the annulus (rounded to whole spacings, at least
    # one): the attached leaflet end then lies on the block's face, not at its corner, where the
    # closed valve leaked round it (57 of the 58 cm^2/s per cm through it in diastole, 9 with the
    # seal; docs/fsi-2d.md, session 10)
    gasket_seal: float = 1.0e-3
    upstream_length: float = TubeSetup().upstream_length        # leaflet base -> inlet plate
    downstream_length: float = TubeSetup().downstream_length    # leaflet base -> outlet plate
    upstream_tap_distance: float = TubeSetup().upstream_tap_distance      # 1 valve diameter
    downstream_tap_distance: float = TubeSetup().downstream_tap_distance  # 3 valve diameters
    velocity_probe_distance: float = 15.0e-3                    # reference Fig. 11c
    # flow-rate sections (x, m): upstream tap, stent inflow, 30 mm downstream, downstream tap
    flow_sections: tuple = field(default=(-23.0e-3, -3.0e-3, 30.0e-3, 69.0e-3))
    plate_travel_per_cycle: float = 60.0e-3   # allowance; the lumped estimate is ~5 cm (docs)
    # room behind the inlet plate: diastolic leakage and the fluid's void push it back upstream
    # (11 mm past its start at 0.6 s in session 9's xcoarse run, which then lost particles round it)
    inlet_retreat_per_cycle: float = 20.0e-3

    def validate(self) -> None:
        checks = [
            ("width", self.width > 2 * self.stent_radius, "> 2 stent_radius"),
            ("stent_radius", self.stent_radius > 0, "> 0"),
            ("stent_start", -self.upstream_length < self.stent_start < 0, "in (-upstream_length, 0)"),
            ("stent_end", self.stent_start < self.stent_end < self.downstream_length, "in (stent_start, downstream_length)"),
            ("upstream_tap_distance", 0 < self.upstream_tap_distance < self.upstream_length, "in (0, upstream_length)"),
            ("downstream_tap_distance", 0 < self.downstream_tap_distance < self.downstream_length, "in (0, downstream_length)"),
            ("velocity_probe_distance", 0 < self.velocity_probe_distance < self.downstream_length, "in (0, downstream_length)"),
            ("flow_sections", all(-self.upstream_length < x < self.downstream_length for x in self.flow_sections),
             "every x in (-upstream_length, downstream_length)"),
            ("plate_travel_per_cycle", self.plate_travel_per_cycle >= 0, ">= 0"),
            ("inlet_retreat_per_cycle", self.inlet_retreat_per_cycle >= 0, ">= 0"),
            ("gasket_seal", 0 <= self.gasket_seal < self.downstream_length, "in [0, downstream_length)"),
        ]
        for name, ok, allowed in checks:
            if not ok:
                raise ValueError(f"2D channel parameter '{name}' = {getattr(self, name)!r}: allowed {allowed}")

    def on_lattice(self, dp: float) -> "Channel2D":
        """This channel with its axial faces (gasket, commissure tops, plates) moved to the nearest
        lattice planes of spacing dp (x = 0 is one); the orifice must span whole spacings."""
        cells = 2.0 * self.stent_radius / dp
        if abs(cells - round(cells)) > 1e-9:
            raise ValueError(f"particle spacing {dp!r} m: the {2 * self.stent_radius * 1e3:g} mm orifice must "
                             f"span a whole number of spacings (it spans {cells:.4f})")
        snap = lambda x: round(x / dp) * dp
        return dataclasses.replace(self, stent_start=snap(self.stent_start), stent_end=snap(self.stent_end),
                                   upstream_length=snap(self.upstream_length),
                                   downstream_length=snap(self.downstream_length))


@functools.lru_cache(maxsize=None)
def peak_forward_velocity() -> float:
    """Bernoulli jet speed of the waveform's peak forward gradient (m/s): sqrt(2 dp / rho)."""
    t = np.linspace(0.0, waveform.PERIOD_S, 8001)
    dp = float(np.max(waveform.transvalvular_pressure_mmHg(t))) * PA_PER_MMHG
    return math.sqrt(2.0 * dp / BLOOD_DENSITY)


def sound_speed_2d() -> float:
    """10x the expected peak speed: the Bernoulli speed (1.57 m/s) rounded up to 0.5 m/s, so
    the Mach number stays <= 0.1 (density variation ~1 %)."""
    return 10.0 * math.ceil(2.0 * peak_forward_velocity()) / 2.0


def mu_one_window(sound_speed: float, valve: ValveParameters | None = None) -> float:
    """Largest window with mu = 2 rho_f c dt / (rho_s t) <= 1 (docs/coupling-numerics.md (b):
    serial explicit is stable for mu < 2 in 1D; the leaflet has fluid on both sides, hence the 2),
    rounded down to 0.5 us."""
    valve = valve or ValveParameters()
    window = LEAFLET_DENSITY * valve.thickness / (2.0 * BLOOD_DENSITY * sound_speed)
    return math.floor(window / 0.5e-6) * 0.5e-6


def coupling_window(sound_speed: float, valve: ValveParameters | None = None) -> float:
    """The cases' window: COUPLING_WINDOW_FACTOR_2D x the mu = 1 window."""
    return COUPLING_WINDOW_FACTOR_2D * mu_one_window(sound_speed, valve)




def _vec(values) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


def fluid_block_2d(particle_spacing: float, cycles: int = CYCLES, channel: Channel2D | None = None,
                   sound_speed: float | None = None, background: bool = True) -> str:
    """The `fluid { ... }` block of the 2D FSI case (valvefsi.cases.FluidCase, 2-vectors).
    background: start the fluid at the aortic pressure at opening as background pressure (else
    at gauge 0; the plates carry the same offset either way, so gauge pressures are the same)."""
    dp = particle_spacing
    ch = (channel or Channel2D()).on_lattice(dp)
    ch.validate()
    c0 = sound_speed or sound_speed_2d()
    half = 0.5 * ch.width
    plate = 3 * dp
    x_in, x_out = -ch.upstream_length, ch.downstream_length
    channel_start = x_in - plate - cycles * ch.inlet_retreat_per_cycle - 2 * dp
    gasket_end = ch.stent_end + max(1, round(ch.gasket_seal / dp)) * dp
    # each plate stops the run before it leaves the channel (its back 2 dp inside the tube's end)
    # or reaches the gasket (2 dp short of it)
    inlet_range = [-cycles * ch.inlet_retreat_per_cycle, ch.stent_start - x_in - 2 * dp]
    outlet_range = [-cycles * ch.plate_travel_per_cycle, x_out - gasket_end - 2 * dp]
    channel_end = x_out + plate + cycles * ch.plate_travel_per_cycle + 2 * dp
    margin = 6 * dp
    offset = aortic_pressure_at_opening_mmHg()
    background_Pa = offset * PA_PER_MMHG if background else 0.0
    wall_top = half + margin
    wall_offset = (half + ch.stent_radius) % dp
    wall_offset = min(wall_offset, dp - wall_offset)
    lines = [
        "fluid {",
        f"  particle_spacing: {dp:.9g}",
        "  kernel: CUBIC_SPLINE",
        f"  density: {BLOOD_DENSITY:g}",
        "  dynamic_viscosity: 0.0035",
        f"  # 10x the Bernoulli speed of the peak forward gradient ({peak_forward_velocity():.2f} m/s, rounded up)",
        f"  sound_speed: {c0:g}",
        "  density_diffusion: 0.1",
        f"  # the fluid's step: CFL {FLUID_CFL_2D:g} (at 0.2 the coarse 2D valve runs away, docs/stability-map.md)",
        f"  cfl: {FLUID_CFL_2D:g}",
        "  # shifting keeps the leaflets' free ends stable (docs/thin-leaflet.md); at the fastest",
        "  # particle's speed near the leaflets, at each particle's own elsewhere, so that blood at",
        "  # rest does not drift past the flow sections (docs/fsi-2d.md, session 19)",
        "  shifting: 1",
        "  shifting_speed: SHIFT_BY_OWN_SPEED_AWAY_FROM_LEAFLETS",
        "  # windows of whole fluid steps: -26 % of the cycle's fluid steps, metrics within the",
        "  # scatter (docs/fsi-2d.md, session 19)",
        "  fit_coupling_window_to_steps: true",
        *([f"  # the fluid starts at the aortic pressure at opening ({offset:g} mmHg): background pressure",
           "  # plus the plates' offset below, so neither plate starts with a step load",
           f"  background_pressure: {background_Pa:.9g}"] if background else
          [f"  # no background pressure: gauge 0 = the aortic pressure at opening ({offset:g} mmHg), the",
           "  # plates' offset below",
           "  background_pressure: 0",
           "  # the diastolic ventricle would run at -75 mmHg gauge and its plate pull away from the",
           "  # blood: both plates are raised together so the lower one stays at 0 (docs/fsi-2d.md)",
           "  plates_never_pull: true",
           f"  # once the lower drive has reached it, the lower plate is held at {PLATE_PRESSURE_FLOOR_2D_MMHG:g} mmHg gauge (the",
           "  # end-diastolic ventricle), so the diastolic ventricle's plate stays on the blood (valve2d.py)",
           f"  plate_pressure_floor_mmHg: {PLATE_PRESSURE_FLOOR_2D_MMHG:g}",
           "  plate_pressure_floor_once_reached: true"]),
        f"  domain_lower: {_vec([channel_start - margin, -half - margin])}",
        f"  domain_upper: {_vec([channel_end + margin, half + margin])}",
        f"  # the stent faces y = +-R lie on lattice planes (the channel walls {wall_offset * 1e3:.2g} mm off them)",
        f"  lattice_origin: {_vec([0.0, -ch.stent_radius])}",
        f"  fluid_blocks {{ box {{ lower: {_vec([x_in, -half])} upper: {_vec([x_out, half])} }} }}",
        f"  # the ISO tube's section: a {ch.width * 1e3:.1f} mm channel, extended behind the inlet plate and past the",
        "  # outlet plate by their travel",
        f"  walls {{ tube {{ origin: {_vec([channel_start, 0])} axis: [1, 0] length: {channel_end - channel_start:.6g} radius: {half:.6g} }} }}",
        f"  # gasket + skirt: rigid blocks narrowing the channel to the {2 * ch.stent_radius * 1e3:.0f} mm orifice, to {(gasket_end - ch.stent_end) * 1e3:.2f} mm",
        "  # past the annulus so that the attached leaflet ends lie on their faces (sealed, valve2d.py)",
        f"  walls {{ solid_box {{ lower: {_vec([ch.stent_start, ch.stent_radius])} upper: {_vec([gasket_end, wall_top])} }} }}",
        f"  walls {{ solid_box {{ lower: {_vec([ch.stent_start, -wall_top])} upper: {_vec([gasket_end, -ch.stent_radius])} }} }}",
        "  # inlet plate: left-ventricular pressure",
        "  plates {",
        f"    shape {{ solid_box {{ lower: {_vec([x_in - plate, -half])} upper: {_vec([x_in, half])} }} }}",
        f"    normal: [1, 0] area: {ch.width:.6g} pressure_source: VENTRICULAR pressure_mmHg: {-offset:g}",
        f"    travel_range: {_vec(inlet_range)}",
        "  }",
        "  # outlet plate: aortic pressure",
        "  plates {",
        f"    shape {{ solid_box {{ lower: {_vec([x_out, -half])} upper: {_vec([x_out + plate, half])} }} }}",
        f"    normal: [-1, 0] area: {ch.width:.6g} pressure_source: AORTIC pressure_mmHg: {-offset:g}",
        f"    travel_range: {_vec(outlet_range)}",
        "  }",
        "  probes {",
        f"    pressure_points {{ name: \"upstream_tap\" position: {_vec([-ch.upstream_tap_distance, 0])} }}",
        f"    pressure_points {{ name: \"downstream_tap\" position: {_vec([ch.downstream_tap_distance, 0])} }}",
        "    # each tap is averaged over its cross-section (docs/hemodynamics.md): four more points across it",
    ]
    for tap, x in (("upstream_tap", -ch.upstream_tap_distance), ("downstream_tap", ch.downstream_tap_distance)):
        for k, fraction in enumerate(SECTION_PROBE_FRACTIONS, start=1):
            lines.append(f"    pressure_points {{ name: \"{tap}{SECTION_SUFFIX}{k}\" position: {_vec([x, fraction * half])} }}")
    lines.append(f"    # the jet core 15 mm downstream: flow through |y| < {JET_CORE_RADIUS_M * 1e3:g} mm (peak speed = flow / width)")
    lines.append(f"    flow_planes {{ name: \"{JET_CORE_PLANE}\" point: {_vec([ch.velocity_probe_distance, 0])} normal: [1, 0] "
                 f"radius: {JET_CORE_RADIUS_M:.6g} }}")
    for x in ch.flow_sections:
        lines.append(f"    flow_planes {{ name: \"{section_name(x)}\" point: {_vec([x, 0])} normal: [1, 0] }}")
    lines.append(f"    velocity_planes {{ name: \"{ch.velocity_probe_distance * 1e3:g}mm_downstream\" "
                 f"point: {_vec([ch.velocity_probe_distance, 0])} normal: [1, 0] }}")
    lines += ["    wall_forces: true", "  }",
              "  # free tips closer than this are joined for the fluid: the 2D section's coaptation (valve2d.py)",
              f"  thin_walls {{ virtual_spacing_ratio: 0.5 clearance_ratio: 0.1 coaptation_distance: {COAPTATION_DISTANCE_2D:g} }}",
              "}"]
    return "\n".join(lines) + "\n"


def section_name(x: float) -> str:
    mm = round(x * 1e3, 3)
    return f"x_{'m' if mm < 0 else 'p'}{abs(mm):g}mm"


# ---------------------------------------------------------------------------------------------
# Case files


@dataclass(frozen=True)
class Case2D:
    kind: str          # "FE" or "FSI"
    material: str      # "Ogden" or "MHGO"
    resolution: str    # "coarse" or "medium"

    @property
    def name(self) -> str:
        return f"{self.kind.lower()}-{self.material.lower()}-2d-{self.resolution}"

    @property
    def mesh_name(self) -> str:
        return f"valve-2d-{self.resolution}.mesh.h5"


def all_specs_2d() -> list[Case2D]:
    return [Case2D(k, m, r) for k in ("FE", "FSI") for m in ("Ogden", "MHGO") for r in SEGMENTS]


def header_2d(spec: Case2D) -> str:
    from .write_cases import _wrap_comment
    p = ValveParameters()
    ch = Channel2D()
    leaflet = (f"two {leaflet_length(p) * 1e3:.2f} mm leaflets (the closed 3D leaflet's radial span, "
               f"flat across the annulus, {SEGMENTS[spec.resolution]} segments each, {p.thickness * 1e3:g} mm thick, "
               f"plane-strain strips {STRIP_DEPTH * 1e3:g} mm deep), {spec.material} (reference Table 1), "
               "attached ends fixed at the skirt's corner (the annulus), opening onto the stent stop with blood behind them (the sinus), "
               "the closed valve held by the annulus contact plane "
               "(docs/fsi-2d.md)")
    if spec.kind == "FE":
        models = (f"the 2D valve: {leaflet}, under the 75 bpm Wiggers transvalvular pressure applied "
                  f"uniformly on the leaflets with no fluid (FE-only), {CYCLES} cycles.")
        shows = ("the leaflets open within ~30 ms onto the stent stop (|y| = R) through ejection, swing shut "
                 "when the gradient reverses (~0.245 s) and lie on the annulus plane through diastole, tips "
                 "within 0.5 mm of the axis (docs/fsi-2d.md)")
        run = f"/usr/bin/python3 scripts/run_case.py cases/{spec.name}.textproto --output runs/{spec.name} --fe-only"
    else:
        dp = PARTICLE_SPACING_2D[spec.resolution]
        models = (f"the 2D valve: {leaflet}, in a {ch.width * 1e3:.1f} mm channel (the ISO tube's "
                  f"axial section) narrowed by the gasket and stent to {2 * ch.stent_radius * 1e3:.0f} mm, "
                  f"SPH blood at {dp * 1e3:g} mm spacing (c0 = {sound_speed_2d():g} m/s), driven by the "
                  "Wiggers ventricular and aortic pressures on two plates, serial explicit coupling "
                  f"every {coupling_window(sound_speed_2d()) * 1e6:g} us; {CYCLES} cycles.")
        shows = ("opening delayed and slower than FE-only (the blood's inertia), a jet through the "
                 "orifice, closure after the gradient reverses (later than FE-only) with a brief "
                 "regurgitant flow, a diastolic leaflet force above the hydrostatic one (water hammer), "
                 "no particle leaking through a leaflet; hemodynamics per metre of depth "
                 "(python -m valve_scene.hemodynamics)")
        run = f"/usr/bin/python3 scripts/run_case.py cases/{spec.name}.textproto --output runs/{spec.name}"
    lines = [f"# {spec.kind}-{spec.material}, 2D valve (plane channel), {spec.resolution}.", "#",
             "# What it models: " + models,
             "# What it should show: " + shows + ".",
             "# Run (from the repository root; the mesh is written by",
             "#   `cd scripts && /usr/bin/python3 -m valve_scene.valve2d`):",
             "#   " + run,
             "# Generated by scripts/valve_scene/valve2d.py (docs/valve-scene.md); edit that, not this file."]
    return "\n".join(_wrap_comment(line) for line in lines) + "\n"


def case_text_2d(spec: Case2D) -> str:
    from .write_cases import MHGO, OGDEN
    title = (f"{spec.kind}-{spec.material}: 2D valve in a plane channel, {spec.resolution} "
             f"({'FE-only' if spec.kind == 'FE' else 'SPH-FE FSI'})")
    snapshots = 0.002 if spec.kind == "FE" else 0.01
    run = ("run {\n"
           f"  end_time: {CYCLES * waveform.PERIOD_S:g}\n"
           f"  output_dir: \"runs/{spec.name}\"\n"
           f"  fe_only: {'true' if spec.kind == 'FE' else 'false'}\n"
           "  dimension: 2\n"
           f"  snapshot_interval: {snapshots:g}\n"
           "  series_interval: 0.0001\n"
           "}\n")
    if spec.material == "Ogden":
        law = "  material: OGDEN\n  ogden { " + " ".join(f"{k}: {v:g}" for k, v in OGDEN.items()) + " }\n"
    else:
        law = "  material: MHGO\n  mhgo { " + " ".join(f"{k}: {v:g}" for k, v in MHGO.items()) + " }\n"
    fsi_settings = ("  # damps the closed tips' chatter on the annulus plane (valve2d.py, docs/fsi-2d.md)\n"
                    f"  mass_damping_per_s: {FSI_MASS_DAMPING_PER_S_2D:g}\n") if spec.kind == "FSI" else ""
    fe_only_settings = ("  # FE-only 2D: damping stands in for the missing fluid (undamped, the strips flap at ~5 m/s\n"
                        "  # and break the run within 0.1 s); a third of the estimated step survives the stent contact\n"
                        f"  mass_damping_per_s: {FE_ONLY_DAMPING_PER_S:g}\n"
                        f"  time_step_safety: {FE_ONLY_TIME_STEP_SAFETY:g}\n") if spec.kind == "FE" else ""
    solid = ("solid {\n"
             f"  mesh_file: \"meshes/{spec.mesh_name}\"\n"
             "  element_family: SHELL\n"
             + law
             + (f"  # {FSI_LEAFLET_DENSITY_FACTOR_2D:g} x the tissue's {LEAFLET_DENSITY:g} kg/m^3: mu = 1 for the window (valve2d.py, docs/fsi-2d.md)\n"
                if spec.kind == "FSI" else "") +
             f"  density: {leaflet_density(spec.kind):g}\n"
             + strip_depth_line() + fe_only_settings + fsi_settings +
             "  fixed_node_sets: \"attachment\"\n"
             "  monitor_node_sets: \"free_edge_midpoints\"\n"
             + ("  # a leaflet cannot pass through itself (a crumpled strip leaked through its own folds, valve2d.py)\n"
                "  leaflet_self_contact: true\n" if LEAFLET_SELF_CONTACT_2D else "")
             + (f"  # the coapted tips stay on the annulus plane until pulled by {COAPTATION_TIE_RELEASE_N_PER_M:g} N/m (valve2d.py)\n"
                f"  coaptation_tie {{ contact_plane: \"{ANNULUS_PLANE}\" release_force_N_per_m: {COAPTATION_TIE_RELEASE_N_PER_M:g} }}\n"
                if COAPTATION_TIE else "") +
             "}\n")
    parts = [header_2d(spec), f"title: \"{title}\"\n", run, waveform.waveform_textproto(), solid]
    if spec.kind == "FSI":
        c0 = sound_speed_2d()
        parts += [fluid_block_2d(PARTICLE_SPACING_2D[spec.resolution], background=BACKGROUND_PRESSURE_2D),
                  "coupling {\n"
                  f"  # restart data every {RESTART_INTERVAL_2D_S:g} s: a cycle run that stops can go on (docs/coupling.md, \"Restarts\")\n"
                  f"  restart_interval_s: {RESTART_INTERVAL_2D_S:g}\n"
                  "  scheme: SERIAL_EXPLICIT\n"
                  f"  # acoustic estimate mu = 2 rho c dt / (rho_s t) = {2 * BLOOD_DENSITY * c0 * coupling_window(c0) / (leaflet_density(spec.kind) * ValveParameters().thickness):.2f} (the 1D piston's limit is 2);\n"
                  f"  # {COUPLING_WINDOW_FACTOR_2D:g} x the tissue's mu = 1 window, the fluid sub-cycling at CFL {FLUID_CFL_2D:g}; the leaflet\n"
                  f"  # {FSI_LEAFLET_DENSITY_FACTOR_2D:g} x as heavy (docs/stability-map.md, docs/fsi-2d.md)\n"
                  f"  window_size: {coupling_window(c0):g}\n"
                  "  mapping: NEAREST_PROJECTION\n"
                  "}\n"]
    return "".join(parts)


def leaflet_density(kind: str) -> float:
    """The solid's density in a 2D case: the tissue's FE-only, FSI_LEAFLET_DENSITY_FACTOR_2D x it coupled."""
    return LEAFLET_DENSITY * (FSI_LEAFLET_DENSITY_FACTOR_2D if kind == "FSI" else 1.0)


def strip_depth_line() -> str:
    return f"  strip_depth: {STRIP_DEPTH:g}\n"


DEFAULT_OPENING_END_S = 0.08   # the FSI valve is fully open by ~60 ms (docs/fsi-2d.md)


def default_opening_case_text(kind: str) -> str:
    """The README's main command (scripts/run-default.sh): the coarse MHGO valve's opening,
    FE-only and FSI, 0-80 ms, side by side (valve_scene.opening_2d)."""
    from .write_cases import _wrap_comment
    spec = Case2D(kind, "MHGO", "coarse")
    label = "fe" if kind == "FE" else "fsi"
    header = "\n".join(_wrap_comment(line) for line in [
        f"# Default case ({'FE-only' if kind == 'FE' else 'FSI'} half of the README's main command): the coarse 2D MHGO",
        f"#   valve of cases/{spec.name}.textproto, first {DEFAULT_OPENING_END_S * 1e3:g} ms only (the opening).",
        "# What it should show: " + ("the FE-only valve, under the uniform Wiggers pressure difference with no blood, "
                                     "opens in a few ms (reference FE-MHGO RVOT: 6 ms)." if kind == "FE" else
                                     "the FSI valve starts to open ~20 ms later and takes several times longer "
                                     "(reference FSI RVOT: 40 ms): the blood's inertia; no particle leaks."),
        "# Run: scripts/run-default.sh (both halves and the side-by-side plot, a few minutes on 2 cores)",
        "# Generated by scripts/valve_scene/valve2d.py; edit that, not this file."]) + "\n"
    text = case_text_2d(spec)
    body = text[text.index("title:"):]
    body = body.replace(f"  end_time: {CYCLES * waveform.PERIOD_S:g}\n", f"  end_time: {DEFAULT_OPENING_END_S:g}\n", 1)
    body = body.replace(f"  output_dir: \"runs/{spec.name}\"\n", f"  output_dir: \"runs/default/{label}\"\n", 1)
    return header + body


def write_2d(cases_dir: Path, meshes: bool = True) -> list[Path]:
    written = []
    for spec in all_specs_2d():
        path = cases_dir / f"{spec.name}.textproto"
        path.write_text(case_text_2d(spec))
        written.append(path)
    for kind in ("FE", "FSI"):
        path = cases_dir / f"default-{kind.lower()}-2d-opening.textproto"
        path.write_text(default_opening_case_text(kind))
        written.append(path)
    if meshes:
        for resolution in SEGMENTS:
            path = cases_dir / "meshes" / f"valve-2d-{resolution}.mesh.h5"
            write_mesh(build_strip_mesh(resolution), path)
            written.append(path)
    return written


def plot_scene(path: Path, resolution: str = "coarse") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    ch = Channel2D()
    lines = leaflet_polylines(ValveParameters(), SEGMENTS[resolution])
    half = 0.5 * ch.width * 1e3
    fig, ax = plt.subplots(figsize=(12, 3.2))
    x0, x1 = -ch.upstream_length * 1e3, ch.downstream_length * 1e3
    ax.plot([x0 - 5, x1 + 5], [half, half], "k-", [x0 - 5, x1 + 5], [-half, -half], "k-")
    for y0 in (ch.stent_radius * 1e3, -half):
        ax.add_patch(Rectangle((ch.stent_start * 1e3, y0), (ch.stent_end - ch.stent_start) * 1e3,
                               half - ch.stent_radius * 1e3, color="0.6"))
    for x, label in ((x0, "LV plate"), (x1, "Ao plate")):
        ax.add_patch(Rectangle((x - 3 if x < 0 else x, -half), 3, 2 * half, color="tab:blue", alpha=0.5))
        ax.text(x, half + 2, label, ha="center", fontsize=8)
    for line in lines:
        ax.plot(line[:, 0] * 1e3, line[:, 1] * 1e3, "o-", color="tab:orange", ms=2, lw=1.5)
    for name, x in (("p", -ch.upstream_tap_distance), ("p", ch.downstream_tap_distance)):
        ax.plot(x * 1e3, 0, "rv")
    for x in ch.flow_sections:
        ax.plot([x * 1e3] * 2, [-half, half], "g:", lw=0.8)
    ax.plot([ch.velocity_probe_distance * 1e3] * 2, [-half, half], "m--", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm, flow direction)")
    ax.set_ylabel("y (mm)")
    ax.set_title("2D valve scene: leaflets (orange), stent/gasket (grey), pressure taps (red), "
                 "flow sections (green), velocity section (magenta)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="Write the 2D valve's strip meshes and its FE-only and FSI case files.")
    parser.add_argument("--cases-dir", type=Path, default=CASES_DIR)
    parser.add_argument("--no-meshes", action="store_true", help="write only the case files")
    parser.add_argument("--png", type=Path, help="optional sketch of the scene")
    args = parser.parse_args(argv)
    for path in write_2d(args.cases_dir, meshes=not args.no_meshes):
        print(path)
    if args.png:
        plot_scene(args.png)
    p = ValveParameters()
    tips = [line[-1] for line in leaflet_polylines(p, SEGMENTS["coarse"])]
    print(f"leaflet length {leaflet_length(p) * 1e3:.2f} mm, tip gap {abs(tips[0][1] - tips[1][1]) * 1e3:.3f} mm, "
          f"c0 {sound_speed_2d():g} m/s, window {coupling_window(sound_speed_2d()) * 1e6:g} us")


if __name__ == "__main__":
    main()
