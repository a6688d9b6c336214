#!/usr/bin/python3
"""Run one case: the coupler, the fluid (under mpirun when asked) and the solid, from one file.

    /usr/bin/python3 scripts/run_case.py CASE [--output DIR] [--fluid-ranks N] [--fe-only]
        [--fluid-exe PATH] [--solid-exe PATH] [--coupler-exe PATH] [--build-dir DIR] [--grace S]
        [--restart RUN/restart] [--resume]

Each program is started as `<executable> <case arguments...> --case CASE --output DIR` (the
solid also gets `--fe-only` with --fe-only), with VALVEFSI_COUPLER_ENDPOINT set so that all
three meet at the same socket. Executables come from the case's `coupling` part, else the
build tree's `fluid_sph`, `solid_fe`, `coupler`; --*-exe overrides both, so a solver can be
swapped without editing the case. A bare name is looked up in the build tree, then on PATH.

Each program's output goes to DIR/<name>.log and to the terminal prefixed with [coupler],
[fluid] or [solid]. When one program fails, the others get SIGTERM (and SIGCONT, in case they
are stopped), then SIGKILL after the grace period; the launcher exits with the failing
program's code (128 + signal for a signal). SIGINT/SIGTERM to the launcher stop them all.
The case is read by the coupler's own loader (`coupler --describe-launch`), so a bad case is
reported exactly as the programs would report it.

--resume makes a run of hours one command however often it is interrupted: into an empty or new
DIR the run goes as usual; into a DIR that holds a run, the run continues from the newest restart
point as a new segment, DIR/segments/NN (the first time, what DIR held becomes DIR/segments/01),
and when it ends (finished, failed or stopped) all segments are joined into DIR's series files,
which the analysis reads (valve_scene.join_segments; the segments keep their logs, particle
snapshots and restart points).
"""

import argparse
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_PROGRAMS = {"fluid": "fluid_sph", "solid": "solid_fe", "coupler": "coupler"}
ENDPOINT_VARIABLE = "VALVEFSI_COUPLER_ENDPOINT"


# Exit code of a program that stopped because a peer aborted the run (coupler/transport).
EXIT_ABORTED_BY_PEER = 5
# Seconds the launcher waits after a failure for the others to relay it and end.
RELAY_SETTLE_S = 2.0


def fail(message, code=2):
    print(f"run_case: {message}", file=sys.stderr, flush=True)
    sys.exit(code)


def find_executable(name, build_dir, role):
    """A path with a '/' is used as is; a bare name is searched in the build tree, then PATH."""
    if "/" in name:
        path = Path(name)
        if not (path.is_file() and os.access(path, os.X_OK)):
            fail(f"{role} executable '{name}' does not exist or is not executable")
        return str(path.resolve())
    if build_dir.is_dir():
        def in_nested_build_tree(path):
            # another CMake build tree inside this one (e.g. build/clean/) is not this build
            return any((parent / "CMakeCache.txt").is_file()
                       for parent in path.parents if parent != build_dir and build_dir in parent.parents)
        found = [c for c in build_dir.rglob(name)
                 if c.is_file() and os.access(c, os.X_OK) and "CMakeFiles" not in c.parts and not in_nested_build_tree(c)]
        if found:
            return str(min(found, key=lambda c: (len(c.parts), str(c))))
    found = shutil.which(name)
    if found:
        return found
    fail(f"{role} executable '{name}' not found in the build tree {build_dir} nor on PATH "
         f"(build it, or pass --{role}-exe PATH)")


def launch_plan(coupler, case_file, output_dir=None):
    command = [coupler, "--case", str(case_file), "--describe-launch"]
    if output_dir is not None:
        command += ["--output", str(output_dir)]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.stderr.write(result.stdout + result.stderr)
        fail(f"the case {case_file} cannot be used (see above)", result.returncode)
    return json.loads(result.stdout.strip().splitlines()[-1])


