"""One run's report (kinematics + hemodynamics) on a synthetic 2D run folder in the solvers'
layouts: a linear opening over 0-5 ms and closing over 230-240 ms of each cycle give RVOT 5.1 ms,
RVCT 10.0 ms, ET 240.0 ms (steepest-slope tangents of the 1 ms-smoothed curve); the probe series of
test_hemodynamics gives its EOA."""
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

import test_hemodynamics as th
from valve_scene import hemodynamics as hd
from valve_scene.run_report import free_edge_kinematics, run_report

R_CLOSED, R_OPEN = 0.3e-3, 11.5e-3


def opening_fraction(t):
    return np.interp(np.mod(t, 0.8), [0, 0.005, 0.230, 0.240, 0.8], [0, 1, 1, 0, 0])


def write_solid_series(run_dir: Path, dimension: int):
    t = np.arange(0, 1.6 + 1e-9, 1e-4)
    r = R_CLOSED + opening_fraction(t) * (R_OPEN - R_CLOSED)
    positions = np.zeros((len(t), 2, 3))
    if dimension == 2:
        positions[:, 0, :2] = np.stack([11e-3 + 0 * r, r], axis=1)
        positions[:, 1, :2] = np.stack([11e-3 + 0 * r, -r], axis=1)
    else:
        positions[:, 0, :2] = np.stack([r, 0 * r], axis=1)
        positions[:, 1, :2] = np.stack([-0.5 * r, np.sqrt(3) / 2 * r], axis=1)
    with h5py.File(run_dir / "solid_series.h5", "w") as f:
        f["time"] = t
        f["monitor/free_edge_midpoints/position"] = positions
        f["transvalvular_pressure_Pa"] = np.zeros_like(t)
        f["energy/relative_balance_error"] = np.zeros_like(t)


class RunReport(unittest.TestCase):
    def test_radial_position_and_orifice_width(self):
        for dimension in (2, 3):
            with tempfile.TemporaryDirectory() as tmp:
                write_solid_series(Path(tmp), dimension)
                t, radial, width = free_edge_kinematics(Path(tmp), dimension, cycle=2)
            self.assertAlmostEqual(t[0], 0.0, delta=1e-9)
            k = np.searchsorted(t, 0.1)
            self.assertAlmostEqual(radial[k], R_OPEN, delta=1e-12)
            if dimension == 2:
                self.assertAlmostEqual(width[k], 2 * R_OPEN, delta=1e-12)
            else:
                self.assertIsNone(width)

    def test_report_of_a_synthetic_2d_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            write_solid_series(folder, 2)
            th.Files().write_run(folder, th.synthetic(dimension=2))
            text = run_report(folder, "FSI-2D", cycle=2, dimension=2, out=folder / "report.md")
            self.assertTrue((folder / "report-kinematics.png").exists())
            self.assertTrue((folder / "report-hemodynamics.png").exists())
        # the ramps read as D / erf(D / (2 sqrt(2) sigma)) after the 1 ms smoothing (valve_events)
        self.assertIn("| RVOT | 5.1 |", text)
        self.assertIn("| RVCT | 10.0 |", text)
        self.assertIn("| ET | 240.0 |", text)
        self.assertIn("peak 23.00 mm", text)
        eoa = hd.analyse_cycle(th.synthetic(dimension=2), closure_time_s=0.239).eoa
        self.assertIn(f"| EOA (cm per cm depth) | {eoa:.2f} |", text)

    def test_missing_parts_are_said(self):
        with tempfile.TemporaryDirectory() as tmp:
            text = run_report(Path(tmp), "empty", cycle=2, dimension=3, out=Path(tmp) / "r.md")
        self.assertIn("No kinematics:", text)
        self.assertIn("No hemodynamics:", text)


if __name__ == "__main__":
    unittest.main()
