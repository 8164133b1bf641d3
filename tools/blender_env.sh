# Sourced by the runners: throw-away Blender user folders, so tests, demos and
# benchmarks never touch (or depend on) the user's own Blender settings.
blender_env() {
  local dir; dir=$(mktemp -d -t kodawari-blender-XXXXXX)
  echo "BLENDER_USER_SCRIPTS=$dir/scripts BLENDER_USER_CONFIG=$dir/config BLENDER_USER_DATAFILES=$dir/data BLENDER_USER_EXTENSIONS=$dir/extensions"
}
BLENDER_ARGS=(-b --factory-startup -noaudio --python-exit-code 1)
