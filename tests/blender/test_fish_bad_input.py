"""Bad input gets a clear report and changes nothing (issue 3, "Must show")."""

import bpy
import numpy as np
import pytest
from fish_helpers import activate, add_swim, live, make_fish, rest


def _snapshot(obj):
    state = {
        "name": obj.name,
        "type": obj.type,
        "modifiers": [m.name for m in getattr(obj, "modifiers", [])],
    }
    if obj.type == "MESH":
        keys = obj.data.shape_keys
        state.update(
            positions=rest(obj).tobytes(),
            keys=[b.name for b in keys.key_blocks] if keys else None,
            groups=[g.name for g in obj.vertex_groups],
            enabled=obj.kodawari_swim.enabled,
            fins=[f.vertex_group for f in obj.kodawari_swim.fins],
            head=obj.kodawari_swim.head_axis,
            frequency=obj.kodawari_swim.frequency,
        )
    return state


def _refused(operator, obj, words, **kwargs):
    before = _snapshot(obj)
    with pytest.raises(RuntimeError) as info:
        operator(**kwargs)
    message = str(info.value)
    for word in words:
        assert word.lower() in message.lower(), message
    assert "Traceback" not in message
    assert _snapshot(obj) == before


def test_non_mesh_object(empty_scene):
    curve = bpy.data.objects.new("path", bpy.data.curves.new("path", "CURVE"))
    bpy.context.scene.collection.objects.link(curve)
    activate(curve)
    _refused(bpy.ops.kodawari.swim_add, curve, ["curve", "not a mesh"])


def test_fewer_than_four_vertices(empty_scene):
    mesh = bpy.data.meshes.new("tri")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new("tri", mesh)
    bpy.context.scene.collection.objects.link(obj)
    activate(obj)
    _refused(bpy.ops.kodawari.swim_add, obj, ["3 vertices", "at least 4"])


def test_negative_frequency(empty_scene):
    obj = make_fish("tuna")
    _refused(bpy.ops.kodawari.swim_add, obj, ["frequency", "-1.5"], frequency=-1.5)


@pytest.mark.parametrize(
    "scale,words", [((1.0, 2.0, 1.0), ["non-uniform scale"]), ((-1.0, -1.0, -1.0), ["negative"])]
)
def test_bad_object_scale(empty_scene, scale, words):
    obj = make_fish("tuna")
    obj.scale = scale
    _refused(bpy.ops.kodawari.swim_add, obj, words + ["apply the scale"])


def test_existing_shape_keys(empty_scene):
    obj = make_fish("tuna")
    obj.shape_key_add(name="Basis")
    obj.shape_key_add(name="Smile")
    _refused(bpy.ops.kodawari.swim_add, obj, ["shape keys"])


def test_existing_modifiers(empty_scene):
    obj = make_fish("tuna")
    obj.modifiers.new("Subdivision", "SUBSURF")
    _refused(bpy.ops.kodawari.swim_add, obj, ["modifiers", "Subdivision"])


def test_unknown_vertex_group(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X")
    _refused(
        bpy.ops.kodawari.swim_fin_add,
        obj,
        ["no vertex group 'fin_tail'"],
        vertex_group="fin_tail",
        kind="CAUDAL",
    )
    _refused(bpy.ops.kodawari.swim_fin_add, obj, ["vertex group"], vertex_group="", kind="CAUDAL")


def test_empty_vertex_group(empty_scene):
    obj = make_fish("tuna")
    obj.vertex_groups.new(name="fin_empty")
    add_swim(obj, head_axis="POS_X")
    _refused(
        bpy.ops.kodawari.swim_fin_add,
        obj,
        ["'fin_empty' is empty"],
        vertex_group="fin_empty",
        kind="DORSAL",
    )


def test_fin_group_covering_most_of_the_mesh(empty_scene):
    obj = make_fish("tuna")
    group = obj.vertex_groups.new(name="everything")
    group.add(list(range(int(0.8 * len(obj.data.vertices)))), 1.0, "REPLACE")
    add_swim(obj, head_axis="POS_X")
    _refused(
        bpy.ops.kodawari.swim_fin_add,
        obj,
        ["covers 80%", "not the body"],
        vertex_group="everything",
        kind="DORSAL",
    )


def test_fin_on_a_mesh_that_does_not_swim(empty_scene):
    obj = make_fish("tuna")
    _refused(
        bpy.ops.kodawari.swim_fin_add,
        obj,
        ["does not swim"],
        vertex_group="fin_dorsal",
        kind="DORSAL",
    )


def test_same_fin_twice(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_dorsal",), head_axis="POS_X")
    _refused(
        bpy.ops.kodawari.swim_fin_add,
        obj,
        ["already a fin"],
        vertex_group="fin_dorsal",
        kind="DORSAL",
    )


def test_swim_add_twice_and_remove_without_swim(empty_scene):
    obj = make_fish("tuna")
    _refused(bpy.ops.kodawari.swim_remove, obj, ["no fish swim"])
    add_swim(obj, head_axis="POS_X")
    _refused(bpy.ops.kodawari.swim_add, obj, ["already swims"])


def test_bake_with_reversed_frame_range(empty_scene, tmp_path):
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X")
    _refused(
        bpy.ops.kodawari.swim_bake,
        obj,
        ["end frame 3 is before start frame 10"],
        frame_start=10,
        frame_end=3,
        filepath=str(tmp_path / "x.pc2"),
    )
    assert not (tmp_path / "x.pc2").exists()


def test_bake_cancel_leaves_everything_as_it_was(empty_scene, tmp_path):
    """Esc during a modal bake runs the job's cancel(): no file, no key, no modifier, same frame."""
    from kodawari.fish import bake

    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X")
    scene = bpy.context.scene
    scene.frame_set(4)
    before = _snapshot(obj)
    for target in ("MESH_CACHE", "SHAPE_KEYS"):
        baker = bake.SwimBakeJob(obj, scene, 1, 10, target, str(tmp_path / "c.pc2"))
        baker.prepare()
        for _ in range(5):
            baker.step()
        baker.cancel()
        assert scene.frame_current == 4
        assert _snapshot(obj) == before
        assert list(tmp_path.iterdir()) == []
        assert obj.kodawari_swim.baked == "NONE"
    # Live evaluation still runs afterwards.
    scene.frame_set(6)
    assert np.abs(rest(obj) - live(obj)).max() > 0
