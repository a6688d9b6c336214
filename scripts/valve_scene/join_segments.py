"""Join the output of a run continued from restarts into one run folder the analysis reads.

    cd scripts && /usr/bin/python3 -m valve_scene.join_segments SEGMENT_DIR [SEGMENT_DIR ...] --output JOINED_DIR

A long coupled run is a chain of segments: each started with `run_case.py --restart` from a
restart point of the one before, in its own output folder. The report tools (`run_report`,
`hemodynamics`, `fsi3d_metrics.py`) read one folder, so this writes one: for every time series
file of the programs (`solid_series.h5`, `coupling_series.h5`, `fluid_probes.h5`) and the solid's
field snapshots (`solid_fields.h5`), segment k contributes its samples before the first sample of
segment k + 1 (the later segment wins: it is the run that went on), in the order given. A series
dataset is one whose first axis matches the `time` dataset of its own group or of a parent group;
everything else (meshes, attributes) is taken from the last segment that has it. The fluid's
particle snapshots are not joined (too large; open each segment's .xmf): the joined folder lists
its segments in `segments.json`, where the report tools find them.

A segment stopped by a signal may have lost the samples it had not yet flushed; the gap between
its last sample and the next segment's first is reported, never filled.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from .launch import RECORD, read_cost

SERIES_FILES = ("solid_series.h5", "coupling_series.h5", "fluid_probes.h5")
SEGMENTS_FILE = "segments.json"   # the joined folder's list of its segments (for their particle snapshots)
SNAPSHOT_FILE = "solid_fields.h5"
GAP_FACTOR = 3.0  # a jump longer than this many median sample intervals is reported as a gap


class JoinError(ValueError):
    pass


@dataclass
class JoinReport:
    files: dict = field(default_factory=dict)   # file name -> (samples, first time, last time)
    gaps: list = field(default_factory=list)    # (file, from time, to time)
    notes: list = field(default_factory=list)   # the cost record's fate

    def lines(self) -> list[str]:
        out = [f"{name}: {n} samples, {a:.6g}-{b:.6g} s" for name, (n, a, b) in self.files.items()]
        out += [f"gap in {name}: no samples between {a:.6g} s and {b:.6g} s" for name, a, b in self.gaps]
        out += self.notes
        return out


def _clock_of(path: str, datasets: dict) -> str | None:
    """The `time` dataset of path's group or the nearest parent group whose length matches."""
    n = datasets[path].shape[0] if datasets[path].shape else None
    if n is None:
        return None
    parts = path.split("/")[:-1]
    while True:
        candidate = "/".join(parts + ["time"])
        if candidate in datasets and datasets[candidate].shape == (n,):
            return candidate
        if not parts:
            return None
        parts = parts[:-1]


def _datasets(f: h5py.File) -> dict:
    found = {}
    f.visititems(lambda name, obj: found.__setitem__(name, obj) if isinstance(obj, h5py.Dataset) else None)
    return found


def _copy_attrs(src, dst) -> None:
    for key, value in src.attrs.items():
        dst.attrs[key] = value


def join_series(paths: list[Path], out: Path, report: JoinReport) -> None:
    files = [h5py.File(p, "r") for p in paths]
    try:
        tables = [_datasets(f) for f in files]
        clocks = {}
        for table in tables:
            for name in table:
                clock = _clock_of(name, table)
                if clock is not None:
                    clocks.setdefault(name, clock)
        for clock in set(clocks.values()):
            starts = [(float(t[clock][0]), paths[k]) for k, t in enumerate(tables) if clock in t and t[clock].shape[0] > 0]
            for (a, pa), (b, pb) in zip(starts, starts[1:]):
                if b <= a:
                    raise JoinError(f"'{pb}' starts at {b:g} s, not after '{pa}' ({a:g} s): give the segments "
                                    f"earliest first ('{clock}' in {out.name})")
        with h5py.File(out, "w") as joined:
            _copy_attrs(files[-1], joined)
            names = list(dict.fromkeys(name for table in tables for name in table))
            for name in names:
                clock = clocks.get(name)
                if clock is None:  # not a series: the last segment's version
                    last = next(t for t in reversed(tables) if name in t)
                    joined.create_dataset(name, data=last[name][()])
                    _copy_attrs(last[name], joined[name])
                    continue
                pieces = []
                for k, table in enumerate(tables):
                    if name not in table:
                        continue
                    t = table[clock][()]
                    keep = np.ones(t.shape, dtype=bool)
                    later = [tl[clock][()] for tl in tables[k + 1:] if clock in tl and tl[clock].shape[0] > 0]
                    if later:
                        keep = t < later[0][0]
                    pieces.append(table[name][()][keep])
                data = np.concatenate(pieces, axis=0) if pieces else np.empty((0,))
                joined.create_dataset(name, data=data, maxshape=(None,) + data.shape[1:], chunks=True)
                _copy_attrs(next(t for t in reversed(tables) if name in t)[name], joined[name])
            for name in set(clocks.values()):
                t = joined[name][()]
                label = f"{out.name}:{name}"
                if t.size:
                    report.files[label] = (t.size, float(t[0]), float(t[-1]))
                if t.size > 2:
                    steps = np.diff(t)
                    if np.any(steps <= 0):
                        raise JoinError(f"{out}: joined '{name}' is not increasing: the segments are out of "
                                        f"order or overlap wrongly ({', '.join(map(str, paths))})")
                    typical = float(np.median(steps))
                    for i in np.nonzero(steps > GAP_FACTOR * typical)[0]:
                        report.gaps.append((label, float(t[i]), float(t[i + 1])))
    finally:
        for f in files:
            f.close()


