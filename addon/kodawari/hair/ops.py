"""Operators of view-dependent hair. Every operator validates first and changes
nothing when it refuses (a clear report, {'CANCELLED'})."""

import math

import bpy
from bpy.app.translations import pgettext_tip as tip_
from mathutils import Vector

from .. import editable
from ..bake_job import BakeError, BakeOperator, frame_range
from . import chains, fitting, props, runtime
from .bake import HairBakeJob


class _Refusal(Exception):
    """Bad input: the message is reported and the operator cancels with nothing changed."""


def _armature(context):
    obj = context.active_object
    if obj is None or obj.type != "ARMATURE":
        raise _Refusal(tip_("Select an armature: the active object is not an armature"))
    why = editable.why_not(obj, tip_("change its hair"))
    if why:
        raise _Refusal(why)
    return obj


def _rod(obj, index):
    settings = obj.kodawari_hair
    if not len(settings.rods):
        raise _Refusal(tip_("This armature has no rods: add one with Add Rod (kodawari.rod_add)"))
    i = settings.active_rod if index < 0 else index
    if i >= len(settings.rods):
        raise _Refusal(
            tip_("Rod index {} is out of range (the armature has {} rods)").format(
                i, len(settings.rods)
            )
        )
    return i, settings.rods[i]


def _chain_pose_bones(obj, rod):
    try:
        parent, reference, chain = chains.resolve_rod(obj, rod)
    except chains.ChainError as exc:
        raise _Refusal(str(exc)) from None
    pose = obj.pose.bones
    return pose[parent.name], pose[reference.name], [pose[b.name] for b in chain]


def _pose_shape(chain):
    """The chain's current pose as per-joint rotations; refuses NaN or zero quaternions."""
    shape = []
    for pb in chain:
        q = (
            tuple(pb.rotation_quaternion)
            if pb.rotation_mode == "QUATERNION"
            else tuple(pb.matrix_basis.to_quaternion())
        )
        if not chains.finite_quaternions(q):
            raise _Refusal(
                tip_(
                    "Bone '{}' has an invalid rotation (NaN or zero): fix the pose before keying"
                ).format(pb.name)
            )
        n = math.sqrt(sum(c * c for c in q))
        shape.append(tuple(c / n for c in q))
    return shape


def _viewport_eye(context):
    """(eye position, forward, perspective) of a 3-D viewport in this screen, or None."""
    spaces = []
    if context.space_data is not None and context.space_data.type == "VIEW_3D":
        spaces.append(context.space_data)
    screen = context.screen
    if screen is not None:
        spaces += [a.spaces.active for a in screen.areas if a.type == "VIEW_3D"]
    for space in spaces:
        rv3d = getattr(space, "region_3d", None)
        if rv3d is not None:
            inverse = rv3d.view_matrix.inverted()
            forward = -(inverse.to_3x3() @ Vector((0.0, 0.0, 1.0)))
            return inverse.translation.copy(), forward.normalized(), rv3d.is_perspective
    return None


def _eye(context, source):
    if source == "VIEWPORT":
        eye = _viewport_eye(context)
        if eye is None:
            raise _Refusal(tip_("No 3D viewport to look through here: use source 'CAMERA'"))
        return eye
    camera = context.scene.camera
    if camera is None:
        raise _Refusal(tip_("The scene has no active camera: set one (or use source 'VIEWPORT')"))
    m = camera.matrix_world
    forward = -(m.to_3x3().normalized() @ Vector((0.0, 0.0, 1.0)))
    perspective = camera.type != "CAMERA" or camera.data.type != "ORTHO"
    return m.translation.copy(), forward.normalized(), perspective


def _new_key(rod, condition, shape, base_name):
    count = sum(1 for k in rod.keys if k.condition == condition)
    key = rod.keys.add()
    key.name = f"{base_name} {count + 1}"
    key.condition = condition
    for q in shape:
        joint = key.shape.add()
        joint.rotation = q
    rod.active_key = len(rod.keys) - 1
    return key


