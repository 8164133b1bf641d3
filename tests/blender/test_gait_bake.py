"""kodawari.gait_bake: the Action it writes, measured back from its F-curves (the
issue's "Must show"), bad input refused with nothing changed, Esc-cancel restoring."""

import bpy
import numpy as np
import pytest
from gait_scene import fcurve_snapshot, horse

GAITS = ("WALK", "TROT", "CANTER", "GALLOP", "GALLOP_ROTARY")


def test_bake_writes_every_channel_and_keeps_the_speed_keys(empty_scene):
    from kodawari import fcurves

    rig = horse(empty_scene, [(1, 1.5), (60, 3.0)])
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=60) == {"FINISHED"}
    action = rig.animation_data.action
    curves = {(c.data_path, c.array_index): c for c in fcurves.action_fcurves(action, rig)}
    for leg in rig.kodawari_gait.legs:
        for bone in leg.bones:
            # Hinges about the bone's own X axis are one Euler channel, others a quaternion.
            euler = curves.get((f'pose.bones["{bone.name}"].rotation_euler', 0))
            quats = [
                curves.get((f'pose.bones["{bone.name}"].rotation_quaternion', i)) for i in range(4)
            ]
            assert euler is not None or all(q is not None for q in quats), bone.name
            for c in [euler] if euler is not None else quats:
                assert len(c.keyframe_points) == 60
    for i in range(3):
        assert ('pose.bones["body"].location', i) in curves
    for i in range(4):
        assert ('pose.bones["body"].rotation_quaternion', i) in curves
    for leg in ("LF", "RF", "LH", "RH"):
        c = curves[(f'["kodawari_contact_{leg}"]', 0)]
        values = fcurves.read_keys(c)[1]
        assert set(np.unique(values)) <= {0.0, 1.0} and values.min() == 0 and values.max() == 1
        assert c.keyframe_points[0].interpolation == "CONSTANT"
        assert f"kodawari_contact_{leg}" in rig.keys()
    assert ("kodawari_gait.speed", 0) in curves  # the user's speed keys survive
    # The pose plays back: a planted hoof's armature-space position holds still.
    empty_scene.frame_set(30)
    assert rig.pose.bones["body"].location.length > 1.0


def _steady(rig, fps, seconds):
    """Bake `seconds` at the settings' speed and gait; measure the baked Action after
    the first 2 s (whole cycles at steady speed)."""
    from kodawari.gait import metrics
    from kodawari.gait import rig as rigmod
    from kodawari.gait.report import measure_baked

    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=int(seconds * fps)) == {"FINISHED"}
    data = measure_baked(rig, fps)
    s = rig.kodawari_gait
    keep = slice(2 * fps, None)
    segs = metrics.measure(
        data["feet"][keep],
        data["roots"][keep],
        data["headings"][keep],
        data["contacts"][keep],
        data["gait"][keep],
        data["angles"][keep],
        np.radians([b.limit_min for leg in s.legs for b in leg.bones]),
        np.radians([b.limit_max for leg in s.legs for b in leg.bones]),
        rigmod.neutral_offsets(data["rig"]),
        data["reach"],
        fps,
    )
    assert len(segs) == 1
    return segs[0]


def test_a_rolled_bone_is_keyed_by_quaternion_and_measures_the_same(empty_scene):
    from kodawari.gait import runtime
    from kodawari.gait.report import measure_baked

    rig = horse(empty_scene, [(1, 3.0), (48, 3.0)])
    bpy.ops.object.mode_set(mode="EDIT")
    rig.data.edit_bones["fore_radius.L"].roll = 0.7  # its X axis is no longer the hinge
    bpy.ops.object.mode_set(mode="OBJECT")
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=48) == {"FINISHED"}
    assert rig.pose.bones["fore_radius.L"].rotation_mode == "QUATERNION"
    assert rig.pose.bones["fore_humerus.L"].rotation_mode == "XYZ"
    measured = measure_baked(rig, 24)
    solved = runtime.last_bake(rig)["result"]
    assert np.abs(measured["feet"] - solved["feet"]).max() < 1e-3
    # and Blender's own evaluation of the baked pose puts the hoof where we solved it
    empty_scene.frame_set(30)
    tail = rig.matrix_world @ rig.pose.bones["fore_cannon.L"].tail
    assert np.abs(np.array(tail) - solved["feet"][29, 0]).max() < 2e-3


