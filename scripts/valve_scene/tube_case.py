"""Writes the ISO 5840-3 tube (tube.py) as the `fluid { ... }` block of a case
(message valvefsi.cases.FluidCase, proto/fluid_case.proto).

Choices (docs/valve-scene.md, "Tube"):
- The gasket and the skirt below the annulus plane are one rigid ring (FluidAnnularDisk)
  between the stent radius and the tube wall, from the gasket's upstream face to the annulus
  plane z = 0 (the leaflet base): above it the open leaflets have blood behind them (a ring to
  the commissure tops left none, and in 2D the open leaflets stuck to the stent).
- Between the annulus plane and the scalloped attachment line the skirt must still seal, or
  blood would bypass the leaflets under the scallops (~1.8 cm2 over the valve). No fluid
  primitive follows a scallop, so the skirt is written as one solid box per lattice column
  (x, y on the fluid lattice) with its centre at R <= r < R + skirt_layers * dp, from the ring
  up to the attachment line's height at the column's azimuth: exactly the lattice points of a
  scalloped cylinder wall skirt_layers particles thick (a kernel support, so the blood inside
  and the blood in the sinus outside do not see each other through it). The columns are those
  of the case's fill lattice: cubic columns on the sector's hex-prism lattice left 33 blood
  particles inside the skirt and 294 inside-sinus pairs within a support (measured with fluid_sph).
- The plates move with the flow (about 4 cm per cycle), so the tube extends beyond the
  outlet plate by the travel of all cycles; the inlet plate's travel fits in the upstream
  length.
"""
from __future__ import annotations

import math

import numpy as np

from .tube import TubeSetup
from .valve_geometry import LEAFLET_COUNT, SECTOR_HALF_ANGLE, ValveParameters

PLATE_LAYERS = 3                      # plate thickness in particle spacings
STROKE_VOLUME_M3 = 60e-6              # generous: the reference's flow implies ~40 mL per beat
VELOCITY_PROBE_DOWNSTREAM = 15e-3     # maximum velocity 15 mm downstream of the annulus (ref. Fig. 11c)
SECTION_PROBE_FRACTIONS = (-0.6, -0.3, 0.3, 0.6)   # extra tap probes across a section, x the tube radius
SECTOR_SECTION_AZIMUTHS_DEG = (10.0, 25.0, 35.0, 50.0)   # the sector's extra tap probes (inside its wedge)
SKIRT_LAYERS = 3                      # skirt thickness in particle spacings: ceil(2h / dp) at h = 1.3 dp
SECTOR_SKIRT_MARGIN = math.radians(15.0)  # skirt columns kept beyond the sector's mirror planes
# Skirt columns reach this far inside the stent radius (in particle spacings), from one spacing
# below the annulus plane to the attachment line: with them and the tops rounded up to the
# lattice, the leaflets' attachment line lies inside the wall (its nearest lattice point is a
# wall point). Without them the line was up to 1.13 dp from the nearest wall particle and, under
# the closed valve's 97 mmHg, blood squeezed from the sinus under the leaflets' base at ~5 m/s
# (docs/fsi-3d.md, "The leak under the leaflets' base").
SKIRT_INNER_OVERLAP = 0.75
SECTOR_FILL_LATTICE = "HEX_PRISM"     # the sector's fluid lattice (the full valve keeps CUBIC: no mirror planes)
# The 3D FSI fluid and window (session 6, docs/thin-leaflet.md "coupled sector"): the 2D valve's
# stable setting. c0 = 20 m/s (10x the waveform's Bernoulli jet speed, Mach <= 0.1), CFL 0.1,
# particle shifting, no background pressure (each kernel defect next to a leaflet pushes the blood
# with ~2 p_b grad(C)/rho: a sector at rest with p_b = 10.8 kPa reached 0.8 m/s, without it stays
# still), plates that never pull, node loads smoothed over 3 dp, and a window of at most 13 us
# (mu <= 2 for the 0.25 mm leaflet). At the old c0 = 145 m/s and 0.1 ms window (mu = 111) the
# coupled sector's force grew x100-1000 per window and the solid stopped at 0.82 ms; with these it
# opened (46.8 ms, session 6, 13 us window).
BLOOD_DENSITY = 1056.0                # kg/m^3, blood
FSI_3D_SOUND_SPEED = 20.0
FSI_3D_CFL = 0.1
FSI_3D_LOAD_SMOOTHING_RADIUS_RATIO = 3.0
# The plates' pressure reserve once reached (mmHg above gauge 0): from the first instant the lower
# plate's drive reaches it (0.118 s, in ejection; the largest lower drive of the cycle is 38.6
# mmHg at 0.158 s) both plates are lifted so that the lower one never falls below it. With the
# floor at 0 the diastolic ventricle's plate cannot hold the blood column the closing leaflets
# push: it coasted away at 0.32 m/s and tore the blood under the leaflets into tension
# (docs/fsi-3d.md, "What drives the closed leaflet").
FSI_3D_PLATE_PRESSURE_RESERVE_MMHG = 35.0
FSI_3D_MAX_COUPLING_WINDOW_S = 13.0e-6  # mu = 2: the explicit coupling's limit (docs/stability-map.md)
FSI_3D_SMOOTHING_LENGTH_RATIO = 1.3     # the fluid's default h / dp
# The fluid sub-cycles a window and shortens its last step to land on the window's end, so a 13 us
# window over 5.85 us steps cost 3 steps (2 and a 1.3 us sliver: session 7's profile,
# docs/fsi-3d.md). A window of two steps at 90 % of the step at rest costs 2 for as long as the
# fastest particle is below c0 / 9 (2.2 m/s; dt = CFL h / (c0 + v)): 16 % fewer fluid steps, and a
# lower mu (1.62 at 0.9 mm).
FSI_3D_FLUID_STEPS_PER_WINDOW = 2
FSI_3D_STEP_MARGIN = 0.9


