"""Wave phase and distance travelled at a frame, accumulated from the scene start.

docs/algorithms.md §2.2 asks for φ += ω·dt, never ω·t: with a keyframed
frequency, ω·t would make the whole wave jump when the frequency changes. The
phase at frame F integrates the (possibly animated) frequency from the scene's
start frame to F, one sample per frame, with the trapezoid rule; the distance
swum integrates the speed the same way. Both depend only on F, so scrubbing,
playback and a bake give the same frames.
"""

import math

import numpy as np

from .. import fcurves, native


def _curve(obj, path):
    anim = obj.animation_data
    if anim is None or anim.action is None:
        return None
    return fcurves.find_fcurve(anim.action, obj, path)


def _samples(frame, start):
    """Integer frames from start to frame (either direction), ending exactly at frame."""
    if frame >= start:
        whole = np.arange(start, math.floor(frame) + 1, dtype=np.float64)
        if whole[-1] != frame:
            whole = np.append(whole, frame)
        return whole
    whole = np.arange(start, math.ceil(frame) - 1, -1, dtype=np.float64)
    if whole[-1] != frame:
        whole = np.append(whole, frame)
    return whole


def _values(obj, settings, name, frames):
    curve = _curve(obj, f"kodawari_swim.{name}")
    if curve is None:
        return np.full(len(frames), float(getattr(settings, name)))
    return np.array([curve.evaluate(f) for f in frames], dtype=np.float64)


def _integrate(values, frames, fps):
    if len(frames) < 2:
        return 0.0
    dt = np.diff(frames) / fps
    return float(np.sum(0.5 * (values[1:] + values[:-1]) * dt))


def phase_and_distance(obj, settings, scene, frame, body_length):
    """(phase radians, distance in object units) at `frame` (may be fractional)."""
    fps = scene.render.fps / scene.render.fps_base
    start = float(scene.frame_start)
    frames = _samples(float(frame), start)
    frequency = _values(obj, settings, "frequency", frames)
    phase = 2.0 * math.pi * _integrate(frequency, frames, fps)
    distance = 0.0
    if settings.speed_mode != "NONE":
        kn = native.module()
        amplitude = _values(obj, settings, "amplitude", frames)
        strouhal = _values(obj, settings, "strouhal", frames)
        speed = np.array(
            [
                kn.swim_speed(settings.speed_mode, body_length, f, a, s)
                for f, a, s in zip(frequency, amplitude, strouhal)
            ]
        )
        distance = _integrate(speed, frames, fps)
    return phase, distance
