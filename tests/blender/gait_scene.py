"""Helpers for the gait tests: sample rigs set up and keyed."""

import bpy


def horse(scene, speeds=None, fps=24):
    from kodawari.gait import samples

    scene.render.fps = fps
    scene.render.fps_base = 1.0
    rig, body = samples.build_horse(scene)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    if speeds:
        samples.key_speed(rig, speeds)
    return rig


def fcurve_snapshot(obj):
    """{(data_path, index): values} of every F-curve on obj's action."""
    from kodawari import fcurves

    anim = obj.animation_data
    if anim is None or anim.action is None:
        return {}
    return {(c.data_path, c.array_index): fcurves.read_keys(c)[1].tolist()
            for c in fcurves.action_fcurves(anim.action, obj)}
