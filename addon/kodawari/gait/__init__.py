"""Quadruped gaits: walk, trot, canter and gallop from a speed curve, legs solved by
CCD IK with joint limits and stiffness, baked to an Action (docs/algorithms.md §4)."""

import bpy

from . import handlers, ops, panel, props

CLASSES = (
    props.KodawariGaitBone,
    props.KodawariGaitLeg,
    props.KodawariGaitEntry,
    props.KodawariGaitSettings,
    ops.KODAWARI_OT_gait_setup,
    ops.KODAWARI_OT_gait_bake,
    ops.KODAWARI_OT_gait_report,
    *panel.CLASSES,
)

PROPERTIES = (
    (
        bpy.types.Object,
        "kodawari_gait",
        lambda: bpy.props.PointerProperty(type=props.KodawariGaitSettings),
    ),
)

HANDLERS = (("load_post", handlers.on_load),)
