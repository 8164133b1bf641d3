"""Settings of view-dependent hair, stored on the armature object (Object.kodawari_hair)."""

import math

import bpy

from . import chains, runtime

# Influence for which a view key keeps half its weight 60 degrees away:
# ((cos 60° + 1) / 2) ** p = 0.5  ->  p = ln 0.5 / ln 0.75 ≈ 2.41 (docs/algorithms.md §3.2).
DEFAULT_INFLUENCE = math.log(0.5) / math.log(0.75)

CONDITIONS = (
    ("VIEW", "View", "Weighted by how close the camera's direction is to the keyed one"),
    ("POSE", "Pose", "Weighted by how close the reference bone's rotation is to the keyed one"),
    ("SPEED", "Speed", "Weighted by how close the reference bone's speed is to the keyed one"),
)


def _changed(self, context):
    runtime.invalidate(self.id_data)


def _root_changed(self, context):
    """A root bone named by hand: the rod's identity moves to that bone (or, when no bone has
    that name, the rod lets go of its old one instead of snapping back to it)."""
    obj = self.id_data
    pose_bone = obj.pose.bones.get(self.root_bone) if obj.pose is not None else None
    if pose_bone is not None:
        chains.tag_root(pose_bone, self)
    elif self.uid:
        self.uid = ""
    runtime.invalidate(obj)


class KodawariHairJoint(bpy.types.PropertyGroup):
    rotation: bpy.props.FloatVectorProperty(
        name="Rotation",
        size=4,
        default=(1.0, 0.0, 0.0, 0.0),
        subtype="QUATERNION",
        update=_changed,
        description="The bone's pose rotation (rotation_quaternion) in this key",
    )


class KodawariHairKey(bpy.types.PropertyGroup):
    name: bpy.props.StringProperty(name="Name", default="Key", description="Name of this key")
    condition: bpy.props.EnumProperty(
        name="Condition",
        items=CONDITIONS,
        default="VIEW",
        update=_changed,
        description="When this shape counts: for a view, a pose or a speed",
    )
    direction: bpy.props.FloatVectorProperty(
        name="Direction",
        size=3,
        default=(0.0, -1.0, 0.0),
        subtype="DIRECTION",
        update=_changed,
        description="View: the direction the camera looks from, seen from the reference bone",
    )
    rotation: bpy.props.FloatVectorProperty(
        name="Rotation",
        size=4,
        default=(1.0, 0.0, 0.0, 0.0),
        subtype="QUATERNION",
        update=_changed,
        description="Pose: the reference bone's rotation this shape belongs to",
    )
    speed: bpy.props.FloatProperty(
        name="Speed",
        default=1.0,
        min=0.0,
        unit="VELOCITY",
        update=_changed,
        description="Speed: how fast the reference bone moves for this shape",
    )
    influence: bpy.props.FloatProperty(
        name="Influence",
        default=DEFAULT_INFLUENCE,
        min=0.01,
        soft_max=64.0,
        update=_changed,
        description="How narrowly this key's shape applies: lower spreads it over more views, poses or speeds",
    )
    shape: bpy.props.CollectionProperty(
        type=KodawariHairJoint, name="Shape", description="The chain's bone rotations in this key"
    )


