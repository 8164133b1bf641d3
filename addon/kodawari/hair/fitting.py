"""Sketch editing (docs/algorithms.md §3.6): the chain takes the shape
of one stroke as seen from the current view. The stroke is projected onto the plane
through the chain root facing the view, resampled by the bone lengths from the root,
and each bone is turned (no twist) to point at its resampled joint."""

from bpy.app.translations import pgettext_tip as tip_
from mathutils import Vector


class FitError(ValueError):
    pass


def project_to_root_plane(points, root, eye, forward, perspective):
    """Stroke points moved along the view onto the plane through `root` facing the view."""
    projected = []
    for p in points:
        if perspective:
            ray = p - eye
            denom = ray.dot(forward)
            if denom <= 1e-9:
                continue  # behind the eye
            t = (root - eye).dot(forward) / denom
            projected.append(eye + ray * t)
        else:
            projected.append(p - forward * (p - root).dot(forward))
    return projected


def resample(polyline, start, lengths):
    """Joints from `start`, each at its bone length from the previous one along the polyline
    (beyond the stroke's end, straight on along its last direction)."""
    joints = [start.copy()]
    segment, current = 0, start.copy()
    last_direction = (polyline[-1] - polyline[-2]).normalized()
    for length in lengths:
        found = None
        while segment < len(polyline) - 1:
            a, b = polyline[segment], polyline[segment + 1]
            # Farthest-forward intersection of |a + t (b - a) - current| = length, t in [0, 1].
            d = b - a
            f = a - current
            qa, qb, qc = d.dot(d), 2 * f.dot(d), f.dot(f) - length * length
            disc = qb * qb - 4 * qa * qc
            if qa > 1e-18 and disc >= 0:
                t = (-qb + disc**0.5) / (2 * qa)
                if 0.0 <= t <= 1.0:
                    found = a + d * t
                    polyline = [found] + polyline[segment + 1 :]
                    segment = 0
                    break
            segment += 1
        if found is None:
            found = current + last_direction * length
            polyline = [found, found + last_direction]
            segment = 0
        joints.append(found)
        current = found
    return joints


def fit_chain_to_stroke(obj, parent, chain, points_world, eye, forward, perspective):
    """Pose-bone rotations (quaternions) that lay `chain` along the stroke."""
    root_world = obj.matrix_world @ chain[0].head
    if perspective and (root_world - eye).dot(forward) <= 1e-6:
        raise FitError(tip_("The chain root is not in front of the view"))
    projected = project_to_root_plane(points_world, root_world, eye, forward, perspective)
    if len(projected) < 2:
        raise FitError(tip_("The stroke is behind the view"))
    to_armature = obj.matrix_world.inverted()
    polyline = [to_armature @ p for p in projected]
    # Clean duplicates, and start the stroke at the end nearer the root.
    cleaned = [polyline[0]]
    for p in polyline[1:]:
        if (p - cleaned[-1]).length > 1e-7:
            cleaned.append(p)
    if len(cleaned) < 2:
        raise FitError(tip_("The stroke has no length"))
    root = chain[0].head.copy()
    if (cleaned[-1] - root).length < (cleaned[0] - root).length:
        cleaned.reverse()
    axes, lengths = [], []
    bones = [pb.bone for pb in chain]
    for k, bone in enumerate(bones):
        if k + 1 < len(bones):
            offset = (bone.matrix_local.inverted() @ bones[k + 1].matrix_local).translation
        else:
            offset = Vector((0.0, bone.length, 0.0))
        axes.append(offset.normalized())
        lengths.append(offset.length)
    joints = resample(cleaned, root, lengths)
    rotations = []
    parent_frame = parent.matrix.to_quaternion()
    previous_rest = parent.bone.matrix_local
    for k, bone in enumerate(bones):
        rest_in_parent = (previous_rest.inverted() @ bone.matrix_local).to_quaternion()
        frame = parent_frame @ rest_in_parent
        target = frame.inverted() @ (joints[k + 1] - joints[k])
        basis = axes[k].rotation_difference(target.normalized())
        rotations.append(basis)
        parent_frame = frame @ basis
        previous_rest = bone.matrix_local
    return rotations
