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
import unittest

from comparison_findings import ComparisonFindings


class ComparisonFindings2D(ComparisonFindings, unittest.TestCase):
    DIMENSION, RESOLUTION, CYCLE = 2, "coarse", 2
    FINDINGS = ("opening", "wider", "water_hammer", "leaks", "cycles")
    RUNS_VARIABLE = "VALVEFSI_COMPARISON_RUNS"

    def test_runs_complete_two_cycles(self):
        for label, run in self.runs.items():
            with self.subTest(run=label):
                self.assertEqual(run.exit_code, 0)


if __name__ == "__main__":
    unittest.main()
