"""A new hair frame solved before Blender evaluates it (issue 13 item 2, docs/algorithms.md §3.7).

When the rods' parent bones are moved only by the armature's action, the add-on predicts them
before the evaluation, solves and writes the hair, and checks the prediction after it. What a
user sees must be exactly what the post-evaluation path (solve after Blender's evaluation,
write, evaluate again) shows, whatever moves the head: an action (predicted), a constraint or
a driver (not predictable), or a driver added in the middle of playback (a wrong prediction,
caught and solved again in the same frame)."""

import bpy
import numpy as np
import pytest
from hair_rig import add_camera, chain_bones, key_head, make_rig, select_only

HEAD_KEYS = (
    (1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    (7, (0.35, 0.0, 0.15), (0.3, 0.0, 0.2)),
    (14, (-0.3, 0.2, 0.0), (-0.2, 0.4, 0.0)),
    (22, (0.0, -0.1, 0.05), (0.0, 0.0, -0.3)),
)
FRAMES = range(1, 31)


def _rig(scene, head_by="action"):
    """Root -> Head (Euler XYZ) with a 5-bone rod on the head, Root turned, a front camera.
    The head moves by its own keys ("action") or copies a keyed control bone's local
    transform through a constraint ("constraint"): the same motion."""
    obj = make_rig(scene)
    select_only(obj, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    obj.kodawari_hair.rods[0].stiffness = 0.3
    obj.pose.bones["Root"].rotation_quaternion = (0.9962, 0.0, 0.0872, 0.0)  # 10 deg, static
    key_head(obj, HEAD_KEYS, by=head_by)
    add_camera(scene, "Front", (0, -4, 1.7))
    scene.frame_start, scene.frame_end = 1, 40
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def _seen(obj):
    """What the user sees after frame_set: the rod bones' rotations in the original pose (what a
    save or a render starts from) and in the evaluated pose, and the evaluated joints."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    bones = chain_bones(obj, "Ahoge")
    names = [pb.name for pb in bones]
    original = np.array([tuple(pb.rotation_quaternion) for pb in bones])
    shown = np.array([tuple(evaluated.pose.bones[n].rotation_quaternion) for n in names])
    joints = np.array(
        [tuple(evaluated.pose.bones[n].head) for n in names]
        + [tuple(evaluated.pose.bones[names[-1]].tail)]
    )
    return original, shown, joints


def _runtime(obj):
    from kodawari.hair import runtime

    return runtime.get(obj)


def _play(scene, obj, frames, before_frame=None):
    seen = {}
    for frame in frames:
        if before_frame is not None:
            before_frame(frame)
        scene.frame_set(frame)
        seen[frame] = _seen(obj)
        original, shown, joints = seen[frame]
        np.testing.assert_array_equal(shown, original, err_msg=f"frame {frame}: stale screen")
        solver = _runtime(obj).system.joint_positions(0)
        np.testing.assert_allclose(joints, solver, atol=2e-4, err_msg=f"frame {frame}")
    return seen


@pytest.fixture
def post_evaluation_path(monkeypatch):
    """Every new frame solved after Blender's evaluation (the path before prediction)."""
    from kodawari.hair import runtime

    def switch():
        monkeypatch.setattr(runtime.ArmatureRuntime, "_predict", lambda *args: False)

    return switch


def _assert_same(seen, reference, atol=1e-6):
    for frame in reference:
        for a, b, what in zip(seen[frame], reference[frame], ("original", "shown", "joints")):
            np.testing.assert_allclose(a, b, atol=atol, err_msg=f"frame {frame}, {what}")


class _FirstPass:
    """After the add-on's frame_change_post: the rod rotations Blender's first evaluation of
    the frame shows (before any second evaluation the add-on may ask for)."""

    def __init__(self, obj):
        self.obj, self.shown, self.rotations = obj, {}, {}

    def __call__(self, scene, depsgraph=None):
        evaluated = self.obj.evaluated_get(depsgraph)
        self.rotations[scene.frame_current] = np.array(
            [
                tuple(evaluated.pose.bones[pb.name].rotation_quaternion)
                for pb in chain_bones(self.obj, "Ahoge")
            ]
        )
        self.shown[scene.frame_current] = np.array(
            [
                tuple(evaluated.pose.bones[pb.name].matrix.to_quaternion())
                for pb in chain_bones(self.obj, "Ahoge")
            ]
        )


def test_a_head_moved_by_its_action_shows_its_new_hair_frames_in_one_evaluation(empty_scene):
    scene = empty_scene
    obj = _rig(scene)
    first = _FirstPass(obj)
    bpy.app.handlers.frame_change_post.append(first)  # runs after the add-on's handler
    try:
        seen = _play(scene, obj, FRAMES)
    finally:
        bpy.app.handlers.frame_change_post.remove(first)
    assert np.abs(seen[30][0] - seen[1][0]).max() > 0.05, "the head should swing the chain"
    final = _FirstPass(obj)
    for frame in FRAMES[1:]:  # frames simulated for the first time, after the start frame
        scene.frame_set(frame)
        final(scene, bpy.context.evaluated_depsgraph_get())
        # The first evaluation already showed the frame's hair: other handlers, render engines
        # and the viewport see it without a second evaluation of the armature.
        np.testing.assert_allclose(
            first.shown[frame], final.shown[frame], atol=1e-6, err_msg=f"frame {frame}"
        )


def test_predicted_frames_equal_the_post_evaluation_path(empty_scene, post_evaluation_path):
    scene = empty_scene
    obj = _rig(scene)
    predicted = _play(scene, obj, FRAMES)
    assert _runtime(obj).prediction_off is None, "the action-driven head should be predicted"
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    obj = _rig(scene)
    post_evaluation_path()
    # The predicted inputs are Blender's within float32 rounding (6e-8 measured), not bit for bit.
    _assert_same(predicted, _play(scene, obj, FRAMES), atol=1e-5)


def test_a_head_moved_by_a_constraint_plays_as_the_same_motion_keyed(empty_scene):
    scene = empty_scene
    obj = _rig(scene, head_by="constraint")
    constrained = _play(scene, obj, FRAMES)
    assert _runtime(obj).prediction_off, "a constrained rig is not predictable"
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    obj = _rig(scene)
    # Blender's constraint and its keyed channels place the head within float rounding.
    _assert_same(constrained, _play(scene, obj, FRAMES), atol=1e-5)


def _add_head_driver(obj):
    fcurve = obj.driver_add('pose.bones["Head"].location', 0)
    fcurve.driver.type = "SCRIPTED"
    fcurve.driver.expression = "0.25"  # a constant: Blender's simple expressions, no Python
    for modifier in list(fcurve.modifiers):
        fcurve.modifiers.remove(modifier)


def test_a_driver_added_during_playback_is_caught_and_corrected_the_same_frame(
    empty_scene, post_evaluation_path
):
    frame = 11  # the driver appears just before this frame is set

    def runs(post_path):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        scene = bpy.context.scene
        obj = _rig(scene)
        if post_path:
            post_evaluation_path()

        def before(f):
            if f == frame:
                _add_head_driver(obj)

        return _play(scene, obj, range(1, 21), before), obj

    predicted, obj = runs(post_path=False)
    assert _runtime(obj).prediction_off, "the driver should have refuted the prediction"
    reference, _ = runs(post_path=True)
    jump = np.abs(reference[frame][2] - reference[frame - 1][2]).max()
    assert jump > 0.05, "the driver should move the head, and the hair with it"
    _assert_same(predicted, reference, atol=1e-5)


def test_predicted_bones_are_where_blender_evaluates_them_for_every_inherit_mode(empty_scene):
    """The forward kinematics behind the prediction, against Blender's evaluation: a chain with
    every supported inherit mode and rotation mode, rolled and unconnected bones, each keyed in
    location, rotation and scale, under an armature object at scale 0.01 that moves and turns.
    (NONE and AVERAGE under an inherited rotation are refused: such a rig takes the evaluated
    path.)"""
    from kodawari.hair import predict

    scene = empty_scene
    data = bpy.data.armatures.new("Chain")
    obj = bpy.data.objects.new("Chain", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    modes = [  # (inherit rotation, inherit scale, rotation mode)
        (True, "FULL", "QUATERNION"),
        (False, "FULL", "ZXY"),
        (True, "FULL", "AXIS_ANGLE"),
        (True, "NONE_LEGACY", "XYZ"),
        (False, "NONE", "YZX"),
        (True, "NONE_LEGACY", "QUATERNION"),
        (False, "AVERAGE", "XZY"),
    ]
    parent = None
    for i in range(len(modes)):
        bone = data.edit_bones.new(f"B{i}")
        bone.head = (0.1 * i, 0.05 * (i % 2), 0.3 * i)
        bone.tail = (0.1 * i + 0.05, 0.2, 0.3 * i + 0.25)
        bone.roll = 0.4 * i - 1.0
        bone.parent, bone.use_connect = parent, False
        parent = bone
    bpy.ops.object.mode_set(mode="POSE")
    rng = np.random.default_rng(5)
    for pb, (rotation, scale, mode) in zip(obj.pose.bones, modes):
        pb.bone.use_inherit_rotation, pb.bone.inherit_scale = rotation, scale
        pb.rotation_mode = mode
        for frame in (1, 6, 11):
            pb.location = rng.uniform(-0.2, 0.2, 3)
            pb.scale = rng.uniform(0.7, 1.4, 3)
            if mode == "QUATERNION":
                pb.rotation_quaternion = rng.normal(size=4)
            elif mode == "AXIS_ANGLE":
                pb.rotation_axis_angle = rng.uniform(-1.0, 1.0, 4)
            else:
                pb.rotation_euler = rng.uniform(-1.0, 1.0, 3)
            for path in ("location", "scale", predict._rotation_property(mode)):
                pb.keyframe_insert(path, frame=frame)
    obj.scale = (0.01, 0.01, 0.01)
    for frame, location, turn in ((1, (0, 0, 0), 0.0), (11, (2.0, -1.0, 0.5), 1.2)):
        obj.location, obj.rotation_euler = location, (0.3, 0.0, turn)
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.object.mode_set(mode="OBJECT")
    bones = list(range(len(modes)))
    predictor = predict.PosePredictor(obj, bones, [])
    for refused in ("AVERAGE", "NONE"):
        obj.pose.bones["B2"].bone.inherit_scale = refused
        with pytest.raises(predict.Unpredictable):
            predict.PosePredictor(obj, bones, [])
    obj.pose.bones["B2"].bone.inherit_scale = "FULL"
    for frame in (1, 3, 6, 8, 13):
        scene.frame_set(frame)
        matrices, world = predictor.predict(scene.frame_current_final)
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        blender = np.array(
            [np.array(pb.matrix).T.reshape(-1) for pb in evaluated.pose.bones], np.float32
        )
        bad = np.abs(matrices - blender).max(axis=1)
        assert bad.max() < 2e-6, f"frame {frame}: bones off by {bad}"
        np.testing.assert_allclose(world, np.array(evaluated.matrix_world), atol=1e-6)


def test_view_keys_under_a_moving_camera_aimed_by_a_constraint_are_predicted(empty_scene):
    """A camera that flies round on its own keys and is aimed by Track To (the usual set-up):
    its position is what its keys say, so a rig with view keys is still predicted, and it
    gives the hair of the post-evaluation path."""
    from hair_rig import pose_curl

    def run(predicting):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        scene = bpy.context.scene
        obj = _rig(scene)
        bpy.ops.object.mode_set(mode="POSE")
        camera = scene.camera
        pose_curl(obj, "Ahoge", "X", 60.0)
        assert bpy.ops.kodawari.rod_key_view(source="CAMERA", influence=1.0) == {"FINISHED"}
        pose_curl(obj, "Ahoge", "X", 0.0)
        bpy.ops.object.mode_set(mode="OBJECT")
        aim = camera.constraints.new("TRACK_TO")
        aim.target = obj
        for frame, location in ((1, (0, -4, 1.7)), (15, (4, 0, 1.7)), (30, (0, 4, 1.7))):
            camera.location = location
            camera.keyframe_insert("location", frame=frame)
        seen, first = _play_watched(scene, obj, predicting)
        return seen, obj, first

    predicted, obj, first = run(predicting=True)
    _assert_first_evaluation_showed_the_hair(first, predicted)
    reference, _, _ = run(predicting=False)
    assert np.abs(reference[30][0] - reference[1][0]).max() > 0.05, "the view should bend it"
    _assert_same(predicted, reference, atol=1e-5)


def _assert_first_evaluation_showed_the_hair(first, predicted):
    """Blender's first evaluation of each new frame (watched by _play_watched) already showed
    the hair the frame ended with: one evaluation, no second pass."""
    for frame in FRAMES[1:]:
        np.testing.assert_array_equal(
            first.rotations[frame], predicted[frame][1], err_msg=f"frame {frame}"
        )


def _play_watched(scene, obj, predicting):
    """Play FRAMES with prediction on or off (off: every new frame takes the post-evaluation
    path), watching what Blender's first evaluation of each frame showed: (seen, first)."""
    from kodawari.hair import runtime

    original = runtime.ArmatureRuntime._predict
    if not predicting:
        runtime.ArmatureRuntime._predict = lambda *args: False
    first = _FirstPass(obj)
    bpy.app.handlers.frame_change_post.append(first)  # runs after the add-on's handler
    try:
        seen = _play(scene, obj, FRAMES)
    finally:
        runtime.ArmatureRuntime._predict = original
        bpy.app.handlers.frame_change_post.remove(first)
    return seen, first


def _add_ik_arm(obj, scene, chain_count, parent="Root"):
    """An arm of two bones under `parent` whose hand an IK constraint pulls to an empty."""
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bones = obj.data.edit_bones
    upper = bones.new("Arm.Upper")
    upper.head, upper.tail, upper.parent = (0.2, 0, 1.4), (0.5, 0, 1.4), bones[parent]
    lower = bones.new("Arm.Lower")
    lower.head, lower.tail, lower.parent = (0.5, 0, 1.4), (0.8, 0, 1.4), upper
    lower.use_connect = True
    bpy.ops.object.mode_set(mode="POSE")
    target = bpy.data.objects.new("HandTarget", None)
    scene.collection.objects.link(target)
    for frame, location in ((1, (0.6, 0.2, 1.2)), (20, (0.4, -0.3, 1.6))):
        target.location = location
        target.keyframe_insert("location", frame=frame)
    ik = obj.pose.bones["Arm.Lower"].constraints.new("IK")
    ik.target, ik.chain_count = target, chain_count
    bpy.ops.object.mode_set(mode="OBJECT")


def test_an_ik_arm_elsewhere_in_the_rig_keeps_the_hair_predicted(empty_scene):
    """Constraints and drivers that cannot reach the head (an IK arm beside it, a driver on the
    arm) leave the rig predicted; an IK chain that reaches the head's ancestors does not."""
    from kodawari.hair import predict

    def run(predicting):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        scene = bpy.context.scene
        obj = _rig(scene)
        _add_ik_arm(obj, scene, chain_count=2)
        # A driver elsewhere in the rig (the arm's scale) moves nothing the rods read.
        driver = obj.driver_add('pose.bones["Arm.Upper"].scale', 0).driver
        driver.type, driver.expression = "SCRIPTED", "1.1"
        seen, first = _play_watched(scene, obj, predicting)
        return seen, obj, first

    predicted, obj, first = run(predicting=True)
    _assert_first_evaluation_showed_the_hair(first, predicted)
    reference, obj, _ = run(predicting=False)
    _assert_same(predicted, reference, atol=1e-5)
    # The same arm whose IK chain runs to the root (through Root, the head's parent).
    obj.pose.bones["Arm.Lower"].constraints[0].chain_count = 0
    rt = _runtime(obj)
    with pytest.raises(predict.Unpredictable):
        predict.PosePredictor(obj, rt.input_bones, rt.written_bones)
