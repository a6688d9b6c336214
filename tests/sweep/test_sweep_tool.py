"""The sweep tool's pieces on synthetic inputs (no programs run): case editing, the opening
metrics, the classification of a run's end, and the choice of the cheapest setting."""
import json
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

from sweep import case_edit, metrics, outcome, plan, report, runner, scenes, stability

ROOT = Path(__file__).resolve().parents[2]

CASE = """# comment
title: "x"
run {
  end_time: 1.6
  output_dir: "runs/a"
}
fluid {
  particle_spacing: 0.001
  sound_speed: 20  # trailing comment
  thin_walls { virtual_spacing_ratio: 0.5 }
}
coupling {
  scheme: SERIAL_EXPLICIT
}
"""


class CaseEdit(unittest.TestCase):
    def test_replaces_an_existing_field_and_keeps_the_rest(self):
        text = case_edit.set_field(CASE, "fluid.sound_speed", 40.0)
        self.assertIn("  sound_speed: 40\n", text)
        self.assertEqual(text.count("sound_speed"), 1)
        self.assertIn("thin_walls { virtual_spacing_ratio: 0.5 }", text)
        self.assertEqual(case_edit.get_field(text, "fluid.particle_spacing"), "0.001")

    def test_adds_a_missing_field_inside_its_block(self):
        text = case_edit.set_field(CASE, "coupling.acceleration", "IQN_ILS")
        block = text[text.index("coupling {"):]
        self.assertIn("  acceleration: IQN_ILS\n}", block)

    def test_adds_a_missing_block(self):
        text = case_edit.set_field(CASE, "solid.density", 550.0)
        self.assertTrue(text.endswith("solid {\n  density: 550\n}\n"))

    def test_literals(self):
        self.assertEqual(case_edit.format_value(True), "true")
        self.assertEqual(case_edit.format_value("SERIAL_IMPLICIT"), "SERIAL_IMPLICIT")
        self.assertEqual(case_edit.format_value("run"), '"run"')
        self.assertEqual(case_edit.format_value(6.5e-6), "6.5e-06")

    def test_a_nested_path_is_refused_with_what_is_allowed(self):
        with self.assertRaisesRegex(ValueError, "block.field"):
            case_edit.set_field(CASE, "fluid.thin_walls.virtual_spacing_ratio", 1.0)

    def test_replace_block(self):
        text = case_edit.replace_block(CASE, "fluid", "fluid {\n  particle_spacing: 0.002\n}\n")
        self.assertEqual(case_edit.get_field(text, "fluid.particle_spacing"), "0.002")
        self.assertIsNone(case_edit.get_field(text, "fluid.sound_speed"))
        self.assertIn("coupling {", text)


