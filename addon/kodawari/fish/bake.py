"""Baking the swim: a PC2 point cache played by Blender's own Mesh Cache modifier,
or one shape key per frame. Either renders and exports without the add-on.

PC2 layout (the format Blender's Mesh Cache modifier reads): a 32-byte header
b'POINTCACHE2\\0', int32 version 1, int32 point count, float32 start frame,
float32 sample rate, int32 sample count; then float32 xyz per point per sample.
"""

import os
import struct

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import cache_paths, editable, fcurves
from ..bake_job import BakeError, BakeJob
from . import route, runtime, visibility

CACHE_MODIFIER = "Kodawari Swim Cache"
BAKED_KEY_PREFIX = "Kodawari Swim "
ADDED_BASIS = "kodawari_swim_basis"  # mesh property: a SHAPE_KEYS bake added the Basis
TRAVEL_GROUP = "Kodawari Swim"  # the F-curve group of the baked travel


def pc2_header(points, start, rate, samples):
    return struct.pack("<12siiffi", b"POINTCACHE2\0", 1, points, float(start), float(rate), samples)


def read_pc2(path):
    """(start, rate, positions float32 (samples, points, 3)) — used by tests and checks."""
    with open(path, "rb") as handle:
        magic, version, points, start, rate, samples = struct.unpack("<12siiffi", handle.read(32))
        if magic != b"POINTCACHE2\0" or version != 1:
            raise ValueError(tip_("{} is not a PC2 point cache").format(path))
        data = np.frombuffer(handle.read(), dtype="<f4")
    return start, rate, data.reshape(samples, points, 3)


def default_cache_path(obj):
    """`//blendcache_<file>/<object>_swim.pc2`; BakeError when the file is unsaved."""
    return cache_paths.default_path(obj, "swim", ".pc2")


class SwimBakeJob(BakeJob):
    """Bakes frame by frame into a PC2 file (played by a Mesh Cache modifier) or shape keys."""

    title = "Fish swim bake"

    def __init__(self, obj, scene, frame_start, frame_end, target, filepath=""):
        self.obj = obj
        self.scene = scene
        self.frames = list(range(frame_start, frame_end + 1))
        self.target = target
        self.filepath = filepath
        self.absolute_path = ""
        self.original_frame = (scene.frame_current, scene.frame_subframe)
        self.index = 0
        self.handle = None
        self.keys = []  # SHAPE_KEYS: positions per frame, made into keys at the end
        self.travel = []  # speed mode: the object's travel per frame
        self.follow = None
        self.stepped = False
        self.was_enabled = None  # set by prepare: the live switch to put back

    def prepare(self):
        obj = self.obj
        why = editable.why_not(obj, tip_("bake its swim"))
        if why:
            raise BakeError(why)
        if obj.kodawari_swim.baked != "NONE":
            raise BakeError(
                tip_("'{}' is already baked: Free Bake first to bake again").format(obj.name)
            )
        # Every binding input checked before a frame is baked (a deleted fin group fails here).
        runtime.get_rig(obj, check_rest=True)
        if obj.kodawari_swim.speed_mode != "NONE":
            self.follow = runtime.path.follow_path(obj)
        if self.target == "MESH_CACHE":
            self.filepath = self.filepath or default_cache_path(obj)
            self.absolute_path = cache_paths.check_target(obj, self.filepath)
            self.handle = cache_paths.open_partial(self.absolute_path)
            count = len(obj.data.vertices)
            self.handle.write(pc2_header(count, self.frames[0], 1.0, len(self.frames)))
        # The bake evaluates the fish itself: the live frame handler leaves it alone meanwhile.
        self.was_enabled = obj.kodawari_swim.enabled
        with runtime.batch(obj):
            obj.kodawari_swim.enabled = False

    def step(self):
        frame = self.frames[self.index]
        self.stepped = True
        self.scene.frame_set(frame)
        positions = runtime.positions(self.obj, self.scene, frame, check_rest=False)
        if self.handle is not None:
            self.handle.write(np.ascontiguousarray(positions, dtype="<f4").tobytes())
        else:
            self.keys.append(positions.copy())
        settings = self.obj.kodawari_swim
        if settings.speed_mode != "NONE":
            self.travel.append(
                self.follow.offset_factor if self.follow else tuple(self.obj.delta_location)
            )
        self.index += 1
        return self.index / len(self.frames)

    def _restore_frame(self):
        self.scene.frame_set(self.original_frame[0], subframe=self.original_frame[1])

    def cancel(self):
        """Leave everything as it was: no file, no key, no modifier, the same frame."""
        if self.absolute_path:
            cache_paths.discard_partial(self.handle, self.absolute_path)
            self.handle = None
        self.keys = []
        settings = self.obj.kodawari_swim
        if self.was_enabled is not None:
            with runtime.batch(self.obj):
                settings.enabled = self.was_enabled
            self.was_enabled = None
        if self.stepped:
            if settings.speed_mode != "NONE" and self.follow is None:
                self.obj.delta_location = settings.rest_delta_location
            self._restore_frame()

    def finish(self):
        obj = self.obj
        settings = obj.kodawari_swim
        if self.target == "MESH_CACHE":
            # The file first: a failing rename leaves the object untouched (cancel cleans up).
            self.handle.close()
            self.handle = None
            os.replace(self.absolute_path + ".part", self.absolute_path)
            self.absolute_path = ""  # the finished file is kept from here on
            modifier = obj.modifiers.get(CACHE_MODIFIER) or obj.modifiers.new(
                CACHE_MODIFIER, "MESH_CACHE"
            )
            modifier.cache_format = "PC2"
            # Relative to the .blend when it is saved, so the pair can move together.
            modifier.filepath = cache_paths.stored_path(bpy.path.abspath(self.filepath))
            modifier.time_mode = "FRAME"
            modifier.play_mode = "SCENE"
            modifier.frame_start = float(self.frames[0])
            modifier.frame_scale = 1.0
            modifier.deform_mode = "OVERWRITE"
            modifier.interpolation = "LINEAR"
            route.move_first(obj, modifier)
            settings.cache_path = modifier.filepath
        else:
            if obj.data.shape_keys is None:
                # Baked keys are relative to a Basis: the rest shape. Ours, so Free Bake
                # takes it away again.
                obj.shape_key_add(name="Basis", from_mix=False)
                obj.data[ADDED_BASIS] = True
            key = obj.data.shape_keys
            first, last = self.frames[0], self.frames[-1]
            action = fcurves.ensure_action(key, "Kodawari Swim Bake")
            for frame, positions in zip(self.frames, self.keys):
                baked = obj.shape_key_add(name=f"{BAKED_KEY_PREFIX}{frame:04d}", from_mix=False)
                baked.data.foreach_set("co", positions.reshape(-1))
                # On at its frame, off at the neighbours: linear keys blend subframes.
                frames = [f for f in (frame - 1, frame, frame + 1) if first <= f <= last]
                values = [1.0 if f == frame else 0.0 for f in frames]
                fcurves.write_channels(
                    action, key, f'key_blocks["{baked.name}"].value', frames, values
                )
            self.keys = []
        if self.travel:
            action = fcurves.ensure_action(obj, obj.name + "Action")
            values = np.array(self.travel, dtype=np.float32)
            if self.follow is not None:
                path = f'constraints["{self.follow.name}"].offset_factor'
            else:
                path = "delta_location"
            fcurves.write_channels(
                action,
                obj,
                path,
                np.array(self.frames, dtype=np.float32),
                values,
                group=TRAVEL_GROUP,
            )
        settings.baked = self.target
        visibility.sync(obj)  # the modifier off: the bake plays
        with runtime.batch(obj):
            settings.enabled = self.was_enabled
        self.was_enabled = None
        self._restore_frame()
        where = (
            tip_("to {}").format(self.filepath)
            if self.target == "MESH_CACHE"
            else tip_("to shape keys")
        )
        return tip_("Baked {} frames of '{}' {}; live evaluation is off").format(
            len(self.frames), obj.name, where
        )


