"""Gaits on rigs nobody on the project made (issue 8): Blender's bundled Rigify animal
metarigs and rigs built here with Mixamo, Unreal, 3ds Max biped and game-export bone
names, at object scale 1 and 0.01, with and without a connected body bone. Everything
is measured on the evaluated pose (scene.frame_set), in world metres."""

import bpy
import numpy as np
import pytest
from gait_scene import (
    build,
    evaluated_legs,
    expected_feet,
    headings,
    joint_angles,
    planted_snaps,
    select_pose_bones,
    stance_end_ratio,
)

CASES = [
    "wolf",
    "horse",
    "cat@0.01",
    "mixamo@0.01",
    "unreal+connected",
    "max_biped@0.01+connected",
    "game",
]
LEGS = ("LF", "RF", "LH", "RH")


def _setup(scene, case, **options):
    obj = build(scene, case)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="OBJECT")
    assert bpy.ops.kodawari.gait_setup(**options) == {"FINISHED"}
    return obj


def _feet(obj):
    return [obj.kodawari_gait.legs[k].bones[-1].name for k in LEGS]


@pytest.mark.parametrize("case", CASES + ["wolf@0.01"])
def test_setup_finds_four_legs_by_name_and_from_four_selected_feet(empty_scene, case):
    obj = _setup(empty_scene, case)
    s = obj.kodawari_gait
    kind = case.split("@")[0].replace("+connected", "")
    assert _feet(obj) == expected_feet(kind)
    by_name = {k: [b.name for b in s.legs[k].bones] for k in LEGS}
    # Root motion lands where Blender applies it: a bone whose location keys count.
    assert s.root_motion == "BONE" and not obj.data.bones[s.body_bone].use_connect
    # Left legs stand on the animal's left (+X for a rig facing -Y), fore legs ahead.
    world = {
        k: obj.matrix_world @ obj.data.bones[s.legs[k].bones[-1].name].tail_local for k in LEGS
    }
    assert world["LF"].x > world["RF"].x and world["LH"].x > world["RH"].x
    assert world["LF"].y < world["LH"].y
    # From the four feet selected (in a scrambled order), nothing named needed: same feet,
    # chains that stop where the spine branches (no spine bone in any leg).
    s.legs.clear()
    feet = expected_feet(kind)
    select_pose_bones(obj, [feet[2], feet[0], feet[3], feet[1]])
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    assert _feet(obj) == feet
    for k in LEGS:
        chain = [b.name for b in s.legs[k].bones]
        assert not any(
            "spine" in n.lower() or "hips" in n.lower() or "pelvis" in n.lower() for n in chain
        ), chain
        assert (
            chain[-len(by_name[k]) :] == by_name[k]
        )  # the named chain, perhaps with its shoulder above


@pytest.mark.parametrize(
    "case,blade",
    [
        ("cat@0.01", "shoulder.{}"),
        ("wolf", "shoulder.{}"),
        ("horse", "shoulder.{}"),
        ("game", "b_{}Shoulder_07"),
        ("unreal", "clavicle_{}"),
    ],
)
def test_fore_legs_take_in_their_shoulder_blade(empty_scene, case, blade):
    """A fore leg's chain starts at the rig's shoulder blade (scapula or clavicle), the
    bone it hangs from that no other leg shares and that runs down to the shoulder joint:
    it carries part of the leg's swing, as a quadruped's scapula does (docs/algorithms.md
    §4.11). Setup used to stop at the upper arm, leaving a small animal's fore leg to
    touch down and lift off nearly straight (240 fps: 11-13.5 deg a frame). Hind legs
    keep their chains (a pelvis runs sideways, and is shared or fused to the spine)."""
    obj = _setup(empty_scene, case)
    s = obj.kodawari_gait
    sides = {"game": ("Left", "Right"), "unreal": ("l", "r")}.get(case.split("@")[0], ("L", "R"))
    for leg, side in zip(("LF", "RF"), sides):
        chain = [b.name for b in s.legs[leg].bones]
        assert chain[0] == blade.format(side), chain
        assert obj.data.bones[chain[1]].parent.name == chain[0]
        # the blade moves least (the fore leg's smallest stiffness share)
        assert s.legs[leg].bones[0].stiffness == min(b.stiffness for b in s.legs[leg].bones)
    hind = [b.name for b in s.legs["LH"].bones]
    assert not any("pelvis" in n.lower() or "hips" in n.lower() for n in hind), hind


