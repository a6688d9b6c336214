#!/usr/bin/env bash
# Sets up (Debian packages), builds, and runs the default case; its output, logs and timing
# report land in runs/default/.
#   scripts/run-default.sh [CASE] [extra launcher options]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
jobs=$(nproc 2>/dev/null || echo 2)
case_file=${1:-cases/standin-plate.textproto}
shift || true

bash scripts/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
/usr/bin/python3 scripts/run_case.py "$case_file" --output runs/default "$@"