class Valve2dScene(unittest.TestCase):
    def test_setting_reaches_the_case(self):
        with tempfile.TemporaryDirectory() as tmp:
            case = scenes.write_case("valve2d", {"spacing_mm": 23.0 / 12.0, "sound_speed": 40.0, "time_step_factor": 2.0,
                                                 "coupling": "implicit", "leaflet_density": 550.0,
                                                 "background_pressure": "off", "thickness_mm": 0.125},
                                     Path(tmp) / "w", 0.05)
            text = case.read_text()
            get = lambda p: case_edit.get_field(text, p)
            self.assertAlmostEqual(float(get("fluid.particle_spacing")), 23e-3 / 12, delta=1e-11)
            self.assertEqual(float(get("fluid.sound_speed")), 40.0)
            # twice the committed CFL (0.1)
            self.assertAlmostEqual(float(get("fluid.cfl")), 0.2)
            # mu = 1 window at c0 = 40 for the default leaflet (1100 kg/m^3, 0.25 mm): 3.0 us; the
            # committed window is twice that, doubled again
            self.assertAlmostEqual(float(get("coupling.window_size")), 12.0e-6)
            self.assertEqual(get("coupling.scheme"), "SERIAL_IMPLICIT")
            self.assertEqual(get("coupling.acceleration"), "IQN_ILS")
            self.assertEqual(float(get("solid.density")), 550.0)
            self.assertEqual(float(get("fluid.background_pressure")), 0.0)
            self.assertEqual(float(get("run.end_time")), 0.05)
            mesh = Path(tmp) / "w" / get("solid.mesh_file").strip('"')
            with h5py.File(mesh, "r") as f:
                self.assertTrue(len(f.keys()) > 0)

    def test_default_background_pressure_is_the_committed_cases_and_on_sets_the_opening_pressure(self):
        from valve_scene import valve2d
        committed = (ROOT / "cases" / "fsi-mhgo-2d-coarse.textproto").read_text()
        with tempfile.TemporaryDirectory() as tmp:
            default = scenes.write_case("valve2d", {}, Path(tmp) / "d", 0.01).read_text()
            on = scenes.write_case("valve2d", {"background_pressure": "on"}, Path(tmp) / "on", 0.01).read_text()
        p_b = lambda text: float(case_edit.get_field(text, "fluid.background_pressure"))
        self.assertEqual(p_b(default), p_b(committed))
        self.assertEqual(p_b(default) > 0, valve2d.BACKGROUND_PRESSURE_2D)
        # 80.73 mmHg, the aortic pressure at opening
        self.assertAlmostEqual(p_b(on), 80.73 * 133.322, delta=5.0)

    def test_unknown_axis_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaisesRegex(ValueError, "unknown axis 'spacing'"):
                scenes.write_case("valve2d", {"spacing": 1.0}, Path(tmp), 0.01)

    def test_mu_of_the_default_is_one_and_scales_with_the_leaflet_mass(self):
        from sweep import stability
        from valve_scene import valve2d
        # the sweep's default is the committed coupled case: its leaflet mass and window give mu = 1
        self.assertEqual(scenes.VALVE2D_DEFAULTS["leaflet_density"], valve2d.leaflet_density("FSI"))
        self.assertAlmostEqual(stability.mu_of({}), 1.0, delta=0.03)
        self.assertAlmostEqual(stability.mu_of({"leaflet_density": 275.0}) / stability.mu_of({}), 8.0, places=9)


class FileCaseScene(unittest.TestCase):
    def test_copy_with_end_time_overrides_and_an_absolute_mesh_path(self):
        source = Path(__file__).resolve().parents[2] / "cases" / "fe-mhgo-sector-coarse.textproto"
        with tempfile.TemporaryDirectory() as tmp:
            case = scenes.write_case("case", {"case": str(source), "set:solid.time_step_safety": 0.5},
                                     Path(tmp) / "w", 0.12)
            text = case.read_text()
            self.assertEqual(float(case_edit.get_field(text, "run.end_time")), 0.12)
            self.assertEqual(float(case_edit.get_field(text, "solid.time_step_safety")), 0.5)
            mesh = Path(case_edit.get_field(text, "solid.mesh_file").strip('"'))
            self.assertTrue(mesh.is_absolute() and mesh.is_file(), mesh)

    def test_a_relative_mesh_set_by_the_sweep_is_made_absolute_from_the_source_case(self):
        source = Path(__file__).resolve().parents[2] / "cases" / "fe-mhgo-sector-coarse.textproto"
        with tempfile.TemporaryDirectory() as tmp:
            case = scenes.write_case("case", {"case": str(source), "set:solid.mesh_file": "meshes/other.mesh.h5"},
                                     Path(tmp) / "w", 0.12)
            mesh = case_edit.get_field(case.read_text(), "solid.mesh_file").strip('"')
            self.assertEqual(Path(mesh), source.parent / "meshes" / "other.mesh.h5")


    def test_a_case_axis_is_labelled_by_the_file_name(self):
        label = scenes.setting_label({"case": "../cases/fe-mhgo-sector-coarse.textproto",
                                      "set:solid.element_family": "HEXAHEDRON"})
        self.assertEqual(label, "case=fe-mhgo-sector-coarse,solid-element_family=HEXAHEDRON")

    def test_the_fe_opening_preset_names_existing_cases_and_its_finest(self):
        from sweep.presets import PRESETS
        spec = PRESETS["fe-opening-3d"]
        scripts = Path(__file__).resolve().parents[2] / "scripts"
        labels = [r.label for r in plan.expand(spec)]
        self.assertIn(plan.finest_label(spec), labels)
        for run in plan.expand(spec):
            self.assertTrue((scripts / run.setting["case"]).is_file(), run.setting["case"])


