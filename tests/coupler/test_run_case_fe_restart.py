"""The launcher continues an FE-only run from its restart point (a full-valve FE-only cycle takes
hours) and records every run's cost: the 2D xcoarse FE-MHGO case to 20 ms, continued to 30 ms
from its 20 ms restart point, ends bit for bit where one run to 30 ms ends; wall_time.json holds
the wall and CPU times, the exit code and the restart point."""
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

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @classmethod
    def launch_run(cls, case, output=None, restart=None):
        output = output or case
        command = ["/usr/bin/python3", str(REPO / "scripts" / "run_case.py"), str(cls.dir / f"{case}.textproto"),
                   "--output", str(cls.dir / output), "--build-dir", str(BUILD), "--fe-only"]
        if restart:
            command += ["--restart", str(restart)]
        result = subprocess.run(command, capture_output=True, text=True, timeout=300)
        cls.logs[output] = (result.returncode, result.stdout + result.stderr)

    def test_every_run_succeeds(self):
        for name, (code, log) in self.logs.items():
            self.assertEqual(code, 0, f"{name}: {log[-2000:]}")

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
