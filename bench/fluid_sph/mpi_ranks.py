#!/usr/bin/python3
"""fluid_sph on 1 and 2 MPI ranks: CPU and wall seconds per step, particle updates per second.

Each rank count runs the case twice, to two end times; the difference removes the set-up
(every rank builds the whole scene before keeping its slab). CPU is the sum of the ranks'
user time (/usr/bin/time), so on a shared machine it is the fairer figure; wall time is
reported too. Example (docs/fluid_sph.md, "MPI"):

  /usr/bin/python3 bench/fluid_sph/mpi_ranks.py --fluid-sph build/fluid_sph/fluid_sph \
      --case fluid_sph/examples/tube_plates_3d.textproto --end-times 0.001 0.003 --ranks 1 2
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

DONE = re.compile(r"done, t = \S+ s in (\d+) steps, wall time ([0-9.]+) s")
PARTICLES = re.compile(r"(\d+) fluid \+ (\d+) wall particles")
USER = re.compile(r"rank user ([0-9.]+)")


def run(fluid_sph, case, end_time, ranks, threads, workdir):
    text = Path(case).read_text()
    text = re.sub(r"end_time:\s*[0-9.eE+-]+", f"end_time: {end_time}", text)
    text = re.sub(r"snapshot_interval:\s*[0-9.eE+-]+", "snapshot_interval: 0", text)
    case_file = Path(workdir) / f"case-{ranks}-{end_time}.textproto"
    case_file.write_text(text)
    command = ["/usr/bin/time", "-f", "rank user %U", fluid_sph, "--case", str(case_file), "--standalone",
               "--output", str(Path(workdir) / f"out-{ranks}-{end_time}"), "--threads", str(threads)]
    if ranks > 1:
        launcher = ["mpirun", "-np", str(ranks)]
        if os.geteuid() == 0:
            launcher.append("--allow-run-as-root")
        launcher.append("--oversubscribe")
        command = launcher + command
    environment = dict(os.environ, OMP_WAIT_POLICY="passive")
    result = subprocess.run(command, capture_output=True, text=True, env=environment)
    log = result.stdout + result.stderr
    done = DONE.search(log)
    if result.returncode != 0 or not done:
        sys.exit(f"run failed ({ranks} ranks, end {end_time}):\n{log[-2000:]}")
    particles = PARTICLES.search(log)
    users = [float(u) for u in USER.findall(log)]
    return {"steps": int(done.group(1)), "wall": float(done.group(2)), "cpu": sum(users),
            "particles": int(particles.group(1)) + int(particles.group(2))}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fluid-sph", required=True)
    parser.add_argument("--case", required=True)
    parser.add_argument("--end-times", type=float, nargs=2, required=True)
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--threads", type=int, default=1, help="OpenMP threads per rank")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    print(f"{Path(args.case).name}, {args.threads} thread(s) per rank, load average {load:.1f}")
    print("ranks | steps | CPU s/step (all ranks) | wall s/step | updates per CPU s | updates per wall s")
    with tempfile.TemporaryDirectory() as workdir:
        for ranks in args.ranks:
            short = run(args.fluid_sph, args.case, args.end_times[0], ranks, args.threads, workdir)
            long = run(args.fluid_sph, args.case, args.end_times[1], ranks, args.threads, workdir)
            steps = long["steps"] - short["steps"]
            cpu = (long["cpu"] - short["cpu"]) / steps
            wall = (long["wall"] - short["wall"]) / steps
            n = long["particles"]
            print(f"{ranks} | {steps} | {cpu:.4f} | {wall:.4f} | {n / cpu:.3g} | {n / wall:.3g}", flush=True)


if __name__ == "__main__":
    main()