def test_a_bone_running_sideways_is_no_shoulder_blade(empty_scene):
    """A clavicle that runs out sideways from the spine, level with the shoulder joint,
    swings nothing in the leg's plane: the fore leg starts at the upper arm."""
    obj = build(empty_scene, "game")
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in obj.data.edit_bones:
        if "Shoulder" in bone.name:
            bone.head.z = bone.tail.z
    bpy.ops.object.mode_set(mode="OBJECT")
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    assert obj.kodawari_gait.legs["LF"].bones[0].name == "b_LeftUpperArm_09"


def _ramp(obj, fps):
    """Walk -> gallop -> walk keyed in this animal's own (Froude-scaled) speed bands.
    Returns ((first frame, last frame, speed) of the steady holds, end frame)."""
    s = obj.kodawari_gait
    top = {e.name: e.speed_max for e in s.table}
    walk = 0.7 * top["WALK"]
    gallop = 0.5 * (top["CANTER"] + top["GALLOP"])
    s.acceleration = 8.0
    t = [0.0, 2.5, 4.5, 7.5, 10.0, 12.5]
    keys = [(1 + round(x * fps), v) for x, v in zip(t, (walk, walk, gallop, gallop, walk, walk))]
    for frame, speed in keys:
        s.speed = speed
        obj.keyframe_insert(data_path="kodawari_gait.speed", frame=frame)
    # steady: from 0.8 s after a hold starts (the acceleration has caught up) to its end
    holds = [
        (keys[0][0] + round(0.8 * fps), keys[1][0], walk),
        (keys[2][0] + round(1.2 * fps), keys[3][0], gallop),
        (keys[4][0] + round(1.0 * fps), keys[5][0], walk),
    ]
    return holds, keys[-1][0]