def join_snapshots(paths: list[Path], out: Path, report: JoinReport) -> None:
    files = [h5py.File(p, "r") for p in paths]
    try:
        times = []
        for f in files:
            groups = f["snapshots"] if "snapshots" in f else {}
            times.append([(float(groups[n].attrs["time"]), n) for n in sorted(groups) if "time" in groups[n].attrs])
        with h5py.File(out, "w") as joined:
            last_with_mesh = next(f for f in reversed(files) if "mesh" in f)
            last_with_mesh.copy("mesh", joined)
            _copy_attrs(files[-1], joined)
            snapshots = joined.create_group("snapshots")
            index = 0
            for k, f in enumerate(files):
                later = [ts[0][0] for ts in times[k + 1:] if ts]
                for t, name in times[k]:
                    if later and t >= later[0]:
                        continue
                    f.copy(f"snapshots/{name}", snapshots, name=f"{index:06d}")
                    index += 1
            all_t = [t for k, ts in enumerate(times) for t, _ in ts]
            if all_t:
                report.files[f"{out.name}:snapshots"] = (index, min(all_t), max(all_t))
    finally:
        for f in files:
            f.close()


def join(segments: list[Path], output: Path) -> JoinReport:
    if len(segments) < 1:
        raise JoinError("give at least one segment folder")
    for s in segments:
        if not s.is_dir():
            raise JoinError(f"segment folder '{s}' does not exist")
    if output.resolve() in [s.resolve() for s in segments]:
        raise JoinError(f"--output '{output}' is one of the segments: write the joined run elsewhere")
    output.mkdir(parents=True, exist_ok=True)
    report = JoinReport()
    for name in SERIES_FILES + (SNAPSHOT_FILE,):
        present = [s / name for s in segments if (s / name).is_file()]
        if not present:
            continue
        if name == SNAPSHOT_FILE:
            join_snapshots(present, output / name, report)
        else:
            join_series(present, output / name, report)
    if not report.files:
        raise JoinError(f"none of {', '.join(SERIES_FILES + (SNAPSHOT_FILE,))} in {', '.join(map(str, segments))}")
    (output / SEGMENTS_FILE).write_text(json.dumps([str(s.resolve()) for s in segments], indent=1) + "\n")
    join_costs(segments, output, report)
    return report


def segments_of(run_dir: Path) -> list[Path]:
    """The segment folders a joined run was made from (empty for a run that was not joined)."""
    path = Path(run_dir) / SEGMENTS_FILE
    return [Path(s) for s in json.loads(path.read_text())] if path.is_file() else []


def join_costs(segments: list[Path], output: Path, report: JoinReport) -> None:
    """OUTPUT/wall_time.json: the segments' wall and CPU times summed (a segment's time past the
    next one's restart point included: it was spent), the last segment's exit code. Written only
    when every segment has its launcher's record; otherwise the report names those without."""
    costs = {s: read_cost(s) for s in segments}
    missing = [str(s) for s, cost in costs.items() if cost is None]
    if missing:
        report.notes.append(f"no cost record ({RECORD}) in {', '.join(missing)}: the joined run has none")
        return
    walls = [c.wall_time_s for c in costs.values()]
    cpus = [c.cpu_time_s for c in costs.values()]
    joined = {"wall_time_s": None if None in walls else sum(walls), "cpu_time_s": None if None in cpus else sum(cpus),
              "exit_code": costs[segments[-1]].exit_code, "segments": [str(s.resolve()) for s in segments]}
    (output / RECORD).write_text(json.dumps(joined, indent=1) + "\n")
    report.notes.append(f"wall time {joined['wall_time_s']} s, CPU time {joined['cpu_time_s']} s over {len(segments)} segments")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("segments", type=Path, nargs="+", help="segment output folders, earliest first")
    parser.add_argument("--output", type=Path, required=True, help="folder for the joined series")
    args = parser.parse_args(argv)
    try:
        report = join(args.segments, args.output)
    except (JoinError, OSError) as e:
        print(f"join_segments: {e}", file=sys.stderr)
        return 2
    print("\n".join(report.lines()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
