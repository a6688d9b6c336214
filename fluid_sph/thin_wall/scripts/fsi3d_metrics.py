"""The coupled 3D sector's metrics as the run goes (docs/fsi-3d.md), beside an FE-only run.

    HDF5_USE_FILE_LOCKING=FALSE /usr/bin/python3 fluid_sph/thin_wall/scripts/fsi3d_metrics.py \
        FSI_RUN_DIR [--fe-only FE_RUN_DIR] [--png FIGURE] [--json OUT.json]

Reads solid_series.h5 / solid_fields.h5 (free-edge midpoint, snapshots), coupling_series.h5
(force on the half leaflet) and, once the fluid has flushed it (every 200 samples), fluid_probes.h5
(flow, taps, leaks). A 1/6 sector stands for the valve: GOA measured in the 0-60 deg wedge x 6,
flows and forces x 6. Uses the scene's own definitions (scripts/valve_scene: analysis.py for the
radial position, GOA, robust peaks and RVOT; hemodynamics.py for the taps and flow sections), so
the numbers are those the full-cycle report would give; it only tolerates a run that has not yet
finished a cycle. The opening start is where the free-edge radius first exceeds its rest value by
OPENING_THRESHOLD_M (a partial run has no closed/open medians for valve_events' levels).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "scripts"))
from valve_scene import analysis, hemodynamics as hd  # noqa: E402

SECTOR_FACTOR = 6
OPENING_THRESHOLD_M = 0.5e-3   # rise of the free-edge radius that counts as "opening started"
PRESSURE_DROP_TIME_S = 0.025   # the reference's PSPD instant


def solid_metrics(run: Path) -> dict:
    out: dict = {}
    with h5py.File(run / "solid_series.h5", "r") as f:
        t = f["time"][()]
        r = f["monitor/free_edge_midpoints/mean_radial_position"][()]
        out["time_s"] = t
        out["radius_m"] = r
        out["energy_error"] = f["energy/relative_balance_error"][()]
        out["kinetic_J"] = f["energy/kinetic"][()]
    rise = np.nonzero(r - r[0] > OPENING_THRESHOLD_M)[0]
    out["opening_start_s"] = float(t[rise[0]]) if rise.size else None
    fields = h5py.File(run / "solid_fields.h5", "r")
    ref = fields["mesh/nodes"][()]
    tri = fields["mesh/triangles"][()]
    areas = analysis.triangle_areas(ref, tri)
    names = sorted(fields["snapshots"])
    ts, goa, strain, stress = [], [], [], []
    for n in names:
        g = fields["snapshots"][n]
        if "position" not in g or "time" not in g.attrs:
            continue
        ts.append(float(g.attrs["time"]))
        goa.append(analysis.geometric_orifice_area(g["position"][()], tri, hd.ANNULUS_RADIUS_M, (0.0, 60.0)))
        strain.append(analysis.area_percentile(g["max_principal_log_strain"][()], areas))
        stress.append(analysis.area_percentile(g["max_principal_stress"][()], areas))
    fields.close()
    out.update(snapshot_time_s=np.array(ts), goa_m2=np.array(goa), strain_p99=np.array(strain),
               stress_p99_Pa=np.array(stress))
    # RVOT as the reference reads it (steepest rise); needs the open plateau in the data
    try:
        ev = analysis.valve_events(t, r)
        out["rvot_s"] = ev.rvot
    except (ValueError, AttributeError):
        out["rvot_s"] = None
    return out


def fluid_metrics(run: Path) -> dict:
    out: dict = {}
    with h5py.File(run / "coupling_series.h5", "r") as f:
        out["window_time_s"] = f["time"][()]
        out["force_N"] = f["force_fluid"][()]
    probes = run / "fluid_probes.h5"
    if not probes.exists():
        return out
    series = hd.read_run(run)
    t = series.time
    out["probe_time_s"] = t
    out["pressure_drop_mmHg"] = series.pressure_drop / hd.PA_PER_MMHG
    flows = np.mean([q for q in series.flow_rates.values()], axis=0)
    out["flow_L_per_min"] = flows * SECTOR_FACTOR * 60e3   # m^3/s per wedge -> L/min valve
    with h5py.File(probes, "r") as f:
        if "interface" in f:
            out["leaks"] = f["interface/leaks"][()].reshape(-1)
            out["corrections"] = f["interface/corrections"][()].reshape(-1)
        out["lost"] = f["lost_particles"][()].reshape(-1)
    return out


def summary(fsi: dict, fe: dict | None) -> dict:
    s = {"reached_s": float(fsi["solid"]["time_s"][-1]),
         "opening_start_s": fsi["solid"]["opening_start_s"],
         "rvot_s": fsi["solid"]["rvot_s"],
         "radius_mm_last": float(fsi["solid"]["radius_m"][-1] * 1e3),
         "radius_mm_rest": float(fsi["solid"]["radius_m"][0] * 1e3),
         "goa_cm2_max": float(fsi["solid"]["goa_m2"].max() * 1e4) if fsi["solid"]["goa_m2"].size else None,
         "strain_p99_max": float(fsi["solid"]["strain_p99"].max()) if fsi["solid"]["strain_p99"].size else None,
         "stress_p99_MPa_max": float(fsi["solid"]["stress_p99_Pa"].max() / 1e6) if fsi["solid"]["stress_p99_Pa"].size else None,
         "energy_error_after_4ms_max": float(np.abs(fsi["solid"]["energy_error"][fsi["solid"]["time_s"] > 4e-3]).max())
         if np.any(fsi["solid"]["time_s"] > 4e-3) else None}
    fl = fsi["fluid"]
    if "probe_time_s" in fl:
        t = fl["probe_time_s"]
        s["probes_until_s"] = float(t[-1])
        if t[-1] >= PRESSURE_DROP_TIME_S:
            k = np.searchsorted(t, PRESSURE_DROP_TIME_S)
            w = np.abs(t - PRESSURE_DROP_TIME_S) <= 1e-3   # +-1 ms mean against the probes' noise
            s["pressure_drop_25ms_mmHg"] = float(fl["pressure_drop_mmHg"][w].mean())
            s["pressure_drop_25ms_raw_mmHg"] = float(fl["pressure_drop_mmHg"][k])
        s["pressure_drop_max_mmHg_1ms_mean"] = float(hd.moving_average(t, fl["pressure_drop_mmHg"], 1e-3).max())
        s["flow_L_per_min_max_1ms_mean"] = float(hd.moving_average(t, fl["flow_L_per_min"], 1e-3).max())
        if "leaks" in fl:
            s["leaks"] = int(fl["leaks"][-1])
            s["corrections"] = int(fl["corrections"][-1])
        s["lost"] = int(fl["lost"][-1])
    if fe is not None:
        s["fe_only"] = {"opening_start_s": fe["opening_start_s"], "rvot_s": fe["rvot_s"],
                        "radius_mm_max": float(fe["radius_m"].max() * 1e3),
                        "goa_cm2_max": float(fe["goa_m2"].max() * 1e4),
                        "strain_p99_max": float(fe["strain_p99"].max()),
                        "stress_p99_MPa_max": float(fe["stress_p99_Pa"].max() / 1e6)}
    return s


def plot(fsi: dict, fe: dict | None, path: Path, others: list | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    so = fsi["solid"]
    ax[0].plot(so["time_s"] * 1e3, so["radius_m"] * 1e3, "b-", lw=1, label=f"FSI {fsi['label']}")
    ax[1].plot(so["snapshot_time_s"] * 1e3, so["goa_m2"] * 1e4, "bo-", ms=3, label=f"FSI {fsi['label']}")
    for other, style in zip(others or [], ("c--", "g--", "y--")):
        oo = other["solid"]
        ax[0].plot(oo["time_s"] * 1e3, oo["radius_m"] * 1e3, style, lw=1.2, label=f"FSI {other['label']}")
        ax[1].plot(oo["snapshot_time_s"] * 1e3, oo["goa_m2"] * 1e4, style, lw=1.2, label=f"FSI {other['label']}")
    if fe is not None:
        ax[0].plot(fe["time_s"] * 1e3, fe["radius_m"] * 1e3, "r-", lw=0.8, label="FE-only sector")
        ax[1].plot(fe["snapshot_time_s"] * 1e3, fe["goa_m2"] * 1e4, "rs-", ms=3, label="FE-only")
    ax[0].axvline(20, color="gray", ls=":", label="reference: FSI opening starts ~20 ms")
    ax[0].set_ylabel("free-edge midpoint radius (mm)")
    ax[1].set_ylabel("GOA, valve (cm$^2$)")
    fl = fsi["fluid"]
    F = fl["force_N"] * SECTOR_FACTOR
    ax[2].plot(fl["window_time_s"] * 1e3, F[:, 2], "k-", lw=0.5, label="axial force on the leaflets x 6 (N)")
    if "probe_time_s" in fl:
        t = fl["probe_time_s"]
        ax[2].plot(t * 1e3, hd.moving_average(t, fl["pressure_drop_mmHg"], 1e-3), "g-", lw=1,
                   label="transvalvular pressure drop, 1 ms mean (mmHg)")
        ax[2].plot(t * 1e3, fl["flow_L_per_min"], "m-", lw=0.8, label="flow rate (L/min)")
        ax[2].plot([25], [11.7], "g*", ms=10, label="reference PSPD 11.7 mmHg (MHGO)")
    ax[2].set_ylim(top=16)
    for a, where in zip(ax, ("center", "center", "upper left")):
        a.set_xlabel("t (ms)")
        a.grid(alpha=0.3)
        a.legend(fontsize=7, loc=where)
    fig.suptitle("Coarse 1/6 sector, FSI-MHGO (c0 20 m/s, dp 0.9 mm, 13 us window) against FE-only", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("run", type=Path)
    p.add_argument("--label", default="", help="legend label of RUN")
    p.add_argument("--also", type=Path, nargs="*", default=[], help="more FSI runs drawn beside RUN")
    p.add_argument("--also-labels", nargs="*", default=[])
    p.add_argument("--fe-only", type=Path)
    p.add_argument("--png", type=Path)
    p.add_argument("--json", type=Path)
    a = p.parse_args(argv)
    fsi = {"solid": solid_metrics(a.run), "fluid": fluid_metrics(a.run), "label": a.label}
    others = [{"solid": solid_metrics(r), "label": (a.also_labels + [str(r)] * len(a.also))[i]}
              for i, r in enumerate(a.also)]
    fe = solid_metrics(a.fe_only) if a.fe_only else None
    s = summary(fsi, fe)
    print(json.dumps(s, indent=1))
    so = fsi["solid"]
    for ms in (10, 20, 25, 30, 35, 40, 45, 50, 60, 70, 80, 90, 100):
        k = np.searchsorted(so["time_s"], ms * 1e-3)
        if k < so["time_s"].size:
            print(f"  {ms:3d} ms: free-edge radius {so['radius_m'][k] * 1e3:.2f} mm")
    for t, g, e, st in zip(so["snapshot_time_s"], so["goa_m2"], so["strain_p99"], so["stress_p99_Pa"]):
        print(f"  snapshot {t * 1e3:6.1f} ms: GOA {g * 1e4:.3f} cm^2, strain p99 {e:.3f}, stress p99 {st / 1e6:.3f} MPa")
    if a.png:
        plot(fsi, fe, a.png, others)
    if a.json:
        a.json.write_text(json.dumps(s, indent=1) + "\n")


if __name__ == "__main__":
    main()