@pytest.mark.parametrize(
    "case,fps",
    [(c, 24) for c in CASES + ["game@0.01/object"]]
    + [(c, 240) for c in ("horse", "cat@0.01", "game@0.01/object")],
)
def test_walk_gallop_walk_on_the_rig(empty_scene, case, fps):
    """The keyed world speed (+-2%), planted feet that hold (< 5 mm), a level body in
    steady gaits (pitch within +-10 deg of rest) and no planted-leg joint snapping: no
    change inside a stance over 3x its neighbouring frames' (+1 deg). A toe joint leaving
    its limit in one 1.07 deg step at a walk, beside 0.01 deg changes, made 1.04x of that
    on the game-style rigs at 24 fps; with such stances evened out, at most 0.74x. At
    240 fps too (the fox-sized rigs turn their joints fastest there)."""
    from kodawari.gait import runtime

    empty_scene.render.fps, empty_scene.render.fps_base = fps, 1.0
    case, _, where = case.partition("/")
    obj = _setup(empty_scene, case, root_motion=where.upper() or "AUTO")
    if where == "object":  # root motion on the armature object, which stands somewhere, turned
        obj.location = (2.0, 1.0, 0.5)
        obj.rotation_euler = (0.0, 0.0, 0.6)
    holds, end = _ramp(obj, fps)
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=end) == {"FINISHED"}
    result = runtime.last_bake(obj)["result"]
    frames = np.arange(1, end + 1)
    legs = evaluated_legs(obj, frames)
    gaits = result["gait"]
    assert (
        gaits.max() >= 3 and gaits[0] == 0 and gaits[-1] == 0
    )  # it galloped, and walked at both ends
    roots = np.mean([legs[k][:, 0] for k in LEGS], axis=0)
    fore = (legs["LF"][:, 0] + legs["RF"][:, 0]) / 2
    hind = (legs["LH"][:, 0] + legs["RH"][:, 0]) / 2
    pitch = np.degrees(
        np.arctan2(fore[:, 2] - hind[:, 2], np.linalg.norm((fore - hind)[:, :2], axis=1))
    )
    empty_scene.frame_set(1)
    rest = {
        k: np.array(
            obj.matrix_world @ obj.data.bones[obj.kodawari_gait.legs[k].bones[0].name].head_local
        )
        for k in LEGS
    }
    rest_fore, rest_hind = (rest["LF"] + rest["RF"]) / 2, (rest["LH"] + rest["RH"]) / 2
    rest_pitch = np.degrees(
        np.arctan2(rest_fore[2] - rest_hind[2], np.linalg.norm((rest_fore - rest_hind)[:2]))
    )
    for a, b, speed in holds:
        travelled = np.linalg.norm(roots[b - 1, :2] - roots[a - 1, :2])
        measured = travelled / ((b - a) / fps)
        assert measured == pytest.approx(speed, rel=0.02), (case, a, b, measured, speed)
        assert np.abs(pitch[a - 1 : b] - rest_pitch).max() <= 10.0, (
            case,
            a,
            np.abs(pitch[a - 1 : b] - rest_pitch).max(),
        )
    # The galloping feet really plant in the frames a user sees (the table's duty factor,
    # 0.2-0.35 at this speed: measured 0.18-0.27 at 24 fps): a foot that lands a long way
    # ahead and leaves early would hide a snap at touch-down by hardly ever planting
    # (0.00-0.14 measured with a ground-speed-matching landing ease tried on these rigs).
    a, b, _ = holds[1]
    duty = (result["contacts"][a - 1 : b] > 0.5).mean(axis=0)
    assert duty.min() >= 0.15, (case, duty)
    heading = headings(legs)
    for k, leg in enumerate(LEGS):
        planted = result["contacts"][:, k] > 0.5
        foot = legs[leg][:, -1]
        # the largest distance a planted foot moves from where it landed
        slide, anchor = 0.0, None
        for f in range(len(frames)):
            if planted[f]:
                anchor = foot[f] if anchor is None else anchor
                slide = max(slide, float(np.linalg.norm(foot[f] - anchor)))
            else:
                anchor = None
        assert slide < 0.005, (case, leg, slide)
        _, ratio = planted_snaps(joint_angles(legs[leg], heading), planted, min_stance=4)
        assert ratio <= 1.0, (case, leg, ratio)


# The rigs measured at 240 fps: the large ones, the fox-sized ones, whose joints turn
# fastest (angular speeds grow as 1/sqrt(size) at Froude-scaled speeds), and the fox-sized
# rig under every naming convention, scale and body bone the set-up tests read.
RIGS_240 = (
    "horse",
    "sample_horse",
    "wolf",
    "cat@0.01",
    "game",
    "game@0.01/object",
    "mixamo@0.01",
    "unreal+connected",
    "max_biped@0.01+connected",
)


