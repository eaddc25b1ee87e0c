#!/usr/bin/env bash
# stiff-drape (128 x 128 cotton onto a sphere, 1 simulated second, headless: collisions included, normals not)
# with each solver setting, the settings alternated over ROUNDS rounds so that the shared machine's noise hits
# them alike; prints every wall time (s per simulated second), then the median per setting.
# Usage: bench/results/stiff-drape-xpbd-2026-12-02.sh [ROUNDS] (from the repository root, after a Release build)
set -euo pipefail
rounds="${1:-3}"
bin=build/release/src/clothsim
declare -A runs=(
  ["xpbd-grid-16-1t"]="--set integration.integrator=xpbd --set integration.substeps=16 --set solver.threads=1"
  ["xpbd-grid-16-2t"]="--set integration.integrator=xpbd --set integration.substeps=16 --set solver.threads=2"
  ["xpbd-grid-32-1t"]="--set integration.integrator=xpbd --set integration.substeps=32 --set solver.threads=1"
  ["xpbd-grid-32-2t"]="--set integration.integrator=xpbd --set integration.substeps=32 --set solver.threads=2"
  ["xpbd-list-16-1t"]="--set integration.integrator=xpbd --set integration.substeps=16 --set solver.method=textbook"
  ["verlet-645-1t"]="--set integration.integrator=verlet --set integration.substeps=645 --set solver.threads=1"
  ["verlet-645-2t"]="--set integration.integrator=verlet --set integration.substeps=645 --set solver.threads=2"
)
names=(xpbd-grid-16-1t xpbd-grid-16-2t xpbd-grid-32-1t xpbd-grid-32-2t xpbd-list-16-1t verlet-645-1t verlet-645-2t)
declare -A times
for ((r = 1; r <= rounds; ++r)); do
  for name in "${names[@]}"; do
    # shellcheck disable=SC2086
    t=$("$bin" --headless --scene stiff-drape ${runs[$name]} --duration 1 --json |
        python3 -c 'import sys, json; print(round(json.load(sys.stdin)["wall_seconds"], 3))')
    echo "round $r $name $t"
    times[$name]="${times[$name]:-} $t"
  done
done
for name in "${names[@]}"; do
  echo "median $name $(echo ${times[$name]} | tr ' ' '\n' | sort -n | awk '{a[NR]=$1} END {print a[int((NR + 1) / 2)]}') s/s"
done
