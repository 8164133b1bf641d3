"""Menu entries where Blender users look for tools, so F3 finds them by name:

  Object ▸ Animation ▸ Kodawari ▸ Fish Swim / Hair / Gait   (Object Mode)
  Pose ▸ Kodawari ▸ Hair / Gait                              (Pose Mode)
  Add Modifier ▸ Deform ▸ Fish Swim                          (Blender 4.x and newer)

Each feature submenu lists its curated entries first, then any other operator the
feature registers, so an operator added later is never left out of the menus."""

import bpy

from . import in_use

# (operator, icon, text or None for its own label, {property: value})
SWIM_ITEMS = (
    ("kodawari.swim_add", "MOD_WAVE", None, {}),
    ("kodawari.swim_fin_find", "VIEWZOOM", None, {}),
    ("kodawari.swim_fin_add", "ADD", None, {}),
    ("kodawari.swim_fin_remove", "REMOVE", None, {}),
    ("kodawari.swim_flip_head", "ARROW_LEFTRIGHT", None, {}),
    None,
    ("kodawari.swim_bake", "FILE_CACHE", "Bake Fish Swim to Mesh Cache", {"target": "MESH_CACHE"}),
    (
        "kodawari.swim_bake",
        "SHAPEKEY_DATA",
        "Bake Fish Swim to Shape Keys",
        {"target": "SHAPE_KEYS"},
    ),
    ("kodawari.swim_apply", "CHECKMARK", None, {}),
    ("kodawari.swim_remove", "X", None, {}),
)
HAIR_ITEMS = (
    ("kodawari.rod_add", "ADD", "Add Hair Rod", {}),
    ("kodawari.rod_remove", "REMOVE", "Remove Hair Rod", {}),
    None,
    ("kodawari.rod_key_view", "CAMERA_DATA", "Key Hair Shape for View", {}),
    ("kodawari.rod_key_pose", "ARMATURE_DATA", "Key Hair Shape for Pose", {}),
    ("kodawari.rod_key_speed", "FORCE_WIND", "Key Hair Shape for Speed", {}),
    ("kodawari.rod_fit_stroke", "GREASEPENCIL", None, {}),
    ("kodawari.rod_key_preview", "HIDE_OFF", None, {}),
    ("kodawari.rod_rekey", "FILE_REFRESH", None, {}),
    ("kodawari.rod_key_remove", "X", None, {}),
    None,
    ("kodawari.rod_collider_add", "MESH_UVSPHERE", None, {}),
    ("kodawari.rod_collider_remove", "REMOVE", None, {}),
    None,
    ("kodawari.rod_bake", "REC", None, {}),
)
GAIT_ITEMS = (
    ("kodawari.gait_setup", "OUTLINER_OB_ARMATURE", None, {}),
    ("kodawari.gait_bake", "REC", None, {}),
    ("kodawari.gait_report", "GRAPH", None, {}),
)


def _registered_operators():
    """idname -> class of every operator the add-on registered (not internal ones)."""
    from . import registration

    found = {}
    for cls in registration.registered_classes():
        idname = getattr(cls, "bl_idname", "")
        if issubclass(cls, bpy.types.Operator) and "INTERNAL" not in getattr(
            cls, "bl_options", set()
        ):
            found[idname] = cls
    return found


def _draw_items(layout, items, prefix):
    operators = _registered_operators()
    listed = set()
    for item in items:
        if item is None:
            layout.separator()
            continue
        idname, icon, text, values = item
        if idname not in operators:
            continue  # not in this build
        listed.add(idname)
        op = (
            layout.operator(idname, icon=icon)
            if text is None
            else layout.operator(idname, text=text, icon=icon)
        )
        for name, value in values.items():
            setattr(op, name, value)
    extra = sorted(
        name for name in operators if name.split(".")[1].startswith(prefix) and name not in listed
    )
    if extra:
        layout.separator()
        for idname in extra:
            layout.operator(idname)


