"""Turns out/bench.json (written by `make bench`) into the README's speed tables (Markdown on stdout).

Whole-frame figures first (each side given what a viewport does per frame), then the solvers
alone. Every row names the Blender it was measured in and the alternative it is compared with.
Times are "min / median" of 3 rounds (ms per frame; seconds per bake for gait), measured in
one process with the sides interleaved; memory is each side's peak resident set in its own
process, "+N" = above the process's size before the side was built.

    python3 tools/bench_table.py [out/bench.json]
"""

import json
import sys

SIDE_NAMES = {
    "kodawari": "Kodawari",
    "geometry_nodes": "Geometry Nodes bend (Sample Curve → Set Position)",
    "curve_modifier": "Curve modifier",
    "floor": "Blender's floor (animated shape-key value)",
    "bare": "Blender's bare evaluation (hair off)",
    "wiggle2_port": "Wiggle 2 algorithm, same-process port",
    "blender_ik": "IK constraints + nla.bake (new action)",
}


def ms(row):
    if not row or "ms_min" not in row:
        return "n/a"
    return f"{row['ms_min']:.1f} / {row['ms_median']:.1f}"


def med(row):
    return f"{row['ms_median']:.1f}" if row and "ms_median" in row else "n/a"


def mem(row):
    if not row or row.get("peak_rss_mb") is None:
        return "n/a"
    above = row.get("above_start_mb")
    return f"{row['peak_rss_mb']:.0f} MB" + (f" (+{above:.0f})" if above is not None else "")


def ratio(a, b, key="ms_median"):
    try:
        value = a[key] / b[key]
    except (KeyError, TypeError, ZeroDivisionError):
        return "n/a"
    return f"{value:.0f}×" if value >= 10 else f"{value:.2f}×"


def mem_ratio(a, b):
    try:
        return f"{a['above_start_mb'] / b['above_start_mb']:.2f}×"
    except (KeyError, TypeError, ZeroDivisionError):
        return "n/a"


def headline_table(runs, out):
    """One row per feature and Blender at the headline size: whole frame first."""
    out.append(
        "| what (whole frame unless said) | Blender | Kodawari | the alternative | alternative ÷ Kodawari (above 1: Kodawari is faster) |"
    )
    out.append("|---|---|---|---|---|")
    for _, run in runs:
        for size in run.get("fish", []):
            if size["vertices"] != 1_000_000:
                continue
            r = size["rows"]
            k = r["kodawari"]
            for side, label in (
                ("geometry_nodes", "Geometry Nodes bend"),
                ("curve_modifier", "Curve modifier"),
                ("floor", "Blender's floor (animated shape-key value)"),
            ):
                out.append(
                    f"| fish swim, 1 M vertices, ms/frame | {run['blender']} | {ms(k)} | {label} {ms(r[side])} | "
                    f"{ratio(r[side], k)} |"
                )
    for _, run in runs:
        for size in run.get("hair", []):
            if size["bones"] != 16_000:
                continue
            r = size["rows"]
            k = r["kodawari"]
            out.append(
                f"| hair, 16,000 bones, ms/frame | {run['blender']} | {ms(k)} | bare evaluation (hair off) "
                f"{ms(r['bare'])} | {ratio(r['bare'], k)} |"
            )
            if r.get("kodawari_paced") and r.get("bare_paced"):
                out.append(
                    f"| hair, 16,000 bones, ms/frame, paced playback ({size.get('fps', 24):g} fps) | "
                    f"{run['blender']} | {ms(r['kodawari_paced'])} | bare evaluation (hair off), paced "
                    f"{ms(r['bare_paced'])} | {ratio(r['bare_paced'], r['kodawari_paced'])} |"
                )
            out.append(
                f"| hair, 16,000 bones, ms/frame | {run['blender']} | {ms(k)} | Wiggle 2 algorithm "
                f"(same-process port) {ms(r['wiggle2_port'])} | {ratio(r['wiggle2_port'], k)} |"
            )
    for _, run in runs:
        rows = run.get("gait", [])
        ours = next((r for r in rows if r["side"] == "kodawari" and r["frames"] == 10_000), None)
        theirs = next(
            (r for r in rows if r["side"] == "blender_ik" and r["frames"] == 10_000), None
        )
        if not ours or not theirs or "s_min" not in ours or "s_min" not in theirs:
            continue
        tag = " (*extrapolated*)" if theirs.get("extrapolated") else ""
        out.append(
            f"| gait bake, 10,000 frames, s | {run['blender']} | {ours['s_min']:.2f} | IK constraints + "
            f"`nla.bake` (new action) {theirs['s_min']:.3g}{tag} | {ratio(theirs, ours, 's_min')}{tag} |"
        )
    for _, run in runs:
        live = run.get("fish_live")
        if live:
            out.append(
                f"| live fish (25 k vertices): frame 10,000 against frame 10, ms/frame | {run['blender']} | "
                f"{ms(live['frame_10000'])} | frame 10: {ms(live['frame_10'])} | "
                f"frame 10,000 ÷ frame 10: {ratio(live['frame_10000'], live['frame_10'])} (target 1.00×) |"
            )
    out.append("")


