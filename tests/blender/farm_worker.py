"""A fresh Blender process for test_bake_all.py, run by the Blender program
(`blender -b --python farm_worker.py -- MODE ...`) or a bpy module's Python
(`python farm_worker.py MODE ...`), whichever runs the tests.

    bake   BLEND                      kodawari.bake_all() on the file (saves it)
    render BLEND OUT addon|no-addon FRAME...
                                      render the frames (Workbench, tiny) to OUT/####.png,
                                      with the add-on enabled first, or without it
"""

import os
import sys

import bpy  # first: importing bpy puts Blender's own modules (addon_utils) on sys.path


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


def main(argv):
    mode, blend = argv[0], argv[1]
    if mode == "bake":
        import addon_utils

        bpy.ops.wm.open_mainfile(filepath=blend)
        addon_utils.modules_refresh()
        import kodawari

        kodawari.bake_all()
    else:
        render(blend, argv[2], argv[3], [int(f) for f in argv[4:]])


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:])