@pytest.mark.parametrize("case,fps", [(c, 240) for c in RIGS_240] + [("mixamo@0.01", 60)])
def test_planted_joints_never_snap(empty_scene, case, fps):
    """A planted leg keeps its configuration: at 240 fps no joint turns more than the
    issue's 10 deg between frames, the change into each touch-down frame included, and
    at 60 fps none more than 3x its neighbouring frames' change (+1 deg) inside a stance
    (measured 0.35x). The first solver turned a joint 55 deg in a frame on the sample
    horse; before stances were evened out the worst was 9.3 deg (Rigify horse), 9.0
    (sample horse), 7.8 (wolf), 12.8 (Rigify cat at 0.01), 15.0 (game-style rig) and
    15.7 (game-style rig at 0.01, root motion on the object); evened out, 7.8, 6.0, 7.0,
    11.0, 12.6 and 13.5: the fox-sized fore legs touched down and lifted off nearly
    straight. With each fore leg's shoulder blade in its chain (docs/algorithms.md
    §4.11), 4.9, 6.0 (its scapula was already in), 5.3, 9.4, 9.4 and 9.7."""
    result, legs = _bake_to_a_gallop_and_back(empty_scene, case, fps)
    heading = headings(legs)
    for k, leg in enumerate(LEGS):
        planted = result["contacts"][:, k] > 0.5
        step, ratio = planted_snaps(
            joint_angles(legs[leg], heading),
            planted,
            min_stance=1 if fps >= 240 else 4,
            touchdown=True,
        )
        if fps >= 240:
            assert step <= 10.0, (case, leg, step)
        else:
            assert ratio <= 1.0, (case, leg, ratio)


@pytest.mark.parametrize(
    "case,fps",
    [(c, 24) for c in ("wolf", "horse", "cat@0.01", "game", "sample_horse", "game@0.01/object")]
    + [(c, 60) for c in ("wolf", "horse", "cat@0.01", "game", "game@0.01/object")],
)
def test_touch_down_and_lift_off_joints_carry_on_the_stance(empty_scene, case, fps):
    """Counting every planted-leg joint change, the touch-down change and the changes
    beside lift-off included, against the issue's allowance (3x the neighbouring frames'
    change + 1 deg). A swinging leg used to meet its stance in another configuration
    (a joint hardly moving in the swing's last frames turned up to 30 deg into the
    touch-down frame and stopped again: Rigify cat at 0.01, 24 fps), to hover just
    above the ground for the swing's last frame while the stance then swept the leg
    back, and to stop the stance's joints dead at lift-off (wolf at 60 fps: 12.7 deg in
    the stance's last frame, 0.4 deg at lift-off). The worst was 7.4x (wolf), 4.7x
    (Rigify horse), 3.7x (cat), 6.8x (game-style rig), 5.1x (sample horse) at 24 fps;
    with each swing meeting its stances and striking feet 1.9x, 1.8x, 2.3x, 2.1x, 2.2x
    (1.9x on the game-style rig at 0.01 with root motion on the object) and at 60 fps
    1.9x, 1.0x, 1.2x, 1.8x (1.9x). Now each stance breaking the rule is evened out with
    the swings beside it and a lift-off beside a slow swing change carries on into the
    swing: 0.98x, 0.97x, 0.90x, 0.98x, 0.97x (0.99x) at 24 fps, 1.00x, 0.99x, 1.00x,
    0.98x (0.96x) at 60 fps: the issue's rule met (docs/algorithms.md §4.8)."""
    result, legs = _bake_to_a_gallop_and_back(empty_scene, case, fps)
    heading = headings(legs)
    for k, leg in enumerate(LEGS):
        planted = result["contacts"][:, k] > 0.5
        ratio = stance_end_ratio(joint_angles(legs[leg], heading), planted)
        assert ratio <= 1.0, (case, fps, leg, ratio)


