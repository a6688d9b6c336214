"""Hemodynamics (issue 7, item 3) on synthetic probe series with known answers: a half-sine
ejection (known rms and volume), a known pressure drop, a closing backflow plus a constant
leak (known regurgitant volume), a known leaflet force, two cycles, 2D units (and the 2D tips'
gap as an orifice), and the HDF5 layouts of fluid_sph, the coupler and the solid."""
import json
import math
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

from valve_scene import hemodynamics as hd

MMHG = hd.PA_PER_MMHG
T = 0.8            # period (s)
TE = 0.25          # ejection (forward flow) duration (s)
TC = 0.04          # closing backflow duration (s)
QMAX = 250e-6      # m^3/s peak forward flow (15 L/min)
A_BACK = 40e-6     # m^3/s closing backflow amplitude
Q_LEAK = 2e-6      # m^3/s leak through the closed valve
DT = 1e-4


def flow(t, scale=1.0):
    tau = np.mod(t, T)
    q = np.zeros_like(tau)
    fwd = tau <= TE
    q[fwd] = scale * QMAX * np.sin(np.pi * tau[fwd] / TE)
    s = tau - TE
    closing = (s > 0) & (s <= TC)
    # closing backflow rising from 0 into the leak level: -A sin(pi s / TC) - Q_LEAK s / TC
    q[closing] = -A_BACK * np.sin(np.pi * s[closing] / TC) - Q_LEAK * s[closing] / TC
    q[s > TC] = -Q_LEAK
    return q


def pressure_drop(t):
    """5 + 3 sin^2 mmHg during ejection (mean 6.5, peak 8 at TE/2), -80 mmHg after."""
    tau = np.mod(t, T)
    return np.where(tau <= TE, 5.0 + 3.0 * np.sin(np.pi * tau / TE) ** 2, -80.0) * MMHG


def axial_force(t):
    """0.25 N pull-out peak at TE/2; a -7 N diastolic spike at 270 ms (width 10 ms) over a
    -5 N plateau."""
    tau = np.mod(t, T)
    f = np.where(tau <= TE, 0.25 * np.sin(np.pi * tau / TE), -5.0 * (1 - np.exp(-(tau - TE) / 0.005)))
    return f - 2.0 * np.exp(-0.5 * ((tau - 0.27) / 0.005) ** 2) * (tau > TE)


def synthetic(cycles=2, dimension=3, first_cycle_scale=1.0, noise=0.0):
    t = np.arange(int(round(cycles * T / DT)) + 1) * DT
    scale = np.where(t < T, first_cycle_scale, 1.0)
    q = flow(t) * scale
    if noise:
        q = q + noise * QMAX * np.sin(2 * np.pi * 2000.0 * t + 0.3)
    p_down = 100 * MMHG + 0 * t
    tf = np.arange(int(round(cycles * T / 2e-5)) + 1) * 2e-5
    return hd.ProbeSeries(time=t, upstream_pressure=p_down + pressure_drop(t), downstream_pressure=p_down,
                          flow_rates={"a": 1.1 * q, "b": 0.9 * q}, max_velocity=1.4 * np.sin(np.pi * np.clip(np.mod(t, T), 0, TE) / TE) ** 2,
                          dimension=dimension, force_time=tf, axial_force=axial_force(tf))


class Ejection(unittest.TestCase):
    def setUp(self):
        self.r = hd.analyse_cycle(synthetic(), cycle=2, smoothing_s=0.0)

    def test_forward_flow_period_is_the_half_sine(self):
        self.assertAlmostEqual(self.r.forward_start_s, 0.0, delta=1e-9)
        self.assertAlmostEqual(self.r.forward_end_s, TE, delta=1e-6)

    def test_rms_flow_of_a_half_sine(self):
        self.assertAlmostEqual(self.r.q_rms, QMAX / math.sqrt(2) * 1e6, delta=1e-6 * QMAX * 1e6)
        self.assertAlmostEqual(self.r.stroke_volume, 2 * QMAX * TE / math.pi * 1e6, delta=1e-5)
        self.assertAlmostEqual(self.r.peak_flow_L_per_min, QMAX * 6e4, delta=1e-6)

    def test_mean_and_peak_pressure_drop(self):
        self.assertAlmostEqual(self.r.mspd_mmHg, 6.5, delta=1e-5)
        self.assertAlmostEqual(self.r.pspd_mmHg, 8.0, delta=1e-5)
        self.assertAlmostEqual(self.r.pspd_time_s, TE / 2, delta=DT)

    def test_eoa_is_gorlins(self):
        expected = QMAX / math.sqrt(2) * 1e6 / (51.6 * math.sqrt(6.5))   # 1.34 cm^2
        self.assertAlmostEqual(self.r.eoa, expected, delta=1e-5)
        self.assertTrue(1.3 < self.r.eoa < 1.45)

    def test_flow_is_averaged_over_the_sections(self):
        volume = 2 * QMAX * TE / math.pi * 1e6
        self.assertAlmostEqual(self.r.section_stroke_volumes["a"], 1.1 * volume, delta=1e-5)
        self.assertAlmostEqual(self.r.section_stroke_volumes["b"], 0.9 * volume, delta=1e-5)

    def test_peak_velocity_and_its_time(self):
        self.assertAlmostEqual(self.r.peak_velocity_m_per_s, 1.4, delta=1e-6)
        self.assertAlmostEqual(self.r.peak_velocity_time_s, TE / 2, delta=DT)


