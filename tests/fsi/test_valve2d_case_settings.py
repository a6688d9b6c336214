"""The checked-in 2D cases carry session 8's two fixes (docs/fsi-2d.md, "Session 8"):
  - every 2D case (FE-only and FSI) switches on the leaflet's self-contact: in cycle 2 of the
    coarse FSI-MHGO run the leaflet folded through itself from 0.87 s and particles leaked
    through the crossing; held apart from itself the same restart ran to 1.6 s without a leak;
  - every coupled case holds the lower plate at the 20 mmHg floor once its drive has reached it
    (fluid.plate_pressure_floor_once_reached), so the diastolic ventricle's plate stays on the
    blood from t = 0 without the start-up load the plain floor gave (88 N/m in 10 ms);
and session 19's: every coupled case fits its coupling windows to whole fluid steps (a cycle of
the coarse FSI-MHGO valve: 184,614 -> 136,495 fluid steps, metrics within the scatter;
docs/fsi-2d.md, "Session 19") and shifts at each particle's own speed away from the leaflets (the
flow sections' drift upstream of the valve gone, 0 lost, 0 leaks over a cycle of each material)."""
import re
import unittest
from pathlib import Path

CASES = Path(__file__).resolve().parents[2] / "cases"
NAME = re.compile(r"(default-)?(fe|fsi)-.*2d.*\.textproto")


def block(text: str, name: str, path: Path) -> str:
    """The body of the top-level `name { ... }` block."""
    start = re.search(rf"^{name} {{$", text, re.M)
    if not start:
        raise AssertionError(f"{path}: no top-level '{name} {{' block")
    body = text[start.end():]
    end = re.search(r"^}$", body, re.M)
    return body[:end.start()] if end else body


class CaseSettings2D(unittest.TestCase):
    def cases(self):
        files = sorted(p for p in CASES.glob("*2d*.textproto") if NAME.fullmatch(p.name))
        self.assertGreaterEqual(len(files), 14, f"the 2D cases in {CASES}")
        return files

    def test_every_2d_leaflet_has_self_contact(self):
        for path in self.cases():
            with self.subTest(case=path.name):
                solid = block(path.read_text(), "solid", path)
                self.assertRegex(solid, r"(?m)^\s*leaflet_self_contact: true\s*$")

    def test_coupled_cases_hold_the_floor_once_reached(self):
        coupled = [p for p in self.cases() if "fsi-" in p.name]
        self.assertGreaterEqual(len(coupled), 7)
        for path in coupled:
            with self.subTest(case=path.name):
                fluid = block(path.read_text(), "fluid", path)
                floor = re.search(r"(?m)^\s*plate_pressure_floor_mmHg: ([0-9.eE+-]+)\s*$", fluid)
                self.assertIsNotNone(floor, "fluid.plate_pressure_floor_mmHg")
                self.assertEqual(float(floor.group(1)), 20.0)
                self.assertRegex(fluid, r"(?m)^\s*plate_pressure_floor_once_reached: true\s*$")
                self.assertRegex(fluid, r"(?m)^\s*plates_never_pull: true\s*$")

    def test_coupled_cases_fit_their_windows_to_whole_fluid_steps(self):
        coupled = [p for p in self.cases() if "fsi-" in p.name]
        for path in coupled:
            with self.subTest(case=path.name):
                self.assertRegex(block(path.read_text(), "fluid", path), r"(?m)^\s*fit_coupling_window_to_steps: true\s*$")

    def test_coupled_cases_shift_at_the_own_speed_away_from_the_leaflets(self):
        for path in [p for p in self.cases() if "fsi-" in p.name]:
            with self.subTest(case=path.name):
                fluid = block(path.read_text(), "fluid", path)
                self.assertRegex(fluid, r"(?m)^\s*shifting: 1\s*$")
                self.assertRegex(fluid, r"(?m)^\s*shifting_speed: SHIFT_BY_OWN_SPEED_AWAY_FROM_LEAFLETS\s*$")


if __name__ == "__main__":
    unittest.main()
