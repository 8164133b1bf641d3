"""The gait report's picture as SVG: real text, axes with units, a legend, and it zooms
without blurring in any browser or image viewer. Written with the standard library;
the curves are formatted by NumPy (np.savetxt), no Python loop per frame.

Top: the footfall (Hildebrand) diagram, one row per foot, a bar while it is planted.
Bottom: each foot's fore-aft position from its leg root, with the reach limits dashed.
Both over time in seconds, on the gait segments' coloured bands."""

import io
from xml.sax.saxutils import escape

import numpy as np

from . import metrics

GAIT_NAMES = {
    "WALK": "Walk",
    "TROT": "Trot",
    "CANTER": "Canter",
    "GALLOP": "Gallop",
    "GALLOP_ROTARY": "Rotary gallop",
}
GAIT_FILLS = ("#dcefdc", "#dce6fa", "#faedd6", "#fadcdc", "#eddcfa")
LEG_NAMES = {"LF": "Left fore", "RF": "Right fore", "LH": "Left hind", "RH": "Right hind"}
LEG_STROKES = ("#d9331a", "#f29919", "#1a59d9", "#1aa699")  # LF, RF, LH, RH
ROW_ORDER = (2, 0, 1, 3)  # LH, LF, RF, RH: the Hildebrand order

WIDTH, LEFT, RIGHT = 1000, 110, 30
FOOT_TOP, ROW_H = 84, 24
TRAJ_TOP, TRAJ_H = 264, 260
HEIGHT = TRAJ_TOP + TRAJ_H + 135


def _ticks(span, target=8):
    """A readable tick step (1, 2 or 5 × 10^k) giving about `target` ticks over span."""
    raw = max(span, 1e-9) / target
    power = 10.0 ** np.floor(np.log10(raw))
    return power * min((1, 2, 5, 10), key=lambda m: abs(m * power - raw))


def _text(x, y, text, size=13, anchor="start", weight="normal", fill="#1a1a1a", rotate=None):
    transform = f' transform="rotate({rotate} {x:.1f} {y:.1f})"' if rotate is not None else ""
    return (
        f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" text-anchor="{anchor}" font-weight="{weight}" '
        f'fill="{fill}"{transform}>{escape(text)}</text>'
    )


def _polyline(xs, ys, stroke, width=1.6, dash=None):
    buffer = io.StringIO()
    np.savetxt(buffer, np.column_stack([xs, ys]), fmt="%.1f,%.1f", newline=" ")
    dashes = f' stroke-dasharray="{dash}"' if dash else ""
    return (
        f'<polyline points="{buffer.getvalue().strip()}" fill="none" stroke="{stroke}" '
        f'stroke-width="{width}"{dashes}/>'
    )