class FieldPeaks(unittest.TestCase):
    def write_fields(self, folder: Path, strain_snapshots):
        # two unit right triangles (area 0.5 each) and one of area 2: 3 elements, total area 3
        nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [2, 2, 0]], float)
        triangles = np.array([[0, 1, 2], [1, 3, 2], [1, 3, 4]])
        with h5py.File(folder / "solid_fields.h5", "w") as f:
            f["mesh/nodes"] = nodes
            f["mesh/triangles"] = triangles
            for k, strain in enumerate(strain_snapshots):
                g = f.create_group(f"snapshots/{k:06d}")
                g.attrs["time"] = 0.01 * k
                g["position"] = nodes
                g["max_principal_log_strain"] = np.asarray(strain, float)
                g["max_principal_stress"] = 1e6 * np.asarray(strain, float)

    def test_robust_peak_ignores_a_small_hot_element_and_takes_the_largest_snapshot(self):
        with tempfile.TemporaryDirectory() as tmp:
            # element 0 (1/6 of the area) is hot in the first snapshot; the 1 % peak of that
            # snapshot is its value; the second snapshot has the large element at 0.3
            self.write_fields(Path(tmp), [[0.9, 0.1, 0.2], [0.1, 0.1, 0.3]])
            peaks = metrics.field_peaks(Path(tmp))
            self.assertAlmostEqual(peaks["peak_strain"], 0.9)
            self.assertAlmostEqual(peaks["peak_stress"], 0.9e6)
            self.assertAlmostEqual(peaks["peak_strain_time"], 0.0)
        from valve_scene.analysis import area_percentile
        # at 50 % of the area the large element (2/3 of it) decides, not the hot small one
        self.assertAlmostEqual(area_percentile([0.9, 0.1, 0.2], [0.5, 0.5, 2.0], 0.5), 0.2)

    def test_a_unit_brick_has_unit_area_and_brick_fields_get_peaks(self):
        cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                         [0, 0, 0.1], [1, 0, 0.1], [1, 1, 0.1], [0, 1, 0.1]], float)
        stretched = cube * [2.0, 1.0, 1.0]
        nodes = np.vstack([cube, stretched + [5, 0, 0]])
        bricks = np.array([range(8), range(8, 16)])
        np.testing.assert_allclose(metrics.hexahedron_mid_areas(nodes, bricks), [1.0, 2.0])
        with tempfile.TemporaryDirectory() as tmp:
            with h5py.File(Path(tmp) / "solid_fields.h5", "w") as f:
                f["mesh/nodes"] = nodes
                f["mesh/hexahedra"] = bricks
                g = f.create_group("snapshots/000000")
                g.attrs["time"] = 0.02
                g["max_principal_log_strain"] = [0.3, 0.1]   # the small brick is 1/3 of the area
                g["max_principal_stress"] = [3e6, 1e6]
            peaks = metrics.field_peaks(Path(tmp))
            self.assertAlmostEqual(peaks["peak_strain"], 0.3)
            self.assertAlmostEqual(peaks["peak_stress_time"], 0.02)

    def test_no_snapshots_no_peaks(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(metrics.field_peaks(Path(tmp)), {})


class OpeningEvents(unittest.TestCase):
    def test_linear_ramp(self):
        t = np.linspace(0, 0.12, 1201)
        r = np.clip((t - 0.03) / 0.05, 0, 1) * 10e-3 + 1e-3   # opens from 30 to 80 ms
        e = metrics.opening_events(t, r)
        self.assertAlmostEqual(e["opening_start"], 0.035, delta=1e-4)
        self.assertAlmostEqual(e["rvot"], 0.040, delta=2e-4)

    def test_a_valve_that_stays_shut_has_no_events(self):
        t = np.linspace(0, 0.04, 401)
        self.assertEqual(metrics.opening_events(t, np.full_like(t, 1e-3)), {})
        # a dip (leaflets pushed back) before the opening does not count as opening
        r = 1e-3 - 1e-4 * np.sin(np.pi * t / 0.04)
        self.assertEqual(metrics.opening_events(t, r), {})


def write_logs(run_dir: Path, logs: dict):
    run_dir.mkdir(parents=True, exist_ok=True)
    for role, text in logs.items():
        (run_dir / f"{role}.log").write_text(text)


def write_coupling(run_dir: Path, t, force):
    with h5py.File(run_dir / "coupling_series.h5", "w") as f:
        f["time"] = np.asarray(t, float)
        f["force_fluid"] = np.asarray(force, float)


class Classify(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name) / "run"

    def tearDown(self):
        self.tmp.cleanup()

    def test_time_step_collapse_named_by_the_fluid(self):
        write_logs(self.dir, {"fluid": "[x] [error] fluid_sph: time step collapsed at t = 0.061 s: dt = 1e-9 s\n",
                              "coupler": "[x] [error] coupler: participant 'fluid' aborted\n", "solid": ""})
        write_coupling(self.dir, [0.01, 0.02], np.zeros((2, 3)))
        launcher = Path(self.tmp.name) / "launcher.log"
        launcher.write_text("run_case: fluid failed with exit code 1; stopping coupler, solid\n")
        o = outcome.classify(self.dir, 1, 0.1, launcher_log=launcher)
        self.assertEqual((o.kind, o.detected_by), ("time-step collapse", "fluid"))
        self.assertAlmostEqual(o.reached_s, 0.02)

    def test_a_long_message_keeps_what_failed_and_the_remedy(self):
        where = "; ".join(f"particle {k} at (x = {k}.0, 0.0)" for k in range(40))
        write_logs(self.dir, {"fluid": f"[error] fluid_sph: time step collapsed at t = 0.015 s: {where}; raise the sound speed\n"})
        o = outcome.classify(self.dir, 1, 0.1)
        self.assertEqual(o.kind, "time-step collapse")
        self.assertIn("time step collapsed", o.detail)
        self.assertIn("raise the sound speed", o.detail)
        self.assertLessEqual(len(o.detail), 400)

    def test_collapse_after_a_runaway_leaflet_is_coupling_divergence(self):
        write_logs(self.dir, {"fluid": "[error] fluid_sph: time step collapsed at t = 3.9e-05 s: dt = 1.28e-08 s; "
                                       "limits: largest fluid speed 169 m/s, leaflet node speed 2.04e+04 m/s\n"})
        o = outcome.classify(self.dir, 1, 0.1)
        self.assertEqual((o.kind, o.detected_by), ("coupling divergence", "fluid (time-step guard)"))

    def test_coupler_stops_are_named_by_kind(self):
        launcher = Path(self.tmp.name) / "launcher.log"
        launcher.write_text("run_case: coupler failed with exit code 6; stopping fluid, solid\n")
        write_logs(self.dir, {"coupler": "08:21:39.928 error coupler: implicit window 10 (t = 6.5e-05 s, size 6.5e-06 s) diverged: "
                                         "relative residual 1.678e+02 after 30 iterations\n",
                              "fluid": "[error] fluid_sph: participant aborted\n"})
        o = outcome.classify(self.dir, 6, 0.1, launcher_log=launcher)
        self.assertEqual((o.kind, o.detected_by), ("coupling divergence", "coupler"))
        write_logs(self.dir, {"coupler": "08:21:39.928 error coupler: window 4 (t = 2e-05 s to 2.6e-05 s): solid interface node 3 "
                                         "at (1.000, 2.000, 0.000) mm moves at 31 m/s > coupling.max_interface_speed = "
                                         "20 m/s: the interface is running away\n"})
        o = outcome.classify(self.dir, 6, 0.1, launcher_log=launcher)
        self.assertEqual((o.kind, o.detected_by), ("energy growth", "coupler"))
        # the slow-runaway watch (session 9): the same class, its message kept
        watch = ("08:21:39.928 error coupler: window 1441 (t = 0.018733 s to 0.018746 s): solid interface node 12 at "
                 "(0.1, 6.6, 0.0) mm (now at 2.1 m/s) jumps in velocity from window to window by 0.573 m/s RMS over the "
                 "last 16 windows, grown in each of the last 12 blocks of 16 windows from 0.0726 m/s, >= "
                 "coupling.runaway_oscillation_speed = 0.5 m/s: the interface is running away (slowly; a physical "
                 "motion is smooth over a window). Under explicit coupling this is the added-mass instability\n")
        write_logs(self.dir, {"coupler": watch})
        o = outcome.classify(self.dir, 6, 0.1, launcher_log=launcher)
        self.assertEqual((o.kind, o.detected_by), ("energy growth", "coupler"))
        self.assertIn("runaway_oscillation_speed = 0.5 m/s", o.detail)

    def test_the_programs_own_stops_are_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp)
            (run / "solid.log").write_text(
                "[solid] t = 0.01720 s (28.7 %), step 40365\n"
                "[solid] solid: energy growth at t = 0.0196004 s, step 46078: the energy balance error is 0.201\n"
                "[solid] stopping at t = 0.0196 s\n")
            ending = outcome.classify(run, 3, 0.06)
            self.assertEqual((ending.kind, ending.detected_by), ("energy growth", "solid"))
            # a sweep's run folder is named by its setting ('material=MHGO,...'): the stop that
            # names its folder is still energy growth, not a material failure
            (run / "solid.log").write_text(
                "[solid] solid: energy growth at t = 0.00183878 s, step 424: the energy balance error is 0.218; "
                "the last sample of /work/runs/s/material=MHGO,leaflet_density=110/run hold this state\n")
            ending = outcome.classify(run, 3, 0.06)
            self.assertEqual((ending.kind, ending.detected_by), ("energy growth", "solid"))
            (run / "solid.log").write_text(
                "[solid] solid: solid at t = 0.011934 s, step 918: element 30: MHGO: in-plane det(C) = -0.01 <= 0 "
                "(element inverted or degenerate)\n")
            self.assertEqual(outcome.classify(run, 3, 0.06).kind, "solid failure")
            (run / "solid.log").write_text("")
            (run / "fluid.log").write_text(
                "[fluid] fluid_sph: fluid leaks through the leaflets: 12 particle(s) found on the wrong side\n")
            ending = outcome.classify(run, 1, 0.06)
            self.assertEqual((ending.kind, ending.detected_by), ("leaks", "fluid"))

    def test_nan_reported_by_the_coupler(self):
        write_logs(self.dir, {"coupler": "[error] coupler: NaN in 'loads' from participant 'fluid' at point 3\n"})
        self.assertEqual(outcome.classify(self.dir, 5, 0.1).kind, "nan")

    def test_unnamed_failure_with_a_runaway_force_is_energy_growth_not_detected(self):
        write_logs(self.dir, {"coupler": "", "fluid": "", "solid": ""})
        write_coupling(self.dir, [0.01, 0.02, 0.03], [[1, 0, 0], [100, 0, 0], [1e4, 0, 0]])
        o = outcome.classify(self.dir, 1, 0.1)
        self.assertEqual((o.kind, o.detected_by), ("energy growth", ""))

    def test_completed_with_leaks_and_with_unconverged_windows(self):
        write_logs(self.dir, {"coupler": "", "fluid": "", "solid": ""})
        write_coupling(self.dir, [0.05, 0.1], np.ones((2, 3)))
        self.assertEqual(outcome.classify(self.dir, 0, 0.1, leaks=3).kind, "leaks")
        self.assertEqual(outcome.classify(self.dir, 0, 0.1, max_edge_speed=30.0).kind, "energy growth")
        self.assertEqual(outcome.classify(self.dir, 0, 0.1).kind, "completed")
        write_logs(self.dir, {"coupler": "[warning] coupler: window 7 (t = 1e-4 s) not converged after 30 iterations\n"})
        self.assertEqual(outcome.classify(self.dir, 0, 0.1).kind, "coupling divergence")

    def test_a_runaway_no_program_stopped_says_when_where_and_what_to_change(self):
        write_logs(self.dir, {"coupler": "", "fluid": "", "solid": ""})
        t = [0.010, 0.011, 0.012, 0.013, 0.030]
        write_coupling(self.dir, t, [[3, 0, 0], [0, 499, 0], [0, -620, 0], [1890, 0, 0], [40, 0, 0]])
        o = outcome.classify(self.dir, 0, 0.03, max_edge_speed=12.0, edge_speed_at=(0.0131, [0.5, -7.25, 0.0]))
        self.assertEqual((o.kind, o.detected_by), ("energy growth", ""))
        self.assertIn("1.89e+03 N/m", o.detail)
        self.assertIn("first above 500 N/m in the window ending at t = 12.00 ms", o.detail)   # |-620| > 500
        self.assertIn("largest at t = 13.00 ms", o.detail)
        self.assertIn("fastest free edge at t = 13.10 ms, at (0.50, -7.25, 0.00) mm", o.detail)
        self.assertIn("lower time_step_factor", o.detail)
        # the edge alone (force within bounds) names the edge's time and place
        write_coupling(self.dir, t, np.ones((5, 3)))
        o = outcome.classify(self.dir, 0, 0.03, max_edge_speed=12.0, edge_speed_at=(0.0131, [0.5, -7.25, 0.0]))
        self.assertIn("a free edge reached 12 m/s (fastest free edge at t = 13.10 ms", o.detail)
        # a failed run that no program explained: the force's times and the remedy
        write_coupling(self.dir, t[:4], [[3, 0, 0], [0, 499, 0], [0, 501, 0], [np.nan, 0, 0]])
        o = outcome.classify(self.dir, 1, 0.03)
        self.assertIn("first above 500 N/m in the window ending at t = 12.00 ms", o.detail)
        self.assertIn("couple implicitly", o.detail)

    def test_run_short_of_its_end_is_not_completed(self):
        write_logs(self.dir, {"coupler": "", "fluid": "", "solid": ""})
        write_coupling(self.dir, [0.05], np.ones((1, 3)))
        self.assertEqual(outcome.classify(self.dir, 0, 0.1).kind, "other")


