#!/usr/bin/env bash
# Benchmarks print figures and ratios against the alternative measured in the same
# run; they never pass or fail on time. C++ programs first, then Blender scripts.
set -uo pipefail
failed=()
cd "$(dirname "$0")/.."
BUILD=${BUILD:-$PWD/build}
BLENDER=${BLENDER:-blender}
source tools/blender_env.sh
shopt -s nullglob
for program in "$BUILD"/bench_*; do
  [ -x "$program" ] || continue
  echo "=== $(basename "$program")"
  "$program" --benchmark_min_time=0.2 2>&1 | grep -v "^\*\*\*" || failed+=("$program")
done
for script in tests/bench/bench_*.py; do
  echo "=== $script (Blender 3.4)"
  env $(blender_env) "$BLENDER" "${BLENDER_ARGS[@]}" --python tools/blender_install_addon.py --python "$script" \
    2>&1 | grep -vE "^(Blender quit|Read blend)" || failed+=("$script (Blender 3.4)")
done
# The same scripts under the bpy modules (4.5 LTS, 5.0), where present: newer
# Blenders evaluate a changed mesh far more cheaply than 3.4.
for python in "${VENV:-$PWD/.venv}/bin/python" "${VENV5:-$PWD/.venv-bpy5}/bin/python"; do
  [ -x "$python" ] || continue
  "$python" -c "import bpy" 2>/dev/null || continue
  for script in tests/bench/bench_*.py; do
    echo "=== $script (bpy $("$python" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1))"
    env $(blender_env) "$python" -c "import runpy, sys; sys.path.insert(0, 'tools')
from blender_install_addon import install_addon; install_addon(); runpy.run_path(sys.argv[1], run_name='__main__')" \
      "$script" 2>&1 | grep -vE "^(Blender quit|Read blend)" || failed+=("$script ($python)")
  done
done
if ((${#failed[@]})); then
  printf '\nbenchmarks that failed to run:\n'; printf '  %s\n' "${failed[@]}"; exit 1
fi
