"""The ISO 5840-3 pulse-duplicator set-up of the reference study (its Fig. 3) as geometric
primitives: a rigid straight tube, a rigid gasket (annular plate) and skirt (cylinder) that
seal the tube to the valve, two pressure plates, and the pressure taps. Frame as the valve
mesh: z is the axis, flow toward +z, the leaflet base (lowest attachment point) at z = 0.

    cd scripts && /usr/bin/python3 -m valve_scene.tube --png ../docs/figures/iso5840-tube.png
"""
from __future__ import annotations

import argparse
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .valve_geometry import ValveParameters, attachment_point, leaflet_point


@dataclass(frozen=True)
class TubeSetup:
    """Dimensions in metres (see docs/valve-scene.md, "Tube", for the sources)."""
    tube_diameter: float = 36.8e-3          # ISO 5840-3 test section (reference, Sec. 2.3)
    downstream_length: float = 110.0e-3     # leaflet base -> outlet plate; a typical ascending aorta
    upstream_length: float = 145.0e-3       # inlet plate -> leaflet base: 255 mm of fluid in all,
                                            # as ~790,200 particles of 0.7 mm imply in the reference
    valve_radius: float = ValveParameters().annulus_radius  # stent inner radius (size 23)
    skirt_inflow_length: float = 5.0e-3     # skirt below the leaflet base, down to the gasket
    skirt_thickness: float = 0.5e-3
    gasket_thickness: float = 1.0e-3        # the gasket is the annular plate tube wall -> skirt
    upstream_tap_distance: float = 23.0e-3  # 1 valve diameter upstream of the leaflet base
    downstream_tap_distance: float = 69.0e-3  # 3 valve diameters downstream

    def validate(self) -> None:
        problems = []
        if not self.tube_diameter > 2 * (self.valve_radius + self.skirt_thickness):
            problems.append(("tube_diameter", "> 2 (valve_radius + skirt_thickness)"))
        if not 0 < self.downstream_tap_distance < self.downstream_length:
            problems.append(("downstream_tap_distance", "in (0, downstream_length)"))
        if not 0 < self.upstream_tap_distance < self.upstream_length - self.skirt_inflow_length:
            problems.append(("upstream_tap_distance", "in (0, upstream_length - skirt_inflow_length)"))
        for name in ("downstream_length", "upstream_length", "skirt_inflow_length", "skirt_thickness", "gasket_thickness"):
            if not getattr(self, name) > 0:
                problems.append((name, "> 0"))
        if problems:
            name, allowed = problems[0]
            raise ValueError(f"tube parameter '{name}' = {getattr(self, name)!r}: allowed {allowed}")

    @property
    def gasket_z(self) -> float:
        """Downstream face of the gasket = lower end of the skirt."""
        return -self.skirt_inflow_length

    def primitives(self, valve: ValveParameters | None = None) -> list[dict]:
        """The rigid parts and plates, each a dict with 'kind' and its dimensions (m). The
        skirt's top edge follows the leaflet attachment line (scalloped): blood passes only
        through the leaflets; above the attachment line the valve opens into the tube."""
        valve = valve or ValveParameters()
        self.validate()
        R_tube = 0.5 * self.tube_diameter
        return [
            {"name": "tube", "kind": "cylinder", "radius": R_tube, "z_min": -self.upstream_length,
             "z_max": self.downstream_length, "wetted_side": "inside"},
            {"name": "gasket", "kind": "annular_plate", "inner_radius": self.valve_radius,
             "outer_radius": R_tube, "z_min": self.gasket_z - self.gasket_thickness, "z_max": self.gasket_z},
            {"name": "skirt", "kind": "scalloped_cylinder", "radius": self.valve_radius,
             "thickness": self.skirt_thickness, "z_min": self.gasket_z - self.gasket_thickness,
             "top_edge": "leaflet attachment line z_att(azimuth) of the valve mesh (node set 'attachment')",
             "top_edge_min_z": 0.0, "top_edge_max_z": valve.commissure_height},
            {"name": "inlet_plate", "kind": "pressure_plate", "radius": R_tube, "z": -self.upstream_length,
             "pressure": "ventricular", "normal": [0.0, 0.0, 1.0]},
            {"name": "outlet_plate", "kind": "pressure_plate", "radius": R_tube, "z": self.downstream_length,
             "pressure": "aortic", "normal": [0.0, 0.0, -1.0]},
            {"name": "upstream_tap", "kind": "pressure_probe", "z": -self.upstream_tap_distance},
            {"name": "downstream_tap", "kind": "pressure_probe", "z": self.downstream_tap_distance},
        ]

    def fluid_volume(self) -> float:
        """Blood volume between the plates outside the rigid parts (m^3), valve closed and
        leaflets of zero volume: for particle-count estimates."""
        R_tube = 0.5 * self.tube_diameter
        total = math.pi * R_tube ** 2 * (self.upstream_length + self.downstream_length)
        gasket = math.pi * (R_tube ** 2 - self.valve_radius ** 2) * self.gasket_thickness
        # dead water between skirt and tube, below the attachment line, is still fluid
        return total - gasket


