"""scripts/run_case.py finds the programs of the build tree it is given, not those of another
build tree nested inside it (a helper's build/clean/ once won silently); --resume picks the
newest restart point and sets aside segments stopped before their first one."""
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



class Resume(unittest.TestCase):
    def test_a_segment_stopped_before_its_first_restart_point_is_set_aside(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp) / "run"
            for name, has_restart in (("01", True), ("02", True), ("03", False)):
                (run / "segments" / name).mkdir(parents=True)
                if has_restart:
                    (run / "segments" / name / "restart").mkdir()
                    (run / "segments" / name / "restart" / "LATEST").write_text("t_0.1\n")
            (run / "fluid_probes.h5").write_text("the last join")
            segment, restart = run_case.prepare_resume(run)
            self.assertEqual(segment, run / "segments" / "04")
            self.assertEqual(restart, run / "segments" / "02" / "restart")
            self.assertTrue((run / "segments" / "03-superseded").is_dir())
            self.assertEqual([p.name for p in run_case.segment_folders(run)], ["01", "02"])
            self.assertFalse((run / "fluid_probes.h5").exists())     # the join is written again

    def test_an_empty_folder_starts_the_run_there(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(run_case.prepare_resume(Path(tmp)), (Path(tmp), None))
            self.assertEqual(run_case.prepare_resume(Path(tmp) / "new"), (Path(tmp) / "new", None))


if __name__ == "__main__":
    unittest.main()