class LastWritten(unittest.TestCase):
    """What a failed run left on disk, per program: the latest time in each series and snapshot
    file, and 'missing' for a file that was never written (session 4's c0 = 2.5 m/s collapse
    left no fluid probe series at all)."""

    def test_latest_time_of_each_file_and_missing_files(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp)
            write_coupling(run, [0.001, 0.002, 0.0119], np.ones((3, 3)))
            with h5py.File(run / "solid_series.h5", "w") as f:
                f["time"] = np.array([0.0, 0.005, 0.0101])
            with h5py.File(run / "solid_fields.h5", "w") as f:
                for k, t in enumerate((0.0, 0.01)):
                    f.create_group(f"snapshots/{k:06d}").attrs["time"] = t
            with h5py.File(run / "fluid_particles.h5", "w") as f:
                for k, t in enumerate((0.01, 0.0)):   # the order of the groups is not the order in time
                    f.create_group(f"snapshot_{k:06d}").attrs["time"] = t
            written = outcome.last_written(run)
            self.assertEqual(list(written), ["interface series", "solid series", "solid snapshot", "fluid probes",
                                             "fluid snapshot"])
            self.assertAlmostEqual(written["interface series"], 0.0119)
            self.assertAlmostEqual(written["solid series"], 0.0101)
            self.assertAlmostEqual(written["solid snapshot"], 0.01)
            self.assertIsNone(written["fluid probes"])
            self.assertAlmostEqual(written["fluid snapshot"], 0.01)
            text = outcome.last_written_text(written)
            self.assertIn("interface series 11.90 ms", text)
            self.assertIn("fluid probes missing", text)

    def test_the_stability_table_shows_it_for_failed_runs_only(self):
        written = {"interface series": 0.0119, "solid series": None}
        failed = fake_result("1", 10, {"last_written": written}, kind="energy growth")
        sound = fake_result("2", 10, {"last_written": written})
        for r in (failed, sound):
            r["setting"] = {"material": "MHGO", "sound_speed": float(r["label"]) * 10}
        rows = [row for row in stability.markdown([failed, sound]).splitlines() if row.startswith("| grid")]
        self.assertEqual(len(rows), 2)
        self.assertTrue(rows[0].endswith("| interface series 11.90 ms, solid series missing |"), rows[0])
        self.assertTrue(rows[1].endswith("|  |"), rows[1])


