"""Joint chains of an armature: which bones make a rod and its static geometry."""

import math
import uuid

import numpy as np


class ChainError(ValueError):
    """A rod that cannot be built; the message is shown to the user as is."""


def chain_from(bone):
    """`bone` and its chain of single children down to the tip (data bones).

    Raises ChainError on a branch or a zero-length bone."""
    chain = [bone]
    while True:
        tip = chain[-1]
        if tip.length < 1e-6:
            raise ChainError(f"Bone '{tip.name}' has zero length: a rod needs bones with a length")
        children = list(tip.children)
        if not children:
            return chain
        if len(children) > 1:
            raise ChainError(
                f"Bone '{tip.name}' has {len(children)} children: a rod must be an unbranched chain "
                f"(select the bones after the branch instead)"
            )
        chain.append(children[0])


# Custom property on a rod's root pose bone holding the rod's uid: it follows the bone
# through renames, so a renamed root is found again (and the setting renamed with it).
ROD_ID_PROPERTY = "kodawari_rod"


def tag_root(pose_bone, rod):
    """Marks `pose_bone` as the root of `rod` (giving the rod a uid if it has none)."""
    if not rod.uid:
        rod.uid = uuid.uuid4().hex
    pose_bone[ROD_ID_PROPERTY] = rod.uid


def _renamed_root(armature_object, rod):
    """The pose bone that carries the rod's uid, if the root was renamed."""
    if not rod.uid:
        return None
    for pose_bone in armature_object.pose.bones:  # only when the name no longer resolves
        if pose_bone.get(ROD_ID_PROPERTY) == rod.uid:
            return pose_bone
    return None


def resolve_rod(armature_object, rod):
    """(parent, reference, chain) data bones of a rod setting, or ChainError. A root bone
    renamed since the rod was made is followed, and the setting takes the new name."""
    bones = armature_object.data.bones
    root = bones.get(rod.root_bone)
    if root is None:
        renamed = _renamed_root(armature_object, rod)
        if renamed is not None:
            root = renamed.bone
            try:
                rod.root_bone = renamed.name
            except (AttributeError, RuntimeError):  # a context that may not write IDs (drawing)
                pass
    if root is None:
        raise ChainError(
            f"Rod '{rod.root_bone}' has 0 joints: its root bone is missing from the armature"
        )
    if root.parent is None:
        raise ChainError(
            f"Bone '{root.name}' has no parent to attach to: a rod hangs from a kinematic bone"
        )
    reference = root.parent
    if rod.reference_bone:
        reference = bones.get(rod.reference_bone)
        if reference is None:
            raise ChainError(
                f"Reference bone '{rod.reference_bone}' of rod '{root.name}' is missing"
            )
    return root.parent, reference, chain_from(root)


def _quat(matrix):
    q = matrix.to_quaternion()
    return (q.w, q.x, q.y, q.z)


def chain_geometry(parent, chain):
    """offsets (n+1, 3) and rest rotations (n, 4) as RodSystem.add_rod wants them."""
    offsets, rotations = [], []
    previous = parent
    for bone in chain:
        relative = previous.matrix_local.inverted() @ bone.matrix_local
        offsets.append(tuple(relative.translation))
        rotations.append(_quat(relative))
        previous = bone
    offsets.append((0.0, chain[-1].length, 0.0))
    return np.array(offsets, dtype=np.float64), np.array(rotations, dtype=np.float64)


def finite_quaternions(values):
    """True when every quaternion is finite and not zero."""
    a = np.asarray(values, dtype=np.float64).reshape(-1, 4)
    return bool(np.isfinite(a).all() and (np.linalg.norm(a, axis=1) > 1e-6).all())


def degrees(radians):
    return radians * 180.0 / math.pi


def is_selected(pose_bone):
    """Bone selection: on the pose bone in Blender 5.0+, on the data bone before."""
    if "select" in pose_bone.bl_rna.properties:
        return pose_bone.select
    return pose_bone.bone.select


def set_selected(pose_bone, value):
    if "select" in pose_bone.bl_rna.properties:
        pose_bone.select = value
    else:
        pose_bone.bone.select = value
