"""Hair, whole frame against whole frame (run by tools/run_bench.sh in every Blender; prints
figures, never fails on time; writes out/bench.json -> hair).

An armature of CHAINS chains x 16 connected bones under an animated "Head" bone (160, 1,600
and 16,000 chain bones). Per frame, every side gets what a viewport does: `scene.frame_set(f)`
then the depsgraph evaluates whatever the frame handlers tagged.

  kodawari      the add-on's live hair (every chain a rod, 4 substeps per frame), frames played
                for the first time: the head's pose predicted from its action, the frame solved
                and written before Blender evaluates it (frame_change_pre), Blender's evaluation,
                the prediction checked against it (frame_change_post); one evaluation. On rigs of
                4,096 rod bones or more the frame was solved ahead, on native threads, while
                Blender evaluated the frame before (runtime.AHEAD_MIN_ROD_BONES; the first new
                frame once the start frame's pass was over); frames set back to back, as here,
                leave that solve only Blender's evaluation to hide in (in real playback it also has
                the viewport's drawing and the wait for the next frame)
  kodawari_inline  the same, every frame solved in its own frame_change_pre (nothing solved ahead:
                the path before, and of rigs below the size above)
  kodawari_post the same frames solved after Blender's evaluation instead (prediction off, the
                path of rigs whose parents a constraint, driver or NLA moves): Blender's
                evaluation, our handler (read, solve, write), the second evaluation our write
                asks for
  bare          the same rig with the hair switched off: Blender's own evaluation, the floor
  wiggle2_port  a same-process port of Wiggle 2's algorithm (see wiggle2_port.py: Wiggle 2
                itself cannot be installed on this machine), every chain bone's tail wiggling
  kodawari_cached  the same frames played again from the cache (scrubbing back): written
                before Blender evaluates the frame (frame_change_pre), one evaluation
  kodawari_paced, bare_paced  kodawari and bare as a user playing the animation feels them: each
                frame requested at the scene's frame rate (frame_set, then a wait until the next
                1/fps tick; a late frame asks for the next one at once; the first new frame one
                tick after the start frame), only the frame itself timed (the main thread's work
                for it), the same way for both sides. Back to back, the frame solved ahead has only
                Blender's evaluation to hide in; paced, it also has the wait
  bare_retag    hair off, but a frame_change_post handler tags the armature as any write after
                Blender's evaluation must: Blender's own price for changing a pose from Python
                once it is evaluated (copy-on-write of the whole object + a second evaluation),
                the floor for every post-evaluation writer (Kodawari's new frames, Wiggle 2)

Sides are timed interleaved round by round in one process; each round starts at the scene's
first frame (every side resets there) and plays the following frames. The start frame is not in
the figures: for kodawari, bare and both paced sides it is set a second time each round (the
runtime built, as when playback starts or loops) and timed apart ("the start frame set again"):
there Kodawari resets the rods, looks at the rig for the prediction and starts solving the first
new frame ahead (runtime._start_after_reset), so the first new frame of a round is solved ahead
like the others. Peak memory per side comes from its own child process.
"""

import math
import os
import sys
import time

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib
import wiggle2_port

print = benchlib.say  # each line at once, also through a pipe

BONES, SUBSTEPS = 16, 4
BONE_LENGTH = 0.02
# chain bones -> (chains, frames per round for kodawari and bare, frames per round for the port).
# A round's first new frame also looks at the rig afresh and has nothing solved ahead: 8 frames
# at 16,000 bones (4 before) so that it weighs an eighth of a round, not a quarter.
SIZES = {160: (10, 12, 6), 1_600: (100, 8, 3), 16_000: (1000, 8, 1)}
# Rounds per side: 5, not benchlib's 3, because on a shared two-core machine the solve ahead and
# Blender's pass share the cores with whatever else runs, and 3 medians swung by 20-40 %.
ROUNDS = 5
SIDES = ("kodawari", "bare", "wiggle2_port")  # each also measured for peak memory
# timed only: their memory is kodawari's / bare's
EXTRA_SIDES = (
    "kodawari_cached",
    "kodawari_inline",
    "kodawari_post",
    "bare_retag",
    "kodawari_paced",
    "bare_paced",
)
PACED = ("kodawari_paced", "bare_paced")
# Sides whose rounds set the start frame a second time, timed apart: what a playback's start (or
# loop) costs once the rig's runtime is built. Kodawari resets there, looks at the rig for the
# prediction and starts solving the next frame ahead (runtime._start_after_reset).
START_TIMED = ("kodawari", "bare") + PACED


