"""The coarse 1/6 sector with its leaflet moved by a prescribed opening (issue 6 item 6,
docs/thin-leaflet.md "Prescribed-motion sector"): the committed FSI case's fluid (c0 20 m/s,
dp 0.9 mm, hex fill, mirror planes) through the coupler with `prescribed_leaflet_solid` in the
solid's place. The open shape is the FE-only sector's at 6 ms (run here, ~2 s).

Short slice (verification, default): the first 0.3 ms of an opening over 2 ms from t = 0 (tip
speed up to ~2 m/s by then). Asserted: no leak and no lost particle; the fluid resists the
motion (its loads do negative work); the force stays below the acoustic-impedance bound of a
piston, 2 rho c0 sum(|v.n| A) (a pressure jump of rho c0 v_n on each side; the free edge and
the gaps relieve it), and in this fast start above a tenth of it (a model whose loads vanish
or leak through the leaflet would fail; measured 0.22-0.75 over the first 0.3 ms). Set PRESCRIBED_SECTOR_FULL=1 for the validation run: opening 5 ms, held
2 ms, closing 5 ms (15 ms, 45 min wall at load 13-16 on one thread), which also asserts that the fluid resists the
closing and that at most 10 particles are removed by the density limit (1 measured).
Needs the programs: VALVEFSI_BUILD_DIR (ctest sets it)."""
import os
import re
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("VALVEFSI_BUILD_DIR", REPO / "build"))
FULL = os.environ.get("PRESCRIBED_SECTOR_FULL", "0") == "1"
RHO, C0 = 1056.0, 20.0
# (open_start, opening, hold, closing, end) in s
SCHEDULE = (0.001, 0.005, 0.002, 0.005, 0.015) if FULL else (0.0, 0.002, 0.0, 0.002, 0.0003)
WINDOW = 5e-5


def case_text(name: str, end_time: float) -> str:
    text = (REPO / "cases" / f"{name}.textproto").read_text()
    text = re.sub(r'mesh_file: "([^"]+)"', lambda m: f'mesh_file: "{REPO / "cases" / m.group(1)}"', text)
    text, n = re.subn(r"end_time: [0-9.eE+-]+", f"end_time: {end_time}", text, count=1)
    assert n == 1
    return text


def run(case: Path, out: Path, *extra) -> subprocess.CompletedProcess:
    env = {**os.environ, "OMP_WAIT_POLICY": "passive"}
    env.setdefault("OMP_NUM_THREADS", "2")
    return subprocess.run([sys.executable, str(REPO / "scripts" / "run_case.py"), str(case), "--output", str(out),
                           "--build-dir", str(BUILD), *extra], capture_output=True, text=True, env=env,
                          timeout=7200 if FULL else 900)