class Program:
    """One child process (its own process group) whose output is prefixed and logged."""

    def __init__(self, role, command, log_path, environment):
        self.role = role
        self.command = command
        self.log = open(log_path, "w", buffering=1)
        self.log.write("# " + " ".join(command) + "\n")
        self.process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        stdin=subprocess.DEVNULL, env=environment, start_new_session=True)
        self.reader = threading.Thread(target=self._pump, daemon=True)
        self.reader.start()
        # When it ended, to tell the cause (the first to fail) from its consequences.
        self.ended_at = None
        self.waiter = threading.Thread(target=self._wait, daemon=True)
        self.waiter.start()

    def _wait(self):
        self.process.wait()
        self.ended_at = time.monotonic()

    def _pump(self):
        for raw in iter(self.process.stdout.readline, b""):
            line = raw.decode("utf-8", "replace")
            self.log.write(line)
            # A program that already tags its lines with its role is not tagged twice.
            tag = f"[{self.role}] "
            sys.stdout.write(line if line.startswith(tag) else tag + line)
            sys.stdout.flush()

    def exit_code(self):
        if self.ended_at is None:
            return None
        code = self.process.returncode
        return 128 - code if code < 0 else code

    def signal_group(self, sig):
        try:
            os.killpg(self.process.pid, sig)
        except ProcessLookupError:
            pass

    def close(self):
        self.reader.join(timeout=2)
        self.log.close()


def stop_all(programs, grace):
    running = [p for p in programs if p.exit_code() is None]
    for program in running:
        program.signal_group(signal.SIGTERM)
        program.signal_group(signal.SIGCONT)  # a stopped process only sees SIGTERM once continued
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and any(p.exit_code() is None for p in running):
        time.sleep(0.05)
    for program in running:
        if program.exit_code() is None:
            print(f"run_case: {program.role} did not stop within {grace} s; killing it", file=sys.stderr, flush=True)
            program.signal_group(signal.SIGKILL)
    for program in running:
        program.waiter.join()


def write_run_record(output_dir: Path, wall_s: float, exit_code: int, restart: Path | None) -> None:
    """OUTPUT/wall_time.json: what the run cost (every run reports its wall time; the comparison
    and join_segments read it). CPU time is the programs' (the launcher reaps them)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    record = {"wall_time_s": round(wall_s, 3), "exit_code": exit_code,
              "cpu_time_s": round(children.ru_utime + children.ru_stime, 3),
              "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    if restart:
        record["restart_from"] = str(restart.resolve())
    try:
        (output_dir / "wall_time.json").write_text(json.dumps(record, indent=1) + "\n")
    except OSError as error:  # the results matter more than their cost record
        print(f"run_case: could not write {output_dir / 'wall_time.json'}: {error}", file=sys.stderr, flush=True)


SEGMENTS_DIR = "segments"
# What a join writes at the top of a resumed run's folder (valve_scene.join_segments), removed
# before the next segment runs and written again after it.
JOINED_FILES = ("solid_series.h5", "coupling_series.h5", "fluid_probes.h5", "solid_fields.h5", "segments.json",
                "wall_time.json")


def segment_folders(run_dir: Path) -> list[Path]:
    folder = run_dir / SEGMENTS_DIR
    if not folder.is_dir():
        return []
    return sorted((p for p in folder.iterdir() if p.is_dir() and p.name.isdigit()), key=lambda p: int(p.name))


def prepare_resume(run_dir: Path) -> tuple[Path, Path | None]:
    """The folder the resumed run writes to and the restart point it continues from: (RUN, None)
    when RUN holds no run yet; else a new RUN/segments/NN and the newest segment's restart/."""
    if not run_dir.exists() or not any(run_dir.iterdir()):
        return run_dir, None
    segments = segment_folders(run_dir)
    if not segments:
        first = run_dir / SEGMENTS_DIR / "01"
        if not (run_dir / "restart" / "LATEST").is_file():
            fail(f"--resume: '{run_dir}' holds no restart point (restart/LATEST; the case's "
                 "coupling.restart_interval_s or solid.restart_interval_s writes them): nothing to continue from. "
                 "Remove the folder, or run without --resume into another one, to start again")
        first.mkdir(parents=True)
        for entry in list(run_dir.iterdir()):
            if entry.name != SEGMENTS_DIR:
                entry.rename(first / entry.name)
        segments = [first]
    else:
        for name in JOINED_FILES:  # the last join's output: written again from the segments
            (run_dir / name).unlink(missing_ok=True)
    with_restart = [s for s in segments if (s / "restart" / "LATEST").is_file()]
    if not with_restart:
        fail(f"--resume: no segment of '{run_dir}' holds a restart point (restart/LATEST): nothing to continue from")
    # Segments stopped before their first restart point are redone by the new one from the same
    # point: kept, renamed out of the join (it needs segments that start one after the other).
    for dead_end in segments[segments.index(with_restart[-1]) + 1:]:
        dead_end.rename(dead_end.with_name(dead_end.name + "-superseded"))
    return run_dir / SEGMENTS_DIR / f"{int(segments[-1].name) + 1:02d}", with_restart[-1] / "restart"


