"""Objects linked from another .blend are refused with a clear message (issue 11 item 6):
Blender keeps none of the changes on save, so a set-up made on them would be lost."""

import bpy
import pytest
from bake_scenes import hair_rig
from fish_helpers import activate, make_fish
from gait_scene import horse


@pytest.fixture
def linked(empty_scene, tmp_path):
    """A library file with a fish, a horse with its gait set up and a hair rig with a rod,
    linked into a new file: {name: linked object}."""
    make_fish("tuna")
    horse(empty_scene, [(1, 2.0), (30, 2.0)])
    hair_rig(empty_scene)
    library = str(tmp_path / "library.blend")
    bpy.ops.wm.save_as_mainfile(filepath=library)
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    with bpy.data.libraries.load(library, link=True) as (_source, target):
        target.objects = ["tuna", "Horse", "Rig"]
    scene = bpy.context.scene
    for obj in target.objects:
        scene.collection.objects.link(obj)
    assert all(obj.library is not None for obj in target.objects)
    return {obj.name: obj for obj in target.objects}


def _refused(operator, obj, **kwargs):
    activate(obj)
    with pytest.raises(RuntimeError) as info:
        operator(**kwargs)
    message = str(info.value)
    assert "linked from" in message and "library.blend" in message, message
    assert "Traceback" not in message


def test_fish_swim_refuses_a_linked_mesh(linked):
    fish = linked["tuna"]
    _refused(bpy.ops.kodawari.swim_add, fish, head_axis="POS_X")
    assert fish.data.shape_keys is None and not fish.kodawari_swim.enabled


def test_gait_refuses_a_linked_armature(linked):
    rig = linked["Horse"]
    action = rig.animation_data.action if rig.animation_data else None
    _refused(bpy.ops.kodawari.gait_setup, rig)
    _refused(bpy.ops.kodawari.gait_bake, rig, frame_start=1, frame_end=30)
    assert (rig.animation_data.action if rig.animation_data else None) == action


def test_hair_refuses_a_linked_armature(linked):
    rig = linked["Rig"]
    _refused(bpy.ops.kodawari.rod_bake, rig, frame_start=1, frame_end=10)
    _refused(bpy.ops.kodawari.rod_remove, rig)
    _refused(bpy.ops.kodawari.rod_collider_add, rig, bone="Head")
    assert len(rig.kodawari_hair.rods) == 1 and rig.animation_data is None
