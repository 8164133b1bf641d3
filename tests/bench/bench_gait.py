"""Benchmark (not a test): bake 10,000 frames of the horse (4 legs x 4 bones + body)
end to end, F-curve writes included, then bake the same foot targets through Blender's
own IK constraints with nla.bake visual keying (fewer frames, scaled per frame), and
print the ratio. Run in Blender by tools/run_bench.sh with the add-on installed."""

import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blend_samples"))

FRAMES = 10_000
IK_FRAMES = 300


def setup():
    import gait_samples as samples

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    rig, _ = samples.build_horse(scene)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.kodawari.gait_setup()
    keys = [(1, 1.5)] + [(f, 15.0 if i % 2 == 0 else 3.0) for i, f in enumerate(range(500, FRAMES + 1, 500))]
    samples.key_speed(rig, keys)
    return scene, rig


def bench_ours(rig):
    from kodawari.gait.bake import GaitBakeJob

    t0 = time.perf_counter()
    job = GaitBakeJob(bpy.context, rig, 1, FRAMES)  # read settings + native plan and solve
    t1 = time.perf_counter()
    job.run()  # F-curve writes
    t2 = time.perf_counter()
    keys = sum(len(c.keyframe_points) for c in __import__("kodawari").fcurves.action_fcurves(
        rig.animation_data.action, rig))
    print(f"kodawari gait bake, {FRAMES} frames, 16 leg bones + body: {t2 - t0:.3f} s "
          f"(solve {t1 - t0:.3f} s, F-curve writes {t2 - t1:.3f} s, {keys} keys)")
    # and through the operator, as a user runs it
    t3 = time.perf_counter()
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=FRAMES)
    t4 = time.perf_counter()
    print(f"  bpy.ops.kodawari.gait_bake end to end: {t4 - t3:.3f} s ({(t4 - t3) / FRAMES * 1e6:.1f} us/frame)")
    return (t4 - t3) / FRAMES, job


def bench_blender_ik(scene, rig, job):
    """The same planned foot targets and body motion, legs solved by Blender's IK
    constraints (hinge-locked, with the same limits), baked by nla.bake visual keying."""
    from kodawari import fcurves

    settings = rig.kodawari_gait
    action = rig.animation_data.action
    # Leg rotations come from the constraints now: drop our leg F-curves, keep the body.
    leg_bones = [b.name for leg in settings.legs for b in leg.bones]
    ours = {f'pose.bones["{n}"].{p}' for n in leg_bones for p in ("rotation_quaternion", "rotation_euler")}
    for curve in list(fcurves.action_fcurves(action, rig)):
        if curve.data_path in ours:
            fcurves.remove_fcurve(action, rig, curve)
    feet = job.result["feet_planned"][:IK_FRAMES]
    frames = np.arange(1, IK_FRAMES + 1, dtype=np.float64)
    for k, leg in enumerate(settings.legs):
        target = bpy.data.objects.new(f"Target{leg.name}", None)
        scene.collection.objects.link(target)
        target_action = fcurves.ensure_action(target, f"Target{leg.name}")
        fcurves.write_channels(target_action, target, "location", frames, feet[:, k, :])
        foot = rig.pose.bones[leg.bones[-1].name]
        ik = foot.constraints.new("IK")
        ik.target = target
        ik.chain_count = len(leg.bones)
        for bone in leg.bones:
            pb = rig.pose.bones[bone.name]
            pb.lock_ik_y = pb.lock_ik_z = True  # a hinge, like ours
            pb.use_ik_limit_x = True
            pb.ik_min_x, pb.ik_max_x = np.radians(bone.limit_min), np.radians(bone.limit_max)
            pb.ik_stiffness_x = 1.0 - bone.stiffness
    bpy.context.view_layer.objects.active = rig
    rig.select_set(True)  # nla.bake works on the selected objects
    bpy.ops.object.mode_set(mode="POSE")
    t0 = time.perf_counter()
    bpy.ops.nla.bake(frame_start=1, frame_end=IK_FRAMES, only_selected=False, visual_keying=True,
                     clear_constraints=False, use_current_action=True, bake_types={"POSE"})
    t1 = time.perf_counter()
    per_frame = (t1 - t0) / IK_FRAMES
    baked = rig.animation_data.action
    keyed = {c.data_path for c in fcurves.action_fcurves(baked, rig) if len(c.keyframe_points) >= IK_FRAMES}
    print(f"  nla.bake wrote {len(keyed)} pose channels of {IK_FRAMES}+ keys into '{baked.name}'")
    print(f"Blender IK constraints + nla.bake visual keying: {IK_FRAMES} frames in {t1 - t0:.3f} s "
          f"({per_frame * 1e6:.0f} us/frame; {per_frame * FRAMES:.1f} s for {FRAMES} frames)")
    return per_frame


def main():
    scene, rig = setup()
    ours, job = bench_ours(rig)
    theirs = bench_blender_ik(scene, rig, job)
    print(f"ratio: kodawari gait bake is {theirs / ours:.1f}x faster per frame than Blender IK + nla.bake")


main()
