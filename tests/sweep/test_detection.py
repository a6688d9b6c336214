"""Failure detection on small coupled scenes (issue 8, item 2; docs/stability-map.md): each scene
triggers one failure kind for real, and the run must stop promptly, all three programs with it,
with a message that names what failed, when, and what to change; the last good state must be
readable. Only failures the programs detect are here; the others are listed with evidence in
docs/stability-map.md ("Detection gaps").
"""
import os
import re
import tempfile
import time
import unittest
from pathlib import Path

import h5py
import numpy as np

from sweep import outcome, runner, scenes

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))


def run_scene(work: Path, setting: dict, end_time: float):
    case = scenes.write_case("valve2d", setting, work, end_time)
    started = time.monotonic()
    cost = runner.run_case(case, work / "run", BUILD, work / "launcher.log", wall_limit_s=300)
    return cost, time.monotonic() - started


class TimeStepCollapse(unittest.TestCase):
    """c0 = 2.5 m/s on the 2D valve (Mach ~0.6 at the jet speed): the first pressure wave
    squeezes particles against the leaflets and the fluid's step collapses at ~15 ms
    (stability map, group "sound speed")."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="sweep-collapse-")
        cls.work = Path(cls.tmp.name)
        cls.cost, cls.wall = run_scene(cls.work, {"sound_speed": 2.5}, 0.03)
        cls.run_dir = cls.work / "run"
        cls.fluid_log = (cls.run_dir / "fluid.log").read_text()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def collapse_time(self) -> float:
        match = re.search(r"time step collapsed at t = ([0-9.eE+-]+) s", self.fluid_log)
        self.assertIsNotNone(match, self.fluid_log[-2000:])
        return float(match.group(1))

    def test_the_run_fails_and_all_programs_stop(self):
        self.assertNotEqual(self.cost.exit_code, 0)
        # the launcher returned: no program left behind (it waits for all three or kills them)
        self.assertFalse(self.cost.timed_out)
        for role in ("coupler", "solid"):
            self.assertIn("time step collapsed", (self.run_dir / f"{role}.log").read_text(),
                          f"{role} did not relay the cause")

    def test_message_says_what_when_and_what_to_change(self):
        t = self.collapse_time()
        self.assertGreater(t, 0.0)
        self.assertLess(t, 0.03)
        for words in ("largest fluid speed", "raise the sound speed", "min_time_step_ratio"):
            self.assertIn(words, self.fluid_log)

    def test_classified_as_time_step_collapse_by_the_fluid(self):
        o = outcome.classify(self.run_dir, self.cost.exit_code, 0.03, launcher_log=self.work / "launcher.log")
        self.assertEqual(o.kind, "time-step collapse")
        self.assertIn("time step collapsed", o.detail)

    def test_last_good_state_is_readable(self):
        t = self.collapse_time()
        with h5py.File(self.run_dir / "coupling_series.h5", "r") as f:
            times, window = f["time"][...], float(f["window_size"][-1])
            self.assertTrue(np.all(np.isfinite(f["force_fluid"][...])))
        # every window before the failing one is in the interface series
        self.assertLessEqual(t - times[-1], window * (1 + 1e-9))
        with h5py.File(self.run_dir / "fluid_particles.h5", "r") as f:
            snapshots = sorted(f)
            self.assertGreaterEqual(len(snapshots), 2, "the 10 ms snapshot before the collapse")
            self.assertTrue(np.all(np.isfinite(f[snapshots[-1]]["position"][...])))
        with h5py.File(self.run_dir / "solid_series.h5", "r") as f:
            self.assertGreater(f["time"][-1], 0.0)


if __name__ == "__main__":
    unittest.main()
