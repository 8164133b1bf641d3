"""Gait bake against Blender's IK constraints + nla.bake (run by tools/run_bench.sh in every
Blender; prints figures, never fails on time; writes out/bench.json -> gait).

The horse sample (4 legs x 4 bones + body), a speed ramp keyed every 500 frames, baked over
1,000, 10,000 and 100,000 frames:

  kodawari   bpy.ops.kodawari.gait_bake end to end (plan, native solve, F-curve writes)
  blender_ik the same planned foot targets (empties keyed per frame) and body motion, legs
             solved by Blender's IK constraints (hinge-locked, the same limits), baked by
             bpy.ops.nla.bake(visual_keying=True) into a NEW, empty action
             (use_current_action=False): no keys already there, nothing extrapolated.

Each (side, length) runs in its own child process: the time is min / median of 3 bakes
(one bake when one takes more than IK_ROUNDS_BELOW_S, said so) and the memory that process's peak. nla.bake's cost
per frame grows with the length in Blender 3.4 (every inserted key reallocates the F-curve);
a length whose bake would take more than IK_BUDGET_S seconds is not run: its figure is
extrapolated from the two longest bakes measured as t(n) = a n + b n^2 (a per frame, b for keys that
cost more as the F-curve grows), and is labelled "extrapolated" everywhere it appears.
"""

import gc
import math
import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib

print = benchlib.say  # each line at once, also through a pipe

LENGTHS = {1_000: None, 10_000: None, 100_000: None}
IK_PROBE = (500, 1_000)  # measured to get the growth exponent
IK_BUDGET_S = 40.0  # longest single IK bake we run; longer ones are extrapolated
IK_ROUNDS_BELOW_S = 5.0  # three bakes when one takes less than this, else one


def setup(frames):
    import gait_samples as samples  # blend_samples/: the sample rigs are not in the add-on

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 1, frames
    rig, _ = samples.build_horse(scene)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    keys = [(1, 1.5)] + [
        (f, 15.0 if i % 2 == 0 else 3.0) for i, f in enumerate(range(500, frames + 1, 500))
    ]
    samples.key_speed(rig, keys)
    return scene, rig


def bake_ours(frames, rounds):
    seconds = []
    for _ in range(rounds):
        start = time.perf_counter()
        result = bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=frames)
        seconds.append(time.perf_counter() - start)
        assert result == {"FINISHED"}, result
    return seconds


def prepare_ik(scene, rig, frames):
    """Feet planned by our planner (untimed), legs handed to IK constraints."""
    from kodawari import fcurves
    from kodawari.gait.bake import GaitBakeJob

    job = GaitBakeJob(bpy.context, rig, 1, frames)
    job.run()
    settings = rig.kodawari_gait
    action = rig.animation_data.action
    leg_bones = [b.name for leg in settings.legs for b in leg.bones]
    ours = {
        f'pose.bones["{n}"].{p}'
        for n in leg_bones
        for p in ("rotation_quaternion", "rotation_euler")
    }
    for curve in list(fcurves.action_fcurves(action, rig)):
        if curve.data_path in ours:
            fcurves.remove_fcurve(action, rig, curve)
    feet = job.result["feet_planned"][:frames]
    keyed = np.arange(1, frames + 1, dtype=np.float64)
    for k, leg in enumerate(settings.legs):
        target = bpy.data.objects.new(f"Target{leg.name}", None)
        scene.collection.objects.link(target)
        target_action = fcurves.ensure_action(target, f"Target{leg.name}")
        fcurves.write_channels(target_action, target, "location", keyed, feet[:, k, :])
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
    del job
    bpy.context.view_layer.objects.active = rig
    rig.select_set(True)  # nla.bake works on the selected objects
    bpy.ops.object.mode_set(mode="POSE")
    return action


def bake_ik(rig, source, frames, rounds):
    from kodawari import fcurves

    slot = fcurves.current_slot_identifier(rig)
    seconds, channels = [], 0
    for _ in range(rounds):
        fcurves.assign_action(rig, source, slot)
        start = time.perf_counter()
        bpy.ops.nla.bake(
            frame_start=1,
            frame_end=frames,
            only_selected=False,
            visual_keying=True,
            clear_constraints=False,
            use_current_action=False,
            bake_types={"POSE"},
        )
        seconds.append(time.perf_counter() - start)
        baked = rig.animation_data.action
        assert baked is not source
        channels = sum(
            1 for c in fcurves.action_fcurves(baked, rig) if len(c.keyframe_points) >= frames
        )
        fcurves.assign_action(rig, source, slot)
        bpy.data.actions.remove(baked)
    return seconds, channels


def child(spec):
    frames, side, rounds = spec["frames"], spec["side"], spec["rounds"]
    scene, rig = setup(frames)
    gc.collect()
    if side == "kodawari":
        start = benchlib.rss_mb()
        benchlib.reset_peak_rss()
        seconds, extra = bake_ours(frames, rounds), {}
    else:
        source = prepare_ik(scene, rig, frames)
        gc.collect()
        start = benchlib.rss_mb()
        benchlib.reset_peak_rss()
        seconds, channels = bake_ik(rig, source, frames, rounds)
        extra = {"channels": channels}
    peak = benchlib.peak_rss_mb()
    benchlib.child_report(
        {
            "seconds": seconds,
            "peak_rss_mb": round(peak, 1),
            "above_start_mb": round(peak - start, 1),
            "load": benchlib.load(),
            **extra,
        }
    )


