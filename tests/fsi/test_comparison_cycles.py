"""The comparison's cycle table and "cycles" finding (issue 7, item 6: the second cycle differs
from the first by less than 10 %): differences |c2 - c1| / |c2| per metric, bold from 10 %,
and the verdict from the largest difference. No runs: the metrics are given."""
import unittest
from pathlib import Path

from valve_scene import comparison


def run_with(kind, material, first, second):
    run = comparison.RunResult(spec=comparison.RunSpec(kind, material, 2, "coarse"), run_dir=Path("."))
    run.cycle_values = (first, second)
    run.cycle_difference = {k: abs(second[k] - first[k]) / abs(second[k]) for k in second if k in first}
    return run


class CycleTable(unittest.TestCase):
    def setUp(self):
        # FE repeats within 1 %; FSI's MSPD goes 1.3 -> 5.43 mmHg (the session-8 measurement)
        self.runs = {
            "FE-Ogden": run_with("FE", "Ogden", {"RVOT": 0.00404, "ET": 0.2413}, {"RVOT": 0.00404, "ET": 0.2410}),
            "FSI-Ogden": run_with("FSI", "Ogden", {"RVOT": 0.0231, "MSPD": 1.30}, {"RVOT": 0.0189, "MSPD": 5.43}),
        }

    def test_rows_hold_both_cycles_and_the_difference(self):
        table = comparison.cycles_table(self.runs, 2)
        rvot = next(line for line in table.splitlines() if line.startswith("| RVOT"))
        self.assertIn("4.04 / 4.04 (0%)", rvot)
        self.assertIn("23.1 / 18.9 (**22%**)", rvot)      # (23.1 - 18.9) / 18.9
        mspd = next(line for line in table.splitlines() if line.startswith("| MSPD"))
        self.assertIn("1.3 / 5.43 (**76%**)", mspd)
        self.assertIn("| – |", mspd.replace("| MSPD (mmHg) ", ""))   # FE has no MSPD
        self.assertNotIn("| RVCT", table)                             # no run measured it

    def test_verdict_follows_the_largest_difference(self):
        findings = {f.key: f for f in comparison.check_findings(self.runs)}
        self.assertFalse(findings["cycles"].holds)
        self.assertIn("FSI-Ogden: largest MSPD 76.1%", findings["cycles"].evidence)
        del self.runs["FSI-Ogden"]
        self.assertTrue({f.key: f for f in comparison.check_findings(self.runs)}["cycles"].holds)

    def test_no_table_for_one_cycle(self):
        for run in self.runs.values():
            run.cycle_values = ()
        self.assertEqual(comparison.cycles_table(self.runs, 1), "")


if __name__ == "__main__":
    unittest.main()


class SliceSpacing(unittest.TestCase):
    def test_the_spacing_of_a_displaced_lattice_is_its_nearest_neighbour_distance(self):
        # a 0.9 mm cubic lattice moved off its planes by up to 5 % of the spacing: the old estimate
        # (gaps between distinct z values) read the jitter, ~1e-6 m, and the 3D slice kept no layer
        import numpy as np
        g = np.arange(12) * 0.9e-3
        x = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
        x += np.random.default_rng(3).uniform(-0.045e-3, 0.045e-3, x.shape)
        self.assertAlmostEqual(comparison.particle_spacing(x), 0.9e-3, delta=0.08e-3)