def _bake_to_a_gallop_and_back(empty_scene, case, fps):
    """0.7 x walk top -> 0.9 x gallop top -> 0.7 x walk top over 7 s at `fps`, baked:
    (the bake's result, the evaluated legs). "case/object": root motion on the armature
    object, which stands somewhere, turned."""
    from kodawari.gait import runtime

    empty_scene.render.fps, empty_scene.render.fps_base = fps, 1.0
    case, _, where = case.partition("/")
    if case == "sample_horse":
        from gait_scene import horse

        obj = horse(empty_scene, fps=fps)
        for child in list(obj.children):  # the skin mesh: not what is measured, slow to evaluate
            bpy.data.objects.remove(child)
    else:
        obj = _setup(empty_scene, case, root_motion=where.upper() or "AUTO")
    if where == "object":
        obj.location = (2.0, 1.0, 0.5)
        obj.rotation_euler = (0.0, 0.0, 0.6)
    s = obj.kodawari_gait
    top = {e.name: e.speed_max for e in s.table}
    end = 7 * fps
    s.acceleration = 6.0
    for frame, speed in (
        (1, 0.7 * top["WALK"]),
        (end // 2, 0.9 * top["GALLOP"]),
        (end, 0.7 * top["WALK"]),
    ):
        s.speed = speed
        obj.keyframe_insert(data_path="kodawari_gait.speed", frame=frame)
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=end) == {"FINISHED"}
    result = runtime.last_bake(obj)["result"]
    return result, evaluated_legs(obj, np.arange(1, end + 1))


@pytest.mark.parametrize("animal", ["cat", "wolf", "horse"])
def test_a_centimetre_rig_is_the_same_animal_in_the_world(empty_scene, animal):
    """The object-scale-0.01 cases are the metarig itself, only stored 100x larger: every
    bone the same length and place in the world (scaling each connected bone in turn
    once scaled a shared joint twice: the cat's thigh came out 20 m long and its gait
    figures meant nothing)."""
    from gait_scene import rigify_metarig

    def world_bones(obj):
        bpy.context.view_layer.update()  # matrix_world after the object scale was set
        m = obj.matrix_world
        return {
            b.name: (np.array(m @ b.head_local), np.array(m @ b.tail_local)) for b in obj.data.bones
        }

    plain = world_bones(rigify_metarig(empty_scene, animal))
    scaled = world_bones(rigify_metarig(empty_scene, animal, scale=0.01))
    assert plain.keys() == scaled.keys()
    for name, (head, tail) in plain.items():
        assert np.allclose(scaled[name][0], head, atol=1e-5), name
        assert np.allclose(scaled[name][1], tail, atol=1e-5), name


def test_root_motion_defaults_to_the_object_when_the_legs_share_no_bone(empty_scene):
    obj = build(empty_scene, "unreal")
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    for bone in obj.data.edit_bones:  # every leg a root of its own
        if bone.name.startswith(("thigh", "clavicle")):
            bone.parent = None
    bpy.ops.object.mode_set(mode="OBJECT")
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    assert obj.kodawari_gait.root_motion == "OBJECT"


@pytest.mark.parametrize(
    "case,fault,message",
    [
        ("mixamo", "three_legs", r"missing RH"),
        ("unreal", "one_bone", r"Leg LH \('thigh_l'\) has a single bone"),
        ("game", "unreachable", r"Leg LF cannot reach the ground"),
    ],
)
def test_a_rig_that_cannot_walk_is_refused_naming_the_leg(empty_scene, case, fault, message):
    obj = build(empty_scene, case)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    eb = obj.data.edit_bones
    side = {"mixamo": "mixamorig:Right", "unreal": "_l", "game": "b_Left"}[case]
    if fault == "three_legs":
        for bone in [
            b
            for b in eb
            if b.name.startswith(side) and ("Leg" in b.name or "Foot" in b.name or "Toe" in b.name)
        ]:
            eb.remove(bone)
    elif fault == "one_bone":
        for name in ("calf_l", "foot_l", "ball_l"):
            eb.remove(eb[name])
    else:  # the left fore paw lifted 30 cm: its leg is too short to reach the ground
        for bone in [
            b for b in eb if b.name.startswith(side) and ("Arm" in b.name or "Hand" in b.name)
        ]:
            if not bone.use_connect:
                bone.head.z += 0.3
            bone.tail.z += 0.3
    bpy.ops.object.mode_set(mode="OBJECT")
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.kodawari.gait_setup()
    assert len(obj.kodawari_gait.legs) == 0 and obj.kodawari_gait.body_bone == ""