class _HairOperator:
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        try:
            return self.run(context)
        except _Refusal as refusal:
            self.report({"ERROR"}, str(refusal))
            return {"CANCELLED"}


class KODAWARI_OT_rod_add(_HairOperator, bpy.types.Operator):
    """Make each selected bone and its chain of single children a simulated rod"""

    bl_idname = "kodawari.rod_add"
    bl_label = "Add Rod"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context):
        obj = _armature(context)
        selected = [pb for pb in obj.pose.bones if chains.is_selected(pb)]
        if not selected:
            raise _Refusal(
                tip_("No bones selected: select the first bone of each chain in pose mode")
            )
        names = {pb.name for pb in selected}
        roots = [pb.bone for pb in selected if pb.parent is None or pb.parent.name not in names]
        used = set()
        for rod in obj.kodawari_hair.rods:
            try:
                used.update(b.name for b in chains.resolve_rod(obj, rod)[2])
            except chains.ChainError:
                continue
        plans = []
        for root in roots:
            if root.parent is None:
                raise _Refusal(
                    tip_(
                        "Bone '{}' has no parent to attach to: a rod hangs from a kinematic bone"
                    ).format(root.name)
                )
            try:
                chain = chains.chain_from(root)
            except chains.ChainError as exc:
                raise _Refusal(str(exc)) from None
            taken = [b.name for b in chain if b.name in used]
            if taken:
                raise _Refusal(tip_("Bone '{}' already belongs to a rod").format(taken[0]))
            used.update(b.name for b in chain)
            plans.append((root, chain))
        settings = obj.kodawari_hair
        for root, chain in plans:
            rod = settings.rods.add()
            rod.root_bone = (
                root.name
            )  # tags the root bone with the rod's identity (props._root_changed)
            for bone in chain:
                pb = obj.pose.bones[bone.name]
                if pb.rotation_mode != "QUATERNION":
                    pb.rotation_mode = "QUATERNION"
        settings.active_rod = len(settings.rods) - 1
        runtime.invalidate(obj)
        # The live handler writes pose bones on frame changes; renders must wait for it.
        context.scene.render.use_lock_interface = True
        names = [r.name for r, _ in plans]
        shown = ", ".join(names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
        self.report({"INFO"}, tip_("Added {} rod(s): {}").format(len(plans), shown))
        return {"FINISHED"}


class KODAWARI_OT_rod_remove(_HairOperator, bpy.types.Operator):
    """Remove a rod (its bones keep their current pose)"""

    bl_idname = "kodawari.rod_remove"
    bl_label = "Remove Rod"
    bl_options = {"REGISTER", "UNDO"}
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        index, rod = _rod(obj, self.rod_index)
        name = rod.root_bone
        settings = obj.kodawari_hair
        settings.rods.remove(index)
        settings.active_rod = max(0, min(settings.active_rod, len(settings.rods) - 1))
        runtime.invalidate(obj)
        self.report({"INFO"}, tip_("Removed rod '{}'").format(name))
        return {"FINISHED"}


class KODAWARI_OT_rod_key_view(_HairOperator, bpy.types.Operator):
    """Key the chain's current pose for the current view direction"""

    bl_idname = "kodawari.rod_key_view"
    bl_label = "Key View"
    bl_options = {"REGISTER", "UNDO"}
    source: bpy.props.EnumProperty(
        name="Source",
        default="CAMERA",
        items=(
            ("CAMERA", "Camera", "Look through the scene's active camera"),
            ("VIEWPORT", "Viewport", "The 3D viewport's view"),
        ),
        description="Which view to key the shape for",
    )
    influence: bpy.props.FloatProperty(
        name="Influence",
        default=props.DEFAULT_INFLUENCE,
        min=0.01,
        soft_max=64.0,
        description="How narrowly the shape applies (the default: half strength 60° away)",
    )
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        _, reference, chain = _chain_pose_bones(obj, rod)
        eye, _, _ = _eye(context, self.source)
        shape = _pose_shape(chain)
        direction = view_direction(obj, reference, eye)
        key = _new_key(rod, "VIEW", shape, "View")
        key.direction = direction
        key.influence = self.influence
        runtime.invalidate(obj)
        self.report({"INFO"}, tip_("Keyed '{}' on rod '{}'").format(key.name, rod.root_bone))
        return {"FINISHED"}


def view_direction(obj, reference, eye_world):
    """Unit direction from the reference bone to the eye, in the reference bone's frame."""
    eye = obj.matrix_world.inverted() @ eye_world
    rotation = reference.matrix.to_quaternion()
    d = rotation.inverted() @ (eye - reference.matrix.translation)
    if d.length < 1e-6:
        raise _Refusal(
            tip_(
                "The camera is at the reference bone '{}': the view direction is undefined"
            ).format(reference.name)
        )
    return d.normalized()


class KODAWARI_OT_rod_key_pose(_HairOperator, bpy.types.Operator):
    """Key the chain's current pose for the reference bone's current rotation"""

    bl_idname = "kodawari.rod_key_pose"
    bl_label = "Key Pose"
    bl_options = {"REGISTER", "UNDO"}
    influence: bpy.props.FloatProperty(
        name="Influence",
        default=props.DEFAULT_INFLUENCE,
        min=0.01,
        soft_max=64.0,
        description="How narrowly the shape applies (the default: half strength 60° away)",
    )
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        _, reference, chain = _chain_pose_bones(obj, rod)
        shape = _pose_shape(chain)
        rotation = tuple(reference.matrix.to_quaternion().normalized())
        if not chains.finite_quaternions(rotation):
            raise _Refusal(
                tip_("Reference bone '{}' has an invalid rotation").format(reference.name)
            )
        key = _new_key(rod, "POSE", shape, "Pose")
        key.rotation = rotation
        key.influence = self.influence
        runtime.invalidate(obj)
        self.report({"INFO"}, tip_("Keyed '{}' on rod '{}'").format(key.name, rod.root_bone))
        return {"FINISHED"}


class KODAWARI_OT_rod_key_speed(_HairOperator, bpy.types.Operator):
    """Key the chain's current pose for a speed of the reference bone"""

    bl_idname = "kodawari.rod_key_speed"
    bl_label = "Key Speed"
    bl_options = {"REGISTER", "UNDO"}
    speed: bpy.props.FloatProperty(
        name="Speed",
        default=2.0,
        min=0.0,
        unit="VELOCITY",
        description="The reference bone's speed (m/s) at which this shape applies",
    )
    influence: bpy.props.FloatProperty(
        name="Influence",
        default=props.DEFAULT_INFLUENCE,
        min=0.01,
        soft_max=64.0,
        description="How narrowly the shape applies (the default: half strength 60° away)",
    )
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        _, _, chain = _chain_pose_bones(obj, rod)
        if not math.isfinite(self.speed):
            raise _Refusal(tip_("The speed must be a finite number"))
        shape = _pose_shape(chain)
        key = _new_key(rod, "SPEED", shape, "Speed")
        key.speed = self.speed
        key.influence = self.influence
        runtime.invalidate(obj)
        self.report(
            {"INFO"},
            tip_("Keyed '{}' at {:g} m/s on rod '{}'").format(key.name, self.speed, rod.root_bone),
        )
        return {"FINISHED"}


def _key(rod, index):
    i = rod.active_key if index < 0 else index
    if not len(rod.keys) or i >= len(rod.keys):
        raise _Refusal(tip_("Rod '{}' has no key {}").format(rod.root_bone, i))
    return i, rod.keys[i]


class KODAWARI_OT_rod_key_preview(_HairOperator, bpy.types.Operator):
    """Snap the chain to a key's shape (turn the live simulation off to keep it)"""

    bl_idname = "kodawari.rod_key_preview"
    bl_label = "Preview Key"
    bl_options = {"REGISTER", "UNDO"}
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )
    key_index: bpy.props.IntProperty(
        name="Key", default=-1, description="Which key (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        _, key = _key(rod, self.key_index)
        _, _, chain = _chain_pose_bones(obj, rod)
        if len(key.shape) != len(chain):
            raise _Refusal(
                tip_("Key '{}' has {} joints, the chain has {}: re-key it").format(
                    key.name, len(key.shape), len(chain)
                )
            )
        for pb, joint in zip(chain, key.shape):
            pb.rotation_mode = "QUATERNION"
            pb.rotation_quaternion = joint.rotation
        self.report({"INFO"}, tip_("Chain '{}' shows key '{}'").format(rod.root_bone, key.name))
        return {"FINISHED"}


class KODAWARI_OT_rod_rekey(_HairOperator, bpy.types.Operator):
    """Replace a key's shape by the chain's current pose (its condition stays)"""

    bl_idname = "kodawari.rod_rekey"
    bl_label = "Re-key"
    bl_options = {"REGISTER", "UNDO"}
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )
    key_index: bpy.props.IntProperty(
        name="Key", default=-1, description="Which key (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        _, key = _key(rod, self.key_index)
        _, _, chain = _chain_pose_bones(obj, rod)
        shape = _pose_shape(chain)
        key.shape.clear()
        for q in shape:
            key.shape.add().rotation = q
        runtime.invalidate(obj)
        self.report({"INFO"}, tip_("Re-keyed '{}'").format(key.name))
        return {"FINISHED"}


class KODAWARI_OT_rod_key_remove(_HairOperator, bpy.types.Operator):
    """Delete a key"""

    bl_idname = "kodawari.rod_key_remove"
    bl_label = "Delete Key"
    bl_options = {"REGISTER", "UNDO"}
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )
    key_index: bpy.props.IntProperty(
        name="Key", default=-1, description="Which key (-1: the active one)"
    )

    def run(self, context):
        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        i, key = _key(rod, self.key_index)
        name = key.name
        rod.keys.remove(i)
        rod.active_key = max(0, min(rod.active_key, len(rod.keys) - 1))
        runtime.invalidate(obj)
        self.report({"INFO"}, tip_("Deleted key '{}'").format(name))
        return {"FINISHED"}


