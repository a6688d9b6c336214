"""The prescribed-motion sector run (docs/thin-leaflet.md "Session 7"): force on the half
leaflet and its power per window (coupler's coupling_series.h5), put-backs and leaks
(fluid_probes.h5), and per particle snapshot the fastest fluid particle and the pressure range
of the fluid within 2 dp of the leaflet's plane of motion (the tube's core, r < 11.5 mm,
0 < z < 15 mm).

    HDF5_USE_FILE_LOCKING=FALSE /usr/bin/python3 prescribed_sector_report.py RUN_OUT [--png FIG]
"""
import argparse
from pathlib import Path

import h5py
import numpy as np

FLUID = 0   # Kind::fluid in fluid_particles.h5


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("run", type=Path)
    p.add_argument("--png", type=Path)
    a = p.parse_args(argv)
    with h5py.File(a.run / "coupling_series.h5", "r") as f:
        t, F, P = f["time"][()], f["force_fluid"][()], f["power_fluid"][()]
    dt = np.diff(np.concatenate([[0.0], t]))
    print(f"windows {len(t)}, to {t[-1] * 1e3:.2f} ms; largest |F| on the half leaflet {np.linalg.norm(F, axis=1).max():.3f} N "
          f"at {t[np.argmax(np.linalg.norm(F, axis=1))] * 1e3:.2f} ms; work of the fluid on the leaflet {np.sum(P * dt):.4e} J")
    for ms in (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15):
        k = np.searchsorted(t, ms * 1e-3 - 1e-9)
        if k < len(t):
            print(f"  {ms:2d} ms: F = ({F[k, 0]:+.3f}, {F[k, 1]:+.3f}, {F[k, 2]:+.3f}) N, power {P[k]:+.3e} W")
    probes = a.run / "fluid_probes.h5"
    if probes.exists():
        with h5py.File(probes, "r") as f:
            print(f"put-backs {int(f['interface/corrections'][-1])}, leaks {int(f['interface/leaks'][-1])}, "
                  f"lost {int(f['lost_particles'][-1])} (series to {f['time'][-1] * 1e3:.2f} ms)")
    with h5py.File(a.run / "fluid_particles.h5", "r") as f:
        for name in sorted(f):
            g = f[name]
            fluid = g["kind"][()] == FLUID
            x, v, pr = g["position"][()][fluid], g["velocity"][()][fluid], g["pressure"][()][fluid]
            r = np.hypot(x[:, 0], x[:, 1])
            core = (r < 11.5e-3) & (x[:, 2] > 0) & (x[:, 2] < 15e-3)
            speed = np.linalg.norm(v, axis=1)
            k = np.argmax(speed)
            print(f"  snapshot {g.attrs['time'] * 1e3:5.2f} ms: fastest {speed[k]:.2f} m/s at r {r[k] * 1e3:.1f} mm z {x[k, 2] * 1e3:.1f} mm; "
                  f"valve region pressure {pr[core].min() / 1e3:+.2f} .. {pr[core].max() / 1e3:+.2f} kPa "
                  f"(p1 {np.percentile(pr[core], 1) / 1e3:+.2f}, p99 {np.percentile(pr[core], 99) / 1e3:+.2f})")
    if a.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
        for d, n in enumerate("xyz"):
            ax[0].plot(t * 1e3, F[:, d], lw=0.8, label=f"F{n}")
        ax[0].plot(t * 1e3, np.linalg.norm(F, axis=1), "k", lw=0.8, label="|F|")
        ax[0].set_ylabel("fluid force on the half leaflet (N)")
        ax[1].plot(t * 1e3, P, "r", lw=0.8)
        ax[1].set_ylabel("power of the fluid on the leaflet (W)")
        for x in ax:
            x.set_xlabel("t (ms)")
            x.grid(alpha=0.3)
        ax[0].legend(fontsize=7)
        fig.suptitle("coarse sector, leaflet opened 1-6 ms, held, closed 8-13 ms (prescribed)", fontsize=10)
        fig.tight_layout()
        fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
