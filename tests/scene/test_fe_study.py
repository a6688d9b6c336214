"""The FE-only study's analysis on a synthetic run folder in solid_fe's output layout."""
import math
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

import json

from valve_scene.fe_study import analyse, main, write_report
from valve_scene.valve_mesh import build_valve_mesh
from valve_scene.write_cases import CaseSpec

R = 11.5e-3


def SMOOTHED_RAMP(duration, sigma=1e-3):
    """What valve_events reads for a linear ramp of `duration` (its steepest slope after the
    Gaussian smoothing is reduced by erf(duration / (2 sqrt(2) sigma)))."""
    return duration / math.erf(duration / (2 * math.sqrt(2) * sigma))


def opening_fraction(t):
    """Per cycle: opens 0 -> 5 ms, stays open, closes 230 -> 240 ms."""
    phase = np.mod(t, 0.8)
    return np.interp(phase, [0, 0.005, 0.230, 0.240, 0.8], [0, 0.8, 0.8, 0, 0])


def deform(nodes, fraction):
    rho = np.hypot(nodes[:, 0], nodes[:, 1])
    alpha = fraction * np.clip(nodes[:, 2] / 12e-3, 0, 1)
    x = nodes.copy()
    x[:, :2] *= (1 + alpha * (R - rho) / rho)[:, None]
    return x


def window_fraction(offset):
    """A window run started at cycle time `offset` from the closed leaflet: closed for its
    first 10 ms (the start-up the analysis must skip), then as the cycle."""
    return lambda t: np.where(np.asarray(t) < 0.01, 0.0, opening_fraction(np.asarray(t) + offset)) if offset > 0 \
        else opening_fraction(t)


def write_fake_run(run_dir: Path, spec: CaseSpec, end=1.6, fraction=opening_fraction, snapshot_interval=0.005):
    mesh = build_valve_mesh(spec.variant, spec.resolution, "triangles")
    mid = mesh.node_sets["free_edge_midpoints"]
    opening_fraction = fraction
    run_dir.mkdir(parents=True, exist_ok=True)
    t_series = np.arange(0, end + 1e-9, 1e-4)
    positions = np.stack([deform(mesh.nodes[mid], f) for f in opening_fraction(t_series)])
    with h5py.File(run_dir / "solid_series.h5", "w") as f:
        f["time"] = t_series
        f["monitor/free_edge_midpoints/position"] = positions
        f["transvalvular_pressure_Pa"] = np.zeros_like(t_series)
        f["energy/relative_balance_error"] = np.full_like(t_series, 1e-3)
    # element fields: strain peaks at the element nearest a commissure top, scaled by the opening
    centroids = mesh.nodes[mesh.triangles].mean(axis=1)
    top = mesh.nodes[mesh.node_sets["attachment"]]
    commissure = top[np.argmax(top[:, 2])]
    pattern = np.exp(-np.linalg.norm(centroids - commissure, axis=1) / 2e-3)
    with h5py.File(run_dir / "solid_fields.h5", "w") as f:
        f["mesh/nodes"] = mesh.nodes
        f["mesh/triangles"] = mesh.triangles
        for k, t in enumerate(np.arange(0, end + 1e-9, snapshot_interval)):
            g = f.create_group(f"snapshots/{k:06d}")
            g.attrs["time"] = t
            frac = float(opening_fraction(t))
            g["position"] = deform(mesh.nodes, frac)
            g["max_principal_log_strain"] = 0.2 * pattern * (0.2 + frac)
            g["max_principal_stress"] = 1e6 * pattern * (0.2 + frac)
    return pattern.max()


class FeStudyAnalysis(unittest.TestCase):
    def test_synthetic_run_gives_its_known_metrics(self):
        spec = CaseSpec("FE", "Ogden", "sector", "coarse")
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp)
            pattern_max = write_fake_run(run, spec)
            result = analyse(spec, run, cycle=2, wall_time_s=12.0)
            self.assertIsNotNone(result.events, result.events_error)
            # r is linear in the opening fraction: 10-90 % of a 5 ms and a 10 ms ramp
            self.assertAlmostEqual(result.events.rvot, SMOOTHED_RAMP(0.005), delta=1e-6)
            self.assertAlmostEqual(result.events.rvct, SMOOTHED_RAMP(0.010), delta=1e-6)
            self.assertAlmostEqual(result.events.et, 0.235 + SMOOTHED_RAMP(0.010) / 2 - (0.0025 - SMOOTHED_RAMP(0.005) / 2), delta=1e-5)
            peak, when = result.peaks["opening/max_principal_log_strain"]
            self.assertEqual(peak.region, "commissure")
            self.assertAlmostEqual(peak.value, 0.2 * pattern_max * (0.2 + 0.8), delta=1e-12)  # fully open
            self.assertGreater(result.series["goa_m2"].max(), 5 * result.series["goa_m2"][0])
            self.assertIn(0.0, result.profiles)
            write_report([result], run / "report.md", run / "figures")
            text = (run / "report.md").read_text()
            self.assertIn("| fe-ogden-sector-coarse | 5.1 | 10.0 | 240.0 |", text)
            self.assertTrue((run / "figures" / "fe-only-fe-ogden-sector-kinematics.png").exists())

    def test_cycles_mode_reports_each_cycle_with_the_recorded_times(self):
        spec = CaseSpec("FE", "Ogden", "sector", "coarse")
        # cycle 1 closes 10 ms later than cycle 2 (230 -> 240 ms against 220 -> 230 ms)
        def fraction(t):
            t = np.asarray(t)
            late = np.interp(np.mod(t, 0.8), [0, 0.005, 0.230, 0.240, 0.8], [0, 0.8, 0.8, 0, 0])
            early = np.interp(np.mod(t, 0.8), [0, 0.005, 0.220, 0.230, 0.8], [0, 0.8, 0.8, 0, 0])
            return np.where(t < 0.8, late, early)
        with tempfile.TemporaryDirectory() as tmp:
            runs = Path(tmp)
            write_fake_run(runs / spec.name, spec, fraction=fraction, snapshot_interval=0.05)
            (runs / spec.name / "wall_time.json").write_text(json.dumps({"wall_time_s": 100.0, "cpu_time_s": 40.0}))
            main(["--mode", "cycles", "--skip-run", "--materials", "Ogden", "--runs-dir", str(runs),
                  "--also-cycles", "1", "--report", str(runs / "report.md")])
            text = (runs / "report.md").read_text()
            shift = 0.0025 - SMOOTHED_RAMP(0.005) / 2
            for cycle, closing_mid in ((1, 0.235), (2, 0.225)):
                et = (closing_mid + SMOOTHED_RAMP(0.010) / 2 - shift) * 1e3
                self.assertIn(f"| fe-ogden-sector-coarse (cycle {cycle}, sharp commissure) | 5.1 | 10.0 | {et:.1f} |", text)
            self.assertIn("| 100 / 40 |", text)