class Regurgitation(unittest.TestCase):
    def test_regurgitant_volume_is_closing_plus_leakage(self):
        r = hd.analyse_cycle(synthetic(), cycle=2, smoothing_s=0.0)
        closing = (2 * A_BACK * TC / math.pi + 0.5 * Q_LEAK * TC) * 1e6
        leakage = Q_LEAK * (T - TE - TC) * 1e6
        # exact up to the trapezoid over the sampled jump back to forward flow (half a sample of leak)
        self.assertAlmostEqual(r.regurgitant_volume, closing + leakage, delta=Q_LEAK * DT * 1e6)
        # the closure instant (90 % back to the leak level) falls just before TE + TC
        self.assertTrue(TE + 0.8 * TC < r.closure_time_s <= TE + TC)
        self.assertAlmostEqual(r.closing_volume, closing, delta=0.02 * closing)

    def test_given_closure_time_splits_exactly(self):
        r = hd.analyse_cycle(synthetic(), cycle=2, smoothing_s=0.0, closure_time_s=TE + TC)
        self.assertAlmostEqual(r.closing_volume, (2 * A_BACK * TC / math.pi + 0.5 * Q_LEAK * TC) * 1e6, delta=1e-5)
        self.assertAlmostEqual(r.leakage_volume, Q_LEAK * (T - TE - TC) * 1e6, delta=Q_LEAK * DT * 1e6)


class Forces(unittest.TestCase):
    def test_pull_out_diastolic_peak_and_water_hammer_ratio(self):
        r = hd.analyse_cycle(synthetic(), cycle=2, smoothing_s=0.0)
        self.assertAlmostEqual(r.pull_out_force, 0.25, delta=1e-6)
        expected_peak = -5.0 * (1 - math.exp(-0.02 / 0.005)) - 2.0
        self.assertAlmostEqual(r.diastolic_force, expected_peak, delta=0.01)
        self.assertAlmostEqual(r.diastolic_force_time_s, 0.27, delta=0.002)
        # hydrostatic: 97.2 mmHg on the size-23 annulus = 5.39 N (docs/valve-scene.md)
        self.assertAlmostEqual(r.hydrostatic_force, -5.39, delta=0.01)
        self.assertAlmostEqual(r.water_hammer_ratio, r.diastolic_force / r.hydrostatic_force, delta=1e-12)
        self.assertAlmostEqual(r.water_hammer_ratio, 6.93 / 5.39, delta=0.01)

    def test_reference_ratio_in_the_table(self):
        table = hd.hemodynamics_table({"synthetic": hd.analyse_cycle(synthetic(), smoothing_s=0.0)})
        self.assertIn("| water-hammer ratio | 1.28 | 1.28 | 1.13 |", table)
        self.assertIn("| EOA (cm²) | 1.34 | 1.22 | 1.50 |", table)


class Cycles(unittest.TestCase):
    def test_each_cycle_is_analysed_on_its_own(self):
        series = synthetic(first_cycle_scale=0.5)
        first = hd.analyse_cycle(series, cycle=1, smoothing_s=0.0)
        second = hd.analyse_cycle(series, cycle=2, smoothing_s=0.0)
        self.assertAlmostEqual(first.q_rms / second.q_rms, 0.5, delta=1e-6)

    def test_incomplete_cycle_is_refused(self):
        series = synthetic(cycles=1.5)
        with self.assertRaisesRegex(ValueError, "cycle 2 is incomplete: the series ends at 1.2 s"):
            hd.analyse_cycle(series, cycle=2)

    def test_partial_cycle_through_closing_gives_the_systolic_metrics(self):
        # a run that stops at 0.35 s, after the closing backflow (ends at TE + TC = 0.29 s)
        full = synthetic(cycles=1)
        cut, cut_f = full.time <= 0.35 + 1e-12, full.force_time <= 0.35 + 1e-12
        part = hd.ProbeSeries(time=full.time[cut], upstream_pressure=full.upstream_pressure[cut],
                              downstream_pressure=full.downstream_pressure[cut],
                              flow_rates={k: v[cut] for k, v in full.flow_rates.items()},
                              max_velocity=full.max_velocity[cut], force_time=full.force_time[cut_f],
                              axial_force=full.axial_force[cut_f])
        with self.assertRaisesRegex(ValueError, "cycle 1 is incomplete"):
            hd.analyse_cycle(part, cycle=1, smoothing_s=0.0)
        a = hd.analyse_cycle(full, cycle=1, smoothing_s=0.0, closure_time_s=TE + TC)
        b = hd.analyse_cycle(part, cycle=1, smoothing_s=0.0, closure_time_s=TE + TC, allow_partial=True)
        for key in ("mspd_mmHg", "pspd_mmHg", "eoa", "q_rms", "peak_flow", "closing_volume", "pull_out_force",
                    "diastolic_force", "water_hammer_ratio", "peak_velocity_m_per_s"):
            self.assertAlmostEqual(getattr(b, key), getattr(a, key), delta=1e-9 * max(1.0, abs(getattr(a, key))), msg=key)
        self.assertAlmostEqual(b.leakage_volume, Q_LEAK * (0.35 - TE - TC) * 1e6, delta=1e-6)
        self.assertAlmostEqual(b.series_end_s, 0.35, delta=1e-9)
        self.assertIsNone(a.series_end_s)
        self.assertIn("partial cycle: series ends at (ms)", hd.hemodynamics_table({"part": b}))

    def test_partial_cycle_needs_the_forward_flow_to_end(self):
        full = synthetic(cycles=1)
        cut = full.time <= 0.2
        part = hd.ProbeSeries(time=full.time[cut], upstream_pressure=full.upstream_pressure[cut],
                              downstream_pressure=full.downstream_pressure[cut],
                              flow_rates={k: v[cut] for k, v in full.flow_rates.items()}, max_velocity=None)
        with self.assertRaisesRegex(ValueError, "forward flow has not ended"):
            hd.analyse_cycle(part, cycle=1, smoothing_s=0.0, allow_partial=True)

    def test_noise_does_not_break_the_forward_period(self):
        # a 2 kHz ripple of 5 % of the peak (SPH-like) crosses zero many times near the ends
        r = hd.analyse_cycle(synthetic(noise=0.05), cycle=2, smoothing_s=0.002)
        self.assertAlmostEqual(r.forward_start_s, 0.0, delta=0.002)
        self.assertAlmostEqual(r.forward_end_s, TE, delta=0.002)
        self.assertAlmostEqual(r.q_rms, math.sqrt(0.5 * QMAX ** 2 + 0.5 * (0.05 * QMAX) ** 2) * 1e6, delta=0.01 * QMAX * 1e6)


