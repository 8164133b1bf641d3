"""Fish Swim's viewport and render toggles, as a modifier's eye and camera buttons.

The swim lives in the "Kodawari Swim" shape key, which shape-key evaluation applies
before every modifier. Hiding the swim mutes that key, so the rest shape shows (and
renders) and the user's modifiers see the undeformed mesh. While a render job runs,
the render toggle decides instead of the viewport one."""

from .rig import SHAPE_KEY

_rendering = [False]


def visible(obj):
    settings = obj.kodawari_swim
    return settings.show_render if _rendering[0] else settings.enabled


def renders(obj):
    """True when a render would show this object swimming live (so a farm bake must bake it)."""
    keys = obj.data.shape_keys
    has_swim = keys is not None and keys.key_blocks.get(SHAPE_KEY) is not None
    return has_swim and obj.kodawari_swim.baked == "NONE" and obj.kodawari_swim.show_render


def sync(obj):
    """Mute the swim's shape key when the swim is hidden in the current context."""
    keys = obj.data.shape_keys
    block = keys.key_blocks.get(SHAPE_KEY) if keys is not None else None
    if block is None:
        return
    mute = not visible(obj)
    if block.mute != mute:
        block.mute = mute


def _sync_scene(scene):
    for obj in scene.objects:
        if obj.type == "MESH" and obj.kodawari_swim.baked == "NONE":
            sync(obj)


def set_rendering(scene, rendering):
    """From the render handlers (handlers.py): which toggle decides, applied to the scene."""
    _rendering[0] = rendering
    _sync_scene(scene)


def draw_toggles(layout, settings):
    """The eye and camera toggles of a modifier header."""
    row = layout.row(align=True)
    row.prop(
        settings,
        "enabled",
        text="",
        icon="RESTRICT_VIEW_OFF" if settings.enabled else "RESTRICT_VIEW_ON",
    )
    row.prop(
        settings,
        "show_render",
        text="",
        icon="RESTRICT_RENDER_OFF" if settings.show_render else "RESTRICT_RENDER_ON",
    )
    return row
