"""The closed-valve load scene (valve_scene.closed_load): its two case files are current, they
differ from the cycle cases only in what the scene changes, and the ramp reaches the cycle's
largest reverse transvalvular difference smoothly from a blood at rest."""
import re
import unittest
from pathlib import Path

import numpy as np

from valve_scene import closed_load, waveform
from valve_scene.write_cases import CaseSpec, case_text

CASES = Path(__file__).resolve().parents[2] / "cases"


def _table(text: str, field: str) -> np.ndarray:
    block = re.search(field + r": \[([^\]]*)\]", text).group(1)
    return np.array([float(v) for v in block.replace("\n", " ").split(",")])


class ClosedLoad(unittest.TestCase):
    def test_checked_in_cases_are_current(self):
        for kind in ("FE", "FSI"):
            base = case_text(CaseSpec(kind, "MHGO", "sector", "coarse"))
            path = CASES / f"{closed_load.case_name(kind)}.textproto"
            self.assertEqual(path.read_text(), closed_load.case_text(kind, base), path)

    def test_only_the_run_and_waveform_differ_from_the_cycle_case(self):
        for kind in ("FE", "FSI"):
            base = case_text(CaseSpec(kind, "MHGO", "sector", "coarse"))
            text = closed_load.case_text(kind, base)
            self.assertEqual(text[text.index("solid {"):], base[base.index("solid {"):])
            self.assertIn("end_time: 0.06\n", text)
            self.assertIn(f'output_dir: "runs/{closed_load.case_name(kind)}"', text)
            self.assertIn(f"scripts/run_case.py cases/{closed_load.case_name(kind)}.textproto", text)
            self.assertEqual("--fe-only" in text[:text.index("title:")], kind == "FE")

    def test_the_load_starts_at_zero_and_holds_the_cycles_largest_reverse_difference(self):
        text = closed_load.case_text("FE", case_text(CaseSpec("FE", "MHGO", "sector", "coarse")))
        t, lv, ao = (_table(text, f) for f in ("time_s", "ventricular_pressure_mmHg", "aortic_pressure_mmHg"))
        reverse = ao - lv
        self.assertLess(abs(reverse[0]), 0.01)              # the blood starts at rest, no step load
        # the cycle's largest reverse difference over its diastole, from the Wiggers table itself
        tc, lvc, aoc = waveform.sampled_table()
        largest = float(np.max(aoc - lvc))
        held = reverse[t >= closed_load.RAMP_S]
        np.testing.assert_allclose(held, largest, atol=0.01)
        self.assertGreater(largest, 90.0)                    # a diastolic load, not a systolic one
        ramp = reverse[t <= closed_load.RAMP_S]
        self.assertTrue(np.all(np.diff(ramp) >= 0))          # monotone
        # smooth: the largest step per ms is the cosine ramp's, pi/2 * dp / (ramp in ms)
        self.assertLess(np.max(np.diff(ramp)), 1.01 * np.pi / 2 * largest / (closed_load.RAMP_S * 1e3))

    def test_the_ventricle_rises_to_the_cycles_pressure_reserve(self):
        # the cycle's plates hold the lower one at its reserve once engaged (tube_case), so the
        # scene's ventricle ends there above its start (gauge 0), the aorta the difference higher
        from valve_scene.tube_case import FSI_3D_PLATE_PRESSURE_RESERVE_MMHG as reserve
        text = closed_load.case_text("FSI", case_text(CaseSpec("FSI", "MHGO", "sector", "coarse")))
        t, lv, ao = (_table(text, f) for f in ("time_s", "ventricular_pressure_mmHg", "aortic_pressure_mmHg"))
        self.assertGreater(reserve, 0.0)
        np.testing.assert_allclose(lv[t >= closed_load.RAMP_S] - lv[0], reserve, atol=0.01)
        self.assertTrue(np.all(np.diff(lv[t <= closed_load.RAMP_S]) >= 0))
        self.assertIn(f"plate_pressure_floor_mmHg: {reserve:g}\n", text)
        self.assertIn("plate_pressure_floor_once_reached: true\n", text)


if __name__ == "__main__":
    unittest.main()


class ClosedLoadAnalysis(unittest.TestCase):
    def test_growth_rate_of_an_exponential(self):
        t = np.linspace(0.0, 0.05, 501)
        kinetic = 1e-9 * np.exp(0.23 * t * 1e3)          # e-folding 1/0.23 ms
        self.assertAlmostEqual(closed_load.growth_rate_per_ms(t, kinetic, 0.02, 0.04), 0.23, places=10)

    def test_force_is_averaged_over_the_window_before_each_time(self):
        import tempfile
        import h5py
        with tempfile.TemporaryDirectory() as run:
            t = np.arange(1, 1001) * 1e-5                  # window ends, 10 us
            force = np.zeros((len(t), 3))
            force[:, 2] = -np.where(t <= 0.005, 1.0, 2.0) + 0.1 * np.sin(2 * np.pi * t / 2e-4)   # a ringing load
            with h5py.File(Path(run) / "coupling_series.h5", "w") as f:
                f["time"] = t.reshape(-1, 1)
                f["force_fluid"] = force
            got = closed_load.force_at(Path(run), [0.005, 0.01], window_s=0.002)
            np.testing.assert_allclose(got, [-1.0, -2.0], atol=1e-3)   # the ringing averages out
            self.assertEqual(closed_load.force_at(Path(run) / "none", [0.01]), [None])
