"""Wave phase and distance travelled at a frame, accumulated from the scene start.

The literature notes (docs/algorithms.md §2.2) ask for φ += ω·dt, never
ω·t: with a keyframed frequency, ω·t would make the whole wave jump when the
frequency changes. The phase at frame F integrates the (possibly animated)
frequency from the scene's start frame to F, one sample per frame, with the
trapezoid rule (the core's swim_accumulate_phase); the distance swum integrates
the speed the same way. Both depend only on F, so scrubbing, playback and a bake
give the same frames.

The running sums are cached per object (one sample per frame, extended in blocks
as later frames are asked for) and dropped when anything they depend on changes
(the curves' keys, the static values, fps, start frame, body length), so a live
frame costs the same at frame 10 and at frame 10,000.
"""

import math

import numpy as np

from .. import fcurves, native

BLOCK = 256  # frames sampled ahead when the cache grows
CURVED = ("frequency", "amplitude", "strouhal")

_cache = {}


def _curve(obj, path):
    anim = obj.animation_data
    if anim is None or anim.action is None:
        return None
    return fcurves.find_fcurve(anim.action, obj, path)


def _curve_signature(curve):
    """The keys of an F-curve as bytes (a few foreach_get per frame: no per-key Python)."""
    points = curve.keyframe_points
    n = len(points)
    data = np.empty(6 * n, dtype=np.float32)
    points.foreach_get("co", data[: 2 * n])
    points.foreach_get("handle_left", data[2 * n : 4 * n])
    points.foreach_get("handle_right", data[4 * n :])
    modes = np.empty(n, dtype=np.int32)
    points.foreach_get("interpolation", modes)
    return (data.tobytes(), modes.tobytes(), curve.extrapolation, len(curve.modifiers))


def _values(obj, settings, name, frames, curves):
    curve = curves[name]
    if curve is None:
        return np.full(len(frames), float(getattr(settings, name)))
    return np.array([curve.evaluate(f) for f in frames], dtype=np.float64)


def _speeds(kn, settings, body_length, frequency, amplitude, strouhal):
    if settings.speed_mode == "NONE":
        return np.zeros(len(frequency))
    return np.array(
        [
            kn.swim_speed(settings.speed_mode, body_length, f, a, s)
            for f, a, s in zip(frequency, amplitude, strouhal)
        ]
    )


class _Accumulation:
    """Phase and distance at every whole frame from the start frame onward."""

    def __init__(self, signature, start, fps):
        self.signature = signature
        self.start = start
        self.fps = fps
        self.phase = np.zeros(1)
        self.distance = np.zeros(1)
        self.frequency = None
        self.speed = None

    def extend(self, obj, settings, curves, body_length, last):
        """Sample whole frames up to at least `last` (in blocks)."""
        have = len(self.phase)
        want = max(int(last - self.start) + 1, have)
        if want <= have and self.frequency is not None:
            return
        want = max(want, have + BLOCK) if self.frequency is not None else max(want, BLOCK)
        first = have if self.frequency is not None else 0
        frames = self.start + np.arange(first, want, dtype=np.float64)
        frequency = _values(obj, settings, "frequency", frames, curves)
        amplitude = _values(obj, settings, "amplitude", frames, curves)
        strouhal = _values(obj, settings, "strouhal", frames, curves)
        kn = native.module()
        speed = _speeds(kn, settings, body_length, frequency, amplitude, strouhal)
        dt = 1.0 / self.fps
        if self.frequency is None:
            self.phase = kn.swim_accumulate_phase(frequency, dt, 0.0)
            self.distance = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)])
            self.frequency, self.speed = frequency, speed
            return
        # Continue from the last cached frame: the joint sample is the old last one.
        joined_f = np.concatenate([self.frequency[-1:], frequency])
        joined_s = np.concatenate([self.speed[-1:], speed])
        phase = kn.swim_accumulate_phase(joined_f, dt, float(self.phase[-1]))[1:]
        distance = self.distance[-1] + np.cumsum(0.5 * (joined_s[1:] + joined_s[:-1]) * dt)
        self.phase = np.concatenate([self.phase, phase])
        self.distance = np.concatenate([self.distance, distance])
        self.frequency = np.concatenate([self.frequency, frequency])
        self.speed = np.concatenate([self.speed, speed])


def _signature(settings, curves, start, fps, body_length):
    keyed = tuple(_curve_signature(c) if c is not None else None for c in curves.values())
    static = tuple(float(getattr(settings, name)) for name in CURVED)
    return (keyed, static, settings.speed_mode, start, fps, round(body_length, 9))


def forget(obj=None):
    if obj is None:
        _cache.clear()
    else:
        _cache.pop(obj.as_pointer(), None)


def _integrate(values, frames, fps):
    if len(frames) < 2:
        return 0.0
    dt = np.diff(frames) / fps
    return float(np.sum(0.5 * (values[1:] + values[:-1]) * dt))


def _direct(obj, settings, curves, frame, start, fps, body_length):
    """Before the start frame: integrate backward directly (rare; not cached)."""
    whole = np.arange(start, math.ceil(frame) - 1, -1, dtype=np.float64)
    if whole[-1] != frame:
        whole = np.append(whole, frame)
    frequency = _values(obj, settings, "frequency", whole, curves)
    amplitude = _values(obj, settings, "amplitude", whole, curves)
    strouhal = _values(obj, settings, "strouhal", whole, curves)
    speed = _speeds(native.module(), settings, body_length, frequency, amplitude, strouhal)
    return 2.0 * math.pi * _integrate(frequency, whole, fps), _integrate(speed, whole, fps)


def phase_and_distance(obj, settings, scene, frame, body_length):
    """(phase radians, distance in object units) at `frame` (may be fractional)."""
    fps = scene.render.fps / scene.render.fps_base
    start = float(scene.frame_start)
    frame = float(frame)
    curves = {name: _curve(obj, f"kodawari_swim.{name}") for name in CURVED}
    if frame < start:
        return _direct(obj, settings, curves, frame, start, fps, body_length)
    signature = _signature(settings, curves, start, fps, body_length)
    key = obj.as_pointer()
    acc = _cache.get(key)
    if acc is None or acc.signature != signature:
        acc = _cache[key] = _Accumulation(signature, start, fps)
    whole = math.floor(frame)
    acc.extend(obj, settings, curves, body_length, whole + 1)
    index = int(whole - start)
    phase, distance = float(acc.phase[index]), float(acc.distance[index])
    part = frame - whole
    if part > 0:
        # Between whole frames: the trapezoid from the last whole frame to `frame`.
        ends = np.array([float(whole), frame])
        f = _values(obj, settings, "frequency", ends, curves)
        phase += 2.0 * math.pi * _integrate(f, ends, fps)
        if settings.speed_mode != "NONE":
            a = _values(obj, settings, "amplitude", ends, curves)
            s = _values(obj, settings, "strouhal", ends, curves)
            speed = _speeds(native.module(), settings, body_length, f, a, s)
            distance += _integrate(speed, ends, fps)
    return phase, distance
