"""The seed's smoothness criteria (section 4.3) measured on baked motion, per gait
segment. Pure NumPy: the bake, the report and the tests all measure with this.

Inputs are per frame: feet and roots (F, 4, 3) in armature space, headings (F, 3),
contacts (F, 4), gait (F,), angles (F, B) with limits (B,), legs LF, RF, LH, RH.
"""

import numpy as np

LEGS = ("LF", "RF", "LH", "RH")
GAITS = ("WALK", "TROT", "CANTER", "GALLOP", "GALLOP_ROTARY")
LIMIT_TOLERANCE = 1e-5  # radians: float32 F-curve storage rounds a clamped angle by ~1e-7


def segments(gait):
    """(gait index, first frame, last frame + 1) of each run of one gait."""
    gait = np.asarray(gait).astype(int)
    edges = np.flatnonzero(np.diff(gait)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [len(gait)]])
    return [(int(gait[s]), int(s), int(e)) for s, e in zip(starts, ends)]


def events(contacts, leg):
    """Frames where `leg` lifts off (1 -> 0) and touches down (0 -> 1)."""
    c = np.asarray(contacts[:, leg]) > 0.5
    lifts = np.flatnonzero(c[:-1] & ~c[1:]) + 1
    downs = np.flatnonzero(~c[:-1] & c[1:]) + 1
    return lifts, downs


def fore_aft(feet, roots, headings, neutral):
    """Fore-aft offset (F, 4) of each foot from where it stands at rest under its root."""
    return np.einsum("fkc,fc->fk", feet - roots, headings) - neutral[None, :]


def stance_slide(feet, contacts, leg, lo, hi):
    """Largest distance a planted foot moves from where it landed, frames [lo, hi)."""
    c = contacts[:, leg] > 0.5
    worst = 0.0
    anchor = None
    for f in range(lo, hi):
        if c[f]:
            if anchor is None:
                anchor = feet[f, leg]
            worst = max(worst, float(np.linalg.norm(feet[f, leg] - anchor)))
        else:
            anchor = None
    return worst


def swing_smoothness(feet, contacts, leg, lo, hi, fps):
    """(largest jump m, largest jump ratio, largest acceleration m/s^2) of the swinging foot.

    A jump is a one-frame move that stands out from both neighbouring moves: its ratio
    is step / max(previous step, next step), about 1 on a smooth path whatever the
    frame rate, and the jump is by how much the step exceeds them. Every swing that
    overlaps frames [lo, hi) is measured whole, from lift-off to landing: a swing cut
    at a gait change would lose the neighbour of its first or last step."""
    c = contacts[:, leg] > 0.5
    jump, ratio, accel = 0.0, 0.0, 0.0
    f = lo
    while 0 < f < len(c) and not c[f] and not c[f - 1]:
        f -= 1  # back to the lift-off of a swing already under way at lo
    while f < hi:
        if c[f]:
            f += 1
            continue
        g = f
        while g < len(c) and not c[g]:
            g += 1
        a, b = max(f - 1, 0), min(g + 1, len(c))  # include the planted frames on both sides
        path = feet[a:b, leg]
        if len(path) >= 3:
            steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
            padded = np.concatenate([[0.0], steps, [0.0]])
            neighbours = np.maximum(padded[:-2], padded[2:])
            jump = max(jump, float((steps - neighbours).max()))
            ratio = max(ratio, float((steps / np.maximum(neighbours, 1e-3)).max()))
            accel = max(
                accel, float(np.linalg.norm(np.diff(path, 2, axis=0), axis=1).max() * fps * fps)
            )
        f = g
    return jump, ratio, accel


def measure(
    feet, roots, headings, contacts, gait, angles, limit_min, limit_max, neutral, reach, fps
):
    """The criteria per gait segment, as a JSON-ready dict."""
    feet = np.asarray(feet, dtype=float)
    roots = np.asarray(roots, dtype=float)
    contacts = np.asarray(contacts, dtype=float)
    offsets = fore_aft(
        feet, roots, np.asarray(headings, dtype=float), np.asarray(neutral, dtype=float)
    )
    outside = (angles < limit_min[None, :] - LIMIT_TOLERANCE) | (
        angles > limit_max[None, :] + LIMIT_TOLERANCE
    )
    result = []
    for g, lo, hi in segments(gait):
        seg = {
            "gait": GAITS[g],
            "frame_start": lo,
            "frame_end": hi - 1,
            "seconds": (hi - lo) / fps,
            "legs": {},
        }
        lh_lifts = [x for x in events(contacts, 2)[0] if lo <= x < hi]
        cycle = float(np.mean(np.diff(lh_lifts))) if len(lh_lifts) >= 2 else None
        seg["cycle_time"] = cycle / fps if cycle else None
        for leg, name in enumerate(LEGS):
            jump, ratio, accel = swing_smoothness(feet, contacts, leg, lo, hi, fps)
            entry = {
                "largest_stance_slide": stance_slide(feet, contacts, leg, lo, hi),
                "largest_swing_jump": jump,
                "largest_swing_jump_ratio": ratio,
                "largest_swing_acceleration": accel,
                "largest_foot_root_distance": float(np.abs(offsets[lo:hi, leg]).max()),
                "reach": float(reach[leg]),
            }
            lifts, downs = events(contacts, leg)
            if cycle and len(lh_lifts) >= 2:
                a, b = lh_lifts[0], lh_lifts[-1]  # whole cycles only
                entry["duty_factor"] = float(contacts[a:b, leg].mean())
                mine = [x for x in lifts if a <= x < b]
                if mine:
                    phases = [((x - lh_lifts[0]) / cycle) % 1.0 for x in mine]
                    # circular mean, so phases near 0 and 1 average correctly
                    angle = np.angle(np.mean(np.exp(2j * np.pi * np.array(phases))))
                    entry["phase"] = float((angle / (2 * np.pi)) % 1.0)
                strides = [
                    np.linalg.norm(feet[d2, leg] - feet[d1, leg])
                    for d1, d2 in zip(downs[:-1], downs[1:])
                    if lo <= d1 and d2 < hi
                ]
                if strides:
                    entry["stride"] = float(np.mean(strides))
            seg["legs"][name] = entry
        seg["joint_limit_violations"] = int(outside[lo:hi].sum())
        seg["largest_stance_slide"] = max(e["largest_stance_slide"] for e in seg["legs"].values())
        seg["largest_swing_jump"] = max(e["largest_swing_jump"] for e in seg["legs"].values())
        seg["largest_swing_jump_ratio"] = max(
            e["largest_swing_jump_ratio"] for e in seg["legs"].values()
        )
        seg["largest_swing_acceleration"] = max(
            e["largest_swing_acceleration"] for e in seg["legs"].values()
        )
        seg["largest_foot_root_distance"] = max(
            e["largest_foot_root_distance"] for e in seg["legs"].values()
        )
        result.append(seg)
    return result