class KODAWARI_OT_rod_collider_add(_HairOperator, bpy.types.Operator):
    """Add a sphere or capsule collider that follows a bone"""

    bl_idname = "kodawari.rod_collider_add"
    bl_label = "Add Collider"
    bl_options = {"REGISTER", "UNDO"}
    bone: bpy.props.StringProperty(name="Bone", description="Empty: the active bone")
    shape: bpy.props.EnumProperty(
        name="Shape",
        items=(
            ("SPHERE", "Sphere", "A ball around a point"),
            ("CAPSULE", "Capsule", "A rounded cylinder along the bone"),
        ),
        description="Shape the hair cannot enter",
    )
    radius: bpy.props.FloatProperty(
        name="Radius",
        default=0.1,
        min=0.0,
        unit="LENGTH",
        subtype="DISTANCE",
        description="Size of the collider",
    )
    length: bpy.props.FloatProperty(
        name="Length",
        default=0.2,
        min=0.0,
        unit="LENGTH",
        subtype="DISTANCE",
        description="Capsule: how far it reaches along the bone",
    )
    offset: bpy.props.FloatVectorProperty(
        name="Offset",
        size=3,
        unit="LENGTH",
        subtype="TRANSLATION",
        description="Where the collider sits, relative to the bone",
    )

    def run(self, context):
        obj = _armature(context)
        name = self.bone or (obj.data.bones.active.name if obj.data.bones.active else "")
        if not name or name not in obj.data.bones:
            raise _Refusal(
                tip_("Bone '{}' is not in the armature: pick the bone the collider follows").format(
                    name
                )
            )
        collider = obj.kodawari_hair.colliders.add()
        collider.bone, collider.shape, collider.radius = name, self.shape, self.radius
        collider.length, collider.offset = self.length, self.offset
        obj.kodawari_hair.active_collider = len(obj.kodawari_hair.colliders) - 1
        runtime.invalidate(obj)
        return {"FINISHED"}