@pytest.mark.parametrize(
    "gait,speed",
    [("WALK", 1.2), ("TROT", 3.5), ("CANTER", 5.5), ("GALLOP", 12.0), ("GALLOP_ROTARY", 12.0)],
)
def test_steady_gait_measured_from_the_action_matches_the_table(empty_scene, gait, speed):
    from kodawari import native
    from kodawari.gait import rig as rigmod

    fps = 240
    rig = horse(empty_scene, fps=fps)
    s = rig.kodawari_gait
    s.gait, s.speed = gait, speed
    seg = _steady(rig, fps, 5)
    assert seg["gait"] == gait
    entry = s.table[gait]
    kn = native.module()
    table = rigmod.table_dict(s)
    phases = kn.gait_leg_phases(table, GAITS.index(gait))
    # the duty factor at this speed (the gallop's falls with speed)
    duty = kn.gait_duty_factor(table, GAITS.index(gait), speed, 1.4)
    for k, leg in enumerate(("LF", "RF", "LH", "RH")):
        got = seg["legs"][leg]
        assert abs(got["duty_factor"] - duty) < 0.03, (leg, got["duty_factor"])
        assert abs((got["phase"] - phases[k] + 0.5) % 1 - 0.5) < 0.03, (
            leg,
            got["phase"],
            phases[k],
        )
        assert got["stride"] == pytest.approx(speed * entry.swing_time / (1 - duty), rel=0.01)
        assert got["largest_stance_slide"] < 0.005


def test_trot_at_5_mps_strides_3_m(empty_scene):
    fps = 240
    rig = horse(empty_scene, fps=fps)
    rig.kodawari_gait.gait, rig.kodawari_gait.speed = "TROT", 5.0
    seg = _steady(rig, fps, 4)
    for leg in ("LF", "RF", "LH", "RH"):
        assert seg["legs"][leg]["stride"] == pytest.approx(3.0, abs=0.02)


def test_speed_zero_stands_still(empty_scene):
    from kodawari.gait.report import measure_baked

    rig = horse(empty_scene)
    rig.kodawari_gait.speed = 0.0
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=48)
    data = measure_baked(rig, 24)
    assert (data["contacts"] == 1).all()
    assert np.ptp(data["feet"], axis=0).max() < 5e-4
    assert np.ptp(data["body_location"], axis=0).max() == 0


def test_bake_is_deterministic(empty_scene):
    rig = horse(empty_scene, [(1, 1.5), (100, 9.0)])
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=100)
    first = fcurve_snapshot(rig)
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=100)
    assert fcurve_snapshot(rig) == first


@pytest.mark.parametrize(
    "case,message",
    [
        ("negative", "speed is negative"),
        ("too_fast", "past the range"),
        ("far_ground", "does not lie under"),
        ("cliff", "out of the legs' reach"),
        ("one_bone", "needs 2 to 6"),
        ("no_body", "no body bone"),
    ],
)
def test_bad_input_is_refused_and_changes_nothing(empty_scene, case, message):
    rig = horse(empty_scene, [(1, 2.0), (40, 2.0)])
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=40)  # an earlier bake to protect
    s = rig.kodawari_gait
    if case == "negative":
        import gait_samples as samples

        samples.key_speed(rig, [(20, -1.0)])
    elif case == "too_fast":
        s.speed = 40.0
        rig.animation_data.action = rig.animation_data.action  # keep the action
        from kodawari import fcurves

        action = rig.animation_data.action
        c = fcurves.find_fcurve(action, rig, "kodawari_gait.speed")
        for point in c.keyframe_points:
            point.co.y = 40.0
        c.update()
    elif case == "far_ground":
        ground = bpy.data.objects.new("Ground", bpy.data.meshes.new("Ground"))
        ground.data.from_pydata(
            [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)]
        )
        ground.location = (500.0, 0.0, 0.0)
        empty_scene.collection.objects.link(ground)
        s.ground = ground
    elif case == "cliff":  # flat, then a 1.2 m wall up across the run
        ground = bpy.data.objects.new("Cliff", bpy.data.meshes.new("Cliff"))
        ground.data.from_pydata(
            [
                (-5, 10, 0),
                (5, 10, 0),
                (5, -3, 0),
                (-5, -3, 0),
                (-5, -3, 1.2),
                (5, -3, 1.2),
                (5, -60, 1.2),
                (-5, -60, 1.2),
            ],
            [],
            [(0, 1, 2, 3), (3, 2, 5, 4), (4, 5, 6, 7)],
        )
        empty_scene.collection.objects.link(ground)
        s.ground = ground
    elif case == "one_bone":
        bones = s.legs["RH"].bones
        while len(bones) > 1:
            bones.remove(len(bones) - 1)
    elif case == "no_body":
        s.body_bone = ""
    before = fcurve_snapshot(rig)
    action = rig.animation_data.action
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=40)
    assert rig.animation_data.action == action
    assert fcurve_snapshot(rig) == before


