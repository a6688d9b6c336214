"""Joining the output of a run continued from restarts (valve_scene.join_segments)."""
import json
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

from valve_scene.join_segments import JoinError, join


def write_series(path: Path, t: np.ndarray, value_offset: float) -> None:
    with h5py.File(path, "w") as f:
        f["time"] = t
        f["energy/kinetic"] = t * 10 + value_offset
        f["monitor/points/position"] = np.stack([t, 2 * t, 3 * t], axis=1)[:, None, :] + value_offset
        f["snapshots/time"] = t[::5]
        f["snapshots/peak"] = t[::5] + value_offset
        f["settings/table"] = np.arange(4) + value_offset  # not a series: taken from the last segment
        f.attrs["program"] = "test"


def write_fields(path: Path, times: list[float], marker: float) -> None:
    with h5py.File(path, "w") as f:
        f["mesh/nodes"] = np.zeros((3, 3))
        for i, t in enumerate(times):
            g = f.create_group(f"snapshots/{i:06d}")
            g.attrs["time"] = t
            g["position"] = np.full((3, 3), marker)


class JoinSegmentsTest(unittest.TestCase):
    def setUp(self):
        self.dir = Path(tempfile.mkdtemp())
        self.a, self.b, self.out = self.dir / "a", self.dir / "b", self.dir / "joined"
        self.a.mkdir()
        self.b.mkdir()
        # segment a runs 0-0.30 s; b restarts from its 0.20 s point and runs to 0.50 s
        write_series(self.a / "solid_series.h5", np.round(np.arange(0, 0.31, 0.01), 10), 0.0)
        write_series(self.b / "solid_series.h5", np.round(np.arange(0.2, 0.51, 0.01), 10), 1000.0)
        write_fields(self.a / "solid_fields.h5", [0.0, 0.1, 0.2, 0.3], 1.0)
        write_fields(self.b / "solid_fields.h5", [0.2, 0.3, 0.4], 2.0)

    def test_later_segment_wins_from_its_first_sample(self):
        join([self.a, self.b], self.out)
        with h5py.File(self.out / "solid_series.h5") as f:
            t = f["time"][()]
            np.testing.assert_allclose(t, np.round(np.arange(0, 0.51, 0.01), 10))
            k = f["energy/kinetic"][()]
            np.testing.assert_allclose(k[t < 0.195], t[t < 0.195] * 10)          # from a
            np.testing.assert_allclose(k[t > 0.195], t[t > 0.195] * 10 + 1000.0)  # from b
            self.assertEqual(f["monitor/points/position"].shape, (51, 1, 3))
            np.testing.assert_allclose(f["snapshots/time"][()], [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5])
            np.testing.assert_allclose(f["settings/table"][()], np.arange(4) + 1000.0)
            self.assertEqual(f.attrs["program"], "test")

    def test_snapshots_renumbered_in_time_order(self):
        join([self.a, self.b], self.out)
        with h5py.File(self.out / "solid_fields.h5") as f:
            names = sorted(f["snapshots"])
            self.assertEqual(names, [f"{i:06d}" for i in range(5)])
            times = [f["snapshots"][n].attrs["time"] for n in names]
            np.testing.assert_allclose(times, [0.0, 0.1, 0.2, 0.3, 0.4])
            self.assertEqual(f["snapshots/000001/position"][0, 0], 1.0)
            self.assertEqual(f["snapshots/000002/position"][0, 0], 2.0)
            self.assertIn("mesh", f)

    def test_unflushed_samples_show_as_a_gap(self):
        # a stopped by a signal before flushing its last samples: it ends at 0.12 s, b starts at 0.2 s
        write_series(self.a / "solid_series.h5", np.round(np.arange(0, 0.125, 0.01), 10), 0.0)
        report = join([self.a, self.b], self.out)
        gaps = [g for g in report.gaps if g[0].endswith(":time")]
        self.assertEqual(len(gaps), 1)
        self.assertAlmostEqual(gaps[0][1], 0.12)
        self.assertAlmostEqual(gaps[0][2], 0.2)

    def test_segments_out_of_order_are_refused(self):
        with self.assertRaisesRegex(JoinError, "earliest first"):
            join([self.b, self.a], self.out)

    def test_costs_are_summed_when_every_segment_has_its_record(self):
        (self.a / "wall_time.json").write_text(json.dumps({"wall_time_s": 100.5, "cpu_time_s": 90.0, "exit_code": 143}))
        report = join([self.a, self.b], self.out)
        self.assertFalse((self.out / "wall_time.json").exists())          # b has no record
        self.assertIn(f"no cost record (wall_time.json) in {self.b}", "\n".join(report.lines()))
        (self.b / "wall_time.json").write_text(json.dumps({"wall_time_s": 20.25, "cpu_time_s": 18.0, "exit_code": 0}))
        join([self.a, self.b], self.out)
        joined = json.loads((self.out / "wall_time.json").read_text())
        self.assertEqual(joined["wall_time_s"], 120.75)
        self.assertEqual(joined["cpu_time_s"], 108.0)
        self.assertEqual(joined["exit_code"], 0)                          # the last segment's
        self.assertEqual(len(joined["segments"]), 2)

    def test_the_joined_folder_lists_its_segments_for_their_particle_snapshots(self):
        from valve_scene.comparison import particle_files
        from valve_scene.join_segments import segments_of
        with h5py.File(self.b / "fluid_particles.h5", "w") as f:
            f.create_group("snapshot_000000").attrs["time"] = 0.3
        join([self.a, self.b], self.out)
        self.assertEqual(segments_of(self.out), [self.a.resolve(), self.b.resolve()])
        self.assertEqual(segments_of(self.a), [])                       # not a joined run
        # the velocity slice looks in the segments: only b has snapshots
        self.assertEqual(particle_files(self.out), [self.b.resolve() / "fluid_particles.h5"])

    def test_output_must_not_be_a_segment(self):
        with self.assertRaisesRegex(JoinError, "is one of the segments"):
            join([self.a, self.b], self.b)


if __name__ == "__main__":
    unittest.main()
