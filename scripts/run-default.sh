#!/usr/bin/env bash
# Sets up (Debian packages), builds, generates the valve meshes and runs the default case:
# the FE-only opening of the MHGO valve (1/6 sector, coarse, first 60 ms; about a minute),
# then summarises it (opening time, orifice area, peak strain, plot in runs/default/).
#   scripts/run-default.sh [CASE [extra launcher options]]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)
case_file=${1:-cases/default-fe-opening.textproto}
shift || true

bash scripts/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
# The meshes are generated, not stored (cases/meshes/ is git-ignored).
(cd scripts && /usr/bin/python3 -m valve_scene.write_cases > /dev/null)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Threads that spin while their partner is descheduled cost 5x on a shared 2-core machine.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
if [ "$case_file" = cases/default-fe-opening.textproto ]; then
  /usr/bin/python3 scripts/run_case.py "$case_file" --fe-only --output runs/default "$@"
  (cd scripts && /usr/bin/python3 -m valve_scene.quick_look ../runs/default --variant sector --resolution coarse)
else
  /usr/bin/python3 scripts/run_case.py "$case_file" "$@"
fi
