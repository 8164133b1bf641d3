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

from .. import fcurves
from . import runtime

CACHE_MODIFIER = "Kodawari Swim Cache"
BAKED_KEY_PREFIX = "Kodawari Swim "


def pc2_header(points, start, rate, samples):
    return struct.pack("<12siiffi", b"POINTCACHE2\0", 1, points, float(start), float(rate), samples)


def read_pc2(path):
    """(start, rate, positions float32 (samples, points, 3)) — used by tests and checks."""
    with open(path, "rb") as handle:
        magic, version, points, start, rate, samples = struct.unpack("<12siiffi", handle.read(32))
        if magic != b"POINTCACHE2\0" or version != 1:
            raise ValueError(f"{path} is not a PC2 point cache")
        data = np.frombuffer(handle.read(), dtype="<f4")
    return start, rate, data.reshape(samples, points, 3)


def default_cache_path(obj):
    name = bpy.path.clean_name(obj.name) + "_swim.pc2"
    if bpy.data.filepath:
        return "//" + name
    return os.path.join(bpy.app.tempdir or os.path.dirname(os.path.abspath(__file__)), name)


class Baker:
    """Bakes frame by frame so a modal operator can show progress and cancel."""

    def __init__(self, obj, scene, frame_start, frame_end, target, filepath):
        self.obj = obj
        self.scene = scene
        self.frames = list(range(frame_start, frame_end + 1))
        self.target = target
        self.filepath = filepath
        self.absolute_path = bpy.path.abspath(filepath) if filepath else ""
        self.original_frame = (scene.frame_current, scene.frame_subframe)
        self.index = 0
        self.handle = None
        self.keys = []  # SHAPE_KEYS: positions per frame, made into keys at the end
        self.travel = []  # speed mode: the object's travel per frame
        self.follow = (
            runtime.path.follow_path(obj) if obj.kodawari_swim.speed_mode != "NONE" else None
        )

    @property
    def done(self):
        return self.index >= len(self.frames)

    @property
    def progress(self):
        return self.index / max(1, len(self.frames))

    def start(self):
        if self.target == "MESH_CACHE":
            folder = os.path.dirname(self.absolute_path)
            if folder:
                os.makedirs(folder, exist_ok=True)
            # Stays open across the modal bake's steps; closed by finish() or cancel().
            self.handle = open(self.absolute_path + ".part", "wb")  # noqa: SIM115
            count = len(self.obj.data.vertices)
            self.handle.write(pc2_header(count, self.frames[0], 1.0, len(self.frames)))

    def step(self):
        frame = self.frames[self.index]
        self.scene.frame_set(frame)
        positions = runtime.evaluate(self.obj, self.scene, frame)
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

    def _restore_frame(self):
        self.scene.frame_set(self.original_frame[0], subframe=self.original_frame[1])

    def cancel(self):
        """Leave everything as it was: no file, no key, no modifier, the same frame."""
        if self.handle is not None:
            self.handle.close()
            self.handle = None
            os.remove(self.absolute_path + ".part")
        self.keys = []
        settings = self.obj.kodawari_swim
        if settings.speed_mode != "NONE" and self.follow is None:
            self.obj.delta_location = settings.rest_delta_location
        self._restore_frame()

    def finish(self):
        obj = self.obj
        settings = obj.kodawari_swim
        block = runtime.swim_key_block(obj)
        if self.target == "MESH_CACHE":
            self.handle.close()
            self.handle = None
            os.replace(self.absolute_path + ".part", self.absolute_path)
            modifier = obj.modifiers.get(CACHE_MODIFIER) or obj.modifiers.new(
                CACHE_MODIFIER, "MESH_CACHE"
            )
            modifier.cache_format = "PC2"
            # Relative to the .blend when it is saved, so the pair can move together.
            modifier.filepath = (
                bpy.path.relpath(self.absolute_path) if bpy.data.filepath else self.absolute_path
            )
            modifier.time_mode = "FRAME"
            modifier.play_mode = "SCENE"
            modifier.frame_start = float(self.frames[0])
            modifier.frame_scale = 1.0
            modifier.deform_mode = "OVERWRITE"
            modifier.interpolation = "LINEAR"
            if hasattr(obj.modifiers, "move"):
                obj.modifiers.move(list(obj.modifiers).index(modifier), 0)
            settings.cache_path = modifier.filepath
        else:
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
                group="Kodawari Swim",
            )
        if block is not None:
            block.value = 0.0
        settings.baked = self.target
        self._restore_frame()
