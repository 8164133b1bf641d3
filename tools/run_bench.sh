#!/usr/bin/env bash
# Benchmarks print figures and ratios against the alternative measured in the same
# run; they never pass or fail on time. C++ programs first (the solvers alone), then
# every tests/bench/bench_*.py in Blender 3.4 and under the bpy 4.5 and 5.0 modules;
# each script adds its figures to out/bench.json, which tools/bench_table.py turns into
# the README's speed table at the end.
#   BENCH_ONLY="fish hair"   run only these scripts (bench_<name>.py)
#   BENCH_BLENDERS="3.4"     run only these Blenders (3.4, 4.5, 5.0)
#   KODAWARI_BENCH_SIZES=100000,160   only these sizes (a quick look)
set -uo pipefail
failed=()
cd "$(dirname "$0")/.."
BUILD=${BUILD:-$PWD/build}
BLENDER=${BLENDER:-blender}
BENCH_BLENDERS=${BENCH_BLENDERS:-3.4 4.5 5.0}
source tools/blender_env.sh
shopt -s nullglob
mkdir -p out
rm -f out/bench.json
started=$(date +%s)
scripts=()
for script in tests/bench/bench_*.py; do
  name=$(basename "$script" .py); name=${name#bench_}
  if [ -n "${BENCH_ONLY:-}" ] && [[ " $BENCH_ONLY " != *" $name "* ]]; then continue; fi
  scripts+=("$script")
done
if [ -z "${BENCH_ONLY:-}" ]; then
  for program in "$BUILD"/bench_*; do
    [ -x "$program" ] || continue
    echo "=== $(basename "$program") (native, the solver alone)"
    "$program" --benchmark_min_time=0.2 2>&1 | grep --line-buffered -v "^\*\*\*" || failed+=("$program")
  done
fi
wants() { [[ " $BENCH_BLENDERS " == *" $1 "* ]]; }
if wants 3.4; then
  for script in "${scripts[@]}"; do
    echo "=== $script (Blender 3.4)"
    env $(blender_env) "$BLENDER" "${BLENDER_ARGS[@]}" --python tools/blender_install_addon.py --python "$script" \
      2>&1 | grep --line-buffered -vE "^(Blender quit|Read blend|Info: |Modules Installed|addon_utils.disable)" || failed+=("$script (Blender 3.4)")
  done
fi
# The same scripts under the bpy modules (4.5 LTS, 5.0), where present.
for python in "${VENV:-$PWD/.venv}/bin/python" "${VENV5:-$PWD/.venv-bpy5}/bin/python"; do
  [ -x "$python" ] || continue
  version=$("$python" -c "import bpy; print('.'.join(map(str, bpy.app.version[:2])))" 2>/dev/null | tail -1) || continue
  wants "$version" || continue
  for script in "${scripts[@]}"; do
    echo "=== $script (bpy $version)"
    env $(blender_env) "$python" -c "import runpy, sys; sys.path.insert(0, 'tools')
from blender_install_addon import install_addon; install_addon(); runpy.run_path(sys.argv[1], run_name='__main__')" \
      "$script" 2>&1 | grep --line-buffered -vE "^(Blender quit|Read blend|Info: |Modules Installed|addon_utils.disable)" || failed+=("$script (bpy $version)")
  done
done
echo "=== speed table (tools/bench_table.py out/bench.json), whole run $(( $(date +%s) - started )) s"
python3 tools/bench_table.py out/bench.json || failed+=("tools/bench_table.py")
if ((${#failed[@]})); then
  printf '\nbenchmarks that failed to run:\n'; printf '  %s\n' "${failed[@]}"; exit 1
fi
