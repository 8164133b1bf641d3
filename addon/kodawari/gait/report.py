"""gait_report: measure the baked Action (not the solver's memory) and write the
seed's smoothness criteria as JSON plus a footfall (Hildebrand) diagram and fore-aft
foot trajectories (seed figures 4.7, 4.8) as one PNG, drawn with NumPy."""

import json
import os

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import fcurves
from . import metrics, report_svg
from . import rig as rigmod
from .bake import CONTACT_PROPS, GAIT_PROP
from .font import draw_text
from .props import LEG_NAMES

GAIT_COLORS = {  # soft backgrounds per gait segment
    0: (0.86, 0.93, 0.86, 1),
    1: (0.86, 0.90, 0.98, 1),
    2: (0.98, 0.93, 0.84, 1),
    3: (0.98, 0.86, 0.86, 1),
    4: (0.93, 0.86, 0.98, 1),
}
LEG_COLORS = ((0.85, 0.2, 0.1, 1), (0.95, 0.6, 0.1, 1), (0.1, 0.35, 0.85, 1), (0.1, 0.65, 0.6, 1))


def _curve(action, obj, path, index=0):
    c = fcurves.find_fcurve(action, obj, path, index)
    if c is None or len(c.keyframe_points) == 0:
        return None
    return fcurves.read_keys(c)


def read_baked(obj):
    """The baked channels as arrays; raises ValueError when there is no gait bake."""
    anim = obj.animation_data
    action = anim.action if anim is not None else None
    if action is None:
        raise ValueError(tip_("'{}' has no Action: bake the gait first").format(obj.name))
    settings = obj.kodawari_gait
    rig, chains = rigmod.rig_dict(obj, settings)
    contacts = [_curve(action, obj, f'["{p}"]') for p in CONTACT_PROPS]
    gait = _curve(action, obj, f'["{GAIT_PROP}"]')
    if any(c is None for c in contacts) or gait is None:
        raise ValueError(
            tip_(
                "'{}' has no gait bake (no kodawari_contact_* channels): bake the gait first"
            ).format(obj.name)
        )
    frames = gait[0]
    n = len(frames)
    axes = rigmod.hinge_axes(obj, chains, rig["forward"])
    angles = []
    for leg in LEG_NAMES:
        for name in chains[leg]:
            mode, sign = rigmod.hinge_channel(axes[name])
            if mode == "X":
                keys = _curve(action, obj, f'pose.bones["{name}"].rotation_euler', 0)
                if keys is None or len(keys[0]) != n:
                    raise ValueError(
                        tip_("bone '{}' has no baked rotation: bake the gait again").format(name)
                    )
                angles.append(sign * keys[1].astype(np.float64))
                continue
            q = []
            for i in range(4):
                keys = _curve(action, obj, f'pose.bones["{name}"].rotation_quaternion', i)
                if keys is None or len(keys[0]) != n:
                    raise ValueError(
                        tip_("bone '{}' has no baked rotation: bake the gait again").format(name)
                    )
                q.append(keys[1].astype(np.float64))
            q = np.stack(q, axis=1)
            # Hinge angle back from the quaternion (w, axis * sin(a/2)).
            angles.append(2 * np.arctan2(q[:, 1:] @ axes[name], q[:, 0]))
    data = {
        "rig": rig,
        "chains": chains,
        "frames": frames,
        "angles": np.ascontiguousarray(np.stack(angles, axis=1)),
        "contacts": np.stack([c[1] for c in contacts], axis=1).astype(np.float64),
        "gait": np.round(gait[1]).astype(int),
    }
    if not rig["on_object"]:
        body = settings.body_bone
        loc = [_curve(action, obj, f'pose.bones["{body}"].location', i) for i in range(3)]
        rot = [
            _curve(action, obj, f'pose.bones["{body}"].rotation_quaternion', i) for i in range(4)
        ]
        if any(c is None for c in loc + rot):
            raise ValueError(
                tip_("the body bone '{}' has no baked motion: bake the gait again").format(body)
            )
        data["body_location"] = np.ascontiguousarray(
            np.stack([c[1] for c in loc], axis=1), dtype=np.float64
        )
        data["body_rotation"] = np.ascontiguousarray(
            np.stack([c[1] for c in rot], axis=1), dtype=np.float64
        )
    return data