def fake_result(label, cpu, m, kind="completed"):
    return {"label": label, "groups": ["grid"], "setting": {"spacing_mm": label}, "end_time": 0.12, "span": "s",
            "cost": {"wall_s": cpu, "cpu_s": cpu, "cpu_s_by_program": {"fluid": cpu}, "peak_rss_mb_by_program": {}}, "core_hours": cpu / 3600,
            "outcome": {"kind": kind, "reached_s": 0.12, "detail": "", "detected_by": ""}, "metrics": m,
            "reference_errors": {}}


class CheapestWithin(unittest.TestCase):
    def test_picks_the_cheapest_run_within_tolerance_on_every_metric(self):
        finest = fake_result("f", 100, {"peak_velocity": 1.0, "rvot": 0.040})
        results = [finest,
                   fake_result("a", 1, {"peak_velocity": 1.2, "rvot": 0.040}),      # velocity 20 % off
                   fake_result("b", 5, {"peak_velocity": 1.04, "rvot": 0.0415}),    # within 5 %
                   fake_result("c", 2, {"peak_velocity": 1.01, "rvot": 0.040}, kind="nan"),  # failed
                   fake_result("d", 3, {"peak_velocity": 1.01})]                   # lacks RVOT
        rows = report.with_errors(results, finest)
        self.assertEqual(report.cheapest_within(rows, finest, 0.05)["label"], "b")
        text = report.markdown(results, "f")
        self.assertIn("**b**", text)
        with tempfile.TemporaryDirectory() as tmp:
            report.chart(results, Path(tmp) / "c.png", "f")
            self.assertGreater((Path(tmp) / "c.png").stat().st_size, 1000)


