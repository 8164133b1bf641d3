"""Every user operator of Kodawari can be found in the menus Blender users look in
(Object ▸ Animation, Pose, and Add Modifier ▸ Deform where Blender has it), which is
also what F3 searches in Blender 3.4. The menus' draw functions are walked with a
recording layout, following submenus, as Blender would draw them."""

import bpy
from fish_helpers import make_fish
from gait_scene import horse
from ui_recording import draw_menu_function, kodawari_classes

TARGET_MENUS = ("VIEW3D_MT_object_animation", "VIEW3D_MT_pose", "OBJECT_MT_modifier_add_deform")


def _appended_functions(menu_class):
    """The draw functions Kodawari appended to one of Blender's menus."""
    functions = getattr(menu_class.draw, "_draw_funcs", [])
    return [f for f in functions if getattr(f, "__module__", "").startswith("kodawari")]


def _reachable(menu_name, context=None):
    """(operator idnames, entries) drawn by Kodawari in a Blender menu, following submenus."""
    menu_class = getattr(bpy.types, menu_name)
    pending = [(menu_class, function) for function in _appended_functions(menu_class)]
    operators, entries, seen = set(), [], set()
    while pending:
        owner, function = pending.pop()
        for entry in draw_menu_function(function, owner, context):
            entries.append(entry)
            if entry.kind == "operator":
                operators.add(entry.name)
            elif entry.kind == "menu" and entry.name not in seen:
                seen.add(entry.name)
                submenu = getattr(bpy.types, entry.name)
                pending.append((submenu, submenu.draw))
    return operators, entries


def _user_operators():
    return {
        cls.bl_idname
        for cls in kodawari_classes("KODAWARI_OT_")
        if "INTERNAL" not in getattr(cls, "bl_options", set())
    }


def test_every_operator_is_in_the_object_animation_menu(empty_scene):
    make_fish("tuna")
    found, _ = _reachable("VIEW3D_MT_object_animation")
    missing = _user_operators() - found
    assert not missing, f"not in Object ▸ Animation: {sorted(missing)}"


def test_rig_operators_are_in_the_pose_menu(empty_scene):
    rig = horse(empty_scene)
    bpy.context.view_layer.objects.active = rig
    found, _ = _reachable("VIEW3D_MT_pose")
    rig_operators = {
        name for name in _user_operators() if name.split(".")[1].startswith(("rod_", "gait_"))
    }
    assert rig_operators, "no hair or gait operators registered"
    assert not rig_operators - found, f"not in the Pose menu: {sorted(rig_operators - found)}"


def test_menu_entries_name_the_tools():
    """F3 finds menu entries by their text: the menus say Kodawari, Fish Swim, Hair, Gait."""
    labels = {cls.bl_label for cls in kodawari_classes("KODAWARI_MT_")}
    assert {"Kodawari", "Fish Swim", "Hair", "Gait"} <= labels


def test_fish_swim_in_add_modifier_deform_where_blender_has_it(empty_scene):
    make_fish("tuna")
    if not hasattr(bpy.types, "OBJECT_MT_modifier_add_deform"):
        # Blender 3.4: Add Modifier is drawn in C and cannot be extended; the swim is in
        # Object ▸ Animation ▸ Kodawari there (checked above).
        assert bpy.app.version < (4, 0, 0)
        return
    found, entries = _reachable("OBJECT_MT_modifier_add_deform")
    assert found == {"kodawari.swim_add"}
    assert any(e.kwargs.get("text") == "Fish Swim" for e in entries)
