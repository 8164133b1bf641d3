"""Fish Swim as a real Geometry Nodes modifier (issue 13 items 1, 4; docs/algorithms.md §1.6):
what Blender shows equals what the core computes (bake, apply), on the sample fish and on a
smooth high-poly fish with a mouth and found fins; the modifier behaves like one (first in
the stack, its eye hides the swim, undo, save and reload); Remove Fish Swim leaves the mesh
exactly as it was; the mesh carries no shape keys and, per vertex, only the bound
coordinates its rest position does not give (4-12 bytes)."""

import bpy
import mathutils
import numpy as np
import pytest
from fish_helpers import (
    activate,
    add_swim,
    evaluated,
    make_fish,
    rest,
    set_fps,
    smooth_fish,
    spindle_with_a_mouth,
)

MODIFIER = "Fish Swim"


def _route_equals_core(obj, frames):
    from kodawari.fish import runtime

    scene = bpy.context.scene
    length = runtime.get_rig(obj).body_length
    worst, moved = 0.0, 0.0
    for frame in frames:
        scene.frame_set(frame)
        shown = evaluated(obj)
        core = runtime.positions(obj, scene, frame).copy()
        worst = max(worst, float(np.abs(shown - core).max()) / length)
        moved = max(moved, float(np.abs(core - rest(obj)).max()) / length)
    return worst, moved


def _route_equals_full_binding(obj, frames):
    """Like _route_equals_core, against a fresh binding that holds every coordinate itself
    (nothing computed from the rest position, nothing released: the deform as before)."""
    from kodawari.fish import rig as rig_module
    from kodawari.fish import timing

    scene = bpy.context.scene
    settings = obj.kodawari_swim
    whole = rig_module.SwimRig(obj, settings)
    assert not whole.binding.released
    worst = 0.0
    for frame in frames:
        scene.frame_set(frame)
        phase, _ = timing.phase_and_distance(obj, settings, scene, frame, whole.body_length)
        expected = whole.evaluate(settings, phase)
        worst = max(worst, float(np.abs(evaluated(obj) - expected).max()) / whole.body_length)
    return worst


def _mesh_state(mesh):
    keys = mesh.shape_keys
    return {
        "positions": rest_of(mesh).tobytes(),
        "attributes": sorted((a.name, a.data_type, a.domain) for a in mesh.attributes),
        "keys": [k.name for k in keys.key_blocks] if keys is not None else None,
    }


def rest_of(mesh):
    out = np.empty((len(mesh.vertices), 3), dtype=np.float32)
    mesh.vertices.foreach_get("co", out.reshape(-1))
    return out


def _stored(obj):
    """Which of the bound (s, u, v) the mesh stores as attributes (the rest computed)."""
    return "".join(c for c in "suv" if obj.data.attributes.find(f".kodawari_swim_{c}") >= 0)


def _data_counts():
    return (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.node_groups))


@pytest.mark.parametrize("kind", ["tuna", "eel", "dolphin"])
def test_the_modifier_shows_what_the_core_computes_on_the_sample_fish(empty_scene, kind):
    set_fps(24)
    obj = make_fish(kind)
    groups = [g.name for g in obj.vertex_groups if g.name.startswith("fin_")]
    add_swim(obj, fins=groups, head_axis="POS_X", frequency=2.0)
    for fin in obj.kodawari_swim.fins:
        fin.feathering = 0.4  # every motion term of the fins in play
    worst, moved = _route_equals_core(obj, (2, 5, 9, 14))
    assert moved > 0.02, "the fish swims"
    assert worst < 1e-5, f"{kind}: the modifier is {worst:.2e} body lengths from the core"


def test_the_tree_for_vertices_past_the_axis_ends_is_exact_too(empty_scene, monkeypatch):
    # The sample fish have no vertex past an end of their axis (w = 0 everywhere, the lean
    # tree); the full tree (w packed into s, docs/algorithms.md §1.6) must be as exact.
    from kodawari.fish import route

    monkeypatch.setattr(route, "has_ends", lambda packed: True)
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral", "fin_caudal"), head_axis="POS_X", frequency=2.0)
    assert any(n.type == "CLAMP" for n in obj.modifiers[MODIFIER].node_group.nodes)
    worst, moved = _route_equals_core(obj, (2, 7))
    assert moved > 0.02 and worst < 1e-5, worst


