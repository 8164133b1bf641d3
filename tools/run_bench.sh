#!/usr/bin/env bash
# Benchmarks print figures and ratios against the alternative measured in the same
# run; they never pass or fail on time. C++ programs first, then Blender scripts.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-$PWD/build}
BLENDER=${BLENDER:-blender}
source tools/blender_env.sh
shopt -s nullglob
for program in "$BUILD"/bench_*; do
  [ -x "$program" ] || continue
  echo "=== $(basename "$program")"
  "$program" --benchmark_min_time=0.2 2>&1 | grep -v "^\*\*\*"
done
for script in tests/bench/bench_*.py; do
  echo "=== $script (Blender 3.4)"
  env $(blender_env) "$BLENDER" "${BLENDER_ARGS[@]}" --python tools/blender_install_addon.py --python "$script" \
    2>&1 | grep -vE "^(Blender quit|Read blend)"
done
