#!/usr/bin/env bash
# Sets up (Debian packages), builds, generates the valve meshes and runs the default case: the
# coarse 2D MHGO valve's opening (0-80 ms), FE-only and FSI side by side (a few minutes on 2
# cores once built), then writes runs/default/opening.md and opening.png: each run's opening
# time against the reference study's and its wall time.
#   scripts/run-default.sh                 the default pair above
#   scripts/run-default.sh CASE [options]  any case file (launcher options after it); the 3D
#                                          FE-only sector opening is cases/default-fe-opening.textproto
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)
case_file=${1:-}
shift || true

bash scripts/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
# The meshes are generated, not stored (cases/meshes/ is git-ignored).
(cd scripts && /usr/bin/python3 -m valve_scene.write_cases > /dev/null)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Threads that spin while their partner is descheduled cost 5x on a shared 2-core machine.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
if [ -z "$case_file" ]; then
  mkdir -p runs/default
  /usr/bin/python3 scripts/run_case.py cases/default-fe-2d-opening.textproto --fe-only 2>&1 | tee runs/default/fe.log
  /usr/bin/python3 scripts/run_case.py cases/default-fsi-2d-opening.textproto 2>&1 | tee runs/default/fsi.log
  (cd scripts && /usr/bin/python3 -m valve_scene.opening_2d ../runs/default/fe ../runs/default/fsi --out ../runs/default)
elif [ "$case_file" = cases/default-fe-opening.textproto ]; then
  /usr/bin/python3 scripts/run_case.py "$case_file" --fe-only --output runs/default-fe-3d "$@"
  (cd scripts && /usr/bin/python3 -m valve_scene.quick_look ../runs/default-fe-3d --variant sector --resolution coarse)
else
  /usr/bin/python3 scripts/run_case.py "$case_file" "$@"
fi