def node_normals(nodes: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Area-weighted unit normals and areas (a third of each triangle) per node."""
    p = nodes[triangles]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    normals = np.zeros_like(nodes)
    areas = np.zeros(len(nodes))
    for k in range(3):
        np.add.at(normals, triangles[:, k], cross)
        np.add.at(areas, triangles[:, k], 0.5 * np.linalg.norm(cross, axis=1) / 3)
    return normals / np.linalg.norm(normals, axis=1)[:, None], areas


class PrescribedSector(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="prescribed-sector-")
        work = Path(cls.tmp.name)
        fe_case = work / "fe.textproto"
        fe_case.write_text(case_text("fe-mhgo-sector-coarse", 0.006))
        cls.fe = run(fe_case, work / "fe", "--fe-only")
        start, opening, hold, closing, end = SCHEDULE
        text = case_text("fsi-mhgo-sector-coarse", end)
        text, n = re.subn(r"window_size: [0-9.eE+-]+", f"window_size: {WINDOW}", text, count=1)
        assert n == 1
        args = ["--open-shape", str(work / "fe" / "solid_fields.h5"), "--open-snapshot", "000003",
                "--open-start", str(start), "--opening", str(opening), "--hold", str(hold), "--closing", str(closing)]
        exe = BUILD / "fluid_sph" / "thin_wall" / "prescribed_leaflet_solid"
        text = text.replace("  mapping: NEAREST_PROJECTION\n",
                            f'  mapping: NEAREST_PROJECTION\n  solid_executable: "{exe}"\n'
                            f'  solid_arguments: [{", ".join(chr(34) + a + chr(34) for a in args)}]\n', 1)
        text = re.sub(r"snapshot_interval: [0-9.eE+-]+", "snapshot_interval: 0", text, count=1)
        # the prescribed solid writes no restart data
        text, n = re.subn(r"  restart_interval_s: [0-9.eE+-]+\n", "", text, count=1)
        assert n == 1
        case = work / "prescribed.textproto"
        case.write_text(text)
        cls.out = work / "prescribed"
        cls.coupled = run(case, cls.out) if cls.fe.returncode == 0 else None
        with h5py.File(work / "fe" / "solid_fields.h5", "r") as f:
            cls.rest = f["mesh/nodes"][()]
            cls.triangles = f["mesh/triangles"][()]
            cls.open = f["snapshots/000003/position"][()]

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def setUp(self):
        self.assertEqual(self.fe.returncode, 0, self.fe.stdout[-2000:] + self.fe.stderr[-2000:])
        self.assertEqual(self.coupled.returncode, 0, self.coupled.stdout[-3000:] + self.coupled.stderr[-3000:])

    def series(self):
        with h5py.File(self.out / "coupling_series.h5", "r") as f:
            t, force = f["time"][()], f["force_fluid"][()]
        with h5py.File(self.out / "fluid_probes.h5", "r") as f:
            leaks = f["interface/leaks"][()].reshape(-1)
            lost = f["lost_particles"][()].reshape(-1)
        return t, force, leaks, lost

    def schedule(self, t):
        start, opening, hold, closing, _ = SCHEDULE
        tau = np.clip((t - start) / opening, 0, 1)
        s = 0.5 * (1 - np.cos(np.pi * tau))
        ds = np.where((tau > 0) & (tau < 1), 0.5 * np.pi * np.sin(np.pi * tau) / opening, 0.0)
        tau2 = np.clip((t - start - opening - hold) / closing, 0, 1)
        s = s - 0.5 * (1 - np.cos(np.pi * tau2))
        ds = ds - np.where((tau2 > 0) & (tau2 < 1), 0.5 * np.pi * np.sin(np.pi * tau2) / closing, 0.0)
        return s, ds

    def test_reaches_the_end_without_leak_or_loss(self):
        t, _, leaks, lost = self.series()
        self.assertAlmostEqual(t[-1], SCHEDULE[4], delta=1e-9)
        self.assertEqual(int(leaks[-1]), 0)
        # the closing squeezes the film where the free edges meet at the axis: 1 particle of
        # 60,337 was removed by the density limit there at 13.9 ms (session 7); the opening loses none
        self.assertLessEqual(int(lost[-1]), 10 if FULL else 0)

    def test_the_fluid_resists_the_motion(self):
        t, force, _, _ = self.series()
        travel = self.open - self.rest
        s_end, _ = self.schedule(t)
        s_start, _ = self.schedule(t - WINDOW)
        # the force_fluid series is the total; the work needs the node loads: the total force
        # against the travel's mean direction, weighted by the node areas, is the same sign
        normals, areas = node_normals(self.rest, self.triangles)
        mean_travel = (travel * areas[:, None]).sum(axis=0) / areas.sum()
        work = float(np.sum((s_end - s_start) * (force @ mean_travel)))
        print(f"work of the fluid's force along the mean travel: {work:.4e} J")
        self.assertLess(work, 0.0)

    def test_force_within_the_acoustic_bounds(self):
        t, force, _, _ = self.series()
        travel = self.open - self.rest
        normals, areas = node_normals(self.rest, self.triangles)
        _, ds = self.schedule(t - 0.5 * WINDOW)
        bound = 2 * RHO * C0 * np.abs(ds) * float(np.sum(np.abs(np.einsum("ij,ij->i", travel, normals)) * areas))
        magnitude = np.linalg.norm(force, axis=1)
        moving = bound > 0.2 * bound.max()
        ratio = magnitude[moving] / bound[moving]
        print(f"|F| / (2 rho c0 sum|v.n|A) over the moving windows: min {ratio.min():.3f} max {ratio.max():.3f} "
              f"(|F| up to {magnitude.max():.4g} N)")
        self.assertLess(ratio.max(), 1.0)
        if not FULL:   # the slow validation opening is far below the acoustic limit
            self.assertGreater(np.median(ratio), 0.1)

    @unittest.skipUnless(FULL, "the closing is in the validation run")
    def test_the_fluid_resists_the_closing_too(self):
        t, force, _, _ = self.series()
        travel = self.open - self.rest
        _, areas = node_normals(self.rest, self.triangles)
        mean_travel = (travel * areas[:, None]).sum(axis=0) / areas.sum()
        s_end, _ = self.schedule(t)
        s_start, _ = self.schedule(t - WINDOW)
        closing = t > SCHEDULE[0] + SCHEDULE[1] + SCHEDULE[2]
        work = float(np.sum(((s_end - s_start) * (force @ mean_travel))[closing]))
        print(f"work of the fluid's force along the mean travel while closing: {work:.4e} J")
        self.assertLess(work, 0.0)


if __name__ == "__main__":
    unittest.main()
