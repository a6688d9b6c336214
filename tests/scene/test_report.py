"""Peak-field location, the report table and the figures (issue 4, item 5)."""
import tempfile
import unittest
from pathlib import Path

import numpy as np

from valve_scene.analysis import ValveEvents, bisection_profile, peak_with_location
from valve_scene.report import kinematics_table, plot_kinematics, plot_profiles, write_markdown_report
from valve_scene.valve_mesh import build_valve_mesh


class PeakLocation(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.mesh = build_valve_mesh("full", "medium", "triangles")
        cls.centroids = cls.mesh.nodes[cls.mesh.triangles].mean(axis=1)

    def locate(self, target):
        values = -np.linalg.norm(self.centroids - target, axis=1)   # peak at the element nearest target
        return peak_with_location(values, self.mesh.nodes, self.mesh.triangles, self.mesh.node_sets)

    def test_regions(self):
        p = self.mesh.description
        R, hc = p["param_annulus_radius"], p["param_commissure_height"]
        top = self.mesh.nodes[self.mesh.node_sets["attachment"]]
        commissure = top[np.argmax(top[:, 2])]
        self.assertEqual(self.locate(commissure).region, "commissure")
        self.assertEqual(self.locate(np.array([R, 0.0, 0.0])).region, "attachment")
        self.assertEqual(self.locate(np.array([0.3e-3, 0.0, p["param_free_edge_centre_height"]])).region, "free edge")
        peak = self.locate(np.array([0.6 * R, 0.0, 0.4 * hc]))
        self.assertEqual(peak.region, "belly")
        self.assertEqual(peak.value, -np.min(np.linalg.norm(self.centroids - np.array([0.6 * R, 0.0, 0.4 * hc]), axis=1)))


class Report(unittest.TestCase):
    def test_table_puts_ours_next_to_the_reference(self):
        events = ValveEvents(0.001, 0.006, 0.230, 0.238, 0.005, 0.008, 0.237)
        table = kinematics_table({"FE-Ogden": events, "FE-MHGO": None})
        lines = table.strip().splitlines()
        self.assertEqual(len(lines), 5)
        self.assertIn("| RVOT | 5.0 | – | 40 | 40 | 5 | 6 | 57.5 ± 11.1 |", lines)
        self.assertIn("| ET | 237.0 | – | 270 | 270 | 240 | 240 | 329 ± 63 |", lines)

    def test_figures_and_page_are_written(self):
        mesh = build_valve_mesh("sector", "coarse", "triangles")
        profile = bisection_profile(mesh.nodes, mesh.triangles, 0.0)
        t = np.linspace(0, 0.8, 81)
        series = {"synthetic": {"time_s": t, "free_edge_radial_position_m": 1e-3 + 0 * t, "goa_m2": 1e-4 + 0 * t}}
        with tempfile.TemporaryDirectory() as tmp:
            plot_kinematics(series, Path(tmp) / "fig5.png")
            plot_profiles({0.0: profile, 0.3: profile * 0.9}, Path(tmp) / "fig6.png", closing_from_s=0.2)
            write_markdown_report(Path(tmp) / "report.md", "test", {"FE-Ogden": None}, ["fig5.png"])
            for name in ("fig5.png", "fig6.png"):
                self.assertEqual((Path(tmp) / name).read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
            self.assertIn("![fig5](fig5.png)", (Path(tmp) / "report.md").read_text())


if __name__ == "__main__":
    unittest.main()
