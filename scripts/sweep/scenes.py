"""A scene and one setting (axis name -> value) -> a case file ready for scripts/run_case.py.

Scenes:
- `valve2d`: the coupled 2D valve (valve_scene.valve2d, docs/valve-scene.md), generated afresh
  for each setting so that every length that depends on the particle spacing (plates, margins,
  lattice origin) follows it. Axes, with their defaults (the committed case's values):
    material           MHGO | Ogden                                   (MHGO)
    spacing_mm         fluid particle spacing                         (1.0)
    sound_speed        fluid c0 (m/s)                                 (20)
    time_step_factor   f: fluid.cfl = f x the committed CFL (valve2d.FLUID_CFL_2D, 0.1) and the
                       coupling window = f x the committed window (valve2d.coupling_window:
                       COUPLING_WINDOW_FACTOR_2D = 2 x the window at which
                       mu = 2 rho_f c0 dt / (rho_s t) = 1 for the default leaflet)   (1)
    coupling           explicit (SERIAL_EXPLICIT) | implicit (SERIAL_IMPLICIT, IQN-ILS)   (explicit)
    density_diffusion  delta-SPH coefficient (0 = off)                (0.1)
    background_pressure on | off (off: p_b = 0, the plates keep their offsets, so the fluid's
                       pressure is the gauge pressure relative to the opening pressure)
                       (off, as valve2d.BACKGROUND_PRESSURE_2D: the committed cases)
    leaflet_density    solid density (kg/m^3); the window stays the default's, so mu grows
                       as the leaflet gets lighter                    (1100)
    thickness_mm       leaflet thickness (a strip mesh is written for it; window as above)  (0.25)
- `case`: any case file given by the axis `case` (path), for scenes that have no generator
  axis here (3D sector vs full, shell vs hexahedron: pick the case files).
Every scene also takes `set:<block.field>` axes, applied last (case_edit.set_field).
"""
from __future__ import annotations

import math
from pathlib import Path

from . import case_edit

VALVE2D_DEFAULTS = {
    "material": "MHGO",
    "spacing_mm": 1.0,
    "sound_speed": 20.0,
    "time_step_factor": 1.0,
    "coupling": "explicit",
    "density_diffusion": 0.1,
    "background_pressure": "off",
    # the committed coupled cases' leaflet: twice the tissue's 1100 kg/m^3 (valve2d.leaflet_density,
    # mu = 1 at the 13 us window; docs/fsi-2d.md "Session 6")
    "leaflet_density": 2200.0,
    "thickness_mm": 0.25,
}
COUPLING_SCHEMES = {
    "explicit": {"coupling.scheme": "SERIAL_EXPLICIT"},
    "implicit": {"coupling.scheme": "SERIAL_IMPLICIT", "coupling.acceleration": "IQN_ILS",
                 "coupling.max_iterations": 30},
}


def case_name(case) -> str:
    """A case file's axis value as shown: its file name without the extension."""
    return Path(str(case)).name.removesuffix(".textproto")


def setting_label(setting: dict) -> str:
    """A file-name-safe label: axis=value pairs in the order given."""
    parts = []
    for key, value in setting.items():
        text = f"{value:g}" if isinstance(value, float) else str(value)
        if key == "case":   # a case file: its name says it
            text = case_name(text)
        key = key.replace("set:", "").replace(".", "-")
        parts.append(f"{key}={text}".replace("/", "_").replace(" ", ""))
    return ",".join(parts) if parts else "default"


