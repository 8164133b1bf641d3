"""Fish swim: any fish mesh swims by bending along a control axis (docs/algorithms.md §1, §2).

Object.kodawari_swim holds the settings; runtime.py writes each frame into the Fish Swim
Geometry Nodes modifier (route.py), called by handlers.py on frame changes; ops.py adds,
tunes, bakes and removes.
"""

import bpy

from . import apply, handlers, ops, panel, props

CLASSES = (
    props.KodawariSwimFin,
    props.KodawariSwimSettings,
    ops.KODAWARI_OT_swim_add,
    ops.KODAWARI_OT_swim_remove,
    ops.KODAWARI_OT_swim_fin_add,
    ops.KODAWARI_OT_swim_fin_remove,
    ops.KODAWARI_OT_swim_fin_find,
    ops.KODAWARI_OT_swim_flip_head,
    ops.KODAWARI_OT_swim_bake,
    ops.KODAWARI_OT_swim_free_bake,
    *apply.CLASSES,
    *panel.CLASSES,
)

PROPERTIES = (
    (
        bpy.types.Object,
        "kodawari_swim",
        lambda: bpy.props.PointerProperty(type=props.KodawariSwimSettings),
    ),
)

HANDLERS = (
    ("frame_change_post", handlers.on_frame_change),
    ("load_post", handlers.on_load),
    ("depsgraph_update_post", handlers.on_depsgraph_update),
    ("render_init", handlers.on_render_init),
    ("render_pre", handlers.on_render_pre),
    ("render_complete", handlers.on_render_done),
    ("render_cancel", handlers.on_render_done),
)