def fsi_3d_coupling_window_s(particle_spacing: float) -> float:
    """The 3D FSI cases' coupling window for a fluid spacing: a whole number of fluid steps (with a
    margin for the flow's speed), never above the mu = 2 limit."""
    step_at_rest = FSI_3D_CFL * FSI_3D_SMOOTHING_LENGTH_RATIO * particle_spacing / FSI_3D_SOUND_SPEED
    return min(FSI_3D_MAX_COUPLING_WINDOW_S, FSI_3D_FLUID_STEPS_PER_WINDOW * FSI_3D_STEP_MARGIN * step_at_rest)


def _vec(values) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


PA_PER_MMHG = 133.322387415
SECTOR_TAP_RADIUS = 3.0e-3            # sector pressure taps: off the axis, where the two mirror planes meet


def aortic_pressure_at_opening_mmHg() -> float:
    """The waveform's pressures at t = 0 (both 80.73 mmHg: dp = 0 there), to 0.01 mmHg."""
    import numpy as np
    from . import waveform
    return round(float(waveform.aortic_pressure_mmHg()(np.array([0.0]))[0]), 2)


def sector_mirror_planes() -> list[tuple[list[float], list[float]]]:
    """The 1/6 sector's cut faces as fluid mirror planes (point, normal toward the fluid): the
    leaflet's bisecting plane y = 0 and the coaptation plane at 60 degrees, as in the sector mesh."""
    a = SECTOR_HALF_ANGLE
    return [([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 0.0], [math.sin(a), -math.cos(a), 0.0])]


def lattice_columns(particle_spacing: float, half_extent: float, lattice: str = "CUBIC") -> list[tuple[float, float]]:
    """The (x, y) of the fluid lattice's columns along z within |x|, |y| <= half_extent, for
    lattice_origin x, y = 0: CUBIC ((i + 1/2) dp, (j + 1/2) dp), or HEX_PRISM with axis z and rows
    along x (fluid_sph's fill, docs/fluid_sph.md "Fill lattice": side a = dp (2/sqrt 3)^1/2, rows
    h = a sqrt(3)/2 apart; x = a/4 + a i + a j/2, y = (j - 1/2) h, the same in every layer)."""
    dp = particle_spacing
    if lattice == "CUBIC":
        n = int(math.ceil(half_extent / dp)) + 1
        return [((i + 0.5) * dp, (j + 0.5) * dp) for i in range(-n, n) for j in range(-n, n)]
    if lattice != "HEX_PRISM":
        raise ValueError(f"fill lattice '{lattice}': allowed CUBIC or HEX_PRISM")
    a = dp * math.sqrt(2.0 / math.sqrt(3.0))
    h = 0.5 * math.sqrt(3.0) * a
    nj = int(math.ceil(half_extent / h)) + 2
    columns = []
    for j in range(-nj, nj + 1):
        start = 0.25 * a + 0.5 * a * j
        ni = int(math.ceil((half_extent + abs(start)) / a)) + 1
        columns += [(start + a * i, (j - 0.5) * h) for i in range(-ni, ni + 1)]
    return [(x, y) for x, y in columns if abs(x) <= half_extent and abs(y) <= half_extent]


