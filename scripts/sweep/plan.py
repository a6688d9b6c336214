"""A sweep specification -> the list of runs, and the running of them one at a time.

Specification (a preset in presets.py, or a JSON file with the same keys):
    scene       "valve2d" | "case"                      (scenes.py)
    end_time    simulated end time (s) of every run
    span        what the span covers, printed with every table ("opening only, 0-120 ms")
    base        axis -> value shared by every run
    grid        axis -> [values]: the Cartesian product, group "grid"
    runs        [{"group": name, "setting": {axis: value}}]: extra runs by group
    finest      axis -> value of the run the others are measured against (optional: else the
                completed run that cost the most CPU)
    wall_limit_s  a run still going after this is stopped (class `timeout`)
Runs are identified by their full setting (base + own axes), so a setting that appears in two
groups runs once. Results: OUTPUT/<label>/result.json (a finished label is not run again).
"""
from __future__ import annotations

import itertools
import json
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from . import metrics as metrics_module
from . import outcome as outcome_module
from . import runner, scenes


@dataclass
class PlannedRun:
    setting: dict
    groups: list = field(default_factory=list)

    @property
    def label(self) -> str:
        return scenes.setting_label(self.setting)


def expand(spec: dict) -> list[PlannedRun]:
    base = dict(spec.get("base", {}))
    planned: dict[str, PlannedRun] = {}

    def add(setting: dict, group: str):
        full = {**base, **setting}
        run = PlannedRun(full, [group])
        if run.label in planned:
            if group not in planned[run.label].groups:
                planned[run.label].groups.append(group)
        else:
            planned[run.label] = run

    grid = spec.get("grid", {})
    if grid:
        axes = list(grid)
        for values in itertools.product(*(grid[a] for a in axes)):
            add(dict(zip(axes, values)), "grid")
    for entry in spec.get("runs", []):
        add(dict(entry["setting"]), entry.get("group", "runs"))
    return list(planned.values())


def finest_label(spec: dict) -> str | None:
    if "finest" not in spec:
        return None
    return scenes.setting_label({**spec.get("base", {}), **spec["finest"]})


def git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=runner.REPO, capture_output=True,
                              text=True).stdout.strip()
    except OSError:
        return ""


def scene_source() -> dict:
    """The generator's state the runs used: commit and whether scripts/valve_scene differs from it
    (the scene may change under a running sweep's feet; results say which version they saw)."""
    import hashlib
    folder = runner.REPO / "scripts" / "valve_scene"
    digest = hashlib.sha1(b"".join(p.read_bytes() for p in sorted(folder.glob("*.py")))).hexdigest()[:12]
    try:
        dirty = subprocess.run(["git", "status", "--porcelain", "--", str(folder)], cwd=runner.REPO,
                               capture_output=True, text=True).stdout.strip() != ""
    except OSError:
        dirty = None
    return {"commit": git_commit(), "valve_scene_sha1": digest, "valve_scene_modified": dirty}


def execute(spec: dict, output: Path, build_dir: Path, only: str | None = None, dry_run: bool = False,
            rerun: bool = False, log=print) -> list[dict]:
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    (output / "spec.json").write_text(json.dumps(spec, indent=1) + "\n")
    results = []
    planned = expand(spec)
    source = scene_source()   # when the generator is first imported below
    for index, run in enumerate(planned):
        if only and only not in run.label:
            continue
        work = output / run.label
        result_path = work / "result.json"
        if result_path.exists() and not rerun:
            log(f"sweep: [{index + 1}/{len(planned)}] {run.label}: done before, kept")
            results.append(json.loads(result_path.read_text()))
            continue
        case = scenes.write_case(spec["scene"], run.setting, work, spec["end_time"])
        if dry_run:
            log(f"sweep: [{index + 1}/{len(planned)}] {run.label}: case {case} (dry run)")
            continue
        log(f"sweep: [{index + 1}/{len(planned)}] {run.label}: running ({time.strftime('%H:%M:%S')})")
        run_dir = work / "run"
        cost = runner.run_case(case, run_dir, build_dir, work / "launcher.log", spec.get("wall_limit_s"))
        material = str(run.setting.get("material", "MHGO"))
        measured, ending = measure(run_dir, work, spec["scene"], run.setting, spec["end_time"], cost.exit_code,
                                   cost.timed_out)
        result = {"label": run.label, "groups": run.groups, "setting": run.setting, "scene": spec["scene"],
                  "end_time": spec["end_time"], "span": spec.get("span", ""), "material": material,
                  "cost": cost, "core_hours": cost.core_hours, "outcome": ending, "metrics": measured,
                  "reference_errors": metrics_module.reference_errors(measured, material),
                  "commit": git_commit(), "scene_source": source, "finished_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime())}
        runner.save_json(result_path, result)
        results.append(json.loads(result_path.read_text()))
        log(f"sweep: {run.label}: {ending.kind} at t = {ending.reached_s} s, wall {cost.wall_s:.1f} s, "
            f"CPU {cost.cpu_s:.1f} s {('(' + ending.detail + ')') if ending.detail else ''}")
    return results


def measure(run_dir: Path, work: Path, scene: str, setting: dict, end_time: float, exit_code: int,
            timed_out: bool) -> tuple[dict, outcome_module.Outcome]:
    """Headline metrics and the ending of a finished run folder."""
    material = str(setting.get("material", "MHGO"))
    measured = metrics_module.run_metrics(run_dir, dimension=2 if scene == "valve2d" else 3, material=material)
    ending = outcome_module.classify(run_dir, exit_code, end_time, timed_out, launcher_log=work / "launcher.log",
                                     leaks=measured.get("leaks"), max_edge_speed=measured.get("max_edge_speed"),
                                     edge_speed_at=((measured["max_edge_speed_time"], measured["max_edge_speed_where_mm"])
                                                    if "max_edge_speed_where_mm" in measured else None))
    # what a failed run left to restart from or to look at (docs/stability-map.md's last column)
    measured["last_written"] = outcome_module.last_written(run_dir)
    return measured, ending


def load_results(output: Path, refresh: bool = False) -> list[dict]:
    """The results of a sweep folder; with `refresh`, metrics and endings are derived again from
    the run folders (after a change of their definitions; the costs are kept)."""
    results = []
    for path in sorted(Path(output).glob("*/result.json")):
        r = json.loads(path.read_text())
        if refresh and (path.parent / "run").is_dir():
            measured, ending = measure(path.parent / "run", path.parent, r["scene"], r["setting"], r["end_time"],
                                       r["cost"]["exit_code"], r["cost"]["timed_out"])
            r.update(metrics=measured, outcome=json.loads(json.dumps(ending, default=runner._jsonable)),
                     reference_errors=metrics_module.reference_errors(measured, r.get("material", "MHGO")))
            runner.save_json(path, r)
        results.append(r)
    return results
