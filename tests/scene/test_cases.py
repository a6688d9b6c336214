"""The checked-in TAV case files are what the generator writes, and each opens with what it
models, what it should show and the command that runs it (issue 4, item 4)."""
import unittest
from pathlib import Path

from valve_scene.write_cases import all_specs, case_text

CASES = Path(__file__).resolve().parents[2] / "cases"


class CaseFiles(unittest.TestCase):
    def test_checked_in_cases_are_current(self):
        for spec in all_specs():
            with self.subTest(case=spec.name):
                self.assertEqual((CASES / f"{spec.name}.textproto").read_text(), case_text(spec))

    def test_each_opens_with_what_it_models_shows_and_how_to_run_it(self):
        for spec in all_specs():
            text = case_text(spec)
            comment = text[:text.index("\ntitle:")]
            self.assertTrue(all(line.startswith("#") for line in comment.splitlines()))
            self.assertIn("# What it models:", comment)
            self.assertIn("# What it should show:", comment)
            self.assertIn(f"scripts/run_case.py cases/{spec.name}.textproto", comment)
            self.assertEqual(spec.kind == "FE", "--fe-only" in comment)

    def test_sector_cases_use_sector_meshes(self):
        for spec in all_specs():
            self.assertIn(f'mesh_file: "meshes/valve-{spec.variant}-{spec.resolution}.mesh.h5"', case_text(spec))


if __name__ == "__main__":
    unittest.main()
