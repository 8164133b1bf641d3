"""A live fish's memory (issue 13 item 4): the rig keeps no copy of the mesh (its rest shape
and its deformed positions were two (N, 3) float arrays per fish), a frame is deformed
straight into the swim shape key, and that write touches nothing else of the user's mesh."""

import bpy
import numpy as np
from fish_helpers import FIN_KIND, add_swim, evaluated, live, make_fish, rest, set_fps

FINS = ("fin_dorsal", "fin_pectoral", "fin_caudal")


def _basis(obj):
    block = obj.data.shape_keys.reference_key
    out = np.empty((len(block.data), 3), dtype=np.float32)
    block.data.foreach_get("co", out.reshape(-1))
    return out


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


def test_the_frame_written_in_place_is_the_deformation_and_nothing_else_changes(empty_scene):
    from kodawari import bulk
    from kodawari.fish import runtime, timing

    set_fps(24)
    obj = make_fish("tuna")
    settings = add_swim(obj, fins=FINS, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    assert set(FINS) <= set(FIN_KIND)
    mesh_before, basis_before = rest(obj).copy(), _basis(obj).copy()
    block = obj.data.shape_keys.key_blocks[runtime.SHAPE_KEY]
    # Where Blender's key memory is reachable (3.4 through 5.0) the frame is written there.
    assert bulk.shape_key_view(block) is not None
    scene = bpy.context.scene
    for frame in (5, 6, 13):
        scene.frame_set(frame)
        rig = runtime.get_rig(obj)
        phase, _ = timing.phase_and_distance(obj, settings, scene, frame, rig.body_length)
        expected = rig.evaluate(settings, phase, out=np.empty((rig.count, 3), np.float32))
        assert np.array_equal(live(obj), expected), frame
        assert np.abs(evaluated(obj) - expected).max() < 1e-6, frame
    # The user's mesh and Basis are untouched by the in-place writes.
    assert np.array_equal(rest(obj), mesh_before)
    assert np.array_equal(_basis(obj), basis_before)


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
    assert np.abs(evaluated(obj) - live(obj)).max() < 1e-6
