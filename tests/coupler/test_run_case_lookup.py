"""scripts/run_case.py finds the programs of the build tree it is given, not those of another
build tree nested inside it (a helper's build/clean/ once won silently)."""
import os
import tempfile
import unittest
from pathlib import Path

import run_case


def executable(path: Path):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/bin/sh\n")
    path.chmod(0o755)


class ExecutableLookup(unittest.TestCase):
    def test_the_build_trees_own_program_wins_over_a_nested_tree(self):
        with tempfile.TemporaryDirectory() as tmp:
            build = Path(tmp) / "build"
            (build / "clean").mkdir(parents=True)
            (build / "CMakeCache.txt").write_text("")
            (build / "clean" / "CMakeCache.txt").write_text("")
            executable(build / "clean" / "coupler" / "program" / "coupler")
            executable(build / "coupler" / "program" / "coupler")
            self.assertEqual(run_case.find_executable("coupler", build, "coupler"),
                             str(build / "coupler" / "program" / "coupler"))

    def test_only_a_nested_tree_has_it_then_path(self):
        with tempfile.TemporaryDirectory() as tmp:
            build = Path(tmp) / "build"
            (build / "clean").mkdir(parents=True)
            (build / "clean" / "CMakeCache.txt").write_text("")
            executable(build / "clean" / "solid_fe" / "solid_fe")
            executable(Path(tmp) / "bin" / "solid_fe")
            old = os.environ["PATH"]
            os.environ["PATH"] = f"{tmp}/bin:{old}"
            try:
                self.assertEqual(run_case.find_executable("solid_fe", build, "solid"), f"{tmp}/bin/solid_fe")
            finally:
                os.environ["PATH"] = old


if __name__ == "__main__":
    unittest.main()
