"""View-dependent hair: joint chains that sway with physics and take the shapes the
artist keyed per view, pose and speed (docs/algorithms.md §3; Koyama & Igarashi 2013)."""

import bpy

from . import handlers, ops, panel, props

CLASSES = props.CLASSES + ops.CLASSES + panel.CLASSES
PROPERTIES = (
    (
        bpy.types.Object,
        "kodawari_hair",
        lambda: bpy.props.PointerProperty(type=props.KodawariHairSettings),
    ),
)
HANDLERS = (
    ("frame_change_pre", handlers.on_frame_change_pre),
    ("frame_change_post", handlers.on_frame_change),
    ("load_post", handlers.on_load),
    ("save_pre", handlers.on_save),
    ("undo_post", handlers.on_undo),
    ("redo_post", handlers.on_undo),
)
