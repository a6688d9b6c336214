"""One run of a setting through scripts/run_case.py, with what it cost.

Cost: wall time of the launcher and the 1-minute load average at its start and end; CPU time (user + system) of all processes, exactly, from
wait4's resource usage of the launcher (which waits for each program, so their times are
included); per program, CPU time and peak resident memory (VmHWM) sampled from /proc every
`poll_s` while it runs (the last sample can miss up to `poll_s` of CPU; the total does not).
The programs run niced (`nice`), one OpenMP thread each unless `threads` says otherwise.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
LAUNCHER = REPO / "scripts" / "run_case.py"
ROLES = {"fluid_sph": "fluid", "solid_fe": "solid", "coupler": "coupler"}
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


@dataclass
class RunCost:
    exit_code: int
    wall_s: float
    cpu_s: float                                   # all processes, exact
    cpu_s_by_program: dict = field(default_factory=dict)     # sampled
    peak_rss_mb_by_program: dict = field(default_factory=dict)
    timed_out: bool = False
    # the machine's 1-minute load average when the run started and ended: on a shared machine the
    # wall time says little without it (CPU time is the stable measure)
    load_avg: tuple = (None, None)

    @property
    def core_hours(self) -> float:
        return self.cpu_s / 3600.0


def _process_table() -> dict:
    """pid -> (ppid, comm, cpu seconds) for every readable process."""
    table = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        # comm is in parentheses and may contain spaces; the fields after it are positional
        close = stat.rfind(")")
        comm = stat[stat.find("(") + 1:close]
        rest = stat[close + 2:].split()
        table[int(entry)] = (int(rest[1]), comm, (int(rest[11]) + int(rest[12])) / CLOCK_TICKS)
    return table


def _peak_rss_mb(pid: int) -> float | None:
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None


def _descendants(root: int, table: dict) -> list[int]:
    children = {}
    for pid, (ppid, _comm, _cpu) in table.items():
        children.setdefault(ppid, []).append(pid)
    found, stack = [], [root]
    while stack:
        for child in children.get(stack.pop(), []):
            found.append(child)
            stack.append(child)
    return found


def run_case(case: Path, output: Path, build_dir: Path, log_path: Path, wall_limit_s: float | None = None,
             threads: int = 1, nice: int = 5, poll_s: float = 0.5, extra_args: list[str] | None = None) -> RunCost:
    """Runs the launcher on `case` into `output`; its terminal output goes to `log_path`."""
    env = {**os.environ, "OMP_NUM_THREADS": str(threads), "OMP_WAIT_POLICY": "passive",
           "PYTHONDONTWRITEBYTECODE": "1"}
    command = ["nice", "-n", str(nice), sys.executable, str(LAUNCHER), str(case), "--output", str(output),
               "--build-dir", str(build_dir)] + (extra_args or [])
    cpu_by, rss_by = {}, {}
    timed_out = False
    load_start = os.getloadavg()[0]
    started = time.monotonic()
    with open(log_path, "w") as log:
        log.write("# " + " ".join(command) + "\n")
        log.flush()
        process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env,
                                   cwd=REPO)
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid == process.pid:
                break
            table = _process_table()
            for child in _descendants(process.pid, table):
                role = ROLES.get(table[child][1])
                if role is None:
                    continue
                cpu_by[role] = max(cpu_by.get(role, 0.0), table[child][2])
                rss = _peak_rss_mb(child)
                if rss is not None:
                    rss_by[role] = max(rss_by.get(role, 0.0), rss)
            if wall_limit_s is not None and not timed_out and time.monotonic() - started > wall_limit_s:
                timed_out = True
                process.send_signal(signal.SIGTERM)   # the launcher stops all three and flushes
            time.sleep(poll_s)
    process.returncode = os.waitstatus_to_exitcode(status)
    code = process.returncode if process.returncode >= 0 else 128 - process.returncode
    return RunCost(exit_code=code, wall_s=time.monotonic() - started, cpu_s=usage.ru_utime + usage.ru_stime,
                   cpu_s_by_program=cpu_by, peak_rss_mb_by_program=rss_by, timed_out=timed_out,
                   load_avg=(load_start, os.getloadavg()[0]))


def save_json(path: Path, data: dict) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=1, default=_jsonable) + "\n")
    tmp.replace(path)


def _jsonable(value):
    if hasattr(value, "__dataclass_fields__"):
        return asdict(value)
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
