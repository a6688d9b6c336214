"""The quick-look summary's opening time on a synthetic radial history with a known answer."""
import unittest

import numpy as np

from valve_scene.quick_look import opening_time_10_90


class OpeningTime(unittest.TestCase):
    def test_linear_ramp_gives_eighty_percent_of_its_duration(self):
        t = np.linspace(0.0, 0.05, 50001)
        radial = np.clip((t - 0.002) / 0.010, 0.0, 1.0) * 9e-3 + 3e-4   # 10 ms ramp from 2 ms
        self.assertAlmostEqual(opening_time_10_90(t, radial), 0.008, delta=2e-6)

    def test_overshoot_counts_from_the_largest_position(self):
        t = np.linspace(0.0, 0.02, 20001)
        radial = np.where(t < 0.01, t / 0.01, 1.0 + 0.2 * np.sin(np.pi * (t - 0.01) / 0.01))
        # the rise is measured to 90 % of the peak 1.2: from t = 1.2 ms to t = 10.8 ms... the ramp
        # reaches 0.12 at 1.2 ms; 1.08 is first reached on the overshoot at 10 + 10/pi*asin(0.4) ms.
        expected = (0.01 + 0.01 / np.pi * np.arcsin(0.4)) - 0.0012
        self.assertAlmostEqual(opening_time_10_90(t, radial), expected, delta=2e-6)


if __name__ == "__main__":
    unittest.main()