def _runs(mask):
    """(first, last + 1) of every run of True."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return edges.reshape(-1, 2)


def render(data, fps, title="Gait report"):
    """The report as an SVG document (str)."""
    contacts, gait, reach = data["contacts"], data["gait"], data["reach"]
    offsets = metrics.fore_aft(data["feet"], data["roots"], data["headings"], data["neutral"])
    n = len(gait)
    seconds = np.arange(n) / fps
    duration = max(seconds[-1], 1.0 / fps)
    plot_w = WIDTH - LEFT - RIGHT

    def x_of(t):
        return LEFT + np.asarray(t) / duration * plot_w

    lim = float(max(reach.max(), np.abs(offsets).max())) * 1.1

    def y_of(v):
        return TRAJ_TOP + TRAJ_H / 2 - np.asarray(v) / lim * (TRAJ_H / 2)

    foot_h = 4 * ROW_H
    out = [
        (
            f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" '
            f'height="{HEIGHT}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">'
        ),
        f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>',
        _text(LEFT, 28, title, size=18, weight="bold"),
    ]
    # Gait segments: coloured bands behind both plots, named above the footfalls.
    for g, lo, hi in metrics.segments(gait):
        x0, x1 = x_of(lo / fps), x_of(min(hi, n - 1) / fps if hi < n else duration)
        for top, h in ((FOOT_TOP, foot_h), (TRAJ_TOP, TRAJ_H)):
            out.append(
                f'<rect x="{x0:.1f}" y="{top}" width="{max(x1 - x0, 0.5):.1f}" height="{h}" '
                f'fill="{GAIT_FILLS[g]}"/>'
            )
        if x1 - x0 > 45:
            out.append(
                _text(
                    (x0 + x1) / 2,
                    FOOT_TOP - 8,
                    GAIT_NAMES[metrics.GAITS[g]],
                    size=12,
                    anchor="middle",
                )
            )
    # Footfalls.
    out.append(
        _text(LEFT, 54, "Footfalls (Hildebrand diagram): a bar while the foot is planted", size=14)
    )
    for row, leg in enumerate(ROW_ORDER):
        y = FOOT_TOP + row * ROW_H
        out.append(
            _text(LEFT - 8, y + ROW_H * 0.65, LEG_NAMES[metrics.LEGS[leg]], size=12, anchor="end")
        )
        for lo, hi in _runs(contacts[:, leg] > 0.5):
            x0, x1 = x_of(lo / fps), x_of(hi / fps)
            out.append(
                f'<rect x="{x0:.1f}" y="{y + 4}" width="{max(x1 - x0, 0.5):.1f}" height="{ROW_H - 8}" '
                f'fill="#1a1a1a"/>'
            )
    out.append(
        f'<rect x="{LEFT}" y="{FOOT_TOP}" width="{plot_w}" height="{foot_h}" fill="none" stroke="#555"/>'
    )
    # Fore-aft trajectories with their reach limits.
    out.append(_text(LEFT, TRAJ_TOP - 14, "Fore-aft foot position from its leg root", size=14))
    out.append(
        f'<line x1="{LEFT}" x2="{LEFT + plot_w}" y1="{y_of(0):.1f}" y2="{y_of(0):.1f}" stroke="#888"/>'
    )
    for leg in range(4):
        for sign in (1, -1):
            level = float(y_of(sign * reach[leg]))
            out.append(
                _polyline([LEFT, LEFT + plot_w], [level, level], LEG_STROKES[leg], 1.0, "6 5")
            )
    for leg in range(4):
        out.append(_polyline(x_of(seconds), y_of(offsets[:, leg]), LEG_STROKES[leg]))
    out.append(
        f'<rect x="{LEFT}" y="{TRAJ_TOP}" width="{plot_w}" height="{TRAJ_H}" fill="none" stroke="#555"/>'
    )
    # Axes: value ticks in metres, time ticks in seconds under both plots.
    step = _ticks(2 * lim, 6)
    for value in np.arange(-np.floor(lim / step) * step, lim + 1e-9, step):
        y = float(y_of(value))
        out.append(f'<line x1="{LEFT - 5}" x2="{LEFT}" y1="{y:.1f}" y2="{y:.1f}" stroke="#555"/>')
        label = "0" if abs(value) < step * 1e-6 else f"{value:+.2f}"
        out.append(_text(LEFT - 8, y + 4, label, size=11, anchor="end"))
    out.append(
        _text(
            40,
            TRAJ_TOP + TRAJ_H / 2,
            "Fore-aft position (m), + ahead",
            size=13,
            anchor="middle",
            rotate=-90,
        )
    )
    step = _ticks(duration, 10)
    for t in np.arange(0.0, duration + 1e-9, step):
        x = float(x_of(t))
        for bottom in (FOOT_TOP + foot_h, TRAJ_TOP + TRAJ_H):
            out.append(
                f'<line x1="{x:.1f}" x2="{x:.1f}" y1="{bottom}" y2="{bottom + 5}" stroke="#555"/>'
            )
        out.append(_text(x, TRAJ_TOP + TRAJ_H + 19, f"{t:g}", size=11, anchor="middle"))
    out.append(
        _text(LEFT + plot_w / 2, TRAJ_TOP + TRAJ_H + 40, "Time (s)", size=13, anchor="middle")
    )
    # Legend.
    y = HEIGHT - 30
    x = LEFT
    for leg in range(4):
        out.append(_polyline([x, x + 26], [y - 4, y - 4], LEG_STROKES[leg], 2.5))
        out.append(_text(x + 32, y, LEG_NAMES[metrics.LEGS[leg]], size=12))
        x += 120
    out.append(_polyline([x, x + 26], [y - 4, y - 4], "#555", 1.0, "6 5"))
    out.append(_text(x + 32, y, "Reach limit (± from the leg root)", size=12))
    x += 240
    out.append(f'<rect x="{x}" y="{y - 11}" width="26" height="10" fill="#1a1a1a"/>')
    out.append(_text(x + 32, y, "Planted", size=12))
    # The gait bands' colours (a short segment has no room for its name).
    y, x = HEIGHT - 55, LEFT
    for g in sorted({g for g, _, _ in metrics.segments(gait)}):
        out.append(
            f'<rect x="{x}" y="{y - 11}" width="26" height="12" fill="{GAIT_FILLS[g]}" stroke="#999"/>'
        )
        out.append(_text(x + 32, y, GAIT_NAMES[metrics.GAITS[g]], size=12))
        x += 120
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write(data, fps, filepath, title="Gait report"):
    with open(filepath, "w", encoding="utf-8") as file:
        file.write(render(data, fps, title))
    return filepath
