"""The sweeps behind docs/speed-accuracy.md and docs/stability-map.md.

Costs were chosen for a 2-core machine shared by others: one run at a time, one thread each,
spans as short as the question allows (stated in `span`).
"""
from __future__ import annotations

OPENING_END_S = 0.10
# FE-only 3D opening: the reference's FE-only leaflets open within ~6 ms of the start of the
# forward gradient (about 20 ms); 60 ms holds the opening, the open plateau and the peak strain.
FE_OPENING_END_S = 0.06
CASES = "../cases/"

PRESETS = {
    # Speed against accuracy: particle spacing x sound speed on the 2D valve's opening.
    "opening-2d": {
        "scene": "valve2d",
        "report": "report",
        "end_time": OPENING_END_S,
        "span": "opening only, 0-100 ms of the first cycle (no EOA, RVCT, diastolic force or closed stress)",
        "base": {"material": "MHGO"},
        # spacings 23 mm / n (n = 16, 23, 30, 40): the orifice spans whole spacings (valve2d.on_lattice).
        # A run costs about c0 x particles (the window shrinks as 1/c0); the full grid does not fit
        # a session on a shared machine. The committed case (1 mm, 20 m/s) runs first, then the
        # finest, so that a sweep cut short has its reference; 0.575 mm (n = 40, ~2.4x the finest's
        # CPU) runs last, for the convergence in the spacing. n = 12 (1.917 mm) is left out: in
        # the first sweep every run at 1.917 and 1.4375 mm fluttered (17-32 m/s edges); n = 16 keeps one.
        "runs": [{"group": "grid", "setting": {"spacing_mm": 23.0 / n, "sound_speed": c}}
                 for n, c in ((23, 20.0), (30, 40.0), (23, 10.0), (23, 40.0), (30, 20.0), (16, 20.0), (40, 40.0))],
        "finest": {"spacing_mm": 23.0 / 30, "sound_speed": 40.0},
        "wall_limit_s": 3600,
    },
    # Stability map: each group varies one thing from the committed coarse case (the default
    # run, shared by every group, is listed in the first). Since session 6 the base leaflet is
    # 2200 kg/m^3 (mu = 1 at the 13 us window) damped at 200/s, so the added-mass rows are the
    # densities of mu = 1, 2, 4, 8, 20 and the undamped rows say what the damping buys.
    "stability-2d": {
        "scene": "valve2d",
        "report": "stability",
        "end_time": 0.03,
        "span": "0-30 ms of the first cycle (start-up and the first pressure wave; the leaflets start to open at 30-50 ms)",
        "base": {"material": "MHGO"},
        # The questions of issue 8 item 2 run first (the largest stable factor, the lowest c0,
        # explicit vs implicit as mu grows, delta, thickness); the groups after them say why
        # (window vs fluid step, damping, background pressure) and run when the machine allows.
        "runs": (
            [{"group": "time-step factor", "setting": {}}]
            + [{"group": "time-step factor", "setting": {"time_step_factor": f}} for f in (1.5, 2.0, 3.0)]
            + [{"group": "sound speed", "setting": {"sound_speed": c}} for c in (2.5, 5.0, 10.0)]
            + [{"group": "added mass, explicit", "setting": {"leaflet_density": rho}}
               for rho in (1100.0, 550.0, 275.0, 110.0)]
            + [{"group": "added mass, implicit", "setting": {"leaflet_density": rho, "coupling": "implicit"}}
               for rho in (1100.0, 275.0, 110.0)]
            + [{"group": "density diffusion", "setting": {"density_diffusion": 0.0}}]
            + [{"group": "thickness / spacing", "setting": {"thickness_mm": t}} for t in (0.5, 0.125, 0.0625)]
            # the cases' 200/s mass damping off: where explicit coupling fails without it
            + [{"group": "added mass, explicit, undamped",
                "setting": {"leaflet_density": rho, "set:solid.mass_damping_per_s": 0.0}}
               for rho in (2200.0, 1100.0)]
            # the window grows but the fluid keeps its step (cfl 0.1 x h / c0 = 6.5 us, sub-cycled):
            # which of the two limits the factor
            + [{"group": "window only", "setting": {"time_step_factor": f, "set:fluid.cfl": 0.1}} for f in (0.5, 2.0)]
            # the fluid's step alone, at the committed window
            + [{"group": "fluid step", "setting": {"set:fluid.cfl": c}} for c in (0.15, 0.2)]
            # the committed cases start at gauge 0; a background pressure (the aortic pressure at
            # opening) acts through the leaflet's incomplete kernels
            + [{"group": "background pressure", "setting": {"background_pressure": "on"}}]
            + [{"group": "added mass, implicit", "setting": {"leaflet_density": 2200.0, "coupling": "implicit"}}]
        ),
        "wall_limit_s": 900,
    },
    # The model choices of issue 8 item 1 that are a choice of case, FE-only (no fluid, uniform
    # prescribed pressure), over the opening: sector vs full valve, shell vs hexahedral leaflets,
    # and the mesh resolution. The finest is the fine sector with shells; its opening costs ~15x
    # the medium's (measured: coarse 16 s, medium 207 s, fine 3226 s of CPU), so it runs last.
    "fe-opening-3d": {
        "scene": "case",
        "report": "report",
        "end_time": FE_OPENING_END_S,
        "span": "FE-only opening, 0-60 ms of the first cycle (uniform prescribed pressure; no fluid)",
        "runs": (
            [{"group": "sector shell", "setting": {"case": CASES + f"fe-mhgo-sector-{r}.textproto"}}
             for r in ("coarse", "medium")]
            + [{"group": "full valve shell", "setting": {"case": CASES + "fe-mhgo-full-coarse.textproto"}}]
            # the cases' meshes hold triangles only; the bricks' meshes are written beside them by
            # `cd scripts && /usr/bin/python3 -m valve_scene.generate --variant sector --resolution R
            #  --elements hexahedra --out ../cases/meshes/valve-sector-R-hexahedra.mesh.h5`
            # bricks are explicit only (the sector cases' AUTOMATIC switch and its filter are refused
            # with them); the shell rows keep their cases' AUTOMATIC, implicit from ~17 ms
            + [{"group": "sector hexahedron",
                "setting": {"case": CASES + f"fe-mhgo-sector-{r}.textproto", "set:solid.element_family": "HEXAHEDRON",
                            "set:solid.mesh_file": f"meshes/valve-sector-{r}-hexahedra.mesh.h5",
                            "set:solid.time_integration": "EXPLICIT", "set:solid.settled_filter_time_s": 0}}
               for r in ("coarse", "medium")]
            + [{"group": "sector shell", "setting": {"case": CASES + "fe-mhgo-sector-fine.textproto"}}]
        ),
        "finest": {"case": CASES + "fe-mhgo-sector-fine.textproto"},
        "wall_limit_s": 3600,
    },
}
