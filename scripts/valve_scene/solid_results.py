"""Reads a solid_fe run's output folder: solid_series.h5 (time series, monitored nodes) and
solid_fields.h5 (snapshots of positions and element fields), as written by
solid_fe/src/solid_output.cpp."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np


@dataclass
class SolidSeries:
    time: np.ndarray                       # [samples] (s)
    midpoint_positions: np.ndarray         # [samples, midpoints, 3] (m)
    transvalvular_pressure_Pa: np.ndarray  # [samples]
    energy_balance_error: np.ndarray       # [samples] relative


def read_series(run_dir: Path, monitor: str = "free_edge_midpoints") -> SolidSeries:
    path = Path(run_dir) / "solid_series.h5"
    if not path.exists():
        raise FileNotFoundError(f"{path}: no solid series (did the run start?)")
    with h5py.File(path, "r") as f:
        name = f"monitor/{monitor}/position"
        if name not in f:
            raise KeyError(f"{path}: no dataset '/{name}'; monitored sets: {list(f.get('monitor', {}))}")

        def column(key):
            return f[key][()] if key in f else np.full(len(f["time"]), np.nan)

        return SolidSeries(f["time"][()], f[name][()], column("transvalvular_pressure_Pa"),
                           column("energy/relative_balance_error"))


class SolidFields:
    """Lazy access to the snapshots of solid_fields.h5."""

    def __init__(self, run_dir: Path):
        self.path = Path(run_dir) / "solid_fields.h5"
        if not self.path.exists():
            raise FileNotFoundError(f"{self.path}: no field snapshots (run.snapshot_interval = 0?)")
        with h5py.File(self.path, "r") as f:
            self.reference_nodes = f["mesh/nodes"][()]
            self.triangles = f["mesh/triangles"][()]
            names = sorted(f["snapshots"])
            self.names = names
            self.times = np.array([float(f["snapshots"][n].attrs["time"]) for n in names])

    def snapshot(self, index: int) -> dict:
        with h5py.File(self.path, "r") as f:
            g = f["snapshots"][self.names[index]]
            return {key: g[key][()] for key in ("position", "max_principal_stress", "max_principal_log_strain") if key in g}

    def nearest(self, time: float) -> int:
        return int(np.argmin(np.abs(self.times - time)))