class KodawariHairRod(bpy.types.PropertyGroup):
    root_bone: bpy.props.StringProperty(
        name="Root Bone",
        update=_root_changed,
        description="First bone of the chain; the chain hangs from its parent",
    )
    reference_bone: bpy.props.StringProperty(
        name="Reference Bone",
        update=_changed,
        description="Bone that views, poses and speeds are measured from, usually the head (empty: the root's parent)",
    )
    stiffness: bpy.props.FloatProperty(
        name="Stiffness",
        default=0.5,
        min=0.01,
        max=1.0,
        update=_changed,
        subtype="FACTOR",
        description="How strongly the chain returns to its keyed shape",
    )
    # 2/s (1/s until this release): with 1/s strands of 24-64 bones swung for more than 10 s (the
    # coarse substep's numerical damping had hidden it); 2/s settles them in about 6 s
    # (docs/algorithms.md §3.3). Rods saved with the old default now use 2/s.
    damping: bpy.props.FloatProperty(
        name="Damping",
        default=2.0,
        min=0.0,
        soft_max=20.0,
        update=_changed,
        description="How quickly swinging dies down (per second)",
    )
    gravity: bpy.props.FloatProperty(
        name="Gravity",
        default=1.0,
        soft_min=0.0,
        soft_max=2.0,
        update=_changed,
        description="How strongly gravity pulls, as a multiple of the scene's gravity",
    )
    substeps: bpy.props.IntProperty(
        name="Substeps",
        default=4,
        min=1,
        max=64,
        update=_changed,
        description="Simulation steps per 1/24 s: more for fast motion (independent of the frame rate)",
    )
    iterations: bpy.props.IntProperty(
        name="Iterations",
        default=1,
        min=1,
        max=64,
        update=_changed,
        description="Solver passes per step: more keeps the chain's length more exactly and holds its shape more stiffly (at high Stiffness, several passes hold the shape almost rigidly)",
    )
    radius: bpy.props.FloatProperty(
        name="Radius",
        default=0.01,
        min=0.0,
        subtype="DISTANCE",
        unit="LENGTH",
        update=_changed,
        description="Thickness of the chain: how far it stays from colliders",
    )
    wind: bpy.props.FloatVectorProperty(
        name="Wind",
        size=3,
        default=(0.0, 0.0, 0.0),
        subtype="VELOCITY",
        unit="VELOCITY",
        update=_changed,
        description="Wind speed and direction in the world; gusts vary it over time",
    )
    keys: bpy.props.CollectionProperty(
        type=KodawariHairKey, name="Keys", description="Shapes of the chain and when each applies"
    )
    active_key: bpy.props.IntProperty(
        name="Active Key", default=0, min=0, description="The key shown below the list"
    )
    # Identity of the rod, also stored on its root pose bone (chains.ROD_ID_PROPERTY): a
    # custom property travels with the bone through renames, so the rod finds it again.
    uid: bpy.props.StringProperty(
        name="Rod ID",
        options={"HIDDEN"},
        description="Identifies the rod when its root bone is renamed",
    )


class KodawariHairCollider(bpy.types.PropertyGroup):
    bone: bpy.props.StringProperty(
        name="Bone", update=_changed, description="The collider follows this bone"
    )
    shape: bpy.props.EnumProperty(
        name="Shape",
        items=(
            ("SPHERE", "Sphere", "A ball around a point"),
            ("CAPSULE", "Capsule", "A rounded cylinder along the bone"),
        ),
        default="SPHERE",
        update=_changed,
        description="Shape the hair cannot enter",
    )
    radius: bpy.props.FloatProperty(
        name="Radius",
        default=0.1,
        min=0.0,
        subtype="DISTANCE",
        unit="LENGTH",
        update=_changed,
        description="Size of the collider",
    )
    length: bpy.props.FloatProperty(
        name="Length",
        default=0.2,
        min=0.0,
        subtype="DISTANCE",
        unit="LENGTH",
        update=_changed,
        description="Capsule: how far it reaches along the bone",
    )
    offset: bpy.props.FloatVectorProperty(
        name="Offset",
        size=3,
        default=(0.0, 0.0, 0.0),
        subtype="TRANSLATION",
        unit="LENGTH",
        update=_changed,
        description="Where the collider sits (a capsule: where it starts), relative to the bone",
    )


class KodawariHairSettings(bpy.types.PropertyGroup):
    enabled: bpy.props.BoolProperty(
        name="Enabled",
        default=True,
        update=_changed,
        description="Simulate the hair live as frames change",
    )
    rods: bpy.props.CollectionProperty(
        type=KodawariHairRod, name="Rods", description="Simulated bone chains"
    )
    colliders: bpy.props.CollectionProperty(
        type=KodawariHairCollider,
        name="Colliders",
        description="Shapes the hair cannot pass through",
    )
    active_rod: bpy.props.IntProperty(
        name="Active Rod", default=0, min=0, description="The rod shown below the list"
    )
    active_collider: bpy.props.IntProperty(
        name="Active Collider", default=0, min=0, description="The collider shown below the list"
    )


CLASSES = (
    KodawariHairJoint,
    KodawariHairKey,
    KodawariHairRod,
    KodawariHairCollider,
    KodawariHairSettings,
)
