"""A live fish's memory (issue 13 item 4): the rig keeps no copy of the mesh (its rest shape
and its deformed positions were two (N, 3) float arrays per fish), a frame is a frame table
written into the Fish Swim modifier's helper (docs/algorithms.md §1.6), and that write
touches nothing of the user's mesh."""

import os
import sys
import tempfile

import bpy
import numpy as np
from fish_helpers import (
    FIN_KIND,
    activate,
    add_swim,
    evaluated,
    make_fish,
    rest,
    set_fps,
    smooth_fish,
    spindle_with_a_mouth,
)

FINS = ("fin_dorsal", "fin_pectoral", "fin_caudal")


def test_a_live_fish_keeps_no_per_vertex_copy_of_its_mesh(empty_scene):
    from kodawari.fish import runtime

    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, fins=FINS, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    for frame in (2, 3, 7):
        bpy.context.scene.frame_set(frame)
    rig = runtime.get_rig(obj)
    count = len(obj.data.vertices)
    copies = [
        name
        for name, value in vars(rig).items()
        if isinstance(value, np.ndarray) and value.ndim == 2 and len(value) == count
    ]
    assert copies == [], f"the rig keeps {copies}: {12 * count * len(copies)} bytes more per fish"
    # What the fin search and fin checks read is still there when asked for.
    assert np.array_equal(rig.rest, rest(obj))


def test_the_frame_written_is_the_deformation_and_the_mesh_is_untouched(empty_scene):
    from kodawari.fish import route, runtime, timing

    set_fps(24)
    obj = make_fish("tuna")
    settings = add_swim(obj, fins=FINS, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    assert set(FINS) <= set(FIN_KIND)
    mesh_before = rest(obj).copy()
    names_before = sorted(obj.data.attributes.keys())
    scene = bpy.context.scene
    for frame in (5, 6, 13):
        scene.frame_set(frame)
        rig = runtime.get_rig(obj)
        phase, _ = timing.phase_and_distance(obj, settings, scene, frame, rig.body_length)
        expected = rig.evaluate(settings, phase, out=np.empty((rig.count, 3), np.float32))
        assert np.abs(evaluated(obj) - expected).max() < 1e-5 * rig.body_length, frame
    # Per frame only the helpers change: the user's mesh keeps its positions and attributes.
    assert np.array_equal(rest(obj), mesh_before)
    assert sorted(obj.data.attributes.keys()) == names_before
    assert set(route.COORDINATES[:2]) <= set(names_before) and obj.data.shape_keys is None


def test_add_fish_swim_binds_the_mesh_once(empty_scene, monkeypatch):
    # Binding a 4 M-vertex mesh takes seconds and a binding's worth of memory: Add Fish Swim
    # keeps its trial bind instead of binding again for the first frame.
    from kodawari.fish import rig as rig_module

    binds = []
    bind = rig_module.SwimRig.__init__

    def counted(self, *args, **kwargs):
        binds.append(args[0].name)
        bind(self, *args, **kwargs)

    monkeypatch.setattr(rig_module.SwimRig, "__init__", counted)
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    for frame in (2, 3):
        bpy.context.scene.frame_set(frame)
    assert binds == [obj.name]


def test_the_frame_after_add_fish_swim_returns_the_setups_freed_memory(empty_scene, monkeypatch):
    # Add Fish Swim reads the mesh and binds it: tens of bytes per vertex of scratch, the
    # last of it freed only when the operator returns. glibc keeps freed memory resident
    # until asked to give it back: at 1 M vertices 20-25 MB, the swim's whole lead over the
    # Geometry Nodes bend's peak while playing (docs/algorithms.md §1.6). The frame after
    # the setup asks once; later frames do not. (The resident size itself moves by more
    # than that between runs of one process, so the request is what is checked.)
    from kodawari.fish import runtime

    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    native = runtime.get_rig(obj).kn
    asked = []
    release = native.release_free_memory

    def counted():
        asked.append(bpy.context.scene.frame_current)
        return release()

    monkeypatch.setattr(native, "release_free_memory", counted)
    for frame in (2, 3, 4):
        bpy.context.scene.frame_set(frame)
    assert asked == [2]


def _blender_memory_mb():
    """Blender's own memory in use (its allocator's count, exact to the kB; what
    Window > Memory Statistics prints), read from that operator's report on stdout."""
    sys.stdout.flush()
    saved = os.dup(1)
    with tempfile.TemporaryFile(mode="w+") as report:
        os.dup2(report.fileno(), 1)
        try:
            bpy.ops.wm.memory_statistics()
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)
        report.seek(0)
        for line in report:
            if line.startswith("total memory len:"):
                return float(line.split()[3])
    raise AssertionError("Blender printed no memory statistics")


def _viewport_frame(obj, frame):
    """What a viewport does: frame change, evaluation, normals read."""
    scene = bpy.context.scene
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    tuple(obj.evaluated_get(depsgraph).data.vertices[0].normal)


def test_playing_keeps_one_copy_of_the_fish_bound_data(empty_scene):
    # Blender 4+ shares the mesh's arrays with its evaluated copy. A per-frame question
    # about the bound attributes that took them writable (attributes.get) made Blender give
    # the user's mesh a second copy, 12 bytes per vertex more (16 with fins) for as long as
    # the fish played: 48 MB at 4 M vertices, over the Geometry Nodes bend's memory.
    set_fps(24)
    obj = smooth_fish.build_smooth_fish("spindle", subdivisions=3)
    activate(obj)
    add_swim(obj, preset="CARANGIFORM", frequency=2.0)
    result = bpy.ops.kodawari.swim_fin_add(vertex_group="truth_fin_dorsal", kind="DORSAL")
    assert result == {"FINISHED"}
    count = len(obj.data.vertices)
    for frame in (2, 3, 4):
        _viewport_frame(obj, frame)
    playing = _blender_memory_mb()
    # Re-copying the mesh into its evaluated copy shares every array again: what Blender
    # needs for this fish. Playing must not hold more.
    # (No frame change after it: the handler would compare the rest shape, reading it.)
    obj.data.update_tag()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    tuple(obj.evaluated_get(depsgraph).data.vertices[0].normal)
    shared = _blender_memory_mb()
    extra = (playing - shared) * 2**20 / count
    assert extra < 4.0, f"playing holds {extra:.1f} bytes per vertex more than Blender needs"


def test_a_straight_axis_fish_keeps_4_bytes_per_vertex_of_binding(empty_scene):
    # Along a straight rest axis the offsets (u, v) of the binding are the rest position's,
    # an affine function of it: the Fish Swim tree computes them from Position and the mesh
    # keeps only the parameter s, one float per vertex (12 bytes before; Blender 3.4 copies
    # the mesh's attributes into its evaluated mesh, so there 8 bytes instead of 24).
    set_fps(24)
    obj = spindle_with_a_mouth(segments=96, rings=64)
    before = {a.name for a in obj.data.attributes}
    activate(obj)
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    for frame in (2, 3):
        _viewport_frame(obj, frame)
    added = [a for a in obj.data.attributes if a.name not in before]
    assert [(a.name, a.data_type, a.domain) for a in added] == [
        (".kodawari_swim_s", "FLOAT", "POINT")
    ]
    shown = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    assert {a.name for a in shown.attributes} <= before, "nothing of the binding handed on"
    assert np.abs(evaluated(obj) - rest(obj)).max() > 0.02, "and it swims"
