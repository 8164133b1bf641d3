"""kodawari.gait_setup finds four legs and the body bone, fills horse defaults, and
refuses bad rigs with a clear message, changing nothing."""

import bpy
import pytest
from gait_scene import horse


def _rename(arm_obj, mapping):
    for bone in arm_obj.data.bones:
        for old, new in mapping:
            if old in bone.name:
                bone.name = bone.name.replace(old, new)


def test_finds_the_horse_by_name_with_seed_defaults(empty_scene):
    rig = horse(empty_scene)
    assert bpy.ops.kodawari.gait_setup(limits="HORSE") == {"FINISHED"}
    s = rig.kodawari_gait
    legs = {leg.name: [b.name for b in leg.bones] for leg in s.legs}
    assert legs["LF"] == ["fore_scapula.L", "fore_humerus.L", "fore_radius.L", "fore_cannon.L"]
    assert legs["RH"] == ["hind_pelvis.R", "hind_femur.R", "hind_tibia.R", "hind_cannon.R"]
    assert s.body_bone == "body"
    assert [e.name for e in s.table] == ["WALK", "TROT", "CANTER", "GALLOP", "GALLOP_ROTARY"]
    trot = s.table["TROT"]
    # The horse table, scaled to this horse's 1.406 m hip by dynamic similarity.
    assert (trot.duty_factor, trot.swing_time) == pytest.approx((0.5, 0.3), rel=2e-3)
    # Seed stiffness, and the scapula range (-55..-15 absolute) shifted to the rest pose (-35).
    lf = s.legs["LF"].bones
    assert [round(b.stiffness, 2) for b in lf] == [0.1, 0.3, 0.5, 1.0]
    assert (lf[0].limit_min, lf[0].limit_max) == pytest.approx((-20.0, 20.0))


def test_finds_legs_named_left_right_arm_rear(empty_scene):
    rig = horse(empty_scene)
    bpy.ops.object.mode_set(mode="OBJECT")
    _rename(rig, [("fore_", "arm_"), ("hind_", "rear_")])
    for bone in rig.data.bones:
        if bone.name.endswith(".L"):
            bone.name = "Left_" + bone.name[:-2]
        elif bone.name.endswith(".R"):
            bone.name = bone.name[:-2] + "_right"
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    legs = {leg.name: [b.name for b in leg.bones] for leg in rig.kodawari_gait.legs}
    assert legs["LF"][0] == "Left_arm_scapula"
    assert legs["RH"][-1] == "rear_cannon_right"


def test_finds_the_dog_with_its_own_naming(empty_scene):
    import gait_samples as samples

    rig, _ = samples.build_dog(empty_scene)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    s = rig.kodawari_gait
    assert [b.name for b in s.legs["RF"].bones] == ["front_upper_R", "front_lower_R", "front_paw_R"]
    assert [b.name for b in s.legs["LH"].bones] == ["back_thigh_L", "back_shin_L", "back_paw_L"]
    assert s.body_bone == "spine"


def test_finds_legs_from_four_selected_feet(empty_scene):
    rig = horse(empty_scene)
    rig.kodawari_gait.legs.clear()
    names = {}
    for i, bone in enumerate(rig.data.bones):  # names that say nothing
        names[bone.name] = f"bone_{i:02d}"
    for old, new in names.items():
        if old != "body":
            rig.data.bones[old].name = new
    feet = [names[n] for n in ("fore_cannon.L", "fore_cannon.R", "hind_cannon.L", "hind_cannon.R")]
    bpy.ops.object.mode_set(mode="POSE")
    for pose_bone in rig.pose.bones:
        owner = pose_bone if hasattr(pose_bone, "select") else pose_bone.bone  # 5.0 moved selection
        owner.select = pose_bone.name in feet
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    legs = {leg.name: [b.name for b in leg.bones] for leg in rig.kodawari_gait.legs}
    assert legs["LF"] == [
        names[n] for n in ("fore_scapula.L", "fore_humerus.L", "fore_radius.L", "fore_cannon.L")
    ]
    assert legs["RH"][-1] == names["hind_cannon.R"]
    assert rig.kodawari_gait.body_bone == "body"


def test_not_an_armature(empty_scene):
    mesh = bpy.data.objects.new("Cube", bpy.data.meshes.new("Cube"))
    empty_scene.collection.objects.link(mesh)
    bpy.context.view_layer.objects.active = mesh
    with pytest.raises(RuntimeError, match="needs an armature"):
        bpy.ops.kodawari.gait_setup()
    assert len(mesh.kodawari_gait.legs) == 0


def test_fewer_than_four_legs_changes_nothing(empty_scene):
    rig = horse(empty_scene)
    rig.kodawari_gait.legs.clear()
    for i, bone in enumerate(
        [b for b in rig.data.bones if b.name.startswith("hind_") and b.name.endswith(".R")]
    ):
        bone.name = f"x_{i}.R"  # names that say no limb
    with pytest.raises(RuntimeError, match="fewer than four legs.*missing RH"):
        bpy.ops.kodawari.gait_setup()
    assert len(rig.kodawari_gait.legs) == 0


def test_a_leg_of_one_bone_changes_nothing(empty_scene):
    rig = horse(empty_scene)
    rig.kodawari_gait.legs.clear()
    for i, name in enumerate(("hind_femur.R", "hind_tibia.R", "hind_cannon.R")):
        rig.data.bones[name].name = f"x_{i}.R"
    with pytest.raises(RuntimeError, match=r"Leg RH \('hind_pelvis.R'\) has a single bone"):
        bpy.ops.kodawari.gait_setup()
    assert len(rig.kodawari_gait.legs) == 0


def test_zero_length_bone_in_the_leg_plane_changes_nothing(empty_scene):
    rig = horse(empty_scene)
    rig.kodawari_gait.legs.clear()
    bpy.ops.object.mode_set(mode="EDIT")
    bone = rig.data.edit_bones["fore_humerus.L"]
    head = bone.head.copy()
    bone.tail = (head.x + 0.3, head.y, head.z)  # points sideways: no length fore-aft or up
    rig.data.edit_bones["fore_radius.L"].use_connect = False
    bpy.ops.object.mode_set(mode="OBJECT")
    with pytest.raises(RuntimeError, match="zero length"):
        bpy.ops.kodawari.gait_setup()
    assert len(rig.kodawari_gait.legs) == 0


@pytest.mark.parametrize("case,femur", [("sample_horse", 1), ("wolf", 0)])
def test_fore_and_hind_legs_get_their_own_stiffness_with_the_hind_femur_leading(
    empty_scene, case, femur
):
    """Takizawa: plain CCD moves the bones nearest the foot first; the hind femur should
    lead. The hind femur (below a sloping pelvis on the sample horse, the thigh of the
    Rigify wolf) takes the largest share; the fore leg keeps (0.1, 0.3, 0.5, 1.0)."""
    from gait_scene import rigify_metarig

    if case == "sample_horse":
        rig = horse(empty_scene)
    else:
        rig = rigify_metarig(empty_scene, "wolf")
        bpy.context.view_layer.objects.active = rig
        assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    legs = rig.kodawari_gait.legs
    for side in "LR":
        hind = [b.stiffness for b in legs[side + "H"].bones]
        fore = [b.stiffness for b in legs[side + "F"].bones]
        assert hind[femur] == max(hind) == pytest.approx(1.0), hind
        assert hind != fore
        assert fore[0] == pytest.approx(0.1) and fore[1] > fore[0]
