"""The checked-in TAV case files are what the generator writes, and each opens with what it
models, what it should show and the command that runs it (issue 4, item 4)."""
import unittest
from pathlib import Path

import numpy as np

from valve_scene.valve_geometry import ValveParameters
from valve_scene.valve_mesh import RESOLUTIONS, build_valve_mesh
from valve_scene.write_cases import all_specs, case_text, stent_radius

CASES = Path(__file__).resolve().parents[2] / "cases"


class CaseFiles(unittest.TestCase):
    def test_checked_in_cases_are_current(self):
        for spec in all_specs():
            with self.subTest(case=spec.name):
                self.assertEqual((CASES / f"{spec.name}.textproto").read_text(), case_text(spec))

    def test_each_opens_with_what_it_models_shows_and_how_to_run_it(self):
        for spec in all_specs():
            text = case_text(spec)
            comment = text[:text.index("\ntitle:")]
            self.assertTrue(all(line.startswith("#") for line in comment.splitlines()))
            self.assertIn("# What it models:", comment)
            self.assertIn("# What it should show:", comment)
            self.assertIn(f"scripts/run_case.py cases/{spec.name}.textproto", comment)
            self.assertEqual(spec.kind == "FE", "--fe-only" in comment)

    def test_sector_cases_use_sector_meshes(self):
        for spec in all_specs():
            self.assertIn(f'mesh_file: "meshes/valve-{spec.variant}-{spec.resolution}.mesh.h5"', case_text(spec))

    def test_sector_fsi_mirrors_are_the_sector_meshs_planes(self):
        import re
        mesh = build_valve_mesh("sector", "coarse", "triangles")
        expected = [mesh.symmetry_planes["leaflet_bisector"][1], mesh.contact_planes["coaptation"][1]]
        for spec in all_specs():
            if spec.kind != "FSI":
                continue
            normals = [np.array([float(v) for v in m.split(",")]) for m in
                       re.findall(r"mirror_planes \{ point: \[0, 0, 0\] normal: \[([^\]]*)\]", case_text(spec))]
            if spec.variant == "full":
                self.assertEqual(normals, [])
                continue
            self.assertEqual(len(normals), 2)
            for got, want in zip(normals, expected):
                np.testing.assert_allclose(got, want, atol=1e-14)

    def test_sector_fsi_solid_takes_two_implicit_steps_per_window(self):
        import re
        for spec in all_specs():
            text = case_text(spec)
            solid = text[text.index("solid {"):text.index("\n}\n", text.index("solid {")) + 1]
            implicit = "time_integration: IMPLICIT" in solid
            self.assertEqual(implicit, spec.kind == "FSI" and spec.variant == "sector", spec.name)
            if implicit:
                # two steps per window: one let the opening's coaptation band flutter grow (docs/fsi-3d.md)
                window = float(re.search(r"  window_size: ([^\n]*)\n", text).group(1))
                step = float(re.search(r"  max_time_step: ([^\n]*)\n", solid).group(1))
                first = float(re.search(r"  implicit_initial_step_s: ([^\n]*)\n", solid).group(1))
                self.assertAlmostEqual(step / window, 0.5, delta=1e-9)
                self.assertEqual(first, step)
                self.assertIn("  spectral_radius_infinity: 0.5\n", solid)
            # every case keeps the energy check's default 0.2: the sector cycles read 0.000 from
            # t = 0 into diastole (docs/fsi-3d.md, session 22)
            self.assertNotIn("max_energy_balance_error", solid)

    def test_fe_only_cases_damp_the_closed_valve_from_its_onset_and_fsi_cases_do_not(self):
        for spec in all_specs():
            text = case_text(spec)
            solid = text[text.index("solid {"):text.index("\n}\n", text.index("solid {")) + 1]
            if spec.kind == "FE":
                # past the closing's end (-6 mmHg at 244.4 ms), so RVCT stays undamped (docs/solid_fe.md)
                self.assertIn("  diastolic_mass_damping_per_s: 500\n", solid, spec.name)
                self.assertIn("  diastolic_damping_onset_mmHg: 20\n", solid, spec.name)
            else:
                # the solid program refuses it when coupled: the fluid damps the valve
                self.assertNotIn("diastolic", solid, spec.name)

    def assert_fluid_line_only_in_fsi_cases(self, field: str, line: str):
        """FE-only cases do not name `field`; every FSI case's fluid block has `line`."""
        for spec in all_specs():
            text = case_text(spec)
            if spec.kind == "FE":
                self.assertNotIn(field, text, spec.name)
            else:
                fluid = text[text.index("fluid {"):text.index("\n}\n", text.index("fluid {")) + 1]
                self.assertIn(f"  {line}\n", fluid, spec.name)

    def test_fsi_cases_fit_their_coupling_windows_to_whole_fluid_steps(self):
        # a window of 2.06 fluid steps costs 3 (fluid.fit_coupling_window_to_steps, docs/fsi-3d.md)
        self.assert_fluid_line_only_in_fsi_cases("fit_coupling_window_to_steps", "fit_coupling_window_to_steps: true")

    def test_fsi_cases_shift_at_the_fastest_speed(self):
        # the own speed away from the leaflets (2D cases) let the sector's opening flutter run away
        # at 20.3 ms from t = 0; the fastest speed ran through (docs/fsi-3d.md, session 20)
        self.assert_fluid_line_only_in_fsi_cases("shifting_speed", "shifting_speed: SHIFT_BY_FASTEST_PARTICLE")

    def test_every_3d_case_has_the_stent_cylinder(self):
        for spec in all_specs():
            self.assertIn(f"contact_cylinders {{ origin: [0, 0, 0] axis: [0, 0, 1] radius: {stent_radius():.6g} }}", case_text(spec))

    def test_no_free_node_starts_inside_the_stent_penalty_zone(self):
        # mid-surface + t/2 within the cylinder for every node the solid moves
        t = ValveParameters().thickness
        worst = []
        for resolution in RESOLUTIONS:
            mesh = build_valve_mesh("full", resolution, "triangles")
            free = np.setdiff1d(np.arange(len(mesh.nodes)), mesh.node_sets["attachment"])
            r = np.hypot(mesh.nodes[free, 0], mesh.nodes[free, 1])
            worst.append(r.max() + 0.5 * t - stent_radius())
        self.assertTrue(all(w <= 0 for w in worst), worst)
        # with the annulus radius itself as the face, the fine mesh would start in contact
        self.assertGreater(worst[-1] + 0.5 * t, 0)


if __name__ == "__main__":
    unittest.main()
