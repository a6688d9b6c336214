"""Validation (long: four runs of two cycles, ~1.5 h on one core each for FSI): the comparison
command at 2D coarse (docs/comparison.md) and the reference's findings of issue 7, item 6 that
a 2D run can show: FSI opening later and several times longer than FE-only, FE-only opening
wider, the water-hammer force beyond the hydrostatic one, no leak through a leaflet, the second
cycle within 10 % of the first, and the interface balance within its stated tolerance. (The
closed-stress ordering Ogden > MHGO is a 3D finding: the 2D closed leaflet lies on its support.)
Coarse, not xcoarse: the xcoarse valve does not seal in diastole (session 16: FSI-MHGO's upstream
plate ran out of travel at 0.361 s as the blood flowed back past the leaflets' tips, a clean stop
naming the plate; FSI-Ogden counted a leak). Session 8's coarse cycles (docs/comparison.md) held
"opening", "wider" and "water_hammer" but not "leaks" (2 and 1 particles) nor "cycles" (EOA moved
107-130 % in cycle 2, docs/fsi-2d.md): this test fails on those until they are mended.
VALVEFSI_COMPARISON_RUNS may name a folder of finished runs to reuse (RUN/wall_time.json)."""
import os
import sys
import tempfile
import unittest
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))


class ComparisonFindings2D(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, str(REPO / "scripts"))
        from valve_scene import comparison
        cls.comparison = comparison
        cls.tmp = tempfile.TemporaryDirectory(prefix="comparison-validation-")
        runs_dir = Path(os.environ.get("VALVEFSI_COMPARISON_RUNS", Path(cls.tmp.name) / "runs"))
        out = Path(cls.tmp.name) / "report" / "comparison.md"
        out.parent.mkdir(parents=True)
        cls.runs = comparison.compare(2, "coarse", "sector", runs_dir, BUILD, out, cycle=2, end_time=None,
                                      reuse=True, command="test_comparison_validation")
        cls.findings = {f.key: f for f in comparison.check_findings(cls.runs)}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_runs_complete_two_cycles(self):
        for label, run in self.runs.items():
            with self.subTest(run=label):
                self.assertEqual(run.exit_code, 0)
                self.assertAlmostEqual(run.simulated_s, 1.6, delta=1e-6)

    def test_findings_hold(self):
        for key in ("opening", "wider", "water_hammer", "leaks", "cycles"):
            with self.subTest(finding=key):
                self.assertTrue(self.findings[key].holds, self.findings[key].evidence)

    def test_interface_balance(self):
        for label in ("FSI-Ogden", "FSI-MHGO"):
            with self.subTest(run=label):
                b = self.runs[label].balance
                self.assertLess(b["work_relative_difference"], self.comparison.BALANCE_TOLERANCE)
                self.assertLess(b["force_relative_difference"], self.comparison.BALANCE_TOLERANCE)


if __name__ == "__main__":
    unittest.main()
