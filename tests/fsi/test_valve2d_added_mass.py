"""The coupled 2D cases keep serial explicit coupling off its stability limit (docs/fsi-2d.md,
"Session 6"). At mu = 2 rho_f c0 dt / (rho_s t) = 2, the two-sided leaflet sits exactly on the
1D acoustic piston's limit (docs/coupling-numerics.md (b)): the lag neither damps nor grows the
leaflet's fastest mode. The coarse MHGO valve at mu = 2 rang in a 10.7-12.4 kHz in-plane mode
from ~0.17 s and was stopped at 0.258 s (energy growth) or 0.275 s (runaway), still open; at
mu = 1 (the leaflet twice as heavy) the same restart closed at 0.28 s. Each checked-in coupled
2D case must have mu <= 1, and the FE-only cases the tissue's density (reference Sec. 2.2)."""
import re
import unittest
from pathlib import Path

from valve_scene.valve_geometry import ValveParameters

CASES = Path(__file__).resolve().parents[2] / "cases"
TISSUE_DENSITY = 1100.0  # kg/m^3, reference Sec. 2.2


def number(text: str, block: str, field: str, path: Path) -> float:
    """The first `field: value` inside the top-level `block { ... }` of a case file."""
    start = re.search(rf"^{block} {{$", text, re.M)
    if not start:
        raise AssertionError(f"{path}: no top-level '{block} {{' block")
    body = text[start.end():]
    end = re.search(r"^}$", body, re.M)
    m = re.search(rf"^\s*{field}: ([0-9.eE+-]+)\s*$", body[:end.start() if end else None], re.M)
    if not m:
        raise AssertionError(f"{path}: field {block}.{field} not found")
    return float(m.group(1))


def coupled_cases():
    return sorted(CASES.glob("fsi-*-2d-*.textproto")) + sorted(CASES.glob("default-fsi-2d-*.textproto"))


class AddedMassNumber2D(unittest.TestCase):
    def test_coupled_cases_have_mu_at_most_one(self):
        files = coupled_cases()
        self.assertGreaterEqual(len(files), 7)  # xcoarse, coarse, medium x Ogden, MHGO + the default
        thickness = ValveParameters().thickness
        for path in files:
            with self.subTest(case=path.name):
                text = path.read_text()
                rho_s = number(text, "solid", "density", path)
                rho_f = number(text, "fluid", "density", path)
                c0 = number(text, "fluid", "sound_speed", path)
                window = number(text, "coupling", "window_size", path)
                mu = 2.0 * rho_f * c0 * window / (rho_s * thickness)
                self.assertLessEqual(mu, 1.0 + 1e-6, f"{path.name}: mu = {mu:.3f} (rho_s {rho_s}, window {window})")
                # the window itself is not shortened: the fluid still sub-cycles at its CFL
                self.assertGreaterEqual(window, 1.3e-5 * (1 - 1e-9), path.name)

    def test_fe_only_cases_keep_the_tissue_density(self):
        files = sorted(CASES.glob("fe-*-2d-*.textproto"))
        self.assertGreaterEqual(len(files), 6)
        for path in files:
            with self.subTest(case=path.name):
                self.assertEqual(number(path.read_text(), "solid", "density", path), TISSUE_DENSITY)


if __name__ == "__main__":
    unittest.main()