def summarize(frames, side, report, rounds, extrapolated=None):
    if extrapolated is not None:
        return {
            "side": side,
            "frames": frames,
            "extrapolated": True,
            "s_min": extrapolated,
            "s_median": extrapolated,
            "us_per_frame": round(extrapolated / frames * 1e6, 1),
            "how": report,
        }
    if "error" in report:
        return {"side": side, "frames": frames, "error": report["error"]}
    s = report["seconds"]
    return {
        "side": side,
        "frames": frames,
        "rounds": rounds,
        "s_min": round(min(s), 4),
        "s_median": round(float(np.median(s)), 4),
        "us_per_frame": round(min(s) / frames * 1e6, 1),
        "load": report["load"],
        "peak_rss_mb": report["peak_rss_mb"],
        "above_start_mb": report["above_start_mb"],
        **({"channels": report["channels"]} if "channels" in report else {}),
    }


def main():
    print(
        f"=== gait bake ({benchlib.blender_label()}, {os.cpu_count()} CPUs, load {benchlib.load()}): "
        f"seconds min / median of the bakes; each side and length in its own process"
    )
    lengths = list(benchlib.sizes(LENGTHS))
    rows = []
    for frames in lengths:
        rows.append(
            summarize(
                frames,
                "kodawari",
                benchlib.run_child(__file__, {"side": "kodawari", "frames": frames, "rounds": 3}),
                3,
            )
        )
    # Blender IK: two probe lengths, then each requested length measured when affordable.
    measured = {}
    for frames in sorted(set(IK_PROBE) | set(lengths)):
        if frames not in IK_PROBE:
            if IK_PROBE[0] not in measured or IK_PROBE[1] not in measured:
                rows.append({"side": "blender_ik", "frames": frames, "error": "probe bakes failed"})
                continue
            # the two longest bakes measured so far
            (n0, t0), (n1, t1) = sorted(measured.items())[-2:]
            # t(n) = a n + b n^2: a per baked frame (evaluate, key), b for keys that get dearer as
            # the curve grows (3.4 reallocates an F-curve's key array on every insert).
            b = max((t1 / n1 - t0 / n0) / (n1 - n0), 0.0)
            a = t0 / n0 - b * n0
            predicted = a * frames + b * frames**2
            exponent = math.log(t1 / t0) / math.log(n1 / n0)
            power_law = t1 * (frames / n1) ** exponent
            if predicted > IK_BUDGET_S:
                rows.append(
                    summarize(
                        frames,
                        "blender_ik",
                        (
                            f"extrapolated from the {n0:,}- and {n1:,}-frame bakes ({t0:.2f} s, {t1:.2f} s) as "
                            f"a*n + b*n^2 (a = {a * 1e3:.2f} ms/frame, b = {b * 1e6:.3f} us/frame^2): {predicted:.0f} s; "
                            f"a power law n^{exponent:.2f} through the same two bakes gives {power_law:.0f} s"
                        ),
                        0,
                        round(predicted, 1),
                    )
                )
                continue
        rounds = 1
        if frames == IK_PROBE[1] and IK_PROBE[0] in measured:
            rounds = 3 if measured[IK_PROBE[0]] * frames / IK_PROBE[0] < IK_ROUNDS_BELOW_S else 1
        row = summarize(
            frames,
            "blender_ik",
            benchlib.run_child(
                __file__, {"side": "blender_ik", "frames": frames, "rounds": rounds}
            ),
            rounds,
        )
        if "s_min" in row:
            measured[frames] = row["s_min"]
        row["probe_only"] = frames not in lengths
        rows.append(row)
    for frames in lengths:
        ours = next(r for r in rows if r["side"] == "kodawari" and r["frames"] == frames)
        theirs = [r for r in rows if r["side"] == "blender_ik" and r["frames"] == frames]
        print(f"  {frames:>7,} frames:")
        for row in [ours, *theirs]:
            if "error" in row:
                print(f"    {row['side']:10s} failed: {row['error']}")
                continue
            if row.get("extrapolated"):
                print(f"    {row['side']:10s} ~{row['s_min']:9.1f} s  EXTRAPOLATED ({row['how']})")
            else:
                print(
                    f"    {row['side']:10s} {row['s_min']:9.3f} / {row['s_median']:9.3f} s ({row['rounds']} bake(s))"
                    f" = {row['us_per_frame']:8.1f} us/frame  {benchlib.fmt_mem(row)}  load {row['load']:4.1f}"
                )
        if theirs and "s_min" in ours and "s_min" in theirs[0]:
            tag = " (extrapolated)" if theirs[0].get("extrapolated") else ""
            print(
                f"    ratio blender_ik / kodawari: {theirs[0]['s_min'] / ours['s_min']:8.0f}x{tag}"
            )
    benchlib.record("gait", rows)


if __name__ == "__main__":
    spec = benchlib.child_spec()
    if spec is not None:
        child(spec)
    else:
        main()
