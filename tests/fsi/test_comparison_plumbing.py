"""The comparison command (valve_scene.comparison, docs/comparison.md) on a few milliseconds of
the 2D xcoarse cases: the four runs go through the launcher, the report holds every section
with the four runs, and each FSI run's interface balances (fluid work = solid work through the
mapping, total forces equal) within the stated tolerance. The findings cannot be judged on 4 ms
and must say so rather than pass."""
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))
END_TIME = 0.004


class ComparisonPlumbing(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, str(REPO / "scripts"))
        from valve_scene import comparison
        cls.comparison = comparison
        cls.tmp = tempfile.TemporaryDirectory(prefix="comparison-")
        work = Path(cls.tmp.name)
        cls.out = work / "report" / "comparison.md"
        cls.out.parent.mkdir()
        cls.runs = comparison.compare(2, "xcoarse", "sector", work / "runs", BUILD, cls.out, cycle=1,
                                      end_time=END_TIME, reuse=False, command="test_comparison_plumbing")
        cls.text = cls.out.read_text()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_four_runs_complete_and_are_timed(self):
        self.assertEqual(sorted(self.runs), ["FE-MHGO", "FE-Ogden", "FSI-MHGO", "FSI-Ogden"])
        for label, run in self.runs.items():
            with self.subTest(run=label):
                self.assertEqual(run.exit_code, 0, (run.run_dir.parent / f"{run.spec.name}.log").read_text()[-2000:])
                self.assertAlmostEqual(run.simulated_s, END_TIME, delta=1e-6)
                self.assertGreater(run.wall_time_s, 0.0)
                self.assertIn(f"| {run.spec.name} | {END_TIME:.4g} |", self.text)

    def test_report_sections_and_figures(self):
        for heading in ("## Runs and wall times", "## Kinematics (reference Table 3)", "## Hemodynamics (reference Table 2)",
                        "## Peak max-principal stress and log strain", "## Interface balance (issue 7, item 5)",
                        "## Findings of the reference (issue 7, item 6)", "## Figures"):
            self.assertIn(heading, self.text)
        self.assertTrue((self.out.parent / "figures" / "comparison-2d-xcoarse-fig5.png").exists())

    def test_interface_balances_within_the_stated_tolerance(self):
        for label in ("FSI-Ogden", "FSI-MHGO"):
            with self.subTest(run=label):
                b = self.runs[label].balance
                self.assertNotIn("error", b)
                self.assertGreater(b["windows"], 300)            # 4 ms of 13 us windows
                self.assertGreater(b["power_scale"], 0.0)       # the fluid did work on the leaflets
                self.assertLess(b["work_relative_difference"], self.comparison.BALANCE_TOLERANCE)
                self.assertLess(b["force_relative_difference"], self.comparison.BALANCE_TOLERANCE)

    def test_findings_are_not_judged_on_a_few_milliseconds(self):
        findings = {f.key: f for f in self.comparison.check_findings(self.runs)}
        self.assertEqual(sorted(findings), sorted(self.comparison.REFERENCE_FINDINGS))
        for key in ("opening", "wider", "water_hammer", "stress", "cycles"):
            self.assertIsNone(findings[key].holds, f"{key}: {findings[key].evidence}")
        self.assertTrue(findings["leaks"].holds, findings["leaks"].evidence)


if __name__ == "__main__":
    unittest.main()