if __name__ == "__main__":
    unittest.main()


class OpeningMetrics(unittest.TestCase):
    def test_linear_opening_gives_its_crossings_and_peaks(self):
        from valve_scene.fe_study import opening_metrics
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp)
            t = np.arange(0, 0.1 + 1e-9, 1e-4)
            r = np.interp(t, [0, 0.002, 0.012, 0.1], [1e-3, 1e-3, 11e-3, 11e-3])   # 1 -> 11 mm over 2-12 ms
            positions = np.stack([r, np.zeros_like(r), np.full_like(r, 0.011)], axis=1)[:, None, :]
            ts = np.arange(0, 0.1 + 1e-9, 0.002)
            with h5py.File(run / "solid_series.h5", "w") as f:
                f["time"] = t
                f["monitor/free_edge_midpoints/position"] = positions
                f["snapshots/time"] = ts
                f["snapshots/peak_max_principal_log_strain"] = np.where(ts == 0.04, 0.25, 0.1)   # at 40 ms: in
                f["snapshots/peak_max_principal_stress"] = np.where(ts == 0.08, 9e6, 1e6)       # at 80 ms: out
            m = opening_metrics(run, end_s=0.06)
            self.assertAlmostEqual(m["opening_start_s"], 0.003, delta=1e-9)   # 10 %: 2 mm
            self.assertAlmostEqual(m["opening_end_s"], 0.011, delta=1e-9)     # 90 %: 10 mm
            self.assertAlmostEqual(m["rvot_s"], 0.008, delta=1e-9)
            self.assertAlmostEqual(m["r_open_m"], 0.011, delta=1e-12)
            self.assertEqual(m["peak_log_strain"], 0.25)
            self.assertEqual(m["peak_stress_Pa"], 1e6)
            with self.assertRaisesRegex(ValueError, "ends at 0.1 s, before 0.2 s"):
                opening_metrics(run, end_s=0.2)


class FeStudyWindows(unittest.TestCase):
    def test_windows_give_the_cycle_metrics(self):
        from valve_scene.fe_study import CLOSING_WINDOW, OPENING_WINDOW, analyse_windows, window_case_text
        spec = CaseSpec("FE", "MHGO", "sector", "coarse")
        with tempfile.TemporaryDirectory() as tmp:
            opening, closing = Path(tmp) / "opening", Path(tmp) / "closing"
            write_fake_run(opening, spec, OPENING_WINDOW[1], window_fraction(0.0))
            write_fake_run(closing, spec, CLOSING_WINDOW[1] - CLOSING_WINDOW[0], window_fraction(CLOSING_WINDOW[0]))
            result = analyse_windows(spec, opening, closing)
            self.assertIsNotNone(result.events, result.events_error)
            self.assertAlmostEqual(result.events.rvot, SMOOTHED_RAMP(0.005), delta=1e-6)
            self.assertAlmostEqual(result.events.rvct, SMOOTHED_RAMP(0.010), delta=1e-6)
            self.assertAlmostEqual(result.events.et, 0.235 + SMOOTHED_RAMP(0.010) / 2 - (0.0025 - SMOOTHED_RAMP(0.005) / 2), delta=1e-5)
            self.assertIn("closed/max_principal_log_strain", result.robust_peaks)
            self.assertAlmostEqual(result.peaks["closed/max_principal_log_strain"][1], 0.30, delta=1e-9)
        # the window's case: the waveform rotated to start at the window's cycle time
        import re
        from valve_scene.waveform import transvalvular_pressure_mmHg
        text = window_case_text(spec, 0.15, 0.32)
        self.assertIn("end_time: 0.17", text)

        def table(name):
            block = re.search(name + r": \[([^\]]*)\]", text).group(1)
            return np.array([float(v) for v in block.replace("\n", " ").split(",")])
        t = table("time_s")
        dp = table("ventricular_pressure_mmHg") - table("aortic_pressure_mmHg")
        for run_time in (0.0, 0.05, 0.09, 0.15):
            k = int(round(run_time / 1e-3))
            self.assertAlmostEqual(t[k], run_time, delta=1e-9)
            self.assertAlmostEqual(dp[k], float(transvalvular_pressure_mmHg(0.15 + run_time)), delta=2e-3)
