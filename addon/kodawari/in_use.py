"""Which Kodawari features an object uses: panels show only where a feature is set up,
and offer one "Add …" entry elsewhere (shared by the panels, sidebar and menus)."""


def swim(obj):
    if obj is None or obj.type != "MESH":
        return False
    settings = obj.kodawari_swim
    keys = obj.data.shape_keys
    has_key = keys is not None and "Kodawari Swim" in keys.key_blocks  # an older file
    has_modifier = any(
        m.type == "NODES" and m.node_group is not None and m.node_group.get("kodawari_swim")
        for m in obj.modifiers
    )
    return settings.enabled or settings.baked != "NONE" or has_key or has_modifier


def hair(obj):
    return (
        obj is not None
        and obj.type == "ARMATURE"
        and bool(obj.kodawari_hair.rods or obj.kodawari_hair.colliders)
    )


def gait(obj):
    return obj is not None and obj.type == "ARMATURE" and bool(obj.kodawari_gait.legs)


def can_swim(obj):
    return obj is not None and obj.type == "MESH"


def can_rig(obj):
    return obj is not None and obj.type == "ARMATURE"


def split_layout(layout):
    """Blender's property layout: labels in a left column, keyframe decorators on the right."""
    layout.use_property_split = True
    layout.use_property_decorate = True
    return layout


def add_panel(idname, label, tab, can_use, uses, operator, text, icon):
    """A headerless Properties panel holding one "Add …" button, shown on an object that could
    use a feature but does not yet (the single entry the feature's own panels give way to)."""
    import bpy

    def poll(cls, context):
        return can_use(context.object) and not uses(context.object)

    def draw(self, context):
        self.layout.operator(operator, text=text, icon=icon)

    return type(
        idname,
        (bpy.types.Panel,),
        {
            "__doc__": f'On an object that could use it: one "{text}" button.',
            "bl_idname": idname,
            "bl_label": label,
            "bl_space_type": "PROPERTIES",
            "bl_region_type": "WINDOW",
            "bl_context": tab,
            "bl_options": {"HIDE_HEADER"},
            "poll": classmethod(poll),
            "draw": draw,
        },
    )