def lattice_plane_at_or_above(z: float, particle_spacing: float, lattice_z0: float) -> float:
    """The lowest layer of the fluid lattice at or above z: layers lie at z0 + (k + 1/2) dp."""
    dp = particle_spacing
    return lattice_z0 + (math.ceil((z - lattice_z0) / dp - 0.5 - 1e-9) + 0.5) * dp


def skirt_columns(particle_spacing: float, valve: ValveParameters | None = None, sector: bool = False,
                  layers: int = SKIRT_LAYERS, lattice: str = "CUBIC", lattice_z0: float | None = None,
                  inner_overlap: float = SKIRT_INNER_OVERLAP) -> list[tuple[float, float, float | None, float]]:
    """The scalloped skirt above the annulus plane as lattice columns (x, y, bottom z, top z): every
    fluid-lattice column (CUBIC or HEX_PRISM, lattice_columns) whose centre lies at
    R - inner_overlap dp <= r < R + layers * dp, topped at the skirt's top edge
    (tube.skirt_top_height: the attachment line, the commissure-tab top between tabs) over the
    column's footprint (its azimuth +- dp / 2r), rounded up to the lattice layer at or above it
    when lattice_z0 (the lattice origin's z) is given. Columns at r >= R start at the ring (bottom
    None); those inside the stent radius start one spacing below the annulus plane, so they seal
    under the leaflets' base without narrowing the stent. A sector keeps the columns within its
    wedge plus a margin."""
    from .tube import skirt_top_height
    valve = valve or ValveParameters()
    dp = particle_spacing
    R = valve.annulus_radius
    outer = R + layers * dp
    inner = R - inner_overlap * dp
    columns = []
    for x, y in lattice_columns(dp, outer + dp, lattice):
        r = math.hypot(x, y)
        if not inner <= r < outer:
            continue
        azimuth = math.atan2(y, x)
        if sector and not -SECTOR_SKIRT_MARGIN <= azimuth <= SECTOR_HALF_ANGLE + SECTOR_SKIRT_MARGIN:
            continue
        # the highest top over the column's footprint, so the narrow gap between two
        # commissure tabs (0.5 mm, under a particle) is closed to the tab tops
        footprint = np.linspace(azimuth - 0.5 * dp / r, azimuth + 0.5 * dp / r, 9)
        top = float(np.max(skirt_top_height(footprint, valve)))
        if lattice_z0 is not None:
            top = lattice_plane_at_or_above(top, dp, lattice_z0) + 0.01 * dp   # the box holds that layer
        columns.append((x, y, None if r >= R else -dp, top))
    return columns


