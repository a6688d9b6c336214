"""The closed-state comparison's pieces on inputs with known answers (valve_scene.closed_state)."""
import math
import unittest

import numpy as np

from valve_scene.closed_state import (coaptation_normal, membrane_fibre_log_strain, mhgo_fibre_stress,
                                      neighbour_stress_ratio, to_sector_frame, top_area_elements)


class SectorFrame(unittest.TestCase):
    def test_every_sixth_maps_back_onto_the_sector(self):
        rng = np.random.default_rng(4)
        r, az, z = rng.uniform(1e-3, 11e-3, 50), rng.uniform(0.01, math.radians(59.0), 50), rng.uniform(0, 12e-3, 50)
        sector = np.stack([r * np.cos(az), r * np.sin(az), z], axis=1)
        for k in range(3):
            for mirrored in (False, True):
                a = (-az if mirrored else az) + k * 2 * math.pi / 3
                full = np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)
                mapped, leaflet = to_sector_frame(full)
                np.testing.assert_allclose(mapped, sector, atol=1e-15)
                self.assertTrue(np.all(leaflet == k))

    def test_a_node_past_the_coaptation_plane_has_a_negative_distance(self):
        n = coaptation_normal()
        inside = np.array([5e-3 * math.cos(math.radians(50)), 5e-3 * math.sin(math.radians(50)), 0.0])
        past = np.array([5e-3 * math.cos(math.radians(70)), 5e-3 * math.sin(math.radians(70)), 0.0])
        self.assertAlmostEqual(inside @ n, 5e-3 * math.sin(math.radians(10)), delta=1e-15)
        self.assertAlmostEqual(past @ n, -5e-3 * math.sin(math.radians(10)), delta=1e-15)


class FibreStrain(unittest.TestCase):
    def setUp(self):
        self.ref = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0]])
        self.tri = np.array([[0, 1, 2]])
        self.c, self.r = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]])

    def test_uniaxial_stretch_along_the_circumference(self):
        stretch = 1.2
        cur = self.ref * np.array([stretch, 1.0, 1.0]) + np.array([0.0, 0.0, 2e-3])   # moved, not only stretched
        for angle, expected in ((0.0, math.log(stretch)), (90.0, 0.0),
                                (45.0, 0.5 * math.log(0.5 * stretch ** 2 + 0.5))):
            got = membrane_fibre_log_strain(self.ref, cur, self.tri, self.c, self.r, angle)[0]
            self.assertAlmostEqual(got, expected, delta=1e-12, msg=f"fibre angle {angle}")

    def test_rigid_rotation_is_no_strain(self):
        a = 0.7
        rot = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
        got = membrane_fibre_log_strain(self.ref, self.ref @ rot.T, self.tri, self.c, self.r, 43.11)[0]
        self.assertAlmostEqual(got, 0.0, delta=1e-12)

    def test_fibre_stress_by_hand(self):
        k1, k2 = 74.5e3, 63.19
        self.assertEqual(mhgo_fibre_stress(-0.05, k1, k2), 0.0)   # fibres carry no compression
        i4 = 1.1
        self.assertAlmostEqual(float(mhgo_fibre_stress(0.5 * math.log(i4), k1, k2)),
                               2 * k1 * 0.1 * math.exp(k2 * 0.01) * i4, delta=1e-6)


class TopArea(unittest.TestCase):
    def test_the_largest_values_covering_one_percent(self):
        values = np.arange(400.0)
        areas = np.ones(400)
        top = top_area_elements(values, areas)
        self.assertEqual(sorted(top.tolist()), [396, 397, 398, 399])   # the 4 largest cover exactly 1 %
        areas[399] = 10.0                                                   # one element larger than 1 % of the area
        self.assertEqual(top_area_elements(values, areas).tolist(), [399])


class Speckle(unittest.TestCase):
    def test_smooth_and_checkerboard_fields(self):
        # a strip of 2 x 10 squares, each split in two triangles: 20 triangles, 29 shared edges
        triangles = []
        for i in range(10):
            a, b, c, d = i, i + 1, 11 + i, 12 + i
            triangles += [[a, b, d], [a, d, c]]
        triangles = np.array(triangles)
        self.assertAlmostEqual(neighbour_stress_ratio(np.full(20, 2e5), triangles), 1.0, delta=1e-12)
        checker = np.where(np.arange(20) % 2 == 0, 1e5, 4e5)   # every shared edge joins a low and a high one
        self.assertAlmostEqual(neighbour_stress_ratio(checker, triangles), 4.0, delta=1e-12)


if __name__ == "__main__":
    unittest.main()
