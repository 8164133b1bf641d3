"""Screenshots of Kodawari's panels in Blender's real window, for the README.

Run by tools/run_demo.sh in Blender 3.4 under Xvfb (not in background: panels only draw
in a window). For each feature it builds a sample creature, shows its tab in the
Properties editor at the default layout's width (in a tall window, so Kodawari's panel
below Blender's own is in view) and saves that editor as out/ui_<name>.png; the fish panel is also shown in Japanese."""

import os
import sys
import traceback

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "blend_samples"), os.path.join(ROOT, "tests", "blender")]
OUT = os.environ.get("KODAWARI_OUT", os.path.join(ROOT, "out"))


def _activate(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


def fish():
    import fish_shapes

    obj = fish_shapes.build_fish("tuna", head_axis="POS_X")
    _activate(obj)
    bpy.ops.kodawari.swim_add(head_axis="AUTO")
    bpy.ops.kodawari.swim_fin_find()
    obj.modifiers.new("Subdivision", "SUBSURF")
    return "MODIFIER", None


def hair():
    from hair_rig import add_camera, make_rig, select_only

    rig = make_rig(
        bpy.context.scene,
        chains=(
            ("Ahoge", (0.0, 0.0, 1.8), (0.0, 0.0, 1.0), 5),
            ("Tail", (0.0, 0.2, 1.0), (0.0, 1.0, -0.3), 6),
        ),
    )
    add_camera(bpy.context.scene, "Front", (0.0, -3.0, 1.7))
    select_only(rig, {"Ahoge.00", "Tail.00"})
    bpy.ops.kodawari.rod_add()
    bpy.ops.kodawari.rod_key_view(source="CAMERA")
    bpy.ops.kodawari.rod_collider_add(bone="Tail.00")
    return "DATA", "Kodawari Hair"


def gait():
    import gait_samples as samples

    rig, _ = samples.build_horse(bpy.context.scene)
    _activate(rig)
    bpy.ops.kodawari.gait_setup()
    samples.key_speed(rig, ((1, 2.0), (48, 5.0)))
    return "OBJECT", "Kodawari Gait"


SHOTS = (
    ("fish_panel", fish, "en_US"),
    ("hair_panel", hair, "en_US"),
    ("gait_panel", gait, "en_US"),
    ("fish_panel_ja", fish, "ja_JP"),
)


def _properties_area(window):
    return max((a for a in window.screen.areas if a.type == "PROPERTIES"), key=lambda a: a.height)


def _override(window, area):
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=window, screen=window.screen, area=area, region=region)


def _set_language(language):
    view = bpy.context.preferences.view
    view.language = language
    view.use_translate_interface = view.use_translate_tooltips = language != "en_US"


def shots():
    os.makedirs(OUT, exist_ok=True)
    for name, build, language in SHOTS:
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        yield 0.3
        _set_language(language)
        tab, _ = build()
        window = bpy.context.window_manager.windows[0]
        area = _properties_area(window)
        area.tag_redraw()
        yield 0.5  # the editor learns the new active object when it redraws
        area.spaces.active.context = tab
        yield 0.5
        path = os.path.join(OUT, f"ui_{name}.png")
        with _override(window, area):
            bpy.ops.screen.screenshot_area(filepath=path)
        print("  wrote", path)
        yield 0.2
    _set_language("en_US")


state = {"runner": None}


def drive():
    try:
        if state["runner"] is None:
            state["runner"] = shots()
        return next(state["runner"])
    except StopIteration:
        code = 0
    except Exception:
        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    os._exit(code)


bpy.app.timers.register(drive, first_interval=1.0, persistent=True)
