"""A fresh Blender process for test_bake_all.py, run by the Blender program
(`blender -b --python farm_worker.py -- MODE ...`) or a bpy module's Python
(`python farm_worker.py MODE ...`), whichever runs the tests.

    bake   BLEND                      kodawari.bake_all() on the file (saves it)
    render BLEND OUT addon|no-addon FRAME...
                                      render the frames (Workbench, tiny) to OUT/####.png,
                                      with the add-on enabled first, or without it
    resave BLEND FRAME                open the file without the add-on, go to FRAME, save it

The tests start it with `run_worker(...)`, which also runs in the tests' own process.
"""

import os
import subprocess
import sys

import bpy  # first: importing bpy puts Blender's own modules (addon_utils) on sys.path

HERE = os.path.dirname(os.path.abspath(__file__))


def run_blender(*args, cwd):
    """Runs a fresh process of the Blender the tests run in; returns (code, output)."""
    if bpy.app.binary_path:  # the Blender program
        command = [bpy.app.binary_path, "-b", "--factory-startup", "-noaudio", *args]
    else:  # the bpy module: its Python, with the worker script
        command = [sys.executable, *args]
    done = subprocess.run(
        command, cwd=cwd, capture_output=True, text=True, timeout=300, check=False
    )
    return done.returncode, done.stdout + done.stderr


def run_worker(*args, cwd):
    """Runs this script in a fresh Blender process with `args` (MODE ...)."""
    script = os.path.join(HERE, "farm_worker.py")
    if bpy.app.binary_path:
        return run_blender("--python-exit-code", "1", "--python", script, "--", *args, cwd=cwd)
    return run_blender(script, *args, cwd=cwd)


def rendered_pixels(path):
    """The RGBA floats of a rendered image file (read in the tests' own process)."""
    import numpy as np

    image = bpy.data.images.load(path)
    try:
        out = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(out)
    finally:
        bpy.data.images.remove(image)
    return out


def _enable_addon():
    import addon_utils

    addon_utils.modules_refresh()
    addon_utils.enable("kodawari", default_set=False)
    assert hasattr(bpy.types.Object, "kodawari_swim"), "the add-on did not register"


def render(blend, out, addon, frames):
    if addon == "addon":
        _enable_addon()  # enabled before the file opens, as for an artist
    bpy.ops.wm.open_mainfile(filepath=blend)
    if addon == "no-addon":
        assert "kodawari" not in bpy.context.preferences.addons
        assert not hasattr(bpy.types.Object, "kodawari_swim")
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x, scene.render.resolution_y = 96, 64
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    for frame in frames:
        scene.frame_set(frame)
        scene.render.filepath = os.path.join(out, f"{frame:04d}.png")
        bpy.ops.render.render(write_still=True)


def resave(blend, frame):
    bpy.ops.wm.open_mainfile(filepath=blend)
    assert not hasattr(bpy.types.Object, "kodawari_swim")
    bpy.context.scene.frame_set(frame)
    bpy.ops.wm.save_as_mainfile(filepath=blend)


def main(argv):
    mode, blend = argv[0], argv[1]
    if mode == "bake":
        import addon_utils

        bpy.ops.wm.open_mainfile(filepath=blend)
        addon_utils.modules_refresh()
        import kodawari

        kodawari.bake_all()
    elif mode == "resave":
        resave(blend, int(argv[2]))
    else:
        render(blend, argv[2], argv[3], [int(f) for f in argv[4:]])


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:])