def evaluated_legs(obj, scene, frames, chains):
    """What Blender shows: feet (the last leg bone's tail) and leg roots (the first
    bone's head), (F, 4, 3) in the gait frame (world metres less the armature's
    placement), from the evaluated pose at each frame (scene.frame_set: other Actions,
    NLA, drivers and constraints included). One frame change and one foreach_get per
    frame; the current frame is put back."""
    names = list(obj.pose.bones.keys())
    feet_index = [names.index(chains[k][-1]) for k in LEG_NAMES]
    root_index = [names.index(chains[k][0]) for k in LEG_NAMES]
    origin = rigmod.gait_origin(obj)
    n = len(names)
    heads = np.empty(n * 3, dtype=np.float32)
    tails = np.empty(n * 3, dtype=np.float32)
    feet = np.empty((len(frames), 4, 3))
    roots = np.empty((len(frames), 4, 3))
    current = scene.frame_current, scene.frame_subframe
    try:
        for i, f in enumerate(frames):
            scene.frame_set(int(f))
            world = rigmod.mat4(obj.matrix_world)
            obj.pose.bones.foreach_get("head", heads)
            obj.pose.bones.foreach_get("tail", tails)
            h = heads.reshape(-1, 3).astype(np.float64) @ world[:3, :3].T + world[:3, 3]
            t = tails.reshape(-1, 3).astype(np.float64) @ world[:3, :3].T + world[:3, 3]
            feet[i] = t[feet_index] - origin
            roots[i] = h[root_index] - origin
    finally:
        scene.frame_set(current[0], subframe=current[1])
    return feet, roots


def headings_from_roots(roots):
    """Unit forward of the body per frame: hind roots to fore roots, horizontal."""
    h = (roots[:, 0] + roots[:, 1] - roots[:, 2] - roots[:, 3]) / 2
    h[:, 2] = 0
    return h / np.maximum(np.linalg.norm(h, axis=1, keepdims=True), 1e-12)


def headings_of(rig, body_rotation):
    """Unit forward of the body per frame, from the baked body rotation."""
    rest = rig["body_rest"]
    q = body_rotation / np.linalg.norm(body_rotation, axis=1, keepdims=True)
    w, x, y, z = q.T
    m = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )
    world = np.einsum("ij,fjk,kl->fil", rest, m, rest.T)
    h = world @ rig["forward"]
    h[:, 2] = 0
    return h / np.linalg.norm(h, axis=1, keepdims=True)


def measure_baked(obj, fps, scene=None):
    """The gait criteria of what Blender shows: contacts, gait and angles from the baked
    Action, feet and roots from the evaluated pose (evaluated_legs)."""
    data = read_baked(obj)
    scene = scene or bpy.context.scene
    feet, roots = evaluated_legs(obj, scene, data["frames"], data["chains"])
    rig = data["rig"]
    limit_min = np.concatenate([leg["limit_min"] for leg in rig["legs"]])
    limit_max = np.concatenate([leg["limit_max"] for leg in rig["legs"]])
    reach = np.array([rig_reach(rig, k) for k in range(4)])
    headings = headings_from_roots(roots)
    segs = metrics.measure(
        feet,
        roots,
        headings,
        data["contacts"],
        data["gait"],
        data["angles"],
        limit_min,
        limit_max,
        rigmod.neutral_offsets(rig),
        reach,
        fps,
    )
    data.update(feet=feet, roots=roots, headings=headings, segments=segs, reach=reach)
    return data


def rig_reach(rig, leg):
    legrig = rig["legs"][leg]
    points = np.vstack([legrig["heads"], legrig["tail"][None, :]])
    planar = np.diff(points, axis=0)
    f = planar @ rig["forward"]
    length = float(np.sum(np.hypot(f, planar[:, 2])))
    return length * rig.get("reach_fraction", 0.5)


