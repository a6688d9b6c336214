"""The ISO 5840-3 tube description (issue 4, item 2)."""
import math
import unittest

from valve_scene.tube import TubeSetup


class Tube(unittest.TestCase):
    def test_reference_dimensions_and_fluid_volume(self):
        setup = TubeSetup()
        setup.validate()
        parts = {p["name"]: p for p in setup.primitives()}
        self.assertAlmostEqual(2 * parts["tube"]["radius"], 36.8e-3, delta=1e-12)
        self.assertAlmostEqual(parts["outlet_plate"]["z"], 110e-3, delta=1e-12)
        self.assertEqual(parts["gasket"]["inner_radius"], parts["skirt"]["radius"])
        self.assertEqual(parts["gasket"]["outer_radius"], parts["tube"]["radius"])
        # the reference's medium resolution: ~790,200 particles of 0.7 mm
        particles = setup.fluid_volume() / 0.7e-3 ** 3
        self.assertAlmostEqual(particles / 790200, 1.0, delta=0.02)
        # the pressure taps lie between the plates and outside the valve
        self.assertGreater(parts["upstream_tap"]["z"], parts["inlet_plate"]["z"])
        self.assertLess(parts["downstream_tap"]["z"], parts["outlet_plate"]["z"])

    def test_bad_dimensions_are_named(self):
        with self.assertRaisesRegex(ValueError, "tube_diameter"):
            TubeSetup(tube_diameter=20e-3).validate()
        with self.assertRaisesRegex(ValueError, "downstream_tap_distance"):
            TubeSetup(downstream_tap_distance=3 * 36.8e-3).validate()


if __name__ == "__main__":
    unittest.main()


class SkirtEdge(unittest.TestCase):
    def test_skirt_top_follows_the_attachment_nodes(self):
        import numpy as np
        from valve_scene.tube import skirt_top_height
        from valve_scene.valve_mesh import build_valve_mesh
        mesh = build_valve_mesh("full", "coarse", "triangles")
        x = mesh.nodes[mesh.node_sets["attachment"]]
        base_row = x[x[:, 2] < mesh.description["param_commissure_height"] - mesh.description["param_tab_height"] + 1e-12]
        phi = np.arctan2(base_row[:, 1], base_row[:, 0])
        np.testing.assert_allclose(skirt_top_height(phi), base_row[:, 2], atol=1e-12)
        gap = math.pi / 3   # the commissure between leaflets 0 and 1
        self.assertEqual(float(skirt_top_height(gap)), mesh.description["param_commissure_height"])


class FluidBlock(unittest.TestCase):
    def test_fluid_block_parses_as_a_case(self):
        import shutil
        import subprocess
        from pathlib import Path
        from valve_scene.tube_case import fluid_block
        if shutil.which("protoc") is None:
            self.skipTest("protoc not installed")
        repo = Path(__file__).resolve().parents[2]
        text = fluid_block(0.7e-3, cycles=2) + "run { end_time: 1.6 }\n"
        result = subprocess.run(["protoc", f"-I{repo / 'proto'}", "--encode=valvefsi.cases.Case",
                                 str(repo / "proto" / "case.proto")], input=text.encode(), capture_output=True)
        self.assertEqual(result.returncode, 0, result.stderr.decode())

    def test_plates_have_room_to_travel(self):
        import re
        from valve_scene.tube_case import fluid_block
        text = fluid_block(0.7e-3, cycles=2)
        length = float(re.search(r"tube \{ origin: \[0, 0, (\S+)\] axis: \[0, 0, 1\] length: (\S+)", text).group(2))
        start = float(re.search(r"tube \{ origin: \[0, 0, (\S+)\]", text).group(1))
        area = math.pi * 0.0184 ** 2
        # two strokes of 60 mL move the outlet plate 0.113 m beyond its start at 0.110 m
        self.assertGreater(start + length, 0.110 + 2 * 60e-6 / area)


def _walls(text):
    """The fluid block's ring (annular disks other than plates) and solid boxes, parsed."""
    import re
    num = r"(-?[\d.eE+-]+)"
    vec = rf"\[{num}, {num}, {num}\]"
    rings = [tuple(map(float, m.groups())) for m in re.finditer(
        rf"walls \{{ annular_disk \{{ origin: {vec} axis: \[0, 0, 1\] thickness: {num} inner_radius: {num} outer_radius: {num}", text)]
    boxes = [tuple(map(float, m.groups())) for m in re.finditer(
        rf"walls \{{ solid_box \{{ lower: {vec} upper: {vec}", text)]
    return rings, boxes


