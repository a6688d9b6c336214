"""Hemodynamics (issue 7, item 3) on synthetic probe series with known answers: a half-sine
ejection (known rms and volume), a known pressure drop, a closing backflow plus a constant
leak (known regurgitant volume), a known leaflet force, two cycles, 2D units, and the HDF5
layouts of fluid_sph and the coupler."""
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


class Sector(unittest.TestCase):
    def test_a_sixth_of_the_valve_times_six_is_the_valve(self):
        full = synthetic()
        sector = synthetic()
        sector.flow_rates = {k: v / 6 for k, v in sector.flow_rates.items()}
        sector.axial_force = sector.axial_force / 6
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

if __name__ == "__main__":
    unittest.main()
