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