class StentRing(unittest.TestCase):
    """The 3D fluid stent ring ends at the annulus plane and a scalloped skirt seals under the
    attachment line (issue 7): the open leaflets have blood behind them, none bypasses them."""

    def check(self, sector):
        import numpy as np
        from valve_scene.tube import TubeSetup, skirt_top_height
        from valve_scene.tube_case import SKIRT_INNER_OVERLAP, fluid_block, lattice_plane_at_or_above
        from valve_scene.valve_geometry import SECTOR_HALF_ANGLE, ValveParameters
        dp = 0.9e-3
        valve, setup = ValveParameters(), TubeSetup()
        R, R_tube = valve.annulus_radius, 0.5 * setup.tube_diameter
        rings, boxes = _walls(fluid_block(dp, cycles=2, sector=sector))
        self.assertEqual(len(rings), 1)
        _, _, z0, thickness, inner, outer = rings[0]
        self.assertAlmostEqual(z0, setup.gasket_z - setup.gasket_thickness, delta=1e-12)
        self.assertAlmostEqual(z0 + thickness, 0.0, delta=1e-9)          # ends at the annulus plane
        self.assertAlmostEqual(inner, R, delta=1e-12)
        self.assertAlmostEqual(outer, R_tube, delta=1e-9)                # seals the tube upstream
        boxes = np.array(boxes)
        # the fluid's lattice (lattice_origin x, y = 0) near the stent, z from the ring to above the tabs:
        # cubic for the full valve, hex prism for the sector (docs/fluid_sph.md "Fill lattice":
        # x = a/4 + a i + a j/2, y = (j - 1/2) h, a = dp (2/sqrt 3)^1/2, h = a sqrt(3)/2)
        if sector:
            a = dp * math.sqrt(2 / math.sqrt(3))
            h = a * math.sqrt(3) / 2
            i, j = np.meshgrid(np.arange(-30, 31), np.arange(-20, 21), indexing="ij")
            x, y = 0.25 * a + a * i + 0.5 * a * j, (j - 0.5) * h
            x, y = x[np.abs(x) < 16 * dp], y[np.abs(x) < 16 * dp]
        else:
            grid = (np.arange(-16, 16) + 0.5) * dp
            x, y = np.meshgrid(grid, grid, indexing="ij")
        r, azimuth = np.hypot(x, y), np.arctan2(y, x)
        z_levels = z0 + (np.arange(0, int((14e-3 - z0) / dp)) + 0.5) * dp
        wedge = (azimuth >= 0) & (azimuth <= SECTOR_HALF_ANGLE) if sector else np.ones_like(r, bool)
        top_at = skirt_top_height(azimuth)
        for z in z_levels:
            solid = np.zeros_like(r, bool)
            for b in boxes:
                solid |= (x > b[0]) & (x < b[3]) & (y > b[1]) & (y < b[4]) & (z > b[2]) & (z < b[5])
            solid |= (z > z0) & (z < 0) & (r >= R) & (r <= R_tube)
            # sealed: every lattice point of the skirt wall (R <= r < R + 3 dp) under the attachment line
            under = wedge & (r >= R) & (r < R + 3 * dp) & (z < top_at)
            self.assertTrue(np.all(solid[under]), f"skirt gap at z = {z}")
            # sealed under the leaflets' base: the lattice points just inside the stent radius are
            # solid from one spacing below the annulus plane up to the attachment line, so the line
            # lies inside the wall (tests/scene/skirt_seal_test.cpp checks it on fluid_sph's fill)
            seal = wedge & (r >= R - SKIRT_INNER_OVERLAP * dp) & (r < R) & (z > -dp) & (z < top_at)
            self.assertTrue(np.all(solid[seal]), f"no seal under the leaflets' base at z = {z}")
            # blood behind the leaflets: outside the skirt and above the annulus plane nothing is solid,
            # and inside the stent nothing but that seal
            self.assertFalse(np.any(solid[wedge & (r < R - SKIRT_INNER_OVERLAP * dp)]), f"skirt inside the stent at z = {z}")
            if z < -dp:
                self.assertFalse(np.any(solid[wedge & (r < R)]), f"seal narrows the stent at z = {z}")
            if z > 0:
                self.assertFalse(np.any(solid[wedge & (r >= R + 3 * dp) & (r < R_tube)]), f"ring above the annulus at z = {z}")
            if z > valve.commissure_height + dp:
                self.assertFalse(np.any(solid[wedge & (r < R_tube)]), f"skirt above the commissures at z = {z}")
        # the scallop: at the leaflet's centre the skirt stops within a particle of the annulus plane,
        # at the commissures it reaches the tab tops
        centre = boxes[np.argmin(np.abs(np.arctan2(boxes[:, 1] + boxes[:, 4], boxes[:, 0] + boxes[:, 3])))]
        self.assertLess(centre[5], dp)
        # tops at the lattice layer at or above the line (lattice_origin z = the inlet plane)
        z_lattice = -setup.upstream_length
        self.assertAlmostEqual(boxes[:, 5].max(), lattice_plane_at_or_above(valve.commissure_height, dp, z_lattice) + 0.01 * dp, delta=1e-12)
        self.assertAlmostEqual(lattice_plane_at_or_above(0.35e-3, dp, z_lattice), 0.35e-3, delta=1e-12)
        self.assertAlmostEqual(lattice_plane_at_or_above(0.36e-3, dp, z_lattice), 1.25e-3, delta=1e-12)

    def test_full_valve(self):
        self.check(sector=False)

    def test_sector(self):
        self.check(sector=True)