def skirt_top_height(azimuth, valve: ValveParameters | None = None) -> np.ndarray:
    """z of the skirt's top edge at the given azimuths (rad): the attachment line of the
    leaflet that covers the azimuth, and the commissure-tab top in the narrow gaps between
    neighbouring leaflets' tabs, so that the skirt closes the stent up to the attachment."""
    valve = valve or ValveParameters()
    azimuth = np.asarray(azimuth, dtype=float)
    sector = 2 * math.pi / 3
    local = np.mod(azimuth + 0.5 * sector, sector) - 0.5 * sector   # azimuth from the nearest leaflet centre
    s = local / valve.leaflet_half_angle
    covered = np.abs(s) <= 1.0 + 1e-9   # tolerance: tab azimuths recomputed from coordinates
    z = attachment_point(valve, np.clip(s, -1.0, 1.0))[..., 2]
    return np.where(covered, z, valve.commissure_height)


def plot(setup: TubeSetup, path: Path, valve: ValveParameters | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    valve = valve or ValveParameters()
    mm = 1e3
    R_tube = 0.5 * setup.tube_diameter * mm
    fig, ax = plt.subplots(figsize=(11, 5))
    z0, z1 = -setup.upstream_length * mm, setup.downstream_length * mm
    for side in (-1, 1):
        ax.add_patch(Rectangle((z0, side * R_tube), z1 - z0, side * 1.5, color="0.5"))
        zg = setup.gasket_z * mm
        ax.add_patch(Rectangle((zg - setup.gasket_thickness * mm, side * valve.annulus_radius * mm),
                               setup.gasket_thickness * mm, side * (R_tube - valve.annulus_radius * mm), color="k"))
    # skirt up to the attachment line, drawn in the x-z section (azimuth 0 and 180 deg)
    R_v = valve.annulus_radius * mm
    zg = setup.gasket_z * mm
    ax.plot([zg - setup.gasket_thickness * mm, 0.0], [R_v, R_v], color="tab:blue", lw=3)
    ax.plot([zg - setup.gasket_thickness * mm, valve.commissure_height * mm], [-R_v, -R_v], color="tab:blue", lw=3,
            label="skirt (to the attachment line: base at +x, commissure at -x in this section)")
    ax.plot([z0, z0], [-R_tube, R_tube], color="tab:red", lw=4, label="inlet plate (ventricular pressure)")
    ax.plot([z1, z1], [-R_tube, R_tube], color="tab:green", lw=4, label="outlet plate (aortic pressure)")
    # the leaflet's centre line in this section
    prof = leaflet_point(valve, 0.0, np.linspace(0, 1, 50)) * mm
    ax.plot(prof[:, 2], prof[:, 0], color="tab:orange", lw=2, label="leaflet (bisection profile, closed)")
    for name, z in (("upstream tap", -setup.upstream_tap_distance), ("downstream tap", setup.downstream_tap_distance)):
        ax.axvline(z * mm, color="0.3", ls=":", lw=1)
        ax.text(z * mm, R_tube + 3, name, ha="center", fontsize=8)
    ax.annotate("", xy=(z1, -R_tube - 5), xytext=(0, -R_tube - 5), arrowprops=dict(arrowstyle="<->"))
    ax.text(z1 / 2, -R_tube - 9, f"{setup.downstream_length * mm:.0f} mm downstream", ha="center", fontsize=8)
    ax.annotate("", xy=(z0, -R_tube - 5), xytext=(0, -R_tube - 5), arrowprops=dict(arrowstyle="<->"))
    ax.text(z0 / 2, -R_tube - 9, f"{setup.upstream_length * mm:.0f} mm upstream", ha="center", fontsize=8)
    ax.text(z0 + 3, 0, f"tube {setup.tube_diameter * mm:.1f} mm", fontsize=8)
    ax.set_xlim(z0 - 8, z1 + 8)
    ax.set_ylim(-R_tube - 13, R_tube + 8)
    ax.set_aspect("equal")
    ax.set_xlabel("z (mm), flow to the right; leaflet base at z = 0")
    ax.set_ylabel("x (mm)")
    ax.set_title("ISO 5840-3 set-up of the reference (its Fig. 3), section y = 0")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="Print the ISO 5840-3 tube primitives and draw them.")
    parser.add_argument("--png", type=Path, help="write the drawing here")
    args = parser.parse_args(argv)
    setup = TubeSetup()
    setup.validate()
    for key, value in asdict(setup).items():
        print(f"{key}: {value * 1e3:.2f} mm")
    print(f"fluid volume: {setup.fluid_volume() * 1e6:.0f} mL "
          f"= {setup.fluid_volume() / 0.7e-3 ** 3:,.0f} particles at 0.7 mm")
    for primitive in setup.primitives():
        print(primitive)
    if args.png:
        args.png.parent.mkdir(parents=True, exist_ok=True)
        plot(setup, args.png)


if __name__ == "__main__":
    main()