def free_bake(obj):
    """Drop the bake and go live again; the setup (fins, preset, bend, timing) stays.
    The PC2 file is deleted only when it lies in this file's own cache folder."""
    settings = obj.kodawari_swim
    modifier = obj.modifiers.get(CACHE_MODIFIER)
    if modifier is not None:
        path = modifier.filepath
        obj.modifiers.remove(modifier)
        if cache_paths.is_own_cache(path) and not cache_paths.caches_in_use().get(
            os.path.normpath(bpy.path.abspath(path))
        ):
            try:
                os.remove(bpy.path.abspath(path))
            except OSError:
                pass  # already gone, or not ours to delete: the modifier is what mattered
    free_bake_keys(obj)
    anim = obj.animation_data
    if anim is not None and anim.action is not None:
        for curve in list(fcurves.action_fcurves(anim.action, obj)):
            if curve.group is not None and curve.group.name == TRAVEL_GROUP:
                fcurves.remove_fcurve(anim.action, obj, curve)
    obj.delta_location = settings.rest_delta_location
    settings.cache_path = ""
    settings.baked = "NONE"
    visibility.sync(obj)  # the modifier on again, as the settings say


def free_bake_keys(obj):
    """Remove the baked shape keys and their F-curves, and the Basis a bake added."""
    keys = obj.data.shape_keys
    if keys is None:
        return
    baked = [b for b in keys.key_blocks if b.name.startswith(BAKED_KEY_PREFIX)]
    anim = keys.animation_data
    for block in baked:
        if anim is not None and anim.action is not None:
            curve = fcurves.find_fcurve(anim.action, keys, f'key_blocks["{block.name}"].value')
            if curve is not None:
                fcurves.remove_fcurve(anim.action, keys, curve)
        obj.shape_key_remove(block)
    keys = obj.data.shape_keys
    if obj.data.get(ADDED_BASIS):
        if keys is not None and len(keys.key_blocks) == 1:
            obj.shape_key_remove(keys.key_blocks[0])
        del obj.data[ADDED_BASIS]
