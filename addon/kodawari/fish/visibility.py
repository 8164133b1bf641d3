"""Fish Swim's viewport and render toggles: the Fish Swim modifier's eye and camera.

The settings (enabled, show_render) are what the Fish Swim panel shows; sync pushes them
onto the modifier, and pull takes a click on the modifier's own toggles back into them.
Hidden, the modifier is skipped: the rest shape shows (and renders) and the user's other
modifiers see the undeformed mesh. A baked swim keeps the modifier off (the bake plays).
While a render job runs, the render toggle decides instead of the viewport one."""

from . import route
from .rig import SHAPE_KEY

_rendering = [False]


def visible(obj):
    settings = obj.kodawari_swim
    return settings.show_render if _rendering[0] else settings.enabled


def renders(obj):
    """True when a render would show this object swimming live (so a farm bake must bake it)."""
    keys = obj.data.shape_keys
    has_key = keys is not None and keys.key_blocks.get(SHAPE_KEY) is not None
    has_swim = has_key or route.modifier(obj) is not None
    return has_swim and obj.kodawari_swim.baked == "NONE" and obj.kodawari_swim.show_render


def sync(obj):
    """Show the modifier as the settings say (off while baked)."""
    mod = route.modifier(obj)
    if mod is None:
        return
    settings = obj.kodawari_swim
    live = settings.baked == "NONE"
    viewport, render = live and settings.enabled, live and settings.show_render
    if mod.show_viewport != viewport:
        mod.show_viewport = viewport
    if mod.show_render != render:
        mod.show_render = render


def pull(obj):
    """The user clicked the modifier's own eye or camera: the settings follow."""
    mod = route.modifier(obj)
    settings = obj.kodawari_swim
    if mod is None or settings.baked != "NONE":
        return
    if mod.show_viewport != settings.enabled:
        settings.enabled = mod.show_viewport
    if mod.show_render != settings.show_render:
        settings.show_render = mod.show_render


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
