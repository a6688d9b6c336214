"""The comparison's validation tests (2D and 3D) share this: run or reuse the four runs, then
assert the runs cover the analysed cycle, the reference's findings hold, and each FSI run's
interface mapping balances within the comparison's stated tolerance."""
import os
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))


class ComparisonFindings:
    """Mixin for a unittest.TestCase; the subclass sets DIMENSION, RESOLUTION, CYCLE, FINDINGS and
    RUNS_VARIABLE (the environment variable naming a folder of runs to reuse)."""
    DIMENSION: int
    RESOLUTION: str
    CYCLE: int
    FINDINGS: tuple
    RUNS_VARIABLE: str

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, str(REPO / "scripts"))
        from valve_scene import comparison
        cls.comparison = comparison
        cls.tmp = tempfile.TemporaryDirectory(prefix=f"comparison-{cls.DIMENSION}d-validation-")
        runs_dir = Path(os.environ.get(cls.RUNS_VARIABLE, Path(cls.tmp.name) / "runs"))
        out = Path(cls.tmp.name) / "report" / "comparison.md"
        out.parent.mkdir(parents=True)
        cls.runs = comparison.compare(cls.DIMENSION, cls.RESOLUTION, "sector", runs_dir, BUILD, out, cycle=cls.CYCLE,
                                      end_time=None, reuse=True, command=f"validation {cls.__name__}")
        cls.findings = {f.key: f for f in comparison.check_findings(cls.runs)}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_runs_cover_the_cycle(self):
        for label, run in self.runs.items():
            with self.subTest(run=label):
                self.assertGreaterEqual(run.simulated_s, self.CYCLE * self.comparison.PERIOD_S - 1e-6)
                self.assertFalse(run.partial)

    def test_findings_hold(self):
        for key in self.FINDINGS:
            with self.subTest(finding=key):
                self.assertTrue(self.findings[key].holds, self.findings[key].evidence)

    def test_interface_mapping_balanced(self):
        for label in ("FSI-Ogden", "FSI-MHGO"):
            with self.subTest(run=label):
                b = self.runs[label].balance
                self.assertLess(b["work_relative_difference"], self.comparison.BALANCE_TOLERANCE)
                self.assertLess(b["force_relative_difference"], self.comparison.BALANCE_TOLERANCE)
