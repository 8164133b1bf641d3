"""Viewport overlay: the active swimming object's control axis (curve and control
points) drawn over the 3D view, so the user sees what the mesh is bound to."""

import bpy
import numpy as np

from .. import native
from . import runtime

_handle = None
CURVE_SAMPLES = 64


def axis_polylines(obj):
    """World-space (curve points (K, 3), control points (n, 3)) of obj's current body axis,
    or None when it does not swim live."""
    if (
        obj is None
        or obj.type != "MESH"
        or not runtime.is_live(obj)
        or not obj.kodawari_swim.show_axis
    ):
        return None
    rig = runtime.get_rig(obj, build=False)
    if rig is None:
        return None
    kn = native.module()
    curve = kn.curve_points(rig.axis, np.linspace(0.0, 1.0, CURVE_SAMPLES))
    world = np.array(obj.matrix_world)
    rotation, offset = world[:3, :3].T, world[:3, 3]
    return curve @ rotation + offset, rig.axis @ rotation + offset


def _shader():
    import gpu

    for name in ("UNIFORM_COLOR", "3D_UNIFORM_COLOR"):  # 3.4 knows the second; 4.x+ the first
        try:
            return gpu.shader.from_builtin(name)
        except ValueError:
            continue
    return None


def _draw():
    lines = axis_polylines(bpy.context.active_object)
    if lines is None:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader

    shader = _shader()
    if shader is None:
        return
    curve, points = lines
    gpu.state.depth_test_set("NONE")
    gpu.state.point_size_set(6.0)
    shader.bind()
    shader.uniform_float("color", (1.0, 0.55, 0.1, 1.0))
    batch_for_shader(shader, "LINE_STRIP", {"pos": curve.astype(np.float32).tolist()}).draw(shader)
    shader.uniform_float("color", (1.0, 0.9, 0.2, 1.0))
    batch_for_shader(shader, "POINTS", {"pos": points.astype(np.float32).tolist()}).draw(shader)
    gpu.state.point_size_set(1.0)


def add():
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")


def remove():
    global _handle
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
