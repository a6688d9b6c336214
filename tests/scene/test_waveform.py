"""The 75 bpm waveform has the properties the reference study implies (issue 4, item 3)."""
import math
import shutil
import subprocess
import unittest
from pathlib import Path

import numpy as np

from valve_scene import MMHG_TO_PA, waveform as wf

REPO = Path(__file__).resolve().parents[2]
CHECKED_IN_FRAGMENT = REPO / "cases" / "waveforms" / "wiggers-75bpm.textproto"


class WaveformProperties(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.t = np.arange(0.0, wf.PERIOD_S, 1e-4)
        cls.p_lv = wf.ventricular_pressure_mmHg()(cls.t)
        cls.p_ao = wf.aortic_pressure_mmHg()(cls.t)
        cls.dp = cls.p_lv - cls.p_ao

    def test_ejection_starts_at_time_zero(self):
        # dp crosses zero upward within 0.1 ms of t = 0
        self.assertLess(wf.transvalvular_pressure_mmHg(-0.0001)[0], 0.0)
        self.assertGreater(wf.transvalvular_pressure_mmHg(0.0001)[0], 0.0)

    def test_forward_difference_of_a_few_mmHg_during_ejection(self):
        ejection = (self.t > 0.003) & (self.t < 0.22)
        self.assertTrue(np.all(self.dp[ejection] > 0.0))
        peak = self.dp[ejection].max()
        t_peak = self.t[ejection][np.argmax(self.dp[ejection])]
        self.assertGreater(peak, 5.0)       # reference PSPD 11.7-14.5 mmHg measured in the tube
        self.assertLess(peak, 15.0)
        self.assertGreater(t_peak, 0.015)   # reference peak at 25 ms
        self.assertLess(t_peak, 0.040)
        mean = self.dp[ejection].mean()
        self.assertGreater(mean, 3.0)       # reference MSPD 5.0-5.3 mmHg
        self.assertLess(mean, 7.0)

    def test_difference_falls_to_zero_between_230_and_250_ms(self):
        after_peak = self.t > 0.1
        crossing = self.t[after_peak][np.argmax(self.dp[after_peak] <= 0.0)]
        self.assertGreaterEqual(crossing, 0.23)
        self.assertLessEqual(crossing, 0.25)

    def test_diastolic_minimum_matches_the_reference_hydrostatic_force(self):
        area = math.pi * 0.0115 ** 2                       # size-23 annulus
        # the arithmetic of the brief: 5.4 N / A in mmHg
        self.assertAlmostEqual(5.4 / area / MMHG_TO_PA, 97.5, delta=0.1)
        dp_min = self.dp.min()
        self.assertGreater(dp_min, -100.0)
        self.assertLess(dp_min, -94.0)
        self.assertAlmostEqual(-dp_min * MMHG_TO_PA * area, 5.4, delta=0.15)
        t_min = self.t[np.argmin(self.dp)]
        self.assertGreater(t_min, 0.27)    # after coaptation (reference: closed before the peak gradient)
        self.assertLess(t_min, 0.45)

    def test_late_diastole_near_minus_70_mmHg(self):
        self.assertAlmostEqual(wf.transvalvular_pressure_mmHg(0.75)[0], -70.0, delta=5.0)

    def test_physiological_ranges(self):
        self.assertAlmostEqual(self.p_ao.max(), 120.0, delta=3.0)   # systolic
        self.assertAlmostEqual(self.p_ao.min(), 80.0, delta=2.0)    # diastolic
        self.assertGreater(self.p_lv.min(), 0.0)
        self.assertLess(self.p_lv.min(), 6.0)

    def test_periodic_and_smooth_at_the_cycle_joint(self):
        for trace in (wf.ventricular_pressure_mmHg(), wf.aortic_pressure_mmHg()):
            h = 1e-4
            t = np.array([-2 * h, -h, 0.0, h, 2 * h])
            wrapped = trace(t)
            shifted = trace(t + wf.PERIOD_S)  # evaluated one period later
            np.testing.assert_allclose(wrapped, shifted, atol=1e-9)
            # the one-sided derivatives at the joint agree to O(h f''), |f''| < 1e6 mmHg/s^2;
            # the unsmoothed trace has a slope jump of ~1500 mmHg/s there
            k = 1e-5
            left = (trace(0.0)[0] - trace(-k)[0]) / k     # -k wraps to the end of the cycle
            right = (trace(k)[0] - trace(0.0)[0]) / k
            self.assertAlmostEqual(left, right, delta=1e6 * k)
            # no step anywhere: max change per 0.1 ms is bounded by the steepest physiological slope
            samples = trace(np.arange(0.0, 2 * wf.PERIOD_S, h))
            self.assertLess(np.abs(np.diff(samples)).max(), 3000.0 * h)  # < 3000 mmHg/s

    def test_smoothing_does_not_overshoot_the_knots(self):
        for knots, trace in ((wf.ventricular_knots(), wf.ventricular_pressure_mmHg()),
                             (wf.aortic_knots(), wf.aortic_pressure_mmHg())):
            values = trace(self.t)
            self.assertGreaterEqual(values.min(), knots[1].min() - 1e-9)
            self.assertLessEqual(values.max(), knots[1].max() + 1e-9)


class WaveformTable(unittest.TestCase):
    def test_table_is_one_ms_over_one_period(self):
        t, p_lv, p_ao = wf.sampled_table()
        self.assertEqual(len(t), 800)
        self.assertEqual(t[0], 0.0)
        self.assertTrue(np.all(np.diff(t) > 0))
        self.assertLess(t[-1], wf.PERIOD_S)
        self.assertEqual(len(p_lv), 800)
        self.assertEqual(len(p_ao), 800)

    def test_checked_in_fragment_is_current(self):
        self.assertEqual(CHECKED_IN_FRAGMENT.read_text(), wf.FRAGMENT_HEADER + wf.waveform_textproto())

    @unittest.skipIf(shutil.which("protoc") is None, "protoc not installed")
    def test_fragment_parses_as_a_case(self):
        with CHECKED_IN_FRAGMENT.open("rb") as text:
            result = subprocess.run(
                ["protoc", f"-I{REPO / 'proto'}", "--encode=valvefsi.cases.Case", str(REPO / "proto" / "case.proto")],
                stdin=text, capture_output=True)
        self.assertEqual(result.returncode, 0, result.stderr.decode())


if __name__ == "__main__":
    unittest.main()
