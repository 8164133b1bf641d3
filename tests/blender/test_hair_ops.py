"""Hair operators: rod set-up, keys and their management, sketch fitting, and refusals."""

import math

import bpy
import numpy as np
import pytest
from hair_rig import add_camera, angle_deg, chain_bones, make_rig, pose_curl, rotations, select_only

ROD_FIELDS = {
    "root_bone",
    "reference_bone",
    "stiffness",
    "damping",
    "gravity",
    "substeps",
    "iterations",
    "radius",
    "wind",
    "keys",
}


def _snapshot(obj):
    """Everything the hair operators may change: settings and the chain pose."""
    s = obj.kodawari_hair
    rods = [
        (
            r.root_bone,
            r.reference_bone,
            [
                (k.name, k.condition, tuple(k.direction), [tuple(j.rotation) for j in k.shape])
                for k in r.keys
            ],
        )
        for r in s.rods
    ]
    pose = [(pb.name, pb.rotation_mode, tuple(pb.rotation_quaternion)) for pb in obj.pose.bones]
    return repr((rods, len(s.colliders), pose))  # repr: NaN compares equal to itself


@pytest.fixture
def rig(empty_scene):
    obj = make_rig(empty_scene)
    select_only(obj, {"Ahoge.00"})
    return obj


def test_rod_add_makes_a_rod_per_selected_chain_with_the_named_settings(empty_scene):
    obj = make_rig(
        empty_scene,
        chains=(("Ahoge", (0, 0, 1.8), (0, 0, 1), 4), ("Ear", (0.1, 0, 1.7), (1, 0, 1), 3)),
    )
    select_only(
        obj, {"Ahoge.00", "Ahoge.01", "Ear.00"}
    )  # a whole chain selected still makes one rod
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    settings = obj.kodawari_hair
    assert [r.root_bone for r in settings.rods] == ["Ahoge.00", "Ear.00"]
    assert {"rods", "enabled", "colliders"} <= set(settings.bl_rna.properties.keys())
    assert set(settings.rods[0].bl_rna.properties.keys()) >= ROD_FIELDS
    assert all(pb.rotation_mode == "QUATERNION" for pb in chain_bones(obj, "Ahoge"))
    # The live handler writes pose bones on frame changes, so renders must lock the interface.
    assert empty_scene.render.use_lock_interface
    # Adding the same chain again is refused.
    assert_refused(obj, lambda: bpy.ops.kodawari.rod_add(), "already belongs")


def assert_refused(obj, call, message):
    before = _snapshot(obj)
    with pytest.raises(RuntimeError, match=message):
        call()
    assert _snapshot(obj) == before


def test_rod_add_refuses_without_an_armature(empty_scene):
    obj = make_rig(empty_scene)
    cam = add_camera(empty_scene, "Cam", (0, -4, 1.7))
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.objects.active = cam
    assert_refused(obj, lambda: bpy.ops.kodawari.rod_add(), "not an armature")


def test_rod_add_refuses_without_a_selection(rig):
    select_only(rig, set())
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_add(), "No bones selected")


def test_rod_add_refuses_a_branching_chain(empty_scene):
    obj = make_rig(empty_scene, branch=True)
    select_only(obj, {"Ahoge.00"})
    assert_refused(obj, lambda: bpy.ops.kodawari.rod_add(), "unbranched")


def test_rod_add_refuses_a_root_without_parent(rig):
    select_only(rig, {"Root"})
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_add(), "no parent")


def test_rod_add_refuses_zero_length_bones(rig):
    # Blender deletes zero-length bones in edit mode; a bone collapsed by pose scale has none either.
    from kodawari.hair import chains

    class Bone:
        name, length, children = "Flat", 0.0, ()

    with pytest.raises(chains.ChainError, match="zero length"):
        chains.chain_from(Bone())


def test_key_view_stores_direction_in_the_reference_frame_and_the_pose(rig, empty_scene):
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    add_camera(empty_scene, "Side", (4, 0, 1.7))
    pose_curl(rig, "Ahoge", "Z", 15)
    assert bpy.ops.kodawari.rod_key_view(source="CAMERA") == {"FINISHED"}
    key = rig.kodawari_hair.rods[0].keys[0]
    # Head bone points up (+Z), so its frame maps armature +X to... compute it the same way Blender does.
    head = rig.pose.bones["Head"]
    expected = head.matrix.to_quaternion().inverted() @ (
        (rig.matrix_world.inverted() @ empty_scene.camera.location) - head.matrix.translation
    )
    np.testing.assert_allclose(key.direction, expected.normalized(), atol=1e-6)
    assert key.condition == "VIEW"
    assert key.influence == pytest.approx(math.log(0.5) / math.log(0.75))
    np.testing.assert_allclose(
        [tuple(j.rotation) for j in key.shape], rotations(rig, "Ahoge"), atol=1e-6
    )


