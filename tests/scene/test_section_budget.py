"""valve_scene.section_budget: a made-up 2D run whose particles (10 rows, dp apart) move along the
channel at U, with a section at x = 50.5 dp reading U H. Moved by their velocity alone, the
particles that crossed equal the section's volume; moved 2 dp further by a "shift" without
velocity, the particles carry 2 dp x H (20 dp^2) that the section does not see."""
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

from valve_scene import section_budget

DP, ROWS, COLUMNS, SPEED = 1e-3, 10, 100, 0.1   # m, -, -, m/s
PLANE = 50.5 * DP
HEIGHT = ROWS * DP


def write_run(folder: Path, shift_per_snapshot: float) -> None:
    (folder / "fluid.log").write_text("fluid_sph: coupled (2D) with solid_fe: 1000 fluid particles, dp = 0.001 m, c0 = 20 m/s\n")
    t = np.linspace(0.0, 0.05, 501)
    with h5py.File(folder / "fluid_probes.h5", "w") as f:
        f["time"] = t
        f["flow_rate/x_mid"] = np.full_like(t, SPEED * HEIGHT)
    x0, y0 = np.meshgrid((np.arange(COLUMNS) + 0.5) * DP, (np.arange(ROWS) + 0.5) * DP)
    with h5py.File(folder / "fluid_particles.h5", "w") as f:
        for k, time in enumerate(np.linspace(0.0, 0.05, 6)):   # the particles move 5 dp between snapshots
            g = f.create_group(f"snapshot_{k:06d}")
            g.attrs["time"] = time
            x = x0.reshape(-1) + SPEED * time + k * shift_per_snapshot
            g["position"] = np.stack([x, y0.reshape(-1), np.zeros(x.size)], axis=1)
            g["kind"] = np.zeros(x.size, dtype=np.uint8)


class SectionBudgetTest(unittest.TestCase):
    def budget(self, shift_per_snapshot):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(Path(tmp), shift_per_snapshot)
            (b,) = section_budget.section_budgets(Path(tmp), {"x_mid": PLANE}, 2)
            return b

    def test_particles_moved_by_their_velocity_match_the_section(self):
        b = self.budget(0.0)
        self.assertEqual(len(b.times), 6)
        np.testing.assert_allclose(b.section_volume, SPEED * HEIGHT * b.times, rtol=1e-12)
        np.testing.assert_allclose(b.crossed_volume, b.section_volume, atol=1e-12)   # whole columns of 10
        self.assertLess(np.abs(b.drift).max(), 1e-12)

    def test_a_shift_without_velocity_shows_as_drift(self):
        b = self.budget(0.4 * DP)   # 2 dp over the 5 snapshot intervals
        self.assertAlmostEqual(b.drift[-1] / (DP * DP), 20.0, places=9)
        self.assertAlmostEqual(b.section_volume[-1] / (DP * DP), 50.0, places=9)

    def test_a_missing_section_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_run(Path(tmp), 0.0)
            with self.assertRaisesRegex(KeyError, r"no flow section\(s\) x_far \(found: x_mid\)"):
                section_budget.section_budgets(Path(tmp), {"x_far": 0.0}, 2)

    def test_table_reports_volumes_per_depth_in_mm2(self):
        b = self.budget(0.4 * DP)
        text = section_budget.table([b], 2)
        self.assertIn("| x_mid (50.5 mm) | 20 | 20 | 20 | +0 |", text)   # whole columns crossed by then
        self.assertIn("| x_mid (50.5 mm) | 50 | 50 | 70 | +20 |", text)


if __name__ == "__main__":
    unittest.main()
