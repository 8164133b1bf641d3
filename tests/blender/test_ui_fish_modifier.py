"""Fish Swim behaves like a modifier a user can manage: the eye and camera toggles of its
header (hidden in the viewport or the render, the fish keeps its rest shape there), its
place in the stack is shown, and Apply makes the current frame's shape the mesh."""

import bpy
import numpy as np
from fish_helpers import add_swim, live, make_fish, rest
from ui_recording import draw_panel


def _evaluated(obj):
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    out = np.empty((len(mesh.vertices), 3), dtype=np.float32)
    mesh.vertices.foreach_get("co", out.reshape(-1))
    evaluated.to_mesh_clear()
    return out


def _render(scene, path):
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(str(path))
    pixels = np.array(image.pixels[:], dtype=np.float32)
    bpy.data.images.remove(image)
    return pixels


def _small_render_setup(scene, obj):
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False  # Debian's 3.4 is built without OpenImageDenoise
    scene.render.resolution_x, scene.render.resolution_y = 64, 32
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = max(obj.dimensions) * 1.3
    camera.location = (
        obj.location.x,
        obj.location.y,
        obj.location.z + 10.0,
    )  # from above: the bend shows
    scene.camera = camera
    light = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(light)


def test_header_has_viewport_and_render_toggles(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj)
    obj.modifiers.new("Subdivision", "SUBSURF")
    drawn = draw_panel(bpy.types.KODAWARI_PT_swim)
    toggles = [e for e in drawn if e.kind == "prop" and e.kwargs.get("text") == ""]
    assert {e.name for e in toggles} >= {"enabled", "show_render"}
    order = [e.name for e in draw_panel(bpy.types.KODAWARI_PT_swim_order) if e.kind == "label"]
    assert order[0].startswith("1.") and "Fish Swim" in order[0]
    assert order[1] == "2. Subdivision", "the stack shows the swim first, then the user's modifiers"


def test_viewport_toggle_shows_the_rest_shape(empty_scene):
    obj = make_fish("tuna")
    original = rest(obj).copy()
    add_swim(obj)
    empty_scene.frame_set(7)
    assert np.abs(_evaluated(obj) - original).max() > 1e-3, "the fish swims"
    obj.kodawari_swim.enabled = False
    assert np.abs(_evaluated(obj) - original).max() < 1e-6, "hidden in the viewport: the rest shape"
    obj.kodawari_swim.enabled = True
    empty_scene.frame_set(8)
    assert np.abs(_evaluated(obj) - live(obj)).max() < 1e-5, "shown again, it swims on"


def test_render_toggle_renders_the_rest_shape(empty_scene, tmp_path):
    obj = make_fish("tuna")
    _small_render_setup(empty_scene, obj)
    empty_scene.frame_set(7)
    at_rest = _render(empty_scene, tmp_path / "rest.png")
    add_swim(obj)
    empty_scene.frame_set(7)
    swimming = _render(empty_scene, tmp_path / "swim.png")
    assert np.abs(swimming - at_rest).max() > 0.1, "the render shows the swim"
    obj.kodawari_swim.show_render = False
    hidden = _render(empty_scene, tmp_path / "hidden.png")
    assert np.array_equal(hidden, at_rest), "render toggle off: the rest shape renders"
    assert np.abs(_evaluated(obj) - live(obj)).max() < 1e-5, "the viewport still shows the swim"


def test_apply_makes_the_current_shape_the_mesh(empty_scene):
    obj = make_fish("tuna")
    original = rest(obj).copy()
    add_swim(obj, fins=("fin_pectoral",))
    empty_scene.frame_set(9)
    shape = live(obj).copy()
    assert np.abs(shape - original).max() > 1e-3
    bpy.ops.ed.undo_push(message="before apply")
    assert bpy.ops.kodawari.swim_apply() == {"FINISHED"}
    assert obj.data.shape_keys is None, "the swim's shape keys are gone"
    assert np.allclose(rest(obj), shape, atol=1e-6), "frame 9's shape is now the mesh"
    assert not obj.kodawari_swim.enabled and not obj.kodawari_swim.fins
    empty_scene.frame_set(12)
    assert np.allclose(_evaluated(obj), shape, atol=1e-6), "it no longer swims"
    bpy.ops.ed.undo_push(message="Apply Fish Swim")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["tuna"]
    assert obj.modifiers.get("Fish Swim") is not None and obj.kodawari_swim.enabled, (
        "undo brings the swim back"
    )
    assert np.array_equal(rest(obj), original)


def test_apply_refuses_with_a_clear_message(empty_scene):
    obj = make_fish("tuna")
    try:
        bpy.ops.kodawari.swim_apply()
    except RuntimeError as exc:
        assert "no Fish Swim" in str(exc)
    else:
        raise AssertionError("apply on a mesh without a swim must refuse")
    add_swim(obj)
    obj.shape_key_add(name="Smile", from_mix=False)
    try:
        bpy.ops.kodawari.swim_apply()
    except RuntimeError as exc:
        assert "Smile" in str(exc)
    else:
        raise AssertionError("apply must refuse when the user's shape keys would be lost")
    assert obj.modifiers.get("Fish Swim") is not None, "nothing changed"


def test_a_swim_hidden_in_the_viewport_can_still_be_tuned_and_baked(empty_scene):
    """Like a modifier with its eye off: the swim is still there to edit and bake."""
    obj = make_fish("tuna")
    original = rest(obj).copy()
    add_swim(obj)
    obj.kodawari_swim.enabled = False
    assert bpy.ops.kodawari.swim_fin_add(vertex_group="fin_pectoral", kind="PECTORAL") == {
        "FINISHED"
    }
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=4, target="SHAPE_KEYS") == {
        "FINISHED"
    }
    baked = [b for b in obj.data.shape_keys.key_blocks if b.name not in ("Basis", "Kodawari Swim")]
    assert len(baked) == 4
    positions = np.empty((len(baked[2].data), 3), dtype=np.float32)
    baked[2].data.foreach_get("co", positions.reshape(-1))
    assert np.abs(positions - original).max() > 1e-3, "the baked frames swim"


def test_farm_bake_follows_the_render_toggle_not_the_viewport(empty_scene, tmp_path):
    """bake_all bakes what a render shows: a swim hidden only in the viewport still renders
    (so it is baked); one hidden from renders renders its rest shape (so it is not)."""
    import kodawari

    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "shot.blend"))
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 3
    viewport_off = make_fish("tuna")
    add_swim(viewport_off)
    viewport_off.kodawari_swim.enabled = False
    render_off = make_fish("dolphin")
    add_swim(render_off)
    render_off.kodawari_swim.show_render = False
    kodawari.bake_all(save=False, exit_on_failure=False)
    assert viewport_off.kodawari_swim.baked == "MESH_CACHE"
    assert render_off.kodawari_swim.baked == "NONE"