class KODAWARI_OT_rod_collider_remove(_HairOperator, bpy.types.Operator):
    """Remove the active collider"""

    bl_idname = "kodawari.rod_collider_remove"
    bl_label = "Remove Collider"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context):
        obj = _armature(context)
        settings = obj.kodawari_hair
        if not len(settings.colliders):
            raise _Refusal(tip_("This armature has no colliders"))
        settings.colliders.remove(min(settings.active_collider, len(settings.colliders) - 1))
        settings.active_collider = max(0, settings.active_collider - 1)
        runtime.invalidate(obj)
        return {"FINISHED"}


class KODAWARI_OT_rod_fit_stroke(_HairOperator, bpy.types.Operator):
    """Give the chain the shape of the newest annotation or grease-pencil stroke, as seen from the view"""

    bl_idname = "kodawari.rod_fit_stroke"
    bl_label = "Fit to Stroke"
    bl_options = {"REGISTER", "UNDO"}
    source: bpy.props.EnumProperty(
        name="View",
        default="CAMERA",
        items=(
            ("CAMERA", "Camera", "As seen through the active camera"),
            ("VIEWPORT", "Viewport", "As seen in the 3D viewport"),
        ),
        description="Which view the stroke was drawn in",
    )
    rod_index: bpy.props.IntProperty(
        name="Rod", default=-1, description="Which rod (-1: the active one)"
    )

    def invoke(self, context, event):
        if _viewport_eye(context) is not None:
            self.source = "VIEWPORT"
        return self.execute(context)

    def run(self, context):
        from . import strokes

        obj = _armature(context)
        _, rod = _rod(obj, self.rod_index)
        parent, _, chain = _chain_pose_bones(obj, rod)
        points, origin = strokes.find_stroke(context, exclude=obj)
        if not points or len(points) < 2:
            raise _Refusal(
                tip_(
                    "No stroke to fit: draw an annotation (or grease-pencil) stroke of two or more points"
                )
            )
        eye, forward, perspective = _eye(context, self.source)
        try:
            rotations = fitting.fit_chain_to_stroke(
                obj, parent, chain, points, eye, forward, perspective
            )
        except fitting.FitError as exc:
            raise _Refusal(str(exc)) from None
        for pb, q in zip(chain, rotations):
            pb.rotation_mode = "QUATERNION"
            pb.rotation_quaternion = q
        self.report(
            {"INFO"}, tip_("Chain '{}' fitted to the {} stroke").format(rod.root_bone, origin)
        )
        return {"FINISHED"}