# --- drawing ------------------------------------------------------------------------
def _line(img, x0, y0, x1, y1, color, width=1):
    n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
    xs = np.linspace(x0, x1, n).round().astype(int)
    ys = np.linspace(y0, y1, n).round().astype(int)
    h, w = img.shape[:2]
    for d in range(-(width // 2), width - width // 2):
        ok = (xs >= 0) & (xs < w) & (ys + d >= 0) & (ys + d < h)
        img[ys[ok] + d, xs[ok]] = color


def draw_report(data, fps, width=1400):
    feet, roots, headings = data["feet"], data["roots"], data["headings"]
    contacts, gait, reach = data["contacts"], data["gait"], data["reach"]
    n = len(gait)
    offsets = metrics.fore_aft(feet, roots, headings, rigmod.neutral_offsets(data["rig"]))
    left, right = 70, 20
    plot_w = width - left - right
    row_h, top = 26, 40
    foot_h = 4 * row_h
    traj_top = top + foot_h + 60
    traj_h = 300
    height = traj_top + traj_h + 50
    img = np.ones((height, width, 4), dtype=np.float32)
    black = (0.1, 0.1, 0.1, 1)
    xs = left + np.arange(n) * plot_w / max(n - 1, 1)
    # gait segments behind both plots, with their names
    for g, lo, hi in metrics.segments(gait):
        x0, x1 = int(xs[lo]), int(xs[hi - 1]) + 1
        img[top : top + foot_h, x0:x1] = GAIT_COLORS[g]
        img[traj_top : traj_top + traj_h, x0:x1] = GAIT_COLORS[g]
        if x1 - x0 > 40:
            draw_text(
                img, x0 + 3, top - 14, metrics.GAITS[g].replace("GALLOP_ROTARY", "ROTARY"), black, 1
            )
    draw_text(img, left, 8, "FOOTFALLS (HILDEBRAND): BLACK = PLANTED", black, 2)
    for row, leg in enumerate((2, 0, 1, 3)):  # LH, LF, RF, RH
        y = top + row * row_h
        draw_text(img, 10, y + 6, metrics.LEGS[leg], black, 2)
        planted = contacts[:, leg] > 0.5
        for f in np.flatnonzero(planted):
            img[y + 4 : y + row_h - 4, int(xs[f]) : int(xs[min(f + 1, n - 1)]) + 1] = black
    # fore-aft trajectories relative to each leg's root (seed figures 4.7, 4.8)
    lim = float(max(reach.max(), np.abs(offsets).max())) * 1.1

    def ypix(v):
        return traj_top + traj_h / 2 - v / lim * (traj_h / 2)

    draw_text(
        img, left, traj_top - 34, "FORE-AFT FOOT POSITION FROM LEG ROOT (M), +- REACH", black, 2
    )
    _line(img, left, ypix(0), left + plot_w, ypix(0), (0.5, 0.5, 0.5, 1))
    for leg in range(4):
        for sign in (1, -1):
            yl = ypix(sign * reach[leg])
            for x in range(left, left + plot_w, 12):
                _line(img, x, yl, min(x + 6, left + plot_w), yl, LEG_COLORS[leg])
    for leg in range(4):
        for f in range(n - 1):
            _line(
                img,
                xs[f],
                ypix(offsets[f, leg]),
                xs[f + 1],
                ypix(offsets[f + 1, leg]),
                LEG_COLORS[leg],
                2,
            )
        draw_text(
            img, left + 10 + leg * 60, traj_top + traj_h + 10, metrics.LEGS[leg], LEG_COLORS[leg], 2
        )
    for v in (-lim / 1.1, 0.0, lim / 1.1):
        draw_text(img, 4, int(ypix(v)) - 4, f"{v:+.1f}", black, 1)
    seconds = n / fps
    draw_text(img, left + plot_w - 160, traj_top + traj_h + 10, f"{seconds:.1f} S", black, 2)
    return img


def save_png(pixels, filepath):
    """(H, W, 4) float image, row 0 at the top, saved through bpy.data.images."""
    h, w = pixels.shape[:2]
    image = bpy.data.images.new("kodawari_gait_report", width=w, height=h, alpha=True)
    try:
        image.pixels.foreach_set(np.ascontiguousarray(pixels[::-1]).reshape(-1))
        image.filepath_raw = filepath
        image.file_format = "PNG"
        image.save()
    finally:
        bpy.data.images.remove(image)


def write_report(obj, filepath, fps):
    base, ext = os.path.splitext(bpy.path.abspath(filepath))
    if ext.lower() not in (".png", ".json"):
        base = base + ext
    data = measure_baked(obj, fps)
    directory = os.path.dirname(base)
    if directory:
        os.makedirs(directory, exist_ok=True)
    report = {
        "object": obj.name,
        "fps": fps,
        "frame_start": float(data["frames"][0]),
        "frame_end": float(data["frames"][-1]),
        "reach": [float(r) for r in data["reach"]],
        "segments": data["segments"],
    }
    with open(base + ".json", "w") as fh:
        json.dump(report, fh, indent=1)
    save_png(draw_report(data, fps), base + ".png")  # a quick look in Blender's Image Editor
    # The report to read and zoom: SVG with real text, axes, units and a legend.
    data["neutral"] = rigmod.neutral_offsets(data["rig"])
    report_svg.write(data, fps, base + ".svg", f"Gait report: {obj.name}")
    return base + ".svg", base + ".json", data
