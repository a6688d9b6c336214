"""The README's main command: the 2D opening summary on synthetic runs with known answers, and
its two default case files are the generator's."""
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

from valve_scene import opening_2d, valve2d

CASES = Path(__file__).resolve().parents[2] / "cases"


def write_run(folder: Path, start_s: float, ramp_s: float, wall_s: float) -> None:
    """A solid series whose two free-edge midpoints move from 0.25 mm to 11.25 mm off the axis
    (y) along a linear ramp, and the launcher's log line with its wall time."""
    folder.mkdir(parents=True)
    t = np.linspace(0.0, 0.08, 8001)
    y = 0.25e-3 + 11e-3 * np.clip((t - start_s) / ramp_s, 0.0, 1.0)
    position = np.zeros((t.size, 2, 3))
    position[:, 0, 1], position[:, 1, 1] = y, -y
    position[:, :, 0] = 2e-3
    with h5py.File(folder / "solid_series.h5", "w") as f:
        f["time"] = t
        f["monitor/free_edge_midpoints/position"] = position
    (folder.parent / f"{folder.name}.log").write_text(
        f"[solid] done\nrun_case: finished in {wall_s:.1f} s wall time; logs and results in {folder}\n")


class Opening2D(unittest.TestCase):
    def test_start_rise_time_wall_time_and_errors_against_the_reference(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp)
            write_run(root / "fe", start_s=0.004, ramp_s=0.005, wall_s=2.0)
            write_run(root / "fsi", start_s=0.020, ramp_s=0.050, wall_s=95.0)
            fe, fsi = opening_2d.read_opening(root / "fe"), opening_2d.read_opening(root / "fsi")
            # 10 % of a linear ramp is reached a tenth of the way in; 10-90 % takes 80 % of it
            self.assertAlmostEqual(fe.start, 0.004 + 0.0005, delta=2e-5)
            self.assertAlmostEqual(fe.duration, 0.004, delta=2e-5)
            self.assertAlmostEqual(fsi.start, 0.020 + 0.005, delta=2e-5)
            self.assertAlmostEqual(fsi.duration, 0.040, delta=2e-5)
            self.assertAlmostEqual(fsi.distance.max(), 11.25e-3, delta=1e-9)
            self.assertEqual((fe.wall_s, fsi.wall_s), (2.0, 95.0))
            text = opening_2d.summary(fe, fsi, None, 0)
            # FE-only 4.0 ms against the reference's 6 ms; FSI 40.0 ms against 40 ms
            self.assertIn("| FE-only | 4.5 | 4.0 | 6 | -33% |", text)
            self.assertIn("| FSI | 25.0 | 40.0 | 40 | +0% |", text)
            self.assertIn("| 95 s |", text)
            self.assertIn("FSI opens 10.0x slower than FE-only and starts 20 ms later", text)

    def test_a_run_that_never_opens_is_named(self):
        with self.assertRaisesRegex(ValueError, "never moves"):
            opening_2d.opening_of(np.linspace(0, 1, 5), np.full(5, 2e-4))

    def test_default_case_files_are_the_generators(self):
        for kind in ("FE", "FSI"):
            with self.subTest(kind=kind):
                text = (CASES / f"default-{kind.lower()}-2d-opening.textproto").read_text()
                self.assertEqual(text, valve2d.default_opening_case_text(kind))
                self.assertIn("  end_time: 0.08\n", text)
                self.assertIn(f'  output_dir: "runs/default/{kind.lower()}"\n', text)


if __name__ == "__main__":
    unittest.main()