class KODAWARI_OT_rod_bake(BakeOperator, bpy.types.Operator):
    """Bake the simulated rods into F-curves (rotation_quaternion) so renders and exports need no add-on"""

    bl_idname = "kodawari.rod_bake"
    bl_label = "Bake Hair"
    bl_options = {"REGISTER", "UNDO"}
    new_action: bpy.props.BoolProperty(
        name="New Action in NLA",
        default=False,
        description="Bake into a new action pushed to an NLA track",
    )

    def make_job(self, context):
        try:
            obj = _armature(context)
        except _Refusal as refusal:
            raise BakeError(str(refusal)) from None
        start, end = frame_range(self, context.scene)
        return HairBakeJob(obj, context.scene, start, end, self.new_action)


CLASSES = (
    KODAWARI_OT_rod_add,
    KODAWARI_OT_rod_remove,
    KODAWARI_OT_rod_key_view,
    KODAWARI_OT_rod_key_pose,
    KODAWARI_OT_rod_key_speed,
    KODAWARI_OT_rod_key_preview,
    KODAWARI_OT_rod_rekey,
    KODAWARI_OT_rod_key_remove,
    KODAWARI_OT_rod_collider_add,
    KODAWARI_OT_rod_collider_remove,
    KODAWARI_OT_rod_fit_stroke,
    KODAWARI_OT_rod_bake,
)