def test_a_renamed_fish_swim_modifier_still_swims_and_goes_with_remove(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    obj.modifiers[MODIFIER].name = "Body wave"
    worst, moved = _route_equals_core(obj, (3, 6))
    assert moved > 0.02 and worst < 1e-5
    activate(obj)
    assert bpy.ops.kodawari.swim_remove() == {"FINISHED"}
    assert len(obj.modifiers) == 0


@pytest.mark.parametrize("form", ["spindle", "cetacean", "eel"])
def test_the_modifier_shows_what_the_core_computes_on_a_smooth_fish_with_a_mouth(empty_scene, form):
    set_fps(24)
    obj = smooth_fish.build_smooth_fish(form, subdivisions=2)
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)  # the fins are found, as a user would
    obj.scale = (0.01, 0.01, 0.01)  # a fish modelled in centimetres
    activate(obj)
    preset = "CETACEAN" if form == "cetacean" else "CARANGIFORM"
    assert bpy.ops.kodawari.swim_add(preset=preset, frequency=2.0) == {"FINISHED"}
    assert bpy.ops.kodawari.swim_fin_find() == {"FINISHED"}
    assert len(obj.kodawari_swim.fins) >= 3
    worst, moved = _route_equals_core(obj, (3, 8, 11))
    assert moved > 0.02
    assert worst < 1e-5, f"{form}: the modifier is {worst:.2e} body lengths from the core"
    assert _route_equals_full_binding(obj, (3, 8)) < 1e-5
    # Its mid-line bends up and down only: v is computed from Position, not stored.
    assert _stored(obj) == "su"


