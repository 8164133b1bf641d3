#!/usr/bin/env bash
# Installs what Kodawari needs and skips what is present.
#   Debian packages: Blender 3.4 (the real program), Eigen, GLM, GoogleTest,
#                    Google Benchmark, the system Python's pytest (Blender 3.4 runs it),
#                    Xvfb and Mesa (Blender's real window for the UI tests).
#   PyPI, into the project virtual environment $VENV: tools/requirements.txt
#   (bpy 4.5, pybind11, scikit-build-core, numpy, pytest, matplotlib, cmake, ninja),
#   and, when it installs for this Python, bpy 5.0 into $VENV5.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${VENV:-.venv}
VENV5=${VENV5:-.venv-bpy5}
PYTHON=${PYTHON:-}
STAMPS=.stamps
mkdir -p "$STAMPS"

say() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] ERROR: %s\n' "$*" >&2; exit 1; }

# --- Debian packages ---------------------------------------------------------
DEBS=(blender libeigen3-dev libglm-dev libgtest-dev libgmock-dev libbenchmark-dev
      python3-pytest python3-numpy g++ make
      ffmpeg fonts-dejavu-core  # the demos' GIFs (fish, hair, gait) and the fish sheet's labels
      xvfb xauth libgl1-mesa-dri)  # a virtual screen for the tests that need Blender's window
missing=()
for pkg in "${DEBS[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
  if [ "$(id -u)" -eq 0 ]; then SUDO=""
  elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO="sudo -n"
  else die "missing Debian packages: ${missing[*]} — install them as root: apt-get install ${missing[*]}"
  fi
  say "installing Debian packages: ${missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}" \
    || die "apt-get could not install: ${missing[*]}"
else
  say "Debian packages present"
fi

# --- Python 3.11 --------------------------------------------------------------
# Blender 3.4 (Debian), bpy 4.5 and bpy 5.0 all embed Python 3.11, so one cp311
# build of kodawari_native serves them all.
if [ -z "$PYTHON" ]; then
  for candidate in python3.11 python3 /usr/bin/python3.11; do
    if command -v "$candidate" >/dev/null && "$candidate" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
      PYTHON=$(command -v "$candidate"); break
    fi
  done
fi
[ -n "$PYTHON" ] || die "no Python 3.11 found (Blender's bpy module needs 3.11); set PYTHON=/path/to/python3.11"

venv_ready() {  # venv dir, requirements file
  [ -x "$1/bin/python" ] && [ -f "$1/.kodawari-req" ] && cmp -s "$2" "$1/.kodawari-req"
}
make_venv() {  # venv dir, requirements file
  if venv_ready "$1" "$2"; then say "$1 up to date"; return 0; fi
  say "installing $2 into $1 (first time: a few minutes, bpy is large)"
  [ -x "$1/bin/python" ] || "$PYTHON" -m venv "$1" || { dpkg -s python3-venv >/dev/null 2>&1 || die "python venv module missing: apt-get install python3-venv"; }
  "$1/bin/python" -m pip install -q -r "$2" 2> >(grep -v "is ignored: it is neither" >&2) || return 1
  cp "$2" "$1/.kodawari-req"
}
make_venv "$VENV" tools/requirements.txt || die "pip could not install tools/requirements.txt into $VENV"
if ! make_venv "$VENV5" tools/requirements-bpy5.txt; then
  say "note: bpy 5.0 did not install for this Python; its test tier will be skipped"
  rm -rf "$VENV5"
fi
say "ready: $("$VENV/bin/python" -c 'import bpy; print("bpy", bpy.app.version_string)' 2>/dev/null | tail -n1), $(blender --version 2>/dev/null | head -n1)"