def test_keys_are_listed_renamed_previewed_rekeyed_and_deleted(rig, empty_scene):
    bpy.ops.kodawari.rod_add()
    add_camera(empty_scene, "Front", (0, -4, 1.7))
    pose_curl(rig, "Ahoge", "X", 10)
    bpy.ops.kodawari.rod_key_view()
    pose_curl(rig, "Ahoge", "X", -10)
    bpy.ops.kodawari.rod_key_pose()
    bpy.ops.kodawari.rod_key_speed(speed=3.0)
    rod = rig.kodawari_hair.rods[0]
    assert [k.name for k in rod.keys] == ["View 1", "Pose 1", "Speed 1"]
    assert [k.condition for k in rod.keys] == ["VIEW", "POSE", "SPEED"]
    assert rod.keys[2].speed == pytest.approx(3.0)
    rod.keys[0].name = "Front"
    pose_curl(rig, "Ahoge", "X", 0)
    assert bpy.ops.kodawari.rod_key_preview(key_index=0) == {"FINISHED"}
    assert (
        angle_deg(chain_bones(rig, "Ahoge")[2].rotation_quaternion, rod.keys[0].shape[2].rotation)
        < 1e-3
    )
    pose_curl(rig, "Ahoge", "Z", 30)
    assert bpy.ops.kodawari.rod_rekey(key_index=0) == {"FINISHED"}
    assert rod.keys[0].name == "Front"
    np.testing.assert_allclose(
        tuple(rod.keys[0].shape[1].rotation), rotations(rig, "Ahoge")[1], atol=1e-6
    )
    assert bpy.ops.kodawari.rod_key_remove(key_index=1) == {"FINISHED"}
    assert [k.name for k in rod.keys] == ["Front", "Speed 1"]


def test_key_view_refuses_without_an_active_camera(rig):
    bpy.ops.kodawari.rod_add()
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_key_view(source="CAMERA"), "no active camera")


def test_key_view_from_the_viewport_uses_the_3d_view_or_refuses_without_one(rig, empty_scene):
    bpy.ops.kodawari.rod_add()
    add_camera(empty_scene, "Front", (0, -4, 1.7))
    screen = bpy.context.screen
    views = (
        [a.spaces.active for a in screen.areas if a.type == "VIEW_3D"] if screen is not None else []
    )
    if not views:  # the Blender program in background mode has no screen
        assert_refused(
            rig, lambda: bpy.ops.kodawari.rod_key_view(source="VIEWPORT"), "No 3D viewport"
        )
        return
    eye = views[0].region_3d.view_matrix.inverted().translation
    assert bpy.ops.kodawari.rod_key_view(source="VIEWPORT") == {"FINISHED"}
    head = rig.pose.bones["Head"]
    expected = head.matrix.to_quaternion().inverted() @ (
        rig.matrix_world.inverted() @ eye - head.matrix.translation
    )
    np.testing.assert_allclose(
        rig.kodawari_hair.rods[0].keys[0].direction, expected.normalized(), atol=1e-6
    )


def test_key_view_refuses_a_camera_at_the_reference_bone(rig, empty_scene):
    bpy.ops.kodawari.rod_add()
    cam = add_camera(empty_scene, "Inside", (0, -4, 1.7))
    cam.location = rig.matrix_world @ rig.pose.bones["Head"].head
    bpy.context.view_layer.update()
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_key_view(), "at the reference bone")


def test_key_refuses_nan_in_the_keyed_pose(rig, empty_scene):
    bpy.ops.kodawari.rod_add()
    add_camera(empty_scene, "Front", (0, -4, 1.7))
    chain_bones(rig, "Ahoge")[2].rotation_quaternion = (math.nan, 0, 0, 0)
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_key_view(), "NaN")
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_key_pose(), "NaN")


def test_key_refuses_a_rod_with_zero_joints(rig, empty_scene):
    bpy.ops.kodawari.rod_add()
    add_camera(empty_scene, "Front", (0, -4, 1.7))
    rig.kodawari_hair.rods[0].root_bone = "Gone"
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_key_view(), "0 joints")
    assert_refused(rig, lambda: bpy.ops.kodawari.rod_bake(frame_start=1, frame_end=3), "0 joints")


def test_operators_refuse_without_rods(rig, empty_scene):
    add_camera(empty_scene, "Front", (0, -4, 1.7))
    for call in (
        bpy.ops.kodawari.rod_key_view,
        bpy.ops.kodawari.rod_key_pose,
        bpy.ops.kodawari.rod_key_speed,
        bpy.ops.kodawari.rod_fit_stroke,
        bpy.ops.kodawari.rod_bake,
    ):
        assert_refused(rig, call, "no rods")


def test_every_hair_operator_is_undoable():
    names = (
        "rod_add",
        "rod_remove",
        "rod_key_view",
        "rod_key_pose",
        "rod_key_speed",
        "rod_key_preview",
        "rod_rekey",
        "rod_key_remove",
        "rod_fit_stroke",
        "rod_bake",
        "rod_collider_add",
        "rod_collider_remove",
    )
    for name in names:
        rna = getattr(bpy.ops.kodawari, name).get_rna_type()
        assert {"REGISTER", "UNDO"} <= set(
            rna.bl_options
            if hasattr(rna, "bl_options")
            else getattr(bpy.types, f"KODAWARI_OT_{name}").bl_options
        ), name