def join_resumed_run(run_dir: Path) -> None:
    """Joins RUN's segments into RUN's series files; a failure leaves the segments as they are."""
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        from valve_scene.join_segments import JoinError, join
        report = join(segment_folders(run_dir), run_dir)
    except (ImportError, JoinError, OSError) as error:
        print(f"run_case: could not join the segments of {run_dir} ({error}); each segment's output is kept in "
              f"{run_dir / SEGMENTS_DIR}", file=sys.stderr, flush=True)
        return
    print("run_case: segments joined into " + str(run_dir) + ":\n  " + "\n  ".join(report.lines()), flush=True)


def main():
    started_at = time.monotonic()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", type=Path, help="case file (cases/*.textproto)")
    parser.add_argument("--output", type=Path, help="output folder (default: the case's run.output_dir)")
    parser.add_argument("--fluid-ranks", type=int, default=1, help="MPI ranks of the fluid (mpirun -np N when N > 1)")
    parser.add_argument("--fe-only", action="store_true", help="run only the solid, under the case's uniform pressure")
    parser.add_argument("--fluid-exe", help="fluid program (overrides the case)")
    parser.add_argument("--solid-exe", help="solid program (overrides the case)")
    parser.add_argument("--coupler-exe", help="coupler program (overrides the case)")
    parser.add_argument("--build-dir", type=Path, default=REPO / "build", help="where bare program names are found")
    parser.add_argument("--restart", type=Path,
                        help="continue from restart data: a run's restart/ folder or one restart/t_<time>/ folder "
                             "(the case's coupling.restart_interval_s writes them)")
    parser.add_argument("--resume", action="store_true",
                        help="continue the run in --output from its newest restart point as a new segment and join "
                             "the segments (a new or empty folder: start the run)")
    parser.add_argument("--grace", type=float, default=5.0, help="seconds between SIGTERM and SIGKILL when stopping")
    args = parser.parse_args()

    if not args.case.is_file():
        fail(f"case file '{args.case}' does not exist")
    if args.fluid_ranks < 1:
        fail(f"--fluid-ranks = {args.fluid_ranks}: allowed >= 1")
    if args.resume and args.restart:
        fail("--resume finds its restart point itself: give --resume or --restart, not both")
    case_file = args.case.resolve()
    build_dir = args.build_dir.resolve()
    coupler = find_executable(args.coupler_exe or DEFAULT_PROGRAMS["coupler"], build_dir, "coupler")
    # Relative output folders (the case's or --output) are relative to where the launcher runs.
    output_dir = (args.output or Path(launch_plan(coupler, case_file)["output_dir"])).resolve()
    run_dir = output_dir
    if args.resume:
        output_dir, args.restart = prepare_resume(run_dir)
        if args.restart:
            print(f"run_case: resuming {run_dir} from {args.restart} as segment {output_dir.name}", flush=True)
    plan = launch_plan(coupler, case_file, output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    if not args.coupler_exe and plan["coupler"]["executable"]:
        coupler = find_executable(plan["coupler"]["executable"], build_dir, "coupler")

    environment = dict(os.environ)
    environment[ENDPOINT_VARIABLE] = plan["endpoint"]
    # Threads that spin while their partner is descheduled cost up to 7x on a shared 2-core machine
    # (measured: the full valve's first 10.8 ms took 71 s of CPU on 2 spinning threads, 10 s on
    # one); the user's own setting wins.
    environment.setdefault("OMP_WAIT_POLICY", "passive")
    common = ["--case", str(case_file), "--output", str(output_dir)]
    fe_only = args.fe_only or plan["fe_only"]

    def command_for(role, override):
        name = override or plan[role]["executable"] or DEFAULT_PROGRAMS[role]
        return [find_executable(name, build_dir, role)] + plan[role]["arguments"] + common

    commands = []
    restart = ["--restart", str(args.restart.resolve())] if args.restart else []
    if not fe_only:
        commands.append(("coupler", [coupler] + common + restart))
    solid = command_for("solid", args.solid_exe)
    # FE-only: the solid reads its own restart point (a full-valve cycle takes hours); coupled: the
    # coupler hands it to every participant
    commands.append(("solid", solid + (["--fe-only"] + restart if fe_only else [])))
    if not fe_only:
        fluid = command_for("fluid", args.fluid_exe)
        if args.fluid_ranks > 1:
            mpirun = ["mpirun", "-np", str(args.fluid_ranks)]
            if os.geteuid() == 0:
                mpirun.append("--allow-run-as-root")
            if args.fluid_ranks > (os.cpu_count() or 1):
                mpirun.append("--oversubscribe")
            fluid = mpirun + fluid
        commands.append(("fluid", fluid))

    programs = []
    interrupted = []

    def on_signal(signum, _frame):
        interrupted.append(signum)

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    print(f"run_case: {case_file.name} -> {output_dir} ({'FE-only' if fe_only else plan['endpoint']})", flush=True)
    for role, command in commands:
        programs.append(Program(role, command, output_dir / f"{role}.log", environment))

    exit_code = 0
    while True:
        if interrupted:
            print(f"run_case: {signal.Signals(interrupted[0]).name} received; stopping everything", file=sys.stderr,
                  flush=True)
            stop_all(programs, args.grace)
            exit_code = 128 + interrupted[0]
            break
        failed = [p for p in programs if p.exit_code() not in (None, 0)]
        if failed:
            # The others relay a failure within moments (Abort, exit 5): let them end, then name
            # the one that did not merely relay it; a relay can exit before its origin.
            settle_until = time.monotonic() + min(args.grace, RELAY_SETTLE_S)
            while time.monotonic() < settle_until and any(p.exit_code() is None for p in programs):
                time.sleep(0.05)
            failed = [p for p in programs if p.exit_code() not in (None, 0)]
            origins = [p for p in failed if p.exit_code() != EXIT_ABORTED_BY_PEER] or failed
            first = min(origins, key=lambda p: p.ended_at)
            exit_code = first.exit_code()
            others = [p.role for p in programs if p is not first and p.exit_code() is None]
            print(f"run_case: {first.role} failed with exit code {exit_code}"
                  + (f"; stopping {', '.join(others)}" if others else ""), file=sys.stderr, flush=True)
            stop_all(programs, args.grace)
            break
        if all(p.exit_code() == 0 for p in programs):
            break
        time.sleep(0.05)
    for program in programs:
        program.close()
    wall_s = time.monotonic() - started_at
    write_run_record(output_dir, wall_s, exit_code, args.restart)
    if exit_code == 0:
        print(f"run_case: finished in {wall_s:.1f} s wall time; logs and results in {output_dir}", flush=True)
    else:
        print(f"run_case: stopped after {wall_s:.1f} s wall time", file=sys.stderr, flush=True)
    if output_dir != run_dir:
        join_resumed_run(run_dir)
    sys.exit(exit_code)


if __name__ == "__main__":
    main()
