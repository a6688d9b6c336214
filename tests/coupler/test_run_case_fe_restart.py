"""The launcher continues an FE-only run from its restart point (a full-valve FE-only cycle takes
hours) and records every run's cost: the 2D xcoarse FE-MHGO case to 20 ms, continued to 30 ms
from its 20 ms restart point, ends bit for bit where one run to 30 ms ends; wall_time.json holds
the wall and CPU times, the exit code and the restart point. With --resume the same two runs go
to one folder (the first starts it, the second continues it as segment 02 and joins both): one
series from 0 to 30 ms that ends bit for bit as the single run, the segments' costs summed."""
import json
import os
import re
import subprocess
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))
CASE = REPO / "cases" / "fe-mhgo-2d-xcoarse.textproto"


def case_text(end_time: float) -> str:
    text = CASE.read_text()
    text = re.sub(r"end_time: [0-9.]+", f"end_time: {end_time:g}", text, count=1)
    text = text.replace('mesh_file: "meshes/', f'mesh_file: "{REPO / "cases" / "meshes"}/')
    return text.replace("\nsolid {\n", "\nsolid {\n  restart_interval_s: 0.01\n", 1)


class FeOnlyRestart(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="fe-restart-")
        cls.dir = Path(cls.tmp.name)
        for name, end in (("first", 0.02), ("whole", 0.03)):
            (cls.dir / f"{name}.textproto").write_text(case_text(end))
        cls.logs = {}
        cls.launch_run("first")
        cls.launch_run("whole")
        cls.launch_run("whole", output="continued", restart=cls.dir / "first" / "restart")
        cls.launch_run("first", output="resumed", resume=True, key="resumed-1")
        cls.launch_run("whole", output="resumed", resume=True, key="resumed-2")
        (cls.dir / "no-restart").mkdir()
        (cls.dir / "no-restart" / "solid.log").write_text("a run stopped before its first restart point\n")
        cls.launch_run("whole", output="no-restart", resume=True, key="no-restart")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @classmethod
    def launch_run(cls, case, output=None, restart=None, resume=False, key=None):
        output = output or case
        command = ["/usr/bin/python3", str(REPO / "scripts" / "run_case.py"), str(cls.dir / f"{case}.textproto"),
                   "--output", str(cls.dir / output), "--build-dir", str(BUILD), "--fe-only"]
        if restart:
            command += ["--restart", str(restart)]
        if resume:
            command += ["--resume"]
        result = subprocess.run(command, capture_output=True, text=True, timeout=300)
        cls.logs[key or output] = (result.returncode, result.stdout + result.stderr)

    def test_every_run_succeeds(self):
        for name, (code, log) in self.logs.items():
            if name != "no-restart":
                self.assertEqual(code, 0, f"{name}: {log[-2000:]}")

    def test_a_resumed_run_is_one_series_in_its_folder(self):
        run = self.dir / "resumed"
        self.assertNotIn("resuming", self.logs["resumed-1"][1])        # an empty folder: a plain start
        self.assertIn("as segment 02", self.logs["resumed-2"][1])
        self.assertEqual(sorted(p.name for p in (run / "segments").iterdir()), ["01", "02"])
        self.assertTrue((run / "segments" / "01" / "solid.log").is_file())
        with h5py.File(run / "solid_series.h5") as f:
            t = f["time"][()]
            resumed = f["monitor/free_edge_midpoints/position"][-1]
        self.assertAlmostEqual(t[0], 0.0, delta=1e-12)
        self.assertAlmostEqual(t[-1], 0.03, delta=1e-9)
        self.assertTrue(np.all(np.diff(t) > 0))
        with h5py.File(self.dir / "whole" / "solid_series.h5") as f:
            np.testing.assert_array_equal(resumed, f["monitor/free_edge_midpoints/position"][-1])
        joined = json.loads((run / "wall_time.json").read_text())
        parts = [json.loads((run / "segments" / n / "wall_time.json").read_text()) for n in ("01", "02")]
        self.assertAlmostEqual(joined["wall_time_s"], sum(p["wall_time_s"] for p in parts), delta=1e-6)
        self.assertEqual(parts[1]["restart_from"], str((run / "segments" / "01" / "restart").resolve()))

    def test_resume_without_a_restart_point_is_refused_and_keeps_the_folder(self):
        code, log = self.logs["no-restart"]
        self.assertEqual(code, 2)
        self.assertIn("holds no restart point", log)
        self.assertTrue((self.dir / "no-restart" / "solid.log").is_file())
        self.assertFalse((self.dir / "no-restart" / "segments").exists())

    def test_the_continued_run_starts_at_the_restart_point_and_ends_as_one_run(self):
        self.assertIn("continuing from", self.logs["continued"][1])
        with h5py.File(self.dir / "continued" / "solid_series.h5") as f:
            t = f["time"][()]
            continued = f["monitor/free_edge_midpoints/position"][-1]
        self.assertGreater(t[0], 0.02 - 1e-9)        # nothing before the restart point is redone
        self.assertAlmostEqual(t[-1], 0.03, delta=1e-9)
        with h5py.File(self.dir / "whole" / "solid_series.h5") as f:
            whole = f["monitor/free_edge_midpoints/position"][-1]
        np.testing.assert_array_equal(continued, whole)

    def test_the_cost_record_names_the_restart_point(self):
        first = json.loads((self.dir / "first" / "wall_time.json").read_text())
        continued = json.loads((self.dir / "continued" / "wall_time.json").read_text())
        for record in (first, continued):
            self.assertEqual(record["exit_code"], 0)
            self.assertGreater(record["wall_time_s"], 0.0)
            self.assertGreaterEqual(record["cpu_time_s"], 0.0)
        self.assertNotIn("restart_from", first)
        self.assertEqual(continued["restart_from"], str((self.dir / "first" / "restart").resolve()))


if __name__ == "__main__":
    unittest.main()
