"""Fin fading at scale (issue 10 item 2; prints figures, never fails on time; writes
out/bench.json -> fish_fin_fade).

A smooth welded spindle fish (blend_samples/smooth_fish.py) subdivided to about 1 M
vertices, its fins found by Find Fins and flapping (FLAP, 0.6 rad, feathering 0.5).
Two sides, timed interleaved round by round in one process, whole frame
(`scene.frame_set`: the handler's frame table and every fin part's displacement, written
into the Fish Swim modifier's helpers, then Blender's evaluation of the modifier): the fins faded in over the reach squashed along their swing (what ships,
docs/algorithms.md §2.4) and over the plain reach (before). The squash changes only the
reach the binding stores, so the frames should cost the same; the binding pays one more
reach pass, printed beside it.
"""

import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib
import smooth_fish

print = benchlib.say  # each line at once, also through a pipe

FRAMES = 10
ROUNDS = 5


def _bind(obj, squashed):
    """A freshly bound rig (and its binding time), with or without the squashed fade."""
    from kodawari.fish import fins, rig

    original = fins.swing_squash
    if not squashed:
        fins.swing_squash = lambda *args: None
    try:
        start = time.perf_counter()
        bound = rig.SwimRig(obj, obj.kodawari_swim)
        return bound, time.perf_counter() - start
    finally:
        fins.swing_squash = original


def main():
    from kodawari.fish import runtime

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    obj = smooth_fish.build_smooth_fish("spindle", rings=84, segments=44, subdivisions=4)
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.kodawari.swim_add(head_axis="POS_X")
    bpy.ops.kodawari.swim_fin_find()
    settings = obj.kodawari_swim
    for fin in settings.fins:
        fin.motion = "FLAP"
        fin.amplitude = 0.6
        fin.feathering = 0.5
    n = len(obj.data.vertices)
    fin_vertices = sum(len(p.indices) for p in runtime.get_rig(obj).parts)
    rigs, bind = {}, {}
    for name, squashed in (("squashed fade", True), ("plain fade", False)):
        rigs[name], bind[name] = _bind(obj, squashed)
    key = obj.as_pointer()
    # Both rigs move the same fin vertices (only their reach differs): the Fish Swim
    # modifier installed for the live rig serves both, so the swap below changes nothing else.
    live = runtime.get_rig(obj)
    for bound in rigs.values():
        assert np.array_equal(bound.fin_vertices, live.fin_vertices)
        bound.installed_on, bound.owner = live.installed_on, obj

    def side(name):
        def play(round_index):
            runtime._rigs[key] = rigs[name]  # the side's binding, nothing else differs
            seconds = []
            for k in range(FRAMES):
                frame = 2 + (round_index * FRAMES + k) % 48
                seconds.append(benchlib.timed(lambda f=frame: scene.frame_set(f)))
            return seconds

        return play

    rows = benchlib.Rounds(ROUNDS).run({name: side(name) for name in rigs})
    label = benchlib.blender_label()
    print(
        f"Fin fade, {n:,} vertices ({fin_vertices:,} in {len(rigs['squashed fade'].parts)} fin "
        f"parts), FLAP 0.6 rad, whole frame min / median over {ROUNDS} rounds ({label}):"
    )
    for name, row in rows.items():
        print(f"  {name:14s} {benchlib.fmt_ms(row)}  (load {row['load']}), bind {bind[name]:.2f} s")
    ratio = rows["squashed fade"]["ms_median"] / rows["plain fade"]["ms_median"]
    print(f"  squashed / plain frame: {ratio:.3f}x")
    benchlib.record(
        "fish_fin_fade",
        {
            "vertices": n,
            "fin_vertices": fin_vertices,
            "sides": rows,
            "bind_s": {k: round(v, 3) for k, v in bind.items()},
            "ratio": round(ratio, 3),
        },
    )


main()