def test_not_an_armature_is_refused(empty_scene):
    mesh = bpy.data.objects.new("Cube", bpy.data.meshes.new("Cube"))
    empty_scene.collection.objects.link(mesh)
    bpy.context.view_layer.objects.active = mesh
    with pytest.raises(RuntimeError, match="not an armature"):
        bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=10)
    assert mesh.animation_data is None


def test_cancel_puts_everything_back(empty_scene):
    from kodawari.gait.bake import GaitBakeJob

    rig = horse(empty_scene, [(1, 2.0), (40, 2.0)])
    action = rig.animation_data.action
    before = fcurve_snapshot(rig)
    modes = {pb.name: pb.rotation_mode for pb in rig.pose.bones}
    job = GaitBakeJob(bpy.context, rig, 1, 40)
    job.begin()
    steps = job.steps()
    next(steps)
    next(steps)  # some channels written, then Esc
    job.cancel()
    assert rig.animation_data.action == action
    assert fcurve_snapshot(rig) == before
    assert {pb.name: pb.rotation_mode for pb in rig.pose.bones} == modes
    assert not any(k.startswith("kodawari_contact_") for k in rig.keys())
    assert len(list(bpy.data.actions)) == 1


def test_feet_follow_a_sloped_ground(empty_scene):
    import math

    from kodawari.gait.report import measure_baked

    rig = horse(empty_scene)
    ground = bpy.data.objects.new("Slope", bpy.data.meshes.new("Slope"))
    ground.data.from_pydata(
        [(-5, -60, 0), (5, -60, 0), (5, 10, 0), (-5, 10, 0)], [], [(0, 1, 2, 3)]
    )
    ground.rotation_euler = (math.radians(-4.0), 0.0, 0.0)  # rises towards -Y, where the horse goes
    empty_scene.collection.objects.link(ground)
    empty_scene.view_layers[0].update()
    s = rig.kodawari_gait
    s.ground, s.speed = ground, 2.0
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=120) == {"FINISHED"}
    data = measure_baked(rig, 24)
    feet, planted = data["feet"], data["contacts"] > 0.5
    slope = math.tan(math.radians(4.0))
    expected = -feet[..., 1] * slope  # plane height under each foot
    assert np.abs(feet[..., 2] - expected)[planted].max() < 0.01
    assert feet[-1, :, 2].mean() > 0.3  # it really climbed


def test_follows_a_path_curve(empty_scene):
    from kodawari.gait import runtime

    rig = horse(empty_scene)
    curve = bpy.data.curves.new("Path", "CURVE")
    curve.dimensions = "3D"
    spline = curve.splines.new("POLY")
    pts = [(0, 0, 0), (0, -10, 0), (10, -20, 0), (20, -20, 0)]
    spline.points.add(len(pts) - 1)
    for p, co in zip(spline.points, pts):
        p.co = (*co, 1.0)
    path = bpy.data.objects.new("Path", curve)
    empty_scene.collection.objects.link(path)
    s = rig.kodawari_gait
    s.path, s.speed = path, 3.0
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=260) == {"FINISHED"}
    result = runtime.last_bake(rig)["result"]
    heading = result["headings"]
    assert heading[0] @ np.array([0.0, -1.0, 0.0]) > 0.99  # starts along -Y
    assert heading[-1] @ np.array([1.0, 0.0, 0.0]) > 0.9  # turned to +X with the curve
    assert result["contacts"].min() == 0