def sixth_of_the_valve():
    """The synthetic valve's series as a 1/6 sector measures it: flows and forces / 6."""
    sector = synthetic()
    sector.flow_rates = {k: v / 6 for k, v in sector.flow_rates.items()}
    sector.axial_force = sector.axial_force / 6
    return sector


class Sector(unittest.TestCase):
    def test_a_sixth_of_the_valve_times_six_is_the_valve(self):
        full = synthetic()
        sector = sixth_of_the_valve()
        a = hd.analyse_cycle(full, smoothing_s=0.0)
        b = hd.analyse_cycle(sector, smoothing_s=0.0, symmetry_factor=6)
        for name in ("q_rms", "eoa", "regurgitant_volume", "pull_out_force", "diastolic_force", "water_hammer_ratio", "mspd_mmHg"):
            self.assertAlmostEqual(getattr(a, name), getattr(b, name), delta=1e-9 * max(1, abs(getattr(a, name))), msg=name)
        # the plot shows the valve's flow and force too, not the sector's
        qa, ta, fa = hd.plotted_flow_and_force(full, a)
        qb, tb, fb = hd.plotted_flow_and_force(sector, b)
        np.testing.assert_allclose(qb, qa, rtol=1e-12)
        np.testing.assert_allclose(tb, ta)
        np.testing.assert_allclose(fb, fa, rtol=1e-12)


class TwoDimensional(unittest.TestCase):
    def test_per_depth_units(self):
        r3 = hd.analyse_cycle(synthetic(dimension=3), smoothing_s=0.0)
        r2 = hd.analyse_cycle(synthetic(dimension=2), smoothing_s=0.0)
        # the same numbers read as m^2/s per metre depth: cm^2/s, i.e. 1e4 instead of 1e6
        self.assertAlmostEqual(r2.q_rms, r3.q_rms * 1e-2, delta=1e-9)
        self.assertAlmostEqual(r2.regurgitant_volume, r3.regurgitant_volume * 1e-2, delta=1e-9)
        self.assertAlmostEqual(r2.eoa, r3.eoa * 1e-2, delta=1e-9)
        # hydrostatic force per metre of depth on the 23 mm orifice: 97.2 mmHg x 0.023 m
        self.assertAlmostEqual(r2.hydrostatic_force, -hd.hydrostatic_pressure_Pa() * 0.023, delta=1e-9)
        self.assertAlmostEqual(r2.hydrostatic_force, -298.1, delta=0.5)
        self.assertIn("cm per cm depth", hd.hemodynamics_table({"2D": r2}))
        self.assertIsNone(r2.tip_gap_mm)
        self.assertNotIn("tips' gap", hd.hemodynamics_table({"2D": r2}))

    def test_tips_gap_as_an_orifice(self):
        # tips 0.4 mm apart (ringing +-0.1 mm) under the -80 mmHg of the closed valve: the slit
        # passes C_d g sqrt(2 |dp| / rho) per depth from the closure to the cycle's end
        series = synthetic(dimension=2)
        series.tip_gap_time = np.arange(0, 2 * T + 1e-9, 1e-4)
        series.tip_gap = 0.4e-3 + 0.1e-3 * np.sin(2 * np.pi * 300.0 * series.tip_gap_time)
        r = hd.analyse_cycle(series, cycle=1, smoothing_s=0.0)
        self.assertAlmostEqual(r.tip_gap_mm, 0.4, delta=2e-3)
        speed = math.sqrt(2 * 80 * MMHG / hd.BLOOD_DENSITY)            # 4.49 m/s
        expected = hd.SLIT_DISCHARGE_COEFFICIENT * 0.4e-3 * speed * (T - r.closure_time_s) * 1e4
        self.assertAlmostEqual(r.tip_gap_orifice_leakage, expected, delta=0.01 * expected)
        self.assertGreater(r.tip_gap_orifice_leakage, 5.0)               # cm^2 per cm: ~5.6
        table = hd.hemodynamics_table({"2D": r})
        self.assertIn("the tips' gap", table)
        self.assertIn(f"{r.tip_gap_orifice_leakage:.2f}", table)
        # forward flow through an open slit counts forward (sign of dp)
        q = hd.tip_gap_orifice_flow(np.array([0.0, 1.0]), np.array([8 * MMHG, -8 * MMHG]), np.array([0.0, 1.0]),
                                    np.array([1e-3, 1e-3]))
        self.assertAlmostEqual(q[0], -q[1], delta=1e-15)
        self.assertGreater(q[0], 0.0)


