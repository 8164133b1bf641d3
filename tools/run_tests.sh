#!/usr/bin/env bash
# Every test tier, then one summary; exits non-zero when any tier fails.
#   ruff     ruff check and ruff format --check over the Python sources
#   native   C++ GoogleTest through ctest
#   python   pytest against kodawari_native, no Blender
#   fuzz     hypothesis on every kodawari_native entry point (tests/fuzz), crash-safe
#   blender-3.4  the real program: blender -b ... --python tests/blender/run_pytest.py
#   ui-3.4       the real program in a window on a virtual screen (modal bakes, Esc)
#   bpy-4.5, bpy-5.0  the same test files under Blender as a Python module
set -uo pipefail
cd "$(dirname "$0")/.."
VENV=${VENV:-$PWD/.venv}
VENV5=${VENV5:-$PWD/.venv-bpy5}
BUILD=${BUILD:-$PWD/build}
BLENDER=${BLENDER:-blender}
REPORTS=$BUILD/test-reports
rm -rf "$REPORTS"; mkdir -p "$REPORTS"
export PYTHONDONTWRITEBYTECODE=1
unset PYTHONPATH
declare -A status

tier() {  # name, command...
  local name=$1; shift
  echo; echo "=== tier: $name"
  if "$@"; then status[$name]=pass; else status[$name]=FAIL; fi
}

source tools/blender_env.sh

ruff_tier() {  # lint + format check of the Python sources (rules: pyproject.toml [tool.ruff])
  local sources=(addon tests tools blend_samples) rc=0
  "$VENV/bin/ruff" check --output-format junit --exit-zero -o "$REPORTS/ruff.xml" "${sources[@]}"
  "$VENV/bin/ruff" check "${sources[@]}" || rc=1
  "$VENV/bin/ruff" format --check "${sources[@]}" || rc=1
  return $rc
}
tier ruff ruff_tier
tier native ctest --test-dir "$BUILD" --output-on-failure --output-junit "$REPORTS/native.xml"
tier python env PYTHONPATH="$PWD/addon/kodawari" "$VENV/bin/python" -m pytest -q -p no:cacheprovider tests/python --junitxml="$REPORTS/python.xml"
# Hypothesis on every kodawari_native entry point (~1 min), in a child process: a crash is reported, not fatal.
tier fuzz env PYTHONPATH="$PWD/addon/kodawari" "$VENV/bin/python" tests/fuzz/run_fuzz.py --junitxml="$REPORTS/fuzz.xml"
pip_install_tier() {  # `pip install .` (scikit-build-core, same CMake) into a scratch folder, then the Python tests on it
  local target; target=$(mktemp -d -t kodawari-pip-XXXXXX)
  "$VENV/bin/python" -m pip install -q --no-build-isolation --no-deps --target "$target" \
      --config-settings=build-dir="$BUILD/pip" . 2> >(grep -v "is ignored: it is neither" >&2) || return 1
  env PYTHONPATH="$target" "$VENV/bin/python" -m pytest -q -p no:cacheprovider tests/python \
      --junitxml="$REPORTS/pip-install.xml"
}
tier pip-install pip_install_tier
tier blender-3.4 env $(blender_env) "$BLENDER" "${BLENDER_ARGS[@]}" \
  --python tests/blender/run_pytest.py -- -q tests/blender --junitxml="$REPORTS/blender-3.4.xml"
# Modal bakes and Esc need Blender's real window: a virtual screen, simulated key presses.
tier ui-3.4 env $(blender_env) KODAWARI_UI_REPORT="$REPORTS/ui-3.4.xml" timeout 600 xvfb-run -a -s "-screen 0 640x480x24" \
  "$BLENDER" --factory-startup -noaudio --python-exit-code 1 --enable-event-simulate \
  --python tools/blender_install_addon.py --python tests/ui/run_ui_tests.py
tier bpy-4.5 env $(blender_env) "$VENV/bin/python" -m pytest -q -p no:cacheprovider tests/blender \
  --junitxml="$REPORTS/bpy-4.5.xml"
if [ -x "$VENV5/bin/python" ]; then
  tier bpy-5.0 env $(blender_env) "$VENV5/bin/python" -m pytest -q -p no:cacheprovider \
    tests/blender --junitxml="$REPORTS/bpy-5.0.xml"
fi

echo; echo "=== summary"
"$VENV/bin/python" tools/summarize_reports.py "$REPORTS" "${!status[@]}" -- "${status[@]}"
