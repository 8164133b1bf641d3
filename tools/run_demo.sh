#!/usr/bin/env bash
# The demo: each blend_samples/*_demo.py runs in the real Blender 3.4 program with
# the packaged add-on installed, builds its sample scene and writes to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
BLENDER=${BLENDER:-blender}
source tools/blender_env.sh
mkdir -p out
started=$(mktemp); trap 'rm -f "$started"' EXIT
shopt -s nullglob
demos=(blend_samples/*_demo.py)
((${#demos[@]})) || { echo "no demo scripts in blend_samples/"; exit 1; }
for demo in "${demos[@]}"; do
  echo "=== demo: $demo"
  env $(blender_env) KODAWARI_OUT="$PWD/out" "$BLENDER" "${BLENDER_ARGS[@]}" \
    --python tools/blender_install_addon.py --python "$demo" 2>&1 | grep -vE "^(Fra:|Blender quit|Read blend)" || exit 1
done
# Screenshots of the panels need Blender's real window: Xvfb, a tall window so each panel is in view.
echo "=== demo: blend_samples/ui_screenshots.py"
env $(blender_env) KODAWARI_OUT="$PWD/out" timeout 600 xvfb-run -a -s "-screen 0 1600x1700x24" "$BLENDER" \
  --factory-startup -noaudio --window-geometry 0 0 1600 1700 \
  --python tools/blender_install_addon.py --python blend_samples/ui_screenshots.py 2>&1 | grep -E "wrote|Error|Traceback|File \"" || exit 1
echo; echo "=== demo wrote:"
find out -maxdepth 1 -type f -newer "$started" | sort | sed 's/^/  /'