def test_fish_swim_is_the_first_modifier_and_its_eye_hides_the_swim(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    original = rest(obj).copy()
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    obj.modifiers.new("Displace", "DISPLACE").strength = 0.0  # the user's, added after
    assert [m.name for m in obj.modifiers] == [MODIFIER, "Displace"]
    assert obj.modifiers[0].type == "NODES"
    scene = bpy.context.scene
    scene.frame_set(4)
    assert np.abs(evaluated(obj) - original).max() > 1e-3, "the fish swims"
    obj.modifiers[MODIFIER].show_viewport = False  # the modifier's own eye
    scene.frame_set(5)
    assert np.abs(evaluated(obj) - original).max() < 1e-6, "hidden: the rest shape"
    assert not obj.kodawari_swim.enabled, "the Fish Swim panel's eye follows the modifier's"
    obj.kodawari_swim.enabled = True  # the panel's eye
    assert obj.modifiers[MODIFIER].show_viewport
    scene.frame_set(6)
    assert np.abs(evaluated(obj) - original).max() > 1e-3, "shown again, it swims"


def test_the_swim_survives_save_and_reload_with_its_helpers_out_of_the_scene(empty_scene, tmp_path):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral", "fin_caudal"), head_axis="POS_X", frequency=2.0)
    scene = bpy.context.scene
    scene.frame_set(7)
    before = evaluated(obj)
    path = str(tmp_path / "fish.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["tuna"]
    scene = bpy.context.scene
    assert obj.modifiers[0].name == MODIFIER and obj.modifiers[0].node_group is not None
    # The helpers live in the file but in no collection: the scene's Outliner lists the fish only.
    assert [o.name for o in scene.objects] == ["tuna"]
    assert all(o.name.startswith(".") for o in bpy.data.objects if o is not obj)
    assert evaluated(obj) == pytest.approx(before, abs=1e-6), "the opened file shows the swim"
    scene.frame_set(3)
    scene.frame_set(7)
    assert np.abs(evaluated(obj) - before).max() < 1e-6, "and plays on as before"


def test_remove_leaves_the_mesh_and_the_file_exactly_as_before(empty_scene):
    set_fps(24)
    obj = make_fish("dolphin")
    before, counts = _mesh_state(obj.data), _data_counts()
    add_swim(obj, fins=("fin_pectoral", "fin_caudal"), head_axis="POS_X", preset="CETACEAN")
    bpy.context.scene.frame_set(9)
    assert _data_counts() != counts
    activate(obj)
    assert bpy.ops.kodawari.swim_remove() == {"FINISHED"}
    assert len(obj.modifiers) == 0
    assert _mesh_state(obj.data) == before, "positions, attributes and keys as before"
    assert _data_counts() == counts, "no node group, helper object or mesh left behind"


def test_undo_of_remove_brings_the_modifier_back_swimming(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral",), head_axis="POS_X", frequency=2.0)
    scene = bpy.context.scene
    scene.frame_set(5)
    swimming = evaluated(obj)
    bpy.ops.ed.undo_push(message="before remove")
    assert bpy.ops.kodawari.swim_remove() == {"FINISHED"}
    bpy.ops.ed.undo_push(message="Remove Fish Swim")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["tuna"]
    assert obj.modifiers[0].name == MODIFIER
    scene = bpy.context.scene
    scene.frame_set(4)
    scene.frame_set(5)
    assert np.abs(evaluated(obj) - swimming).max() < 1e-5


def test_a_duplicate_swims_with_its_own_settings(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    activate(obj)
    bpy.ops.object.duplicate()  # Shift-D: the modifier's node group is shared at first
    twin = bpy.context.active_object
    assert twin is not obj
    twin.kodawari_swim.frequency = 1.0
    scene = bpy.context.scene
    scene.frame_set(2)
    scene.frame_set(4)
    assert twin.modifiers[MODIFIER].node_group != obj.modifiers[MODIFIER].node_group
    for fish in (obj, twin):
        from kodawari.fish import runtime

        core = runtime.positions(fish, scene, 4)
        assert np.abs(evaluated(fish) - core).max() < 1e-5, fish.name
    assert np.abs(evaluated(obj) - evaluated(twin)).max() > 1e-3, "each with its own frequency"


def test_the_live_mesh_carries_one_small_attribute_and_no_shape_key(empty_scene):
    # Memory (issue 13 item 4): per vertex the swim adds at most 12 bytes to the user's mesh
    # ((s, u, v), three floats); the tuna is the same on both sides, its rest axis never
    # leaves the plane of its head and back, so v (across it) is computed from the rest
    # position (docs/algorithms.md §1.6): 8 bytes. No shape key (24 bytes more per vertex).
    set_fps(24)
    obj = make_fish("tuna")
    names = {a.name for a in obj.data.attributes}
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    bpy.context.scene.frame_set(3)
    added = [(a.name, a.data_type, a.domain) for a in obj.data.attributes if a.name not in names]
    assert sorted(added) == [(f".kodawari_swim_{c}", "FLOAT", "POINT") for c in "su"]
    assert obj.data.shape_keys is None
    # ... and hands none on: what renders, exports and later modifiers see has no copy.
    shown = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    assert not [a.name for a in shown.attributes if a.name.startswith(".kodawari")]


def test_a_file_saved_with_the_old_swim_shape_key_plays_through_the_modifier(empty_scene):
    # Before the modifier, the swim lived in a "Kodawari Swim" shape key over a Basis; such
    # a file swims again on its next frame, through the modifier, its keys gone.
    set_fps(24)
    obj = make_fish("tuna")
    original = rest(obj).copy()
    settings = add_swim(obj, head_axis="POS_X", frequency=2.0)
    from kodawari.fish import route, runtime

    route.uninstall(obj)  # what the older add-on left in the file:
    obj.shape_key_add(name="Basis", from_mix=False)
    obj.shape_key_add(name="Kodawari Swim", from_mix=False).value = 1.0
    runtime.forget(obj)
    assert settings.enabled and runtime.has_swim(obj)
    worst, moved = _route_equals_core(obj, (3, 5))
    assert moved > 0.02 and worst < 1e-5
    assert obj.data.shape_keys is None and obj.modifiers[0].name == MODIFIER
    assert np.array_equal(rest(obj), original)


def test_a_file_saved_with_the_packed_float3_binding_swims_again(empty_scene):
    # The route first kept (s, u, v) in one float3 attribute, read through Separate XYZ.
    # Such a file swims on its next frame, bound again to the three float attributes, the
    # float3 gone (no 12 bytes per vertex left behind).
    set_fps(24)
    obj = make_fish("tuna")
    original = rest(obj).copy()
    settings = add_swim(obj, fins=("fin_caudal",), head_axis="POS_X", frequency=2.0)
    from kodawari.fish import route, runtime

    rig = runtime.get_rig(obj)
    packed = rig.packed_coordinates().copy()
    mesh = obj.data
    for name in route.COORDINATES:  # what that version left in the file:
        if mesh.attributes.find(name) >= 0:
            mesh.attributes.remove(mesh.attributes[name])
    old = mesh.attributes.new(route.PACKED, "FLOAT_VECTOR", "POINT")
    old.data.foreach_set("vector", packed.reshape(-1))
    runtime.forget(obj)  # a file opened: the rigs are rebuilt
    assert settings.enabled and runtime.has_swim(obj)
    worst, moved = _route_equals_core(obj, (3, 5))
    assert moved > 0.02 and worst < 1e-5
    assert mesh.attributes.find(route.PACKED) < 0
    assert _stored(obj) == "su"  # v computed from the rest position (the tuna's axis is planar)
    assert np.array_equal(rest(obj), original)


def test_the_frame_helper_holds_only_the_rows_the_tree_reads(empty_scene):
    # Where no vertex lies past an end of the axis the tree never reads e1 or its change:
    # the helper holds six rows a segment, not eight (a quarter less written every frame).
    # A helper holding all eight (installed before) still swims exactly, all eight written.
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    from kodawari.fish import route, runtime

    mod = route.modifier(obj)
    table = route.helpers(mod)[0]
    rows = {a.name for a in table.attributes if a.name in route.FIELDS}
    assert rows == {"o", "do", "e2", "de2", "e3", "de3"}
    worst, moved = _route_equals_core(obj, (3, 5))
    assert moved > 0.02 and worst < 1e-5
    for name in ("e1", "de1"):  # what an installation from before held
        table.attributes.new(name, "FLOAT_VECTOR", "POINT")
    worst, moved = _route_equals_core(obj, (4, 6))
    assert moved > 0.02 and worst < 1e-5
    written = np.empty(route.ROWS * 3, np.float32)
    table.attributes["e1"].data.foreach_get("vector", written)
    assert np.abs(written).max() > 0.5, "its e1 row is written too"
    runtime.forget(obj)  # a file opened: bound and installed again, with six rows
    worst, _ = _route_equals_core(obj, (7,))
    table = route.helpers(route.modifier(obj))[0]
    assert worst < 1e-5 and {a.name for a in table.attributes if a.name in route.FIELDS} == rows


def test_a_straight_axis_fish_stores_only_its_parameter(empty_scene):
    # Along a straight rest axis u and v are the rest position's offsets across it, an affine
    # function of Position, measured on every vertex at bind time (docs/algorithms.md §1.6);
    # s is not (the clamped spline runs faster near its ends), so it alone is stored.
    set_fps(24)
    obj = spindle_with_a_mouth()
    obj.scale = (0.01, 0.01, 0.01)  # modelled in centimetres
    # ... away from its origin: u and v are offsets from an axis that does not pass through it
    obj.data.transform(mathutils.Matrix.Translation((0.3, -0.2, 0.15)))
    activate(obj)
    assert bpy.ops.kodawari.swim_add(head_axis="POS_X", preset="CARANGIFORM", frequency=2.0) == {
        "FINISHED"
    }
    worst, moved = _route_equals_core(obj, (3, 8))
    assert moved > 0.02 and worst < 1e-5, worst
    assert _route_equals_full_binding(obj, (3, 8)) < 1e-5
    assert _stored(obj) == "s"
    from kodawari.fish import route

    offsets = route.modifier(obj).node_group["kodawari_offsets"]
    assert np.abs(offsets) == pytest.approx((0.15, 0.2), abs=1e-6), "the axis's constants"
    shown = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    assert not [a.name for a in shown.attributes if a.name.startswith(".kodawari")]


def test_a_fish_curved_at_rest_keeps_every_coordinate(empty_scene):
    # A smooth fish with a mouth modelled bent to one side: its rest axis curves, no
    # coordinate is affine in the rest position, all three stay attributes, still exact.
    set_fps(24)
    obj = smooth_fish.build_smooth_fish("spindle", subdivisions=2)
    co = rest(obj).astype(np.float64)
    co[:, 1] += 0.12 * np.cos(np.pi * co[:, 0])  # a C to the side, snout and tail back
    obj.data.vertices.foreach_set("co", co.astype(np.float32).reshape(-1))
    obj.data.update()
    obj.scale = (0.01, 0.01, 0.01)
    activate(obj)
    assert bpy.ops.kodawari.swim_add(preset="CARANGIFORM", frequency=2.0) == {"FINISHED"}
    worst, moved = _route_equals_core(obj, (3, 8))
    assert moved > 0.02 and worst < 1e-5, worst
    assert _route_equals_full_binding(obj, (3, 8)) < 1e-5
    assert _stored(obj) == "suv"


def test_the_users_shape_keys_bring_the_stored_offsets_back(empty_scene):
    # With shape keys Position is no longer the rest position: the offsets it gave are
    # stored again, and the key still rides on the swim.
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", frequency=2.0)
    scene = bpy.context.scene
    scene.frame_set(4)
    assert _stored(obj) == "su"
    swim = evaluated(obj).copy()
    obj.shape_key_add(name="Basis", from_mix=False)
    smile = obj.shape_key_add(name="Smile", from_mix=False)
    offsets = np.zeros_like(swim)
    offsets[:, 1] = 0.01  # across the body: what v would wrongly take as rest
    smile.data.foreach_set("co", (rest(obj) + offsets).reshape(-1))
    smile.value = 1.0
    scene.frame_set(4)
    assert _stored(obj) == "suv"
    assert np.abs(evaluated(obj) - (swim + offsets)).max() < 1e-5
    obj.shape_key_clear()  # and without them v is computed again
    scene.frame_set(5)
    assert _stored(obj) == "su"
    worst, _ = _route_equals_core(obj, (5,))
    assert worst < 1e-5


def test_a_file_bound_with_every_coordinate_stored_binds_again(empty_scene):
    # Files saved before stored all three (s, u, v) and their node group carries no mark of
    # what it stores: on their next frame they are bound again, v computed, its attribute
    # gone (4 bytes per vertex), the swim unchanged.
    set_fps(24)
    obj = make_fish("tuna")
    original = rest(obj).copy()
    settings = add_swim(obj, fins=("fin_caudal",), head_axis="POS_X", frequency=2.0)
    from kodawari.fish import route, runtime

    scene = bpy.context.scene
    scene.frame_set(6)
    before = evaluated(obj).copy()
    rig = runtime.get_rig(obj)
    packed = rig.packed_coordinates().copy()
    mesh = obj.data
    mod = route.modifier(obj)
    group = mod.node_group
    # What that version left in the file: its tree read all three, unmarked ...
    mod.node_group = route.build_group(
        group.nodes["frames"].inputs[0].default_value,
        group.nodes["fins"].inputs[0].default_value,
        rig.end_scale,
        with_ends=route.has_ends(packed),
    )
    bpy.data.node_groups.remove(group)
    del mod.node_group["kodawari_stored"]
    mod.node_group["kodawari_with_keys"] = False
    # ... from three attributes
    mesh.attributes.new(route.COORDINATES[2], "FLOAT", "POINT").data.foreach_set(
        "value", np.ascontiguousarray(packed[:, 2])
    )
    runtime.forget(obj)  # a file opened: the rigs are rebuilt
    assert settings.enabled and runtime.has_swim(obj) and _stored(obj) == "suv"
    scene.frame_set(5)
    scene.frame_set(6)
    assert _stored(obj) == "su"
    assert np.abs(evaluated(obj) - before).max() < 1e-5
    worst, moved = _route_equals_core(obj, (3, 5))
    assert moved > 0.02 and worst < 1e-5
    assert np.array_equal(rest(obj), original)


def test_bake_and_apply_give_what_the_core_gave_from_every_stored_coordinate(empty_scene, tmp_path):
    # Bake and Apply deform in the core from the bound attributes and, for a coordinate the
    # route computes, the same affine row of the rest position: the shape is what a binding
    # holding every coordinate itself (as before) gives.
    set_fps(24)
    obj = make_fish("dolphin")
    settings = add_swim(obj, fins=("fin_pectoral",), head_axis="POS_X", preset="CETACEAN")
    scene = bpy.context.scene
    scene.frame_set(9)
    from kodawari.fish import bake, timing
    from kodawari.fish import rig as rig_module

    assert _stored(obj) == "su"
    whole = rig_module.SwimRig(obj, settings)  # a fresh binding, nothing released
    assert not whole.binding.released

    def as_before(frame):
        phase, _ = timing.phase_and_distance(obj, settings, scene, frame, whole.body_length)
        return whole.evaluate(settings, phase).copy()

    cache = str(tmp_path / "dolphin.pc2")
    activate(obj)
    result = bpy.ops.kodawari.swim_bake(
        frame_start=3, frame_end=5, target="MESH_CACHE", filepath=cache
    )
    assert result == {"FINISHED"}
    _, _, baked = bake.read_pc2(cache)
    for k, frame in enumerate((3, 4, 5)):
        assert np.abs(baked[k] - as_before(frame)).max() < 1e-6 * whole.body_length, frame
    assert bpy.ops.kodawari.swim_free_bake() == {"FINISHED"}
    scene.frame_set(9)
    before = as_before(9)
    shown = evaluated(obj).copy()
    activate(obj)
    assert bpy.ops.kodawari.swim_apply() == {"FINISHED"}
    assert np.abs(rest(obj) - before).max() < 1e-6 * whole.body_length
    assert np.abs(shown - before).max() < 1e-5 * whole.body_length


@pytest.mark.parametrize("head_axis", ["NEG_X", "POS_Y"])
def test_a_computed_offset_along_a_negative_object_axis_is_exact(empty_scene, head_axis):
    # Heading -X or +Y the side axis is an object axis turned over: the tree reads v as
    # that axis's coordinate of Position and the table's e3 turns over instead (route._rows).
    from kodawari.fish import route

    set_fps(24)
    obj = make_fish("tuna", head_axis=head_axis)
    add_swim(obj, fins=("fin_pectoral",), head_axis=head_axis, frequency=2.0)
    worst, moved = _route_equals_core(obj, (3, 7))
    assert moved > 0.02 and worst < 1e-5, worst
    assert _route_equals_full_binding(obj, (3, 7)) < 1e-5
    assert _stored(obj) == "su"
    assert list(route.modifier(obj).node_group["kodawari_signs"]) == [1.0, -1.0]


def test_a_computed_offset_off_the_object_axes_reads_a_dot_product(empty_scene, monkeypatch):
    # A row that is not an object axis (a rest axis modelled at a slant) is read as
    # Dot Product(Position, n); the same shape.
    from kodawari.fish import route

    monkeypatch.setattr(route, "_object_axis", lambda row: None)
    set_fps(24)
    obj = make_fish("tuna", head_axis="NEG_X")
    add_swim(obj, head_axis="NEG_X", frequency=2.0)
    nodes = route.modifier(obj).node_group.nodes
    assert any(n.type == "VECT_MATH" and n.operation == "DOT_PRODUCT" for n in nodes)
    assert not any(n.type == "SEPXYZ" for n in nodes)
    worst, moved = _route_equals_core(obj, (3, 7))
    assert moved > 0.02 and worst < 1e-5, worst
    assert _route_equals_full_binding(obj, (3, 7)) < 1e-5