class MachineLoad(unittest.TestCase):
    def test_a_run_records_the_load_at_its_start_and_end(self):
        with tempfile.TemporaryDirectory() as tmp:
            fake = Path(tmp) / "launcher.py"   # stands in for scripts/run_case.py: burns a little CPU
            fake.write_text("import sys\nsum(i * i for i in range(200000))\nsys.exit(3)\n")
            saved, runner.LAUNCHER = runner.LAUNCHER, fake
            try:
                cost = runner.run_case(Path(tmp) / "case.textproto", Path(tmp) / "run", Path(tmp), Path(tmp) / "log",
                                       poll_s=0.05)
            finally:
                runner.LAUNCHER = saved
        self.assertEqual(cost.exit_code, 3)
        self.assertGreater(cost.cpu_s, 0.0)
        self.assertEqual(len(cost.load_avg), 2)
        self.assertTrue(all(isinstance(v, float) and v >= 0.0 for v in cost.load_avg))

    def test_both_tables_show_the_load_and_a_dash_for_runs_recorded_without_it(self):
        loaded = fake_result("1", 10, {"peak_velocity": 1.0})
        loaded["cost"]["load_avg"] = [3.25, 7.5]
        old = fake_result("2", 20, {"peak_velocity": 1.0})
        self.assertEqual(report.load_text(loaded["cost"]), "3.2–7.5")
        self.assertEqual(report.load_text(old["cost"]), "–")
        table = report.markdown([loaded, old], "2")
        self.assertIn("| load |", table)
        self.assertIn("| 3.2–7.5 |", table)
        loaded["setting"] = {"material": "MHGO", "sound_speed": 10.0}
        old["setting"] = {"material": "MHGO"}
        for r in (loaded, old):
            r["metrics"].update(max_edge_speed=0.5, max_interface_force=3.0, leaks=0)
        rows = stability.markdown([loaded, old]).splitlines()
        self.assertIn("| load |", rows[2])
        # the load column, then the last-state column (empty for completed runs)
        self.assertEqual(sum(row.endswith("| 3.2–7.5 |  |") for row in rows), 1)
        self.assertEqual(sum(row.endswith("| – |  |") for row in rows), 1)


class Plan(unittest.TestCase):
    def test_a_setting_in_two_groups_runs_once(self):
        spec = {"scene": "valve2d", "end_time": 0.01, "base": {"material": "MHGO"},
                "runs": [{"group": "a", "setting": {"sound_speed": 20.0}},
                         {"group": "b", "setting": {"sound_speed": 20.0}},
                         {"group": "b", "setting": {"sound_speed": 10.0}}]}
        runs = plan.expand(spec)
        self.assertEqual(len(runs), 2)
        self.assertEqual(runs[0].groups, ["a", "b"])
        json.dumps([r.setting for r in runs])


if __name__ == "__main__":
    unittest.main()
