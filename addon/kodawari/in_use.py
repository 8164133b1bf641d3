"""Which Kodawari features an object uses: panels show only where a feature is set up,
and offer one "Add …" entry elsewhere (shared by the panels, sidebar and menus)."""


def swim(obj):
    if obj is None or obj.type != "MESH":
        return False
    settings = obj.kodawari_swim
    keys = obj.data.shape_keys
    has_key = keys is not None and "Kodawari Swim" in keys.key_blocks
    return settings.enabled or settings.baked != "NONE" or has_key


def hair(obj):
    return obj is not None and obj.type == "ARMATURE" and bool(obj.kodawari_hair.rods or obj.kodawari_hair.colliders)


def gait(obj):
    return obj is not None and obj.type == "ARMATURE" and bool(obj.kodawari_gait.legs)


def can_swim(obj):
    return obj is not None and obj.type == "MESH"


def can_rig(obj):
    return obj is not None and obj.type == "ARMATURE"