def fluid_block(particle_spacing: float, cycles: int, setup: TubeSetup | None = None,
                valve: ValveParameters | None = None, sound_speed: float = FSI_3D_SOUND_SPEED,
                sector: bool = False) -> str:
    """The fluid part of a full-valve (or, with sector=True, 1/6-sector) FSI case (3D). The
    sector keeps the full tube's walls, blocks and plates; its two mirror planes leave only the
    wedge's particles (fluid_sph drops those beyond a mirror plane), the plates' wetted areas
    are a sixth, and the pressure taps move 3 mm off the axis into the wedge (on the axis,
    where the planes meet, images of images are missing)."""
    setup = setup or TubeSetup()
    valve = valve or ValveParameters()
    setup.validate()
    dp = particle_spacing
    offset = aortic_pressure_at_opening_mmHg()
    R_tube = 0.5 * setup.tube_diameter
    tube_area = math.pi * R_tube ** 2
    area = tube_area / (2 * LEAFLET_COUNT if sector else 1)   # the plates' wetted area
    plate = PLATE_LAYERS * dp
    travel = cycles * STROKE_VOLUME_M3 / tube_area
    z_inlet = -setup.upstream_length
    z_outlet = setup.downstream_length
    tube_start = z_inlet - plate - 2 * dp
    tube_end = z_outlet + plate + travel + 2 * dp
    ring_start = setup.gasket_z - setup.gasket_thickness
    margin = 6 * dp
    lattice = SECTOR_FILL_LATTICE if sector else "CUBIC"
    half_column = 0.45 * dp   # a column box holds exactly its lattice column's points
    # flow sections stay ahead of the inlet plate over all cycles (it travels ~5 cm per cycle)
    probes_z = {"upstream_tap": -setup.upstream_tap_distance,
                "leaflet_base": 0.0, "commissure_tops": valve.commissure_height,
                "downstream_30mm": 30e-3, "downstream_tap": setup.downstream_tap_distance}
    lines = [
        "fluid {",
        f"  particle_spacing: {dp:g}",
        "  kernel: CUBIC_SPLINE",
        f"  density: {BLOOD_DENSITY:g}",
        "  dynamic_viscosity: 0.0035",
        "  # the 2D valve's stable fluid (tube_case.FSI_3D_*, docs/thin-leaflet.md): c0 = 10x the jet",
        "  # speed, CFL 0.1 (the coupling window below sub-cycled), particle shifting",
        f"  sound_speed: {sound_speed:g}",
        f"  cfl: {FSI_3D_CFL:g}",
        "  shifting: 1",
        "  # at the fastest particle's speed everywhere: shifting at each particle's own speed away from",
        "  # the leaflets (the 2D cases' setting) let the coarse sector's opening flutter run away at",
        "  # 20.3 ms from t = 0 (docs/fsi-3d.md, session 20)",
        "  shifting_speed: SHIFT_BY_FASTEST_PARTICLE",
        "  density_diffusion: 0.1",
        f"  # no background pressure: gauge 0 is the aortic pressure at opening ({offset:g} mmHg, the",
        "  # plates' offset below, so neither plate starts with a step load); a background pressure acts",
        "  # through the leaflets' incomplete kernels. No plate ever pulls on the blood.",
        "  background_pressure: 0",
        "  plates_never_pull: true",
        f"  # a pressure reserve for the diastolic blood columns, engaged in ejection (tube_case.py)",
        f"  plate_pressure_floor_mmHg: {FSI_3D_PLATE_PRESSURE_RESERVE_MMHG:g}",
        "  plate_pressure_floor_once_reached: true",
        "  # windows of whole fluid steps: the diastole's 3 steps per window become ~2.1 (docs/fsi-3d.md, session 18)",
        "  fit_coupling_window_to_steps: true",
        f"  thin_walls {{ load_smoothing_radius_ratio: {FSI_3D_LOAD_SMOOTHING_RADIUS_RATIO:g} }}",
        f"  domain_lower: {_vec([-margin if sector else -R_tube - margin, -margin if sector else -R_tube - margin, tube_start - margin])}",
        f"  domain_upper: {_vec([R_tube + margin, R_tube + margin, tube_end + margin])}",
        f"  lattice_origin: {_vec([0.0, 0.0, z_inlet])}",
        *(["  # hex-prism fill: triangular layers along the axis, rows along both mirror planes (docs/fluid_sph.md)",
           "  fill_lattice: HEX_PRISM",
           "  lattice_axis: [0, 0, 1]",
           "  lattice_row_direction: [1, 0, 0]"] if lattice == "HEX_PRISM" else []),
        *([f"  # 1/6 sector: the bisecting plane (on a lattice plane) and the coaptation plane as mirrors"] +
          [f"  mirror_planes {{ point: {_vec(point)} normal: [{', '.join(f'{v:.15g}' for v in normal)}] }}"
           for point, normal in sector_mirror_planes()]
          if sector else []),
        "  # blood between the plates; the walls take precedence",
        f"  fluid_blocks {{ box {{ lower: {_vec([-R_tube, -R_tube, z_inlet])} upper: {_vec([R_tube, R_tube, z_outlet])} }} }}",
        f"  # ISO 5840-3 tube, {setup.tube_diameter * 1e3:.1f} mm, extended past the outlet plate by its travel",
        f"  walls {{ tube {{ origin: {_vec([0, 0, tube_start])} axis: [0, 0, 1] length: {tube_end - tube_start:.6g} radius: {R_tube:.6g} }} }}",
        "  # gasket + skirt below the annulus: rigid ring from the stent radius to the tube wall, gasket to",
        "  # the annulus plane z = 0 (above it the open leaflets have blood behind them)",
        f"  walls {{ annular_disk {{ origin: {_vec([0, 0, ring_start])} axis: [0, 0, 1] "
        f"thickness: {-ring_start:.6g} inner_radius: {valve.annulus_radius:.6g} outer_radius: {R_tube:.6g} }} }}",
        f"  # scalloped skirt from the annulus plane to the attachment line, {SKIRT_LAYERS} particles thick and",
        f"  # {SKIRT_INNER_OVERLAP:g} dp inside the stent around the attachment (sealing under the leaflets' base):",
        "  # one solid box per fluid-lattice column, tops at the lattice layer at or above the line (tube_case.py)",
        *[f"  walls {{ solid_box {{ lower: {_vec([x - half_column, y - half_column, ring_start if bottom is None else bottom])} "
          f"upper: {_vec([x + half_column, y + half_column, top])} }} }}"
          for x, y, bottom, top in skirt_columns(dp, valve, sector, lattice=lattice, lattice_z0=z_inlet)],
        "  # inlet plate: left-ventricular pressure",
        "  plates {",
        f"    shape {{ annular_disk {{ origin: {_vec([0, 0, z_inlet - plate])} axis: [0, 0, 1] thickness: {plate:.6g} outer_radius: {R_tube:.6g} }} }}",
        f"    normal: [0, 0, 1] area: {area:.6g} pressure_source: VENTRICULAR pressure_mmHg: {-offset:g}",
        "  }",
        "  # outlet plate: aortic pressure",
        "  plates {",
        f"    shape {{ annular_disk {{ origin: {_vec([0, 0, z_outlet])} axis: [0, 0, 1] thickness: {plate:.6g} outer_radius: {R_tube:.6g} }} }}",
        f"    normal: [0, 0, -1] area: {area:.6g} pressure_source: AORTIC pressure_mmHg: {-offset:g}",
        "  }",
        "  probes {",
    ]
    tap_xy = ([SECTOR_TAP_RADIUS * math.cos(0.5 * SECTOR_HALF_ANGLE), SECTOR_TAP_RADIUS * math.sin(0.5 * SECTOR_HALF_ANGLE)]
              if sector else [0.0, 0.0])
    from .hemodynamics import JET_CORE_PLANE, JET_CORE_RADIUS_M, SECTION_SUFFIX
    for name in ("upstream_tap", "downstream_tap"):
        lines.append(f"    pressure_points {{ name: \"{name}\" position: {_vec(tap_xy + [probes_z[name]])} }}")
    lines.append("    # each tap is averaged over its cross-section (docs/hemodynamics.md): four more points at half the tube radius")
    for name in ("upstream_tap", "downstream_tap"):
        azimuths = (SECTOR_SECTION_AZIMUTHS_DEG if sector else (0.0, 90.0, 180.0, 270.0))
        for k, azimuth in enumerate(azimuths, start=1):
            a = math.radians(azimuth)
            xy = [0.5 * R_tube * math.cos(a), 0.5 * R_tube * math.sin(a)]
            lines.append(f"    pressure_points {{ name: \"{name}{SECTION_SUFFIX}{k}\" position: {_vec(xy + [probes_z[name]])} }}")
    lines.append(f"    # the jet core 15 mm downstream: flow through r < {JET_CORE_RADIUS_M * 1e3:g} mm (peak speed = flow / area)")
    lines.append(f"    flow_planes {{ name: \"{JET_CORE_PLANE}\" point: {_vec([0, 0, VELOCITY_PROBE_DOWNSTREAM])} normal: [0, 0, 1] "
                 f"radius: {JET_CORE_RADIUS_M:.6g} }}")
    for name, z in probes_z.items():
        lines.append(f"    flow_planes {{ name: \"{name}\" point: {_vec([0, 0, z])} normal: [0, 0, 1] }}")
    lines.append(f"    velocity_planes {{ name: \"15mm_downstream\" point: {_vec([0, 0, VELOCITY_PROBE_DOWNSTREAM])} normal: [0, 0, 1] }}")
    lines += ["    wall_forces: true", "  }", "}"]
    return "\n".join(lines) + "\n"