class Files(unittest.TestCase):
    def write_run(self, folder: Path, series: hd.ProbeSeries):
        with h5py.File(folder / "fluid_probes.h5", "w") as f:
            f["time"] = series.time.reshape(-1, 1)
            f["pressure/upstream_tap"] = series.upstream_pressure.reshape(-1, 1)
            f["pressure/downstream_tap"] = series.downstream_pressure.reshape(-1, 1)
            for name, q in series.flow_rates.items():
                f[f"flow_rate/{name}"] = q.reshape(-1, 1)
            f["max_velocity/15mm_downstream"] = series.max_velocity.reshape(-1, 1)
            f["wall_force/fixed_walls"] = np.zeros((len(series.time), series.dimension))
        with h5py.File(folder / "coupling_series.h5", "w") as f:
            f["time"] = series.force_time
            force = np.zeros((len(series.force_time), 3))
            force[:, 2 if series.dimension == 3 else 0] = series.axial_force
            f["force_fluid"] = force

    def test_read_run_gives_the_in_memory_answer(self):
        for dimension in (2, 3):
            series = synthetic(dimension=dimension)
            with tempfile.TemporaryDirectory() as tmp:
                self.write_run(Path(tmp), series)
                read = hd.read_run(Path(tmp))
                self.assertEqual(read.dimension, dimension)
                a = hd.analyse_cycle(read, smoothing_s=0.0)
                png = Path(tmp) / "fig11.png"
                hd.plot_cycle(read, a, png)
                self.assertGreater(png.stat().st_size, 10000)
            b = hd.analyse_cycle(series, smoothing_s=0.0)
            self.assertAlmostEqual(a.eoa, b.eoa, delta=1e-12)
            self.assertAlmostEqual(a.diastolic_force, b.diastolic_force, delta=1e-12)

    def test_the_fluids_recorded_symmetry_factor_scales_a_sector(self):
        expected = hd.analyse_cycle(synthetic(), smoothing_s=0.0)
        sector = sixth_of_the_valve()
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            self.write_run(folder, sector)
            self.assertIsNone(hd.read_run(folder).symmetry_factor)   # written before the fluid recorded it
            with h5py.File(folder / "fluid_probes.h5", "a") as f:
                f.attrs["symmetry_factor"] = 6.0
            read = hd.read_run(folder)
            self.assertEqual(read.symmetry_factor, 6.0)
            r = hd.analyse_cycle(read, smoothing_s=0.0)
            self.assertAlmostEqual(r.eoa, expected.eoa, delta=1e-9 * expected.eoa)
            self.assertAlmostEqual(r.diastolic_force, expected.diastolic_force, delta=1e-9 * abs(expected.diastolic_force))
            self.assertEqual(hd.analyse_cycle(read, smoothing_s=0.0, symmetry_factor=6).eoa, r.eoa)
            with self.assertRaisesRegex(ValueError, "fluid_probes.h5: symmetry factor 1 requested, but the fluid recorded 6"):
                hd.analyse_cycle(read, smoothing_s=0.0, symmetry_factor=1)
            with h5py.File(folder / "fluid_probes.h5", "a") as f:
                f.attrs["symmetry_factor"] = 0.0
            with self.assertRaisesRegex(ValueError, "mirror planes are parallel"):
                hd.analyse_cycle(hd.read_run(folder), smoothing_s=0.0)

    def test_2d_run_reads_the_tips_gap_from_the_solid_series(self):
        series = synthetic(dimension=2)
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            self.write_run(folder, series)
            ts = np.arange(0, 2 * T + 1e-9, 1e-3)
            tips = np.zeros((len(ts), 2, 3))
            tips[:, 0, 1], tips[:, 1, 1] = 0.15e-3, -0.15e-3      # 0.3 mm apart across the axis
            tips[:, :, 2] = 0.5e-3                                  # the strip's depth does not count
            with h5py.File(folder / "solid_series.h5", "w") as f:
                f["time"] = ts
                f["monitor/free_edge_midpoints/position"] = tips
            read = hd.read_run(folder)
            np.testing.assert_allclose(read.tip_gap, 0.3e-3, atol=1e-12)
            r = hd.analyse_cycle(read, cycle=1, smoothing_s=0.0)
            self.assertAlmostEqual(r.tip_gap_mm, 0.3, delta=1e-9)

    def test_chosen_sections_are_averaged(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.write_run(Path(tmp), synthetic())
            only_a = hd.read_run(Path(tmp), sections=["a"])
            self.assertEqual(list(only_a.flow_rates), ["a"])
            r = hd.analyse_cycle(only_a, smoothing_s=0.0)
            self.assertAlmostEqual(r.q_rms, 1.1 * QMAX / math.sqrt(2) * 1e6, delta=1e-6 * QMAX * 1e6)
            with self.assertRaisesRegex(ValueError, "no dataset '/flow_rate/c': have a, b"):
                hd.read_run(Path(tmp), sections=["a", "c"])

    def test_missing_tap_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.write_run(Path(tmp), synthetic())
            with self.assertRaisesRegex(ValueError, "no dataset '/pressure/inlet': have downstream_tap, upstream_tap"):
                hd.read_run(Path(tmp), upstream="inlet")


class Smoothed(unittest.TestCase):
    """PSPD from the section-averaged, 2 ms smoothed drop and the jet-core speed: a one-sample
    spike of one probe or one particle does not move them (docs/hemodynamics.md)."""

    def write_spiky_run(self, folder: Path, dimension: int):
        series = synthetic(dimension=dimension)
        t = series.time
        spike = np.zeros_like(t)
        spike[int(round((T + 0.01) / DT))] = 200 * MMHG             # one sample of the centre tap
        core_area = math.pi * hd.JET_CORE_RADIUS_M ** 2 if dimension == 3 else 2 * hd.JET_CORE_RADIUS_M
        core_speed = 1.4 * np.sin(np.pi * np.clip(np.mod(t, T), 0, TE) / TE) ** 2
        particle = core_speed * 1.2
        particle[int(round((T + 0.4) / DT))] = 27.0                   # one particle squeezed out
        with h5py.File(folder / "fluid_probes.h5", "w") as f:
            f["time"] = t.reshape(-1, 1)
            f["pressure/upstream_tap"] = (series.upstream_pressure + spike).reshape(-1, 1)
            f["pressure/downstream_tap"] = series.downstream_pressure.reshape(-1, 1)
            for k in range(1, 5):
                f[f"pressure/upstream_tap_section_{k}"] = series.upstream_pressure.reshape(-1, 1)
                f[f"pressure/downstream_tap_section_{k}"] = series.downstream_pressure.reshape(-1, 1)
            for name, q in series.flow_rates.items():
                f[f"flow_rate/{name}"] = q.reshape(-1, 1)
            f[f"flow_rate/{hd.JET_CORE_PLANE}"] = (core_speed * core_area).reshape(-1, 1)
            f["max_velocity/15mm_downstream"] = particle.reshape(-1, 1)
            f["wall_force/fixed_walls"] = np.zeros((len(t), dimension))

    def test_spikes_do_not_move_pspd_and_peak_speed(self):
        for dimension in (2, 3):
            with tempfile.TemporaryDirectory() as tmp:
                self.write_spiky_run(Path(tmp), dimension)
                series = hd.read_run(Path(tmp))
            self.assertEqual(sorted(series.flow_rates), ["a", "b"])   # the core is not a flow section
            r = hd.analyse_cycle(series, cycle=2, smoothing_s=0.002)
            self.assertAlmostEqual(r.pspd_mmHg, 8.0, delta=0.01)
            self.assertAlmostEqual(r.pspd_time_s, TE / 2, delta=0.002)
            self.assertAlmostEqual(r.pspd_probe_mmHg, 5.0 + 3.0 * math.sin(math.pi * 0.01 / TE) ** 2 + 200, delta=0.01)
            self.assertLessEqual(abs(r.mspd_mmHg - 6.5), 40 * DT / TE + 1e-6)   # the mean keeps at most the spike's share
            self.assertAlmostEqual(r.peak_velocity_m_per_s, 1.4, delta=0.002)
            self.assertAlmostEqual(r.peak_velocity_time_s, TE / 2, delta=0.002)
            self.assertAlmostEqual(r.peak_particle_speed, 27.0, delta=1e-9)

    def test_sector_core_flow_times_six(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.write_spiky_run(Path(tmp), 3)
            series = hd.read_run(Path(tmp))
        series.jet_core_flow = series.jet_core_flow / 6
        r = hd.analyse_cycle(series, cycle=2, smoothing_s=0.002, symmetry_factor=6)
        self.assertAlmostEqual(r.peak_velocity_m_per_s, 1.4, delta=0.002)


CLOSURE = TE + TC       # the closing backflow's end (s in the cycle)
RING_PERIOD = 0.03      # s: the blood column between the plates rings after the closing ...
RING_DECAY = 0.15       # s: ... its flow amplitude falling by e in this time ...
RING_FLOW = 60e-6       # m^3/s: ... from this (the 3D sector's: ~32 ms, ~180 ms, ~75 mL/s)


def ringing_series(stop, flow_scale=1.0):
    """Cycle 1 to `stop` (s): the synthetic flow (closing backflow, then a constant leak) plus the
    ringing, a decaying sine from the closing's end (the flow stays continuous), and the 2 kHz
    ripple of 5 % of the peak flow; every section carries it (flow_scale: a sector's share)."""
    full = synthetic(cycles=1)
    keep = full.time <= stop + 1e-12
    t = full.time[keep]
    s = t - CLOSURE
    ring = np.where(s > 0, RING_FLOW * np.exp(-s / RING_DECAY) * np.sin(2 * np.pi * s / RING_PERIOD), 0.0)
    q = (flow(t) + ring + 0.05 * QMAX * np.sin(2 * np.pi * 2000.0 * t + 0.3)) * flow_scale
    return hd.ProbeSeries(time=t, upstream_pressure=full.upstream_pressure[keep],
                          downstream_pressure=full.downstream_pressure[keep], flow_rates={"a": q, "b": q},
                          max_velocity=None)


class LeakRate(unittest.TestCase):
    """The closed valve's leak rate under the column's ringing (hemodynamics.leak_rate)."""
    LEAK = Q_LEAK * 1e6          # mL/s, backflow positive
    TOLERANCE = 0.01             # mL/s: 0.5 % of the leak

    def analyse(self, stop, flow_scale=1.0, symmetry_factor=1.0):
        return hd.analyse_cycle(ringing_series(stop, flow_scale), cycle=1, smoothing_s=0.0, closure_time_s=CLOSURE,
                                allow_partial=stop < T, symmetry_factor=symmetry_factor)

    def test_rate_period_and_decay_at_any_stop(self):
        # stops at the backflow volume's ringing peaks (after 3.5 and 5.5 periods) and troughs (4 and 7
        # periods), where the integral to the end misses most, between them, and at the cycle's end
        stops = [CLOSURE + k * RING_PERIOD for k in (3.5, 4.0, 5.5, 7.0)] + [0.43, 0.62, T]
        for stop in stops:
            r = self.analyse(stop)
            self.assertIsNotNone(r.leak, msg=f"stop {stop}: {r.leak_refusal}")
            self.assertAlmostEqual(r.leak.rate, self.LEAK, delta=self.TOLERANCE, msg=f"stop {stop}")
            self.assertAlmostEqual(r.leak.period_s, RING_PERIOD, delta=0.01 * RING_PERIOD, msg=f"stop {stop}")
            self.assertAlmostEqual(r.leak.decay_time_s, RING_DECAY, delta=0.1 * RING_DECAY, msg=f"stop {stop}")
            self.assertLess(r.leak.uncertainty, self.TOLERANCE, msg=f"stop {stop}")
            # the fit starts one period after the closure and ends with the series
            self.assertAlmostEqual(r.leak.start_s, CLOSURE + RING_PERIOD, delta=0.01 * RING_PERIOD)
            self.assertAlmostEqual(r.leak.end_s, stop, delta=DT)
            for name in ("a", "b"):
                self.assertAlmostEqual(r.leak.section_rates[name], self.LEAK, delta=self.TOLERANCE)

    def test_the_integral_to_the_end_misses_by_far_more(self):
        for periods in (3.5, 4.0, 5.5, 7.0):   # peaks and troughs of the ringing's volume
            stop = CLOSURE + periods * RING_PERIOD
            r = self.analyse(stop)
            raw_rate = r.leakage_volume / (stop - CLOSURE)
            fit_miss, raw_miss = abs(r.leak.rate - self.LEAK), abs(raw_rate - self.LEAK)
            self.assertLess(fit_miss, self.TOLERANCE)
            self.assertGreater(raw_miss, 0.5, msg=f"{periods} periods")       # 25 % of the leak or more
            self.assertGreater(raw_miss, 20 * fit_miss, msg=f"{periods} periods")

    def test_partial_cycle_regurgitant_volume_is_extrapolated(self):
        stop = CLOSURE + 5.5 * RING_PERIOD
        r = self.analyse(stop)
        self.assertTrue(r.regurgitant_extrapolated)
        self.assertAlmostEqual(r.leakage_from_rate, r.leak.rate * (T - CLOSURE), delta=1e-12)
        self.assertAlmostEqual(r.leakage_from_rate, self.LEAK * (T - CLOSURE), delta=self.TOLERANCE * (T - CLOSURE))
        self.assertAlmostEqual(r.leakage_from_rate_uncertainty, r.leak.uncertainty * (T - CLOSURE), delta=1e-12)
        self.assertAlmostEqual(r.regurgitant_volume, r.closing_volume + r.leakage_from_rate, delta=1e-12)
        # the integral to the series' end stays, and the table shows both, marked
        self.assertAlmostEqual(r.leakage_volume, -hd.integral(ringing_series(stop).time,
                                                              ringing_series(stop).mean_flow_rate,
                                                              CLOSURE, stop) * 1e6, delta=1e-12)
        table = hd.hemodynamics_table({"part": r})
        self.assertIn(f"| {r.regurgitant_volume:.2f} (extrap.) |", table)
        self.assertIn(f"| — leakage to the series' end, −∫Q (mL) | {r.leakage_volume:.2f} |", table)
        self.assertIn(f"| {r.leakage_from_rate:.2f} ± {r.leakage_from_rate_uncertainty:.2f} (extrap.) |", table)
        self.assertIn("; 30.0, 150 |", table)   # period and e-folding time (ms)

    def test_complete_cycle_keeps_the_integral(self):
        r = self.analyse(T)
        self.assertFalse(r.regurgitant_extrapolated)
        self.assertAlmostEqual(r.regurgitant_volume, r.closing_volume + r.leakage_volume, delta=1e-12)
        self.assertNotIn("(extrap.)", hd.hemodynamics_table({"whole": r}))

    def test_too_short_a_span_is_refused(self):
        stop = CLOSURE + 2.5 * RING_PERIOD   # three periods needed: one skipped, two fitted
        r = self.analyse(stop)
        self.assertIsNone(r.leak)
        self.assertIsNone(r.leakage_from_rate)
        self.assertRegex(r.leak_refusal, r"holds 75 ms after the closure, less than three ringing periods \(30\.\d ms\)")
        # the partial cycle's regurgitant volume falls back to the integral to the end, unmarked
        self.assertFalse(r.regurgitant_extrapolated)
        self.assertAlmostEqual(r.regurgitant_volume, r.closing_volume + r.leakage_volume, delta=1e-12)
        self.assertIn("No leak rate: short: the series holds 75 ms", hd.hemodynamics_table({"short": r}))
        # within one period the ringing is not found, and a line does not fit either
        r = self.analyse(CLOSURE + RING_PERIOD)
        self.assertIsNone(r.leak)
        self.assertRegex(r.leak_refusal, "no ringing period within half of the 30 ms after the closure, .*too short a span")

    def test_a_sector_times_six_is_the_valve(self):
        stop = CLOSURE + 5.5 * RING_PERIOD
        valve = self.analyse(stop)
        sector = self.analyse(stop, flow_scale=1 / 6, symmetry_factor=6)
        for name in ("rate", "uncertainty", "period_s", "decay_time_s", "ringing_volume"):
            a, b = getattr(valve.leak, name), getattr(sector.leak, name)
            self.assertAlmostEqual(a, b, delta=1e-6 * max(1.0, abs(a)), msg=name)
        self.assertAlmostEqual(sector.leak.rate, self.LEAK, delta=self.TOLERANCE)
        self.assertAlmostEqual(sector.leakage_from_rate, valve.leakage_from_rate, delta=1e-6)

    def test_without_ringing_the_rate_is_the_slope_from_the_closure(self):
        r = hd.analyse_cycle(synthetic(), cycle=2, smoothing_s=0.0, closure_time_s=CLOSURE)
        self.assertIsNone(r.leak.period_s)
        self.assertAlmostEqual(r.leak.rate, self.LEAK, delta=1e-6)
        self.assertAlmostEqual(r.leak.start_s, CLOSURE, delta=DT)
        self.assertIn("; no ringing |", hd.hemodynamics_table({"steady": r}))


# The leak through the valve by particle count (hemodynamics.valve_leak): a 60-degree sector's
# leaflet (a flat disc sector at z = 5 mm, attached at R, bulging towards the ventricle and
# ringing), particles on both sides of it and far from it, and a known number moving from the
# aorta's side to the ventricle's per second; the flow sections read a different "leak".
VALVE_R = 11.5e-3
VALVE_Z = 5e-3
SPACING = 3e-4                 # m: particle volume 2.7e-11 m^3, ~9 particles per 2 ms at the leak below
TRUE_LEAK = 0.75               # mL/s, whole valve (x 6)
SNAPSHOT_DT = 0.002


def leaflet_mesh(rings=6, spokes=6):
    """Nodes (reference, flat at VALVE_Z) and triangles (normals +z) of a 60-degree disc sector."""
    nodes = [[0.0, 0.0, VALVE_Z]]
    for i in range(1, rings + 1):
        for j in range(spokes + 1):
            a = math.radians(60.0) * j / spokes
            nodes.append([VALVE_R * i / rings * math.cos(a), VALVE_R * i / rings * math.sin(a), VALVE_Z])
    index = lambda i, j: 0 if i == 0 else 1 + (i - 1) * (spokes + 1) + j
    triangles = []
    for i in range(rings):
        for j in range(spokes):
            if i == 0:
                triangles.append([index(0, 0), index(1, j), index(1, j + 1)])
            else:
                triangles.append([index(i, j), index(i + 1, j), index(i + 1, j + 1)])
                triangles.append([index(i, j), index(i + 1, j + 1), index(i, j + 1)])
    return np.array(nodes), np.array(triangles)


def bulge(t):
    """The leaflet's centre deflection towards the ventricle (m): 1 mm, ringing by 0.3 mm."""
    return 1e-3 + 3e-4 * np.sin(2 * np.pi * max(t - CLOSURE, 0.0) / RING_PERIOD)


def leaflet_at(nodes, t):
    r = np.hypot(nodes[:, 0], nodes[:, 1])
    out = nodes.copy()
    out[:, 2] -= bulge(t) * (1 - (r / VALVE_R) ** 2)
    return out


def wedge_points(rng, n, z_low, z_high, r_max=0.0184):
    r = r_max * np.sqrt(rng.uniform(0, 1, n))
    a = rng.uniform(0.02, math.radians(58.0), n)
    return np.column_stack([r * np.cos(a), r * np.sin(a), rng.uniform(z_low, z_high, n)])


class ValveScene:
    """Particle snapshots of the scene at `times`: n_moved(t) particles have crossed to the ventricle."""

    def __init__(self, times, seed=1):
        rng = np.random.default_rng(seed)
        self.times = np.asarray(times)
        self.nodes, self.triangles = leaflet_mesh()
        self.ventricle = wedge_points(rng, 300, -0.04, -0.01)
        self.aorta = wedge_points(rng, 3000, 0.02, 0.06)
        sinus = wedge_points(rng, 50, 0.006, 0.012)   # beyond the attachment radius, above the base
        r = np.hypot(sinus[:, 0], sinus[:, 1])
        sinus[:, :2] *= ((0.012 + 0.006 * r / 0.0184) / r)[:, None]
        self.sinus = sinus
        near = wedge_points(rng, 200, 0, 0, r_max=0.9 * VALVE_R)
        self.near_r = near[:, :2]
        self.per_second = TRUE_LEAK * 1e-6 / (6 * SPACING ** 3)     # particles per second (sector)

    def moved(self, t):
        return int(round(self.per_second * max(t - CLOSURE, 0.0)))

    def snapshot(self, t):
        """(positions, kind): near-leaflet particles 0.4 mm either side of the bulging surface,
        far ones, the sinus's; the movers taken from the aorta's far set into the ventricle's."""
        r = np.hypot(self.near_r[:, 0], self.near_r[:, 1])
        zs = VALVE_Z - bulge(t) * (1 - (r / VALVE_R) ** 2)
        below = np.column_stack([self.near_r, zs - 4e-4])
        above = np.column_stack([self.near_r, zs + 4e-4])
        k = self.moved(t)
        aorta, moved = self.aorta[k:], self.aorta[:k].copy()
        moved[:, 2] = -0.01 - 0.5 * (moved[:, 2] - 0.02)    # from 20-60 mm above to 10-30 mm below
        x = np.concatenate([self.ventricle, moved, below, above, self.sinus, aorta])
        kind = np.zeros(len(x), dtype=np.int32)
        if t > CLOSURE + 0.08:        # mid-span, 40 particles taken out on the ventricle's side stay counted
            kind[:40] = 2
        return x, kind

    def ventricle_count(self, t):
        return len(self.ventricle) + self.moved(t) + len(self.near_r)


def write_valve_run(folder: Path, stop: float, scene: ValveScene, particle_times=None, log=True,
                    section_error=(-5e-6, 2e-6)):
    """A 3D sector run: probes (ringing_series's flows / 6, each section off the true leak by
    section_error, m^3/s whole valve), leaflet snapshots every 2 ms, particle snapshots at
    particle_times (default: the scene's), fluid.log stating the spacing."""
    folder.mkdir(parents=True, exist_ok=True)
    series = ringing_series(stop)
    t = series.time
    after = t > CLOSURE
    q = {}
    for name, error in zip(("a", "b"), section_error):
        # the closed valve's backflow reads the section's error instead of the synthetic leak
        q[name] = (series.flow_rates[name] + np.where(after, Q_LEAK - TRUE_LEAK * 1e-6 + error, 0.0)) / 6
    with h5py.File(folder / "fluid_probes.h5", "w") as f:
        f["time"] = t.reshape(-1, 1)
        f["pressure/upstream_tap"] = series.upstream_pressure.reshape(-1, 1)
        f["pressure/downstream_tap"] = series.downstream_pressure.reshape(-1, 1)
        for name, flow_rate in q.items():
            f[f"flow_rate/{name}"] = flow_rate.reshape(-1, 1)
        f["wall_force/fixed_walls"] = np.zeros((len(t), 3))
    solid_times = np.arange(0.0, stop + 1e-9, SNAPSHOT_DT)
    with h5py.File(folder / "solid_fields.h5", "w") as f:
        f["mesh/nodes"] = scene.nodes
        f["mesh/triangles"] = scene.triangles
        for k, ts in enumerate(solid_times):
            g = f.create_group(f"snapshots/{k:06d}")
            g.attrs["time"] = ts + 1e-5          # a coupling window's end, not the fluid's step
            g["position"] = leaflet_at(scene.nodes, ts)
    write_particles(folder, scene, scene.times if particle_times is None else particle_times)
    if log:
        (folder / "fluid.log").write_text("[info] fluid_sph: coupled (3D) ...: 3650 fluid + 0 wall particles, "
                                          f"195 interface nodes, dp = {SPACING} m, c0 = 20 m/s, 2 plate(s)\n")
    return series


def write_particles(folder: Path, scene: ValveScene, times):
    with h5py.File(folder / "fluid_particles.h5", "w") as f:
        for k, ts in enumerate(times):
            x, kind = scene.snapshot(ts)
            g = f.create_group(f"snapshot_{k:06d}")
            g.attrs["time"] = ts
            g["position"] = x
            g["kind"] = kind
            g["id"] = np.arange(len(x), dtype=np.uint32)


class ValveLeak(unittest.TestCase):
    STOP = CLOSURE + 5.5 * RING_PERIOD
    TOLERANCE = 0.01             # mL/s

    def scene(self):
        return ValveScene(np.arange(CLOSURE - 0.02, self.STOP + 1e-9, SNAPSHOT_DT))

    def analyse(self, folder, **kwargs):
        series = hd.read_run(folder)
        return series, hd.analyse_cycle(series, cycle=1, smoothing_s=0.0, closure_time_s=CLOSURE, allow_partial=True,
                                        symmetry_factor=6, **kwargs)

    def test_valve_side(self):
        nodes, triangles = leaflet_mesh()
        bulged = leaflet_at(nodes, CLOSURE)            # 1 mm down at the centre
        points = np.array([[3e-3, 1e-3, 4.6e-3],       # under the flat leaflet
                           [3e-3, 1e-3, 5.4e-3],       # over it
                           [3e-3, 1e-3, 4.3e-3],       # over the bulged one (at 4.07 mm), under the flat
                           [13e-3, 2e-3, 8e-3],        # the sinus, beyond the attachment radius
                           [13e-3, 2e-3, 4e-3],        # beyond it and below the base: under the gasket
                           [3e-3, 1e-3, -20e-3], [3e-3, 1e-3, 30e-3]])
        for tris in (triangles, triangles[:, ::-1]):   # either orientation: the aorta is +z
            flat = hd.valve_side(points, nodes, tris, VALVE_Z, VALVE_Z, VALVE_R)
            self.assertEqual(flat.tolist(), [-1, 1, -1, 1, -1, -1, 1])
            self.assertEqual(hd.valve_side(points, bulged, tris, VALVE_Z, VALVE_Z, VALVE_R).tolist(),
                             [1, 1, 1, 1, -1, -1, 1])

    def test_leak_by_particle_count_is_the_known_leak(self):
        with tempfile.TemporaryDirectory() as tmp:
            scene = self.scene()
            write_valve_run(Path(tmp), self.STOP, scene)
            series, r = self.analyse(Path(tmp))
        self.assertEqual(series.particle_spacing, SPACING)
        self.assertIsNotNone(r.valve_leak, msg=r.valve_leak_refusal)
        self.assertAlmostEqual(r.valve_leak.rate, TRUE_LEAK, delta=self.TOLERANCE)
        self.assertLess(r.valve_leak.uncertainty, self.TOLERANCE)
        # from where the flow sections' fit starts (one ringing period after the closure) to the end
        self.assertAlmostEqual(r.valve_leak.start_s, r.leak.start_s, delta=SNAPSHOT_DT)
        self.assertAlmostEqual(r.valve_leak.end_s, self.STOP, delta=SNAPSHOT_DT)
        # the flow sections read the leak + their errors' mean, 1.5 mL/s: the fit finds that, not the leak
        self.assertAlmostEqual(r.leak.rate, TRUE_LEAK + 1.5, delta=0.05)
        # the leakage and the partial cycle's regurgitant volume use the leak through the valve
        self.assertEqual(r.leakage_rate_source, "particles")
        self.assertAlmostEqual(r.leakage_from_rate, r.valve_leak.rate * (T - CLOSURE), delta=1e-12)
        self.assertAlmostEqual(r.regurgitant_volume, r.closing_volume + r.leakage_from_rate, delta=1e-12)
        table = hd.hemodynamics_table({"valve": r})
        self.assertIn(f"| {r.leakage_from_rate:.2f} ± {r.leakage_from_rate_uncertainty:.2f} (extrap.) (particles) |", table)
        self.assertIn(f"| {r.valve_leak.rate:.2f} ± {r.valve_leak.uncertainty:.2f} (halves", table)

    def test_joined_segments_later_wins(self):
        with tempfile.TemporaryDirectory() as tmp:
            scene = self.scene()
            joined, first, second = Path(tmp) / "joined", Path(tmp) / "s1", Path(tmp) / "s2"
            write_valve_run(joined, self.STOP, scene, particle_times=[], log=False)
            (joined / "fluid_particles.h5").unlink()
            half = len(scene.times) // 2
            split = scene.times[half]
            first.mkdir(); second.mkdir()
            write_particles(first, scene, scene.times[:half])
            # the first segment went on past the second's start: its later snapshots (every particle in
            # the aorta here) are not the run's
            with h5py.File(first / "fluid_particles.h5", "a") as f:
                n = len(f)
                for k, ts in enumerate([split, split + SNAPSHOT_DT]):
                    g = f.create_group(f"snapshot_{n + k:06d}")
                    x, kind = scene.snapshot(ts)
                    x[:, 2] = 0.05
                    g.attrs["time"] = ts
                    g["position"], g["kind"], g["id"] = x, kind, np.arange(len(x), dtype=np.uint32)
            write_particles(second, scene, scene.times[half:])
            (second / "fluid.log").write_text(f"... dp = {SPACING} m, c0 = 20 m/s\n")
            (joined / "segments.json").write_text(json.dumps([str(first), str(second)]))
            snapshots = hd.particle_snapshots(joined)
            self.assertEqual(len(snapshots), len(scene.times))
            _, r = self.analyse(joined)
        self.assertIsNotNone(r.valve_leak, msg=r.valve_leak_refusal)
        self.assertAlmostEqual(r.valve_leak.rate, TRUE_LEAK, delta=self.TOLERANCE)

    def test_without_the_spacing_it_is_refused_or_given(self):
        with tempfile.TemporaryDirectory() as tmp:
            write_valve_run(Path(tmp), self.STOP, self.scene(), log=False)
            _, r = self.analyse(Path(tmp))
            self.assertIsNone(r.valve_leak)
            self.assertIn("particle spacing is unknown", r.valve_leak_refusal)
            self.assertEqual(r.leakage_rate_source, "flow sections")
            self.assertAlmostEqual(r.leakage_from_rate, r.leak.rate * (T - CLOSURE), delta=1e-12)
            self.assertIn("No leak rate through the valve by particle count: valve: the particle spacing",
                          hd.hemodynamics_table({"valve": r}))
            _, given = self.analyse(Path(tmp), particle_spacing=SPACING)
        self.assertAlmostEqual(given.valve_leak.rate, TRUE_LEAK, delta=self.TOLERANCE)

    def test_too_few_snapshots_and_no_particles(self):
        with tempfile.TemporaryDirectory() as tmp:
            scene = self.scene()
            write_valve_run(Path(tmp), self.STOP, scene, particle_times=scene.times[::12])
            _, r = self.analyse(Path(tmp))
            self.assertIsNone(r.valve_leak)
            self.assertRegex(r.valve_leak_refusal, r"^\d particle snapshots with the leaflets' between \d+ and \d+ ms, fewer than 6$")
            without = hd.read_run(Path(tmp), particles=False)
        self.assertIsNone(without.particle_run)
        r = hd.analyse_cycle(without, cycle=1, smoothing_s=0.0, closure_time_s=CLOSURE, allow_partial=True)
        self.assertIsNone(r.valve_leak)
        self.assertEqual(r.valve_leak_refusal, "")

if __name__ == "__main__":
    unittest.main()