class KODAWARI_MT_swim(bpy.types.Menu):
    bl_idname = "KODAWARI_MT_swim"
    bl_label = "Fish Swim"

    def draw(self, context):
        _draw_items(self.layout, SWIM_ITEMS, "swim_")


class KODAWARI_MT_hair(bpy.types.Menu):
    bl_idname = "KODAWARI_MT_hair"
    bl_label = "Hair"

    def draw(self, context):
        _draw_items(self.layout, HAIR_ITEMS, "rod_")


class KODAWARI_MT_gait(bpy.types.Menu):
    bl_idname = "KODAWARI_MT_gait"
    bl_label = "Gait"

    def draw(self, context):
        _draw_items(self.layout, GAIT_ITEMS, "gait_")


class KODAWARI_MT_hair_key_add(bpy.types.Menu):
    """The "+" of the hair key list: which condition to key."""

    bl_idname = "KODAWARI_MT_hair_key_add"
    bl_label = "Add Key"

    def draw(self, context):
        layout = self.layout
        layout.operator("kodawari.rod_key_view", text="View", icon="CAMERA_DATA").source = "CAMERA"
        layout.operator(
            "kodawari.rod_key_view", text="View (Viewport)", icon="VIEW3D"
        ).source = "VIEWPORT"
        layout.operator("kodawari.rod_key_pose", text="Pose", icon="ARMATURE_DATA")
        layout.operator("kodawari.rod_key_speed", text="Speed", icon="FORCE_WIND")


def _covered_prefixes():
    return ("swim_", "rod_", "gait_")


class KODAWARI_MT_main(bpy.types.Menu):
    bl_idname = "KODAWARI_MT_main"
    bl_label = "Kodawari"

    def draw(self, context):
        layout = self.layout
        layout.menu("KODAWARI_MT_swim", icon="MOD_WAVE")
        layout.menu("KODAWARI_MT_hair", icon="STRANDS")
        layout.menu("KODAWARI_MT_gait", icon="ANIM")
        # Anything registered outside the three features (e.g. whole-file tools).
        others = sorted(
            name
            for name in _registered_operators()
            if not name.split(".")[1].startswith(_covered_prefixes())
        )
        if others:
            layout.separator()
            for idname in others:
                layout.operator(idname)


class KODAWARI_MT_pose(bpy.types.Menu):
    bl_idname = "KODAWARI_MT_pose"
    bl_label = "Kodawari"

    def draw(self, context):
        self.layout.menu("KODAWARI_MT_hair", icon="STRANDS")
        self.layout.menu("KODAWARI_MT_gait", icon="ANIM")


def draw_object_animation(self, context):
    self.layout.separator()
    self.layout.menu("KODAWARI_MT_main", icon="ANIM_DATA")


def draw_pose(self, context):
    self.layout.separator()
    self.layout.menu("KODAWARI_MT_pose", icon="ANIM_DATA")


def draw_modifier_deform(self, context):
    # Blender 4.x: Add Modifier ▸ Deform. The swim is not a modifier type, so the entry adds it.
    if in_use.can_swim(context.object):
        self.layout.operator("kodawari.swim_add", text="Fish Swim", icon="MOD_WAVE")


CLASSES = (
    KODAWARI_MT_swim,
    KODAWARI_MT_hair,
    KODAWARI_MT_gait,
    KODAWARI_MT_hair_key_add,
    KODAWARI_MT_main,
    KODAWARI_MT_pose,
)

# (menu class name, draw function): the menu exists in every supported Blender except the
# Deform submenu of Add Modifier, which Blender 4.0 introduced (3.4's Add Modifier is not Python).
APPENDS = (
    ("VIEW3D_MT_object_animation", draw_object_animation),
    ("VIEW3D_MT_pose", draw_pose),
    ("OBJECT_MT_modifier_add_deform", draw_modifier_deform),
)


def append():
    appended = []
    for menu_name, function in APPENDS:
        menu = getattr(bpy.types, menu_name, None)
        if menu is not None:
            menu.append(function)
            appended.append((menu, function))
    return appended
