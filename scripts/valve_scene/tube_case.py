"""Writes the ISO 5840-3 tube (tube.py) as the `fluid { ... }` block of a case
(message valvefsi.cases.FluidCase, proto/fluid_case.proto).

Choices (docs/valve-scene.md, "Tube"):
- The gasket and the skirt are merged into one rigid ring (FluidAnnularDisk) between the stent
  radius and the tube wall, from the gasket's upstream face up to the commissure tops. A skirt
  as thin as the reference's would be a two-sided thin wall thinner than a particle, and a
  skirt ending below the scalloped attachment line would let blood bypass the leaflets; the
  ring avoids both and keeps the reference's "sudden contraction and expansion".
- The plates move with the flow (about 4 cm per cycle), so the tube extends beyond the
  outlet plate by the travel of all cycles; the inlet plate's travel fits in the upstream
  length.
"""
from __future__ import annotations

import math

from .tube import TubeSetup
from .valve_geometry import ValveParameters

PLATE_LAYERS = 3                      # plate thickness in particle spacings
STROKE_VOLUME_M3 = 60e-6              # generous: the reference's flow implies ~40 mL per beat
VELOCITY_PROBE_DOWNSTREAM = 15e-3     # maximum velocity 15 mm downstream of the annulus (ref. Fig. 11c)


def _vec(values) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


def fluid_block(particle_spacing: float, cycles: int, setup: TubeSetup | None = None,
                valve: ValveParameters | None = None, sound_speed: float = 145.0) -> str:
    """The fluid part of a full-valve FSI case (3D)."""
    setup = setup or TubeSetup()
    valve = valve or ValveParameters()
    setup.validate()
    dp = particle_spacing
    R_tube = 0.5 * setup.tube_diameter
    area = math.pi * R_tube ** 2
    plate = PLATE_LAYERS * dp
    travel = cycles * STROKE_VOLUME_M3 / area
    z_inlet = -setup.upstream_length
    z_outlet = setup.downstream_length
    tube_start = z_inlet - plate - 2 * dp
    tube_end = z_outlet + plate + travel + 2 * dp
    ring_start = setup.gasket_z - setup.gasket_thickness
    margin = 6 * dp
    probes_z = {"inlet_side": z_inlet + 10e-3, "upstream_tap": -setup.upstream_tap_distance,
                "leaflet_base": 0.0, "commissure_tops": valve.commissure_height,
                "downstream_tap": setup.downstream_tap_distance}
    lines = [
        "fluid {",
        f"  particle_spacing: {dp:g}",
        "  kernel: CUBIC_SPLINE",
        "  density: 1056",
        "  dynamic_viscosity: 0.0035",
        f"  sound_speed: {sound_speed:g}",
        "  density_diffusion: 0.1",
        f"  domain_lower: {_vec([-R_tube - margin, -R_tube - margin, tube_start - margin])}",
        f"  domain_upper: {_vec([R_tube + margin, R_tube + margin, tube_end + margin])}",
        f"  lattice_origin: {_vec([0.0, 0.0, z_inlet])}",
        "  # blood between the plates; the walls take precedence",
        f"  fluid_blocks {{ box {{ lower: {_vec([-R_tube, -R_tube, z_inlet])} upper: {_vec([R_tube, R_tube, z_outlet])} }} }}",
        f"  # ISO 5840-3 tube, {setup.tube_diameter * 1e3:.1f} mm, extended past the outlet plate by its travel",
        f"  walls {{ tube {{ origin: {_vec([0, 0, tube_start])} axis: [0, 0, 1] length: {tube_end - tube_start:.6g} radius: {R_tube:.6g} }} }}",
        "  # gasket + skirt: rigid ring from the stent radius to the tube wall, gasket to commissure tops",
        f"  walls {{ annular_disk {{ origin: {_vec([0, 0, ring_start])} axis: [0, 0, 1] "
        f"thickness: {valve.commissure_height - ring_start:.6g} inner_radius: {valve.annulus_radius:.6g} outer_radius: {R_tube:.6g} }} }}",
        "  # inlet plate: left-ventricular pressure",
        "  plates {",
        f"    shape {{ annular_disk {{ origin: {_vec([0, 0, z_inlet - plate])} axis: [0, 0, 1] thickness: {plate:.6g} outer_radius: {R_tube:.6g} }} }}",
        f"    normal: [0, 0, 1] area: {area:.6g} pressure_source: VENTRICULAR",
        "  }",
        "  # outlet plate: aortic pressure",
        "  plates {",
        f"    shape {{ annular_disk {{ origin: {_vec([0, 0, z_outlet])} axis: [0, 0, 1] thickness: {plate:.6g} outer_radius: {R_tube:.6g} }} }}",
        f"    normal: [0, 0, -1] area: {area:.6g} pressure_source: AORTIC",
        "  }",
        "  probes {",
    ]
    for name in ("upstream_tap", "downstream_tap"):
        lines.append(f"    pressure_points {{ name: \"{name}\" position: {_vec([0, 0, probes_z[name]])} }}")
    for name, z in probes_z.items():
        lines.append(f"    flow_planes {{ name: \"{name}\" point: {_vec([0, 0, z])} normal: [0, 0, 1] }}")
    lines.append(f"    velocity_planes {{ name: \"15mm_downstream\" point: {_vec([0, 0, VELOCITY_PROBE_DOWNSTREAM])} normal: [0, 0, 1] }}")
    lines += ["    wall_forces: true", "  }", "}"]
    return "\n".join(lines) + "\n"