def fish_table(runs, out):
    out.append(
        "### Fish swim, whole frame (`scene.frame_set` + evaluation + normals read), ms per frame"
    )
    out.append("")
    out.append(
        "Kodawari = live handler (control axis, frame table into the Fish Swim modifier's helper), then "
        "Blender's evaluation of the Fish Swim Geometry Nodes modifier (the bound parameter s as an attribute; "
        "u and v, affine in the rest position on this body's straight axis, computed from Position; Sample Index). "
        "Geometry Nodes = Sample Curve → Set Position along the same animated curve (the fish's own control "
        "axis, keyed per frame). Curve modifier = the same curve. Floor = the same mesh whose only change is "
        "an animated shape-key value. Ratios use the medians; memory ratios the peak above start."
    )
    out.append("")
    out.append(
        "| Blender | vertices | Kodawari | Geometry Nodes | Curve modifier | floor | Kodawari ÷ GN | "
        "Kodawari ÷ floor | Kodawari ÷ Curve | peak RSS Kodawari / GN / Curve / floor | memory Kodawari ÷ GN | load |"
    )
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for _, run in runs:
        for size in run.get("fish", []):
            r = size["rows"]
            k, g, c, f = (
                r.get(s) for s in ("kodawari", "geometry_nodes", "curve_modifier", "floor")
            )
            out.append(
                f"| {run['blender']} | {size['vertices']:,} | {ms(k)} | {ms(g)} | {ms(c)} | {ms(f)} | "
                f"{ratio(k, g)} | {ratio(k, f)} | {ratio(k, c)} | {mem(k)} / {mem(g)} / {mem(c)} / {mem(f)} | "
                f"{mem_ratio(k, g)} | {k.get('load', 'n/a')} |"
            )
    out.append("")


def fish_live_table(runs, out):
    rows = [(run["blender"], run["fish_live"]) for _, run in runs if "fish_live" in run]
    if not rows:
        return
    out.append(
        "### Live fish frame early and late in the timeline (~25 k vertices, fins, frequency keyframed), ms per whole frame"
    )
    out.append("")
    out.append("| Blender | frame 10 | frame 10,000 | 10,000 ÷ 10 | load |")
    out.append("|---|---|---|---|---|")
    for blender, r in rows:
        out.append(
            f"| {blender} | {ms(r['frame_10'])} | {ms(r['frame_10000'])} | "
            f"{ratio(r['frame_10000'], r['frame_10'])} | {r['frame_10'].get('load')} |"
        )
    out.append("")


def hair_table(runs, out):
    out.append("### Hair, whole frame (`scene.frame_set` + evaluation), ms per frame")
    out.append("")
    out.append(
        "Chains of 16 connected bones under an animated head bone. Kodawari = live rods, 4 substeps, new frames "
        "(the head's pose predicted from its action, the hair written before Blender evaluates the frame: one "
        "evaluation; from 4,096 rod bones each frame solved ahead, on native threads, while Blender evaluated the "
        "frame before: frames set back to back leave that solve only Blender's pass to hide in, real playback "
        "also the drawing and the wait for the next frame). Inline = the same, every frame solved in its own pre-frame handler (nothing ahead). "
        "Post-eval = the same frames solved after Blender's evaluation (the path of rigs moved by "
        "constraints, drivers or NLA: two evaluations). Bare = the same "
        "rig, hair off. Wiggle 2 port = Wiggle 2's per-bone Python algorithm ported into the benchmark "
        "(tests/bench/wiggle2_port.py; Wiggle 2 itself cannot be installed here), every chain bone's tail "
        "wiggling, Quality 2. Cached = Kodawari replaying frames it already simulated (scrubbing back: "
        "written before Blender evaluates, one evaluation). Bare + re-tag = hair off, the armature tagged after "
        "each evaluation: Blender's own price for changing a pose once it is evaluated, the floor for any "
        "writer after the evaluation (Kodawari's new frames, Wiggle 2). Paced = Kodawari and bare played as a "
        "user plays the animation: each frame requested at the scene's frame rate (frame_set, then a wait "
        "for the next 1/fps tick), only the frame itself timed, the same way for both sides; the other "
        "columns set frames back to back."
    )
    out.append("")
    out.append(
        "| Blender | chain bones | Kodawari | bare | Wiggle 2 port | Kodawari ÷ bare | port ÷ Kodawari | "
        "inline ÷ bare | post-eval ÷ bare | cached ÷ bare | bare + re-tag ÷ bare | "
        "paced: Kodawari / bare (ms, medians) | paced Kodawari ÷ bare | "
        "peak RSS Kodawari / bare / port | load |"
    )
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for _, run in runs:
        for size in run.get("hair", []):
            r = size["rows"]
            k, b, w = (r.get(s) for s in ("kodawari", "bare", "wiggle2_port"))
            cached, retag = r.get("kodawari_cached"), r.get("bare_retag")
            post, inline = r.get("kodawari_post"), r.get("kodawari_inline")
            paced, paced_bare = r.get("kodawari_paced"), r.get("bare_paced")
            out.append(
                f"| {run['blender']} | {size['bones']:,} | {ms(k)} | {ms(b)} | {ms(w)} | {ratio(k, b)} | "
                f"{ratio(w, k)} | {ratio(inline, b)} | {ratio(post, b)} | {ratio(cached, b)} | {ratio(retag, b)} | "
                f"{med(paced)} / {med(paced_bare)} | {ratio(paced, paced_bare)} | "
                f"{mem(k)} / {mem(b)} / {mem(w)} | "
                f"{k.get('load', 'n/a')} |"
            )
    out.append("")


