"""Running a case through scripts/run_case.py from the study tools, and reading what it cost.

run_case.py records every run's wall time, CPU time (its programs') and exit code in
OUTPUT/wall_time.json; the study tools (fe_study, comparison) run it as a subprocess and read that
record instead of timing the run themselves, so every table quotes the same numbers.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
RECORD = "wall_time.json"


@dataclass(frozen=True)
class RunCost:
    wall_time_s: float | None
    cpu_time_s: float | None
    exit_code: int | None


def read_cost(run_dir: Path) -> RunCost | None:
    """The run's cost record, or None when it has none (a run from before the record existed)."""
    path = Path(run_dir) / RECORD
    if not path.exists():
        return None
    record = json.loads(path.read_text())
    return RunCost(record.get("wall_time_s"), record.get("cpu_time_s"), record.get("exit_code"))


def launch(case: Path, output: Path, build_dir: Path, log_path: Path, fe_only: bool = False,
           one_thread: bool = False) -> RunCost:
    """Runs CASE into OUTPUT through the launcher, its console in LOG_PATH; returns its cost (the
    launcher's record, or the wall time measured here when the launcher died before writing it)."""
    command = [sys.executable, str(REPO / "scripts" / "run_case.py"), str(case), "--output", str(output),
               "--build-dir", str(build_dir)] + (["--fe-only"] if fe_only else [])
    env = dict(os.environ)
    if one_thread:
        env.update({"OMP_NUM_THREADS": "1", "OMP_WAIT_POLICY": "passive"})
    Path(output).mkdir(parents=True, exist_ok=True)
    (Path(output) / RECORD).unlink(missing_ok=True)   # a record left by an earlier run is not this one's
    Path(log_path).parent.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    with open(log_path, "w") as log:
        code = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=REPO).returncode
    return read_cost(output) or RunCost(time.monotonic() - start, None, code)
