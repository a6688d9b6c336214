"""The interface balance's integrator check over joined segments (valve_scene.comparison): the
solid's booked external work is summed over the coupling windows present, so a span a killed
segment never flushed to its coupling series (then continued from a later restart point) is left
out of both sides instead of counting against the solid. No runs: synthetic series."""
import unittest

import numpy as np

from valve_scene import comparison

WINDOW = 1e-5                  # s
GAP = (2.0e-3, 2.3e-3)         # no coupling windows here (the segment's series end, the restart)


def cumulative_work(t):
    return 1.0 * np.asarray(t) ** 2   # J, a load doing work at a growing rate


class IntegratorOverWindows(unittest.TestCase):
    def setUp(self):
        ends = np.arange(1, 401) * WINDOW
        keep = (ends <= GAP[0] + 1e-12) | (ends - WINDOW >= GAP[1] - 1e-12)
        self.ends, self.sizes = ends[keep], np.full(int(keep.sum()), WINDOW)
        self.load_work = cumulative_work(self.ends) - cumulative_work(self.ends - self.sizes)  # F . dx per window
        self.series_time = np.arange(0, 41) * 1e-4                                            # the solid's 0.1 ms samples
        self.series_work = cumulative_work(self.series_time)

    def test_the_booked_work_over_the_windows_equals_the_loads_work(self):
        booked = comparison.booked_over_windows(self.series_time, self.series_work, self.ends, self.sizes)
        self.assertAlmostEqual(booked, float(np.sum(self.load_work)), delta=1e-12 * float(np.sum(self.load_work)))

    def test_first_to_last_would_count_the_gap_against_the_solid(self):
        # what the check did before: the series' increase from the first window's start to the last one's end
        span = float(np.interp(self.ends[-1], self.series_time, self.series_work)
                     - np.interp(self.ends[0] - WINDOW, self.series_time, self.series_work))
        missing = cumulative_work(GAP[1]) - cumulative_work(GAP[0])
        self.assertAlmostEqual(span - float(np.sum(self.load_work)), missing, delta=1e-15)
        self.assertGreater(missing / float(np.sum(self.load_work)), 100 * comparison.INTEGRATOR_TOLERANCE / 2)

    def test_the_gap_is_measured(self):
        self.assertAlmostEqual(comparison.window_gap(self.ends, self.sizes), GAP[1] - GAP[0], delta=1e-12)
        full = np.arange(1, 401) * WINDOW
        self.assertAlmostEqual(comparison.window_gap(full, np.full(full.size, WINDOW)), 0.0, delta=1e-12)


if __name__ == "__main__":
    unittest.main()