def gait_table(runs, out):
    out.append("### Gait bake, seconds per bake (horse, 4 legs × 4 bones + body)")
    out.append("")
    out.append(
        "Kodawari = `kodawari.gait_bake` end to end. IK = the same planned feet and body, legs by Blender's IK "
        "constraints, `nla.bake` visual keying into a new, empty action. *Extrapolated* figures were not run: "
        "they follow t(n) = a·n + b·n² through the two longest IK bakes measured (the fit is stated in out/bench.json). Ratios use the fastest bake of each side."
    )
    out.append("")
    out.append(
        "| Blender | frames | Kodawari | IK + nla.bake | IK ÷ Kodawari | peak RSS Kodawari / IK | load |"
    )
    out.append("|---|---|---|---|---|---|---|")
    for _, run in runs:
        rows = run.get("gait", [])
        for ours in (r for r in rows if r["side"] == "kodawari"):
            theirs = next(
                (r for r in rows if r["side"] == "blender_ik" and r["frames"] == ours["frames"]), {}
            )

            def s(row):
                if "s_min" not in row:
                    return "n/a"
                if row.get("extrapolated"):
                    return f"~{row['s_min']:.0f} (*extrapolated*)"
                return f"{row['s_min']:.3g} / {row['s_median']:.3g}" + (
                    " (1 bake)" if row.get("rounds") == 1 else ""
                )

            r = ratio(theirs, ours, "s_min") if "s_min" in theirs and "s_min" in ours else "n/a"
            if theirs.get("extrapolated") and r != "n/a":
                r = f"~{r} (*extrapolated*)"
            out.append(
                f"| {run['blender']} | {ours['frames']:,} | {s(ours)} | {s(theirs)} | {r} | "
                f"{mem(ours)} / {mem(theirs)} | {ours.get('load', 'n/a')} |"
            )
    out.append("")


def solver_table(runs, out):
    out.append("### The solvers alone (no Blender evaluation), ms per frame")
    out.append("")
    out.append("| Blender | case | handler (read, solve, write) | native solve alone |")
    out.append("|---|---|---|---|")
    for _, run in runs:
        for size in run.get("fish", []):
            s = size["solver"]
            out.append(
                f"| {run['blender']} | fish {size['vertices']:,} vertices | {s['handler_ms_min']:.2f} / "
                f"{s['handler_ms_median']:.2f} | FFD deform {s['deform_ms_min']:.2f} / {s['deform_ms_median']:.2f} "
                f"({s['deform_ms_min'] * 1e6 / size['vertices']:.2f} ns/vertex) |"
            )
        for size in run.get("hair", []):
            s = size["solver"]
            out.append(
                f"| {run['blender']} | hair {size['bones']:,} bones | {s['handler_ms_min']:.2f} / "
                f"{s['handler_ms_median']:.2f} ({s['handler_ms_min'] * 1e3 / size['bones']:.2f} µs/bone) | "
                f"rod step {s['step_ms_min']:.2f} / {s['step_ms_median']:.2f} |"
            )
    out.append("")


def main(path="out/bench.json"):
    with open(path) as f:
        data = json.load(f)
    runs = sorted(
        data.get("runs", {}).items(), key=lambda kv: tuple(int(x) for x in kv[0].split("."))
    )
    out = [
        "## Speed, measured by `make bench` (min / median of 3 rounds; machine load = 1-min load average)",
        "",
    ]
    headline_table(runs, out)
    fish_table(runs, out)
    hair_table(runs, out)
    fish_live_table(runs, out)
    gait_table(runs, out)
    solver_table(runs, out)
    print("\n".join(out))


if __name__ == "__main__":
    main(*sys.argv[1:])