def _valve2d_case(setting: dict, work: Path, end_time: float) -> Path:
    from valve_scene import valve2d
    from valve_scene.mesh_io import write_mesh
    from valve_scene.valve_geometry import ValveParameters

    unknown = [k for k in setting if k not in VALVE2D_DEFAULTS and not k.startswith("set:") and k != "case"]
    if unknown:
        raise ValueError(f"valve2d scene: unknown axis '{unknown[0]}': allowed {', '.join(VALVE2D_DEFAULTS)} "
                         "or set:<block.field>")
    s = {**VALVE2D_DEFAULTS, **setting}
    material = str(s["material"])
    if material not in ("MHGO", "Ogden"):
        raise ValueError(f"valve2d scene: material '{material}': allowed MHGO, Ogden")
    dp = float(s["spacing_mm"]) * 1e-3
    c0 = float(s["sound_speed"])
    factor = float(s["time_step_factor"])
    if not (dp > 0 and c0 > 0 and factor > 0):
        raise ValueError(f"valve2d scene: spacing_mm {s['spacing_mm']}, sound_speed {c0}, time_step_factor {factor}: "
                         "allowed > 0")
    if str(s["coupling"]) not in COUPLING_SCHEMES:
        raise ValueError(f"valve2d scene: coupling '{s['coupling']}': allowed {', '.join(COUPLING_SCHEMES)}")
    if str(s["background_pressure"]) not in ("on", "off"):
        raise ValueError(f"valve2d scene: background_pressure '{s['background_pressure']}': allowed on, off")

    work.mkdir(parents=True, exist_ok=True)
    spec = valve2d.Case2D("FSI", material, "coarse")
    text = valve2d.case_text_2d(spec)
    cycles = max(1, math.ceil(end_time / valve2d.waveform.PERIOD_S - 1e-9))
    text = case_edit.replace_block(text, "fluid", valve2d.fluid_block_2d(
        dp, cycles=cycles, sound_speed=c0, background=s["background_pressure"] == "on"))

    thickness = float(s["thickness_mm"]) * 1e-3
    params = ValveParameters(thickness=thickness)
    mesh_path = work / "meshes" / f"valve-2d-coarse-t{thickness * 1e6:.0f}um.mesh.h5"
    if not mesh_path.exists():
        write_mesh(valve2d.build_strip_mesh("coarse", params=params), mesh_path)
    window = factor * valve2d.coupling_window(c0)   # the committed window at this c0
    overrides = {
        "run.end_time": float(end_time),
        "run.output_dir": "run",
        "solid.mesh_file": str(mesh_path.relative_to(work)),
        "solid.density": float(s["leaflet_density"]),
        "fluid.cfl": valve2d.FLUID_CFL_2D * factor,
        "fluid.density_diffusion": float(s["density_diffusion"]),
        "coupling.window_size": window,
        **COUPLING_SCHEMES[str(s["coupling"])],
    }
    for path, value in overrides.items():
        text = case_edit.set_field(text, path, value)
    for key, value in setting.items():
        if key.startswith("set:"):
            text = case_edit.set_field(text, key[4:], value)
    case = work / "case.textproto"
    case.write_text(text)
    return case


def _file_case(setting: dict, work: Path, end_time: float) -> Path:
    if "case" not in setting:
        raise ValueError("case scene: the setting needs the axis 'case' (a case file)")
    source = Path(setting["case"]).resolve()
    if not source.is_file():
        raise ValueError(f"case scene: case file '{source}' does not exist")
    unknown = [k for k in setting if k != "case" and not k.startswith("set:")]
    if unknown:
        raise ValueError(f"case scene: unknown axis '{unknown[0]}': allowed case, set:<block.field>")
    text = case_edit.set_field(source.read_text(), "run.end_time", float(end_time))
    text = case_edit.set_field(text, "run.output_dir", "run")
    for key, value in setting.items():
        if key.startswith("set:"):
            text = case_edit.set_field(text, key[4:], value)
    # the copy lives in the work folder: a relative mesh path (the case's own or a set: one) is
    # made absolute from the source case's folder
    mesh = case_edit.get_field(text, "solid.mesh_file")
    if mesh and not Path(mesh.strip('"')).is_absolute():
        text = case_edit.set_field(text, "solid.mesh_file", str(source.parent / mesh.strip('"')))
    work.mkdir(parents=True, exist_ok=True)
    case = work / "case.textproto"
    case.write_text(text)
    return case


SCENES = {"valve2d": _valve2d_case, "case": _file_case}


def write_case(scene: str, setting: dict, work: Path, end_time: float) -> Path:
    if scene not in SCENES:
        raise ValueError(f"scene '{scene}': allowed {', '.join(SCENES)}")
    return SCENES[scene](dict(setting), Path(work), end_time)
