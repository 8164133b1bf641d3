#!/usr/bin/env bash
# The demo: each blend_samples/*_demo.py runs in the real Blender 3.4 program with
# the packaged add-on installed, builds its sample scene and writes to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
BLENDER=${BLENDER:-blender}
source tools/blender_env.sh
mkdir -p out
shopt -s nullglob
demos=(blend_samples/*_demo.py)
((${#demos[@]})) || { echo "no demo scripts in blend_samples/"; exit 1; }
for demo in "${demos[@]}"; do
  echo "=== demo: $demo"
  env $(blender_env) KODAWARI_OUT="$PWD/out" "$BLENDER" "${BLENDER_ARGS[@]}" \
    --python tools/blender_install_addon.py --python "$demo" 2>&1 | grep -vE "^(Fra:|Blender quit|Read blend)" || exit 1
done
echo; echo "=== demo wrote:"
find out -maxdepth 1 -type f -print | sort | sed 's/^/  /'