def build_rig(scene, chain_count):
    data = bpy.data.armatures.new("Bench")
    obj = bpy.data.objects.new("Bench", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    head = data.edit_bones.new("Head")
    head.head, head.tail = (0, 0, 1.5), (0, 0, 1.8)
    side = math.ceil(math.sqrt(chain_count))
    for c in range(chain_count):
        x, y = (c % side - side / 2) * 0.01, (c // side - side / 2) * 0.01
        parent, position = head, Vector((x, y, 1.8))
        for b in range(BONES):
            bone = data.edit_bones.new(f"C{c:04d}.{b:02d}")
            bone.head, bone.tail = position, position + Vector((0.0, 0.0, BONE_LENGTH))
            bone.parent, bone.use_connect = parent, b > 0
            parent, position = bone, position + Vector((0.0, 0.0, BONE_LENGTH))
    bpy.ops.object.mode_set(mode="POSE")
    from kodawari.hair import chains

    for pb in obj.pose.bones:
        chains.set_selected(pb, pb.name.endswith(".00"))
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    for rod in obj.kodawari_hair.rods:
        rod.substeps = SUBSTEPS
    head_pb = obj.pose.bones["Head"]
    for frame, location in (
        (1, (0, 0, 0)),
        (6, (0.2, 0, 0.05)),
        (12, (-0.2, 0.1, 0)),
        (18, (0, 0, 0)),
        (24, (0.1, -0.1, 0)),
    ):
        head_pb.location = location
        head_pb.keyframe_insert("location", frame=frame)
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def _no_prediction(self, obj, scene, frame):
    return False  # every new frame solved after Blender's evaluation


def _nothing_ahead(self, scene, frame, fps, after_reset=False):
    self.ahead_inputs = None  # every frame solved in its own frame_change_pre


_PREDICT = []  # the add-on's own ArmatureRuntime._predict and _start_ahead, once imported


def chain_bones(obj):
    return [pb for pb in obj.pose.bones if pb.name != "Head"]


class Sides:
    """Switches the rig between the three sides."""

    def __init__(self, scene, obj):
        from kodawari.hair import runtime

        if not _PREDICT:
            _PREDICT.extend(
                (runtime.ArmatureRuntime._predict, runtime.ArmatureRuntime._start_ahead)
            )
        self.scene, self.obj = scene, obj
        self.start_frames = {}  # side -> seconds of the start frame set again, per round
        self.wiggle = wiggle2_port.WigglePort(scene, obj, chain_bones(obj))

    def use(self, side):
        from kodawari.hair import runtime

        if side in PACED:
            side = side.removesuffix("_paced")  # the same rig and path, only the requests paced
        self.obj.kodawari_hair.enabled = side in (
            "kodawari",
            "kodawari_cached",
            "kodawari_inline",
            "kodawari_post",
        )
        runtime.ArmatureRuntime._start_ahead = (
            _nothing_ahead if side == "kodawari_inline" else _PREDICT[1]
        )
        if side == "kodawari_post":
            runtime.ArmatureRuntime._predict = _no_prediction
        elif "_predict" in vars(runtime.ArmatureRuntime) and (
            runtime.ArmatureRuntime._predict is _no_prediction
        ):
            runtime.ArmatureRuntime._predict = _PREDICT[0]
        if side == "wiggle2_port":
            self.wiggle.install()
        else:
            self.wiggle.uninstall()
        post = bpy.app.handlers.frame_change_post
        if side == "bare_retag" and self._retag not in post:
            post.append(self._retag)
        elif side != "bare_retag" and self._retag in post:
            post.remove(self._retag)

    def _retag(self, scene, depsgraph=None):
        self.obj.update_tag(refresh={"OBJECT"})  # what the live hair's write asks of Blender

    def frame(self, frame):
        self.scene.frame_set(frame)
        self.scene.view_layers[0].depsgraph.update()

    def paced(self, frames):
        """Plays `frames` as playback requests them: one every 1/fps seconds of the scene's frame
        rate, the first one tick after the start frame just shown (a frame that ends after its
        successor's tick has it requested at once); returns each frame's own time (frame_set and
        the evaluation), not the wait."""
        scene = self.scene
        period = scene.render.fps_base / scene.render.fps
        seconds = []
        tick = time.perf_counter() + period
        for frame in frames:
            while (left := tick - time.perf_counter()) > 0:
                time.sleep(left)
            start = time.perf_counter()
            self.frame(frame)
            end = time.perf_counter()
            seconds.append(end - start)
            tick = max(tick + period, end)
        return seconds

    def player(self, side, frames):
        def play(_round):
            self.use(side)
            self.frame(1)  # every side resets at the first frame (untimed; builds the runtime)
            if side in START_TIMED:
                # The start frame again, as playback starting or looping sets it (the runtime
                # built): timed apart, not in the side's figure (Sides.start_frames).
                start = time.perf_counter()
                self.frame(1)
                self.start_frames.setdefault(side, []).append(time.perf_counter() - start)
            if side == "wiggle2_port":
                self.wiggle.reset()
            if side == "kodawari_cached":
                for frame in frames:  # simulated once (untimed); timing starts with a jump back
                    self.frame(frame)
            seconds = []
            if side in PACED:
                seconds = self.paced(frames)
            for frame in frames if side not in PACED else ():
                start = time.perf_counter()
                self.frame(frame)
                seconds.append(time.perf_counter() - start)
            self.use(None)
            return seconds

        return play


def child(spec):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    start = benchlib.rss_mb()
    obj = build_rig(scene, spec["chains"])
    sides = Sides(scene, obj)
    build_peak = benchlib.peak_rss_mb()
    benchlib.reset_peak_rss()  # from here: the peak while playing
    sides.player(spec["side"], list(range(2, spec["frames"] + 2)))(0)
    play_peak = benchlib.peak_rss_mb()
    benchlib.child_report(
        {
            "peak_rss_mb": round(max(build_peak, play_peak), 1),
            "above_start_mb": round(play_peak - start, 1),
            "play_peak_mb": round(play_peak, 1),
            "build_peak_mb": round(build_peak, 1),
            "start_mb": round(start, 1),
        }
    )


def solver_alone(scene, obj, frames):
    """The add-on's handler alone (read parents, native step, write rotations) and the native
    step alone, on frames after a real frame_set (Blender's evaluation not counted)."""
    from kodawari.hair import runtime

    obj.kodawari_hair.enabled = False
    rt = runtime.ArmatureRuntime(obj)
    handler, native = [], []
    for _ in range(benchlib.ROUNDS):
        scene.frame_set(1)
        rt.evaluate(obj, scene, 1)
        times = []
        for frame in frames:
            scene.frame_set(frame)
            times.append(benchlib.timed(lambda f=frame: rt.evaluate(obj, scene, f)))
        handler.append(np.mean(times))
        armature = np.array([tuple(r) for r in obj.matrix_world], np.float64)
        camera, gravity = np.array([0.0, -5.0, 1.7]), np.array([0.0, 0.0, -9.81])

        def step(i, armature=armature, camera=camera, gravity=gravity):
            rt.system.step(
                rt.matrices, armature, camera, gravity, 3.0 + i / 24, 1 / 24, rt.rotations
            )

        native.append(np.mean([benchlib.timed(lambda i=i: step(i)) for i in range(len(frames))]))
    return {
        "handler_ms_min": round(min(handler) * 1e3, 3),
        "handler_ms_median": round(float(np.median(handler)) * 1e3, 3),
        "step_ms_min": round(min(native) * 1e3, 3),
        "step_ms_median": round(float(np.median(native)) * 1e3, 3),
    }


def measure_size(bones, chain_count, frames_ours, frames_port):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 250
    t = time.perf_counter()
    obj = build_rig(scene, chain_count)
    sides = Sides(scene, obj)
    setup = time.perf_counter() - t
    frames = {
        side: list(range(2, (frames_port if side == "wiggle2_port" else frames_ours) + 2))
        for side in SIDES
    }
    for side in EXTRA_SIDES:
        frames[side] = frames["kodawari"]
    players = {side: sides.player(side, frames[side]) for side in SIDES + EXTRA_SIDES}
    players["kodawari_untagged"] = untagged(sides.player("kodawari_post", frames["kodawari"]))
    rows = benchlib.Rounds(ROUNDS).run(players)
    split = rows.pop("kodawari_untagged")
    solver = solver_alone(scene, obj, frames["kodawari"])
    for side in EXTRA_SIDES:
        rows[side]["bones"] = bones
        rows[side]["frames_per_round"] = len(frames[side])
    for side in SIDES:
        memory = benchlib.run_child(
            __file__, {"side": side, "chains": chain_count, "frames": len(frames[side])}
        )
        rows[side].update(memory)
        rows[side]["bones"] = bones
        rows[side]["frames_per_round"] = len(frames[side])
    solver["untagged_ms_median"] = split["ms_median"]
    start_frames = {
        side: round(float(np.median(seconds)) * 1e3, 2)
        for side, seconds in sides.start_frames.items()
    }
    predicted, ahead = predicted_frames(sides.player("kodawari", frames["kodawari"]))
    phases = breakdown(sides, frames["kodawari"])
    return {
        "bones": bones,
        "rows": rows,
        "solver": solver,
        "setup_s": round(setup, 1),
        "predicted": predicted,
        "solved_ahead": ahead,
        "phases_ms": phases,
        "start_frame_ms": start_frames,
        "new_frames": len(frames["kodawari"]),
        "fps": scene.render.fps / scene.render.fps_base,
    }


def predicted_frames(play):
    """How many of the kodawari side's new frames were solved before Blender's evaluation (their
    predicted inputs confirmed after it), and how many of those had been solved ahead while
    Blender evaluated the frame before, in one more untimed round."""
    from kodawari.hair import predict, runtime

    confirmed, ahead = [], []
    mismatch = predict.Prediction.mismatch
    take = runtime.ArmatureRuntime._take_ahead

    def spy(self, *args):
        wrong = mismatch(self, *args)
        confirmed.append(wrong is None)
        return wrong

    def spy_ahead(self, *args):
        taken = take(self, *args)
        ahead.append(taken)
        return taken

    predict.Prediction.mismatch = spy
    runtime.ArmatureRuntime._take_ahead = spy_ahead
    try:
        play(0)
    finally:
        predict.Prediction.mismatch = mismatch
        runtime.ArmatureRuntime._take_ahead = take
    return sum(confirmed), sum(ahead)


# Where a new frame's time goes: the add-on's handler phases (timed around the runtime's own
# methods), Blender's pass being the rest of the frame.
PHASES = (
    ("show_cached_frames", None, "pre: all"),
    ("_take_ahead", "runtime", "pre: take the frame solved ahead (wait, exchange)"),
    ("_step", "runtime", "pre: step in place"),
    ("_start_ahead", "runtime", "pre: start solving the next frame"),
    ("_write_evaluated", "runtime", "pre: write the evaluated copy"),
    ("evaluate_scene", None, "post: all"),
    ("_store", "runtime", "post: cache the frame"),
    ("_write", "runtime", "post: verify the pass"),
)


def breakdown(sides, frames):
    """ms per frame of each phase in one more round of the kodawari side, and Blender's pass
    (the frame minus both handlers); the cores the process used in that round and in one round
    of the bare rig."""
    from kodawari.hair import runtime

    spent = dict.fromkeys((label for _, _, label in PHASES), 0.0)
    # The main thread's processor time in each phase (time.thread_time): what our part of the
    # frame costs that thread whatever else the machine runs (wall time adds waits for a core).
    cpu = dict.fromkeys(spent, 0.0)
    sides.use("kodawari")  # first: it sets the runtime's methods the side uses
    sides.frame(1)  # the reset at the first frame is not a new frame's work
    originals = []
    for name, owner, label in PHASES:
        target = runtime.ArmatureRuntime if owner else runtime
        original = getattr(target, name)
        originals.append((target, name, original))

        def timed(*args, _original=original, _label=label, **kwargs):
            start, start_cpu = time.perf_counter(), time.thread_time()
            try:
                return _original(*args, **kwargs)
            finally:
                spent[_label] += time.perf_counter() - start
                cpu[_label] += time.thread_time() - start_cpu

        setattr(target, name, timed)
    try:
        start, start_cpu = time.perf_counter(), time.process_time()
        for frame in frames:
            sides.frame(frame)
        total, total_cpu = time.perf_counter() - start, time.process_time() - start_cpu
    finally:
        for target, name, original in originals:
            setattr(target, name, original)
        sides.use(None)
    out = {label: round(seconds / len(frames) * 1e3, 2) for label, seconds in spent.items()}
    out["Blender's pass (frame - handlers)"] = round(
        (total - spent["pre: all"] - spent["post: all"]) / len(frames) * 1e3, 2
    )
    for label in ("pre: all", "post: all"):
        out[f"{label}, main-thread CPU"] = round(cpu[label] / len(frames) * 1e3, 2)
    # How many cores the process had: its processor time (every thread) over the wall time of the
    # same frames, here and for the bare rig right after. Near 1 the machine left the process one
    # core (other work held the other): the step ahead then adds its whole processor time.
    out["cores used (process CPU / wall)"] = round(total_cpu / total, 2)
    sides.use("bare")
    sides.frame(1)
    start, start_cpu = time.perf_counter(), time.process_time()
    for frame in frames:
        sides.frame(frame)
    bare, bare_cpu = time.perf_counter() - start, time.process_time() - start_cpu
    sides.use(None)
    out["bare frame"] = round(bare / len(frames) * 1e3, 2)
    out["bare: cores used"] = round(bare_cpu / bare, 2)
    return out


def untagged(play):
    """The post-evaluation path without its write (Blender then never shows the hair): measured
    only to split that path's whole frame into Blender's first evaluation + our handler and what
    the write costs: a copy-on-write of the whole armature object, evaluated again."""
    from kodawari.hair import runtime

    def run(round_):
        write = runtime.ArmatureRuntime._write
        runtime.ArmatureRuntime._write = lambda self, obj, depsgraph=None: None
        try:
            return play(round_)
        finally:
            runtime.ArmatureRuntime._write = write

    return run


def main():
    print(
        f"=== hair, whole frame ({benchlib.blender_label()}, {os.cpu_count()} CPUs, load {benchlib.load()}): "
        f"ms per frame min / median of {ROUNDS} rounds; peak RSS per side in its own process"
    )
    results = []
    for bones, (chain_count, frames_ours, frames_port) in benchlib.sizes(SIZES).items():
        size = measure_size(bones, chain_count, frames_ours, frames_port)
        results.append(size)
        rows = size["rows"]
        ours, bare = rows["kodawari"], rows["bare"]
        print(f"  {bones:>6,} chain bones ({chain_count} chains, set-up {size['setup_s']} s):")
        for side in SIDES + EXTRA_SIDES:
            row = rows[side]
            if side in (
                "kodawari",
                "kodawari_cached",
                "kodawari_inline",
                "kodawari_post",
                "bare_retag",
            ):
                ratio = f"  this / bare {row['ms_median'] / bare['ms_median']:5.2f}x"
            elif side == "kodawari_paced":
                paced_bare = rows["bare_paced"]["ms_median"]
                ratio = f"  this / bare_paced {row['ms_median'] / paced_bare:5.2f}x"
            elif side in ("bare", "bare_paced"):
                ratio = ""
            else:
                ratio = f"  this / kodawari {row['ms_median'] / ours['ms_median']:7.1f}x"
            err = f"  [memory child: {row['error']}]" if "error" in row else ""
            print(
                f"    {side:15s} {benchlib.fmt_ms(row)}  {benchlib.fmt_mem(row)}  load {row['load']:4.1f}"
                f"  ({row['frames_per_round']} frames/round){ratio}{err}"
            )
        s = size["solver"]
        print(
            f"    solver alone: handler (read, step, write) {s['handler_ms_min']:.2f} / {s['handler_ms_median']:.2f} ms"
            f" = {s['handler_ms_min'] * 1e3 / bones:.2f} us/bone; native step {s['step_ms_min']:.2f} /"
            f" {s['step_ms_median']:.2f} ms"
        )
        post = rows["kodawari_post"]
        second = post["ms_median"] - s["untagged_ms_median"]
        print(
            f"    post-evaluation path split: first evaluation + handler (no write) {s['untagged_ms_median']:.2f} ms, "
            f"the write and the second evaluation it asks for {second:.2f} ms = {second / bare['ms_median']:.2f}x "
            f"the bare evaluation; predicted / post-evaluation path {ours['ms_median'] / post['ms_median']:.2f}x"
        )
        floor = rows["bare_retag"]["ms_median"]
        print(
            f"    Blender's price for a pose changed after its evaluation (bare_retag - bare): "
            f"{floor - bare['ms_median']:.2f} ms = {(floor - bare['ms_median']) / bare['ms_median']:.2f}x the "
            f"bare evaluation; kodawari / bare_retag {ours['ms_median'] / floor:.2f}x"
        )
        predicted, ahead = size["predicted"], size["solved_ahead"]
        print(
            f"    kodawari predicted {predicted} of {size['new_frames']} new frames, {ahead} of them solved "
            f"ahead while Blender evaluated the frame before; kodawari / kodawari_inline "
            f"{ours['ms_median'] / rows['kodawari_inline']['ms_median']:.2f}x"
        )
        paced, paced_bare = rows["kodawari_paced"], rows["bare_paced"]
        print(
            f"    paced playback at {size['fps']:g} fps (each frame requested on the tick, the frame's own "
            f"time): kodawari {paced['ms_median']:.2f} ms, bare {paced_bare['ms_median']:.2f} ms = "
            f"{paced['ms_median'] / paced_bare['ms_median']:.2f}x (back to back "
            f"{ours['ms_median'] / bare['ms_median']:.2f}x)"
        )
        start = size["start_frame_ms"]
        print(
            "    the start frame set again (playback starting or looping; not in the figures above), "
            "median ms: "
            + "; ".join(f"{side} {start[side]:.2f}" for side in START_TIMED if side in start)
        )
        print(
            "    where kodawari's new frame goes (ms, one more round): "
            + "; ".join(f"{k} {v:.2f}" for k, v in size["phases_ms"].items())
        )
        benchlib.record("hair", results)


if __name__ == "__main__":
    spec = benchlib.child_spec()
    if spec is not None:
        child(spec)
    else:
        main()
