"""Box-modelled fish the way artists make them: one welded mesh, fins extruded out of
the body's faces, a mouth pushed into the snout, smoothed by subdivision.

Unlike fish_shapes.py (fins as separate plates), here every fin grows out of the
body surface with no seam, and the snout has a mouth cavity with thin lips: the
shapes on which a fin finder or a fin motion can go wrong. Each region the
builder makes is recorded in a vertex group "truth_<part>" (fin_dorsal,
fin_pectoral, fin_pelvic, fin_anal, fin_caudal, mouth) that the tests compare
against; the subdivision interpolates those weights, so a vertex belongs to a
part when its weight is over one half. Body length is 1 unit, snout at +X.

Forms: spindle (tuna), deep (goldfish, bream), flat (dorsoventrally flattened,
catfish-like), eel, cetacean (dolphin, horizontal flukes, a beak), shark.
"""

import math

import bpy  # first: puts Blender's own modules on sys.path

# isort: split
import bmesh
import numpy as np

# w, h: half width / half height at the widest point; peak: where; ped: peduncle half size.
FORMS = {
    "spindle": {
        "w": 0.085,
        "h": 0.11,
        "peak": 0.38,
        "ped": 0.014,
        "fins": "DPVAC",
        "tail": "caudal",
    },
    "deep": {"w": 0.09, "h": 0.2, "peak": 0.4, "ped": 0.03, "fins": "DPVAC", "tail": "caudal"},
    "flat": {"w": 0.16, "h": 0.045, "peak": 0.35, "ped": 0.02, "fins": "DPVAC", "tail": "caudal"},
    "eel": {"w": 0.03, "h": 0.035, "peak": 0.25, "ped": 0.008, "fins": "DPA", "tail": "none"},
    "cetacean": {"w": 0.085, "h": 0.095, "peak": 0.35, "ped": 0.018, "fins": "DP", "tail": "fluke"},
    "shark": {
        "w": 0.075,
        "h": 0.085,
        "peak": 0.33,
        "ped": 0.014,
        "fins": "DPVAC",
        "tail": "caudal",
    },
}
PARTS = ("fin_dorsal", "fin_pectoral", "fin_pelvic", "fin_anal", "fin_caudal", "mouth")


def _profile(form, s):
    f = FORMS[form]
    front = np.sqrt(np.clip(s / f["peak"], 0, 1))
    back = np.clip((1 - s) / (1 - f["peak"]), 0, 1) ** 0.9
    shape = np.where(s < f["peak"], front, back)
    return f["ped"] + (f["w"] - f["ped"]) * shape, f["ped"] + (f["h"] - f["ped"]) * shape


def _extrude(bm, faces, moves):
    """Extrude a face region once per move; move(verts) places the new verts. Returns
    every vertex the extrusions made."""
    made = []
    for move in moves:
        ret = bmesh.ops.extrude_face_region(bm, geom=faces)
        verts = [e for e in ret["geom"] if isinstance(e, bmesh.types.BMVert)]
        faces = [e for e in ret["geom"] if isinstance(e, bmesh.types.BMFace)]
        move(verts)
        made.extend(verts)
    return made


def _tip_move(direction, length, squash, squash_axis, taper=0.75, sweep=(0.0, 0.0, 0.0)):
    """A move that pushes the region out by length/steps, shrinks it across (taper)
    and flattens it along squash_axis (a thin blade)."""
    direction = np.asarray(direction, float)
    sweep = np.asarray(sweep, float)

    def move(verts):
        co = np.array([v.co[:] for v in verts])
        centre = co.mean(axis=0)
        rel = (co - centre) * taper
        rel[:, squash_axis] *= squash
        new = centre + rel + direction * length + sweep * length
        for v, c in zip(verts, new):
            v.co = c

    return move


def build_smooth_fish(form="spindle", rings=28, segments=16, subdivisions=2, name=None):
    """The fish object (linked to the scene) with truth_* vertex groups."""
    f = FORMS[form]
    s = np.linspace(0.03, 0.97, rings)
    if form == "eel":
        s = np.linspace(0.02, 0.99, rings)
    w, h = _profile(form, s)
    angles = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    bm = bmesh.new()
    ring_verts = []
    for i in range(rings):
        ring = []
        for a in angles:
            ring.append(bm.verts.new((0.5 - s[i], w[i] * math.cos(a), h[i] * math.sin(a))))
        ring_verts.append(ring)
    for i in range(rings - 1):
        for k in range(segments):
            a, b = ring_verts[i][k], ring_verts[i][(k + 1) % segments]
            c, d = ring_verts[i + 1][(k + 1) % segments], ring_verts[i + 1][k]
            bm.faces.new((a, d, c, b))
    front = bm.faces.new(list(reversed(ring_verts[0])))
    back = bm.faces.new(ring_verts[-1])
    bm.normal_update()
    parts = {p: [] for p in PARTS}

    def faces_at(ring_range, seg_list):
        out = []
        for i in ring_range:
            for k in seg_list:
                a, b = ring_verts[i][k % segments], ring_verts[i][(k + 1) % segments]
                c = ring_verts[i + 1][(k + 1) % segments]
                out.append(next(fc for fc in a.link_faces if b in fc.verts and c in fc.verts))
        return out

    def ring_of(frac):
        return int(np.clip(np.searchsorted(s, frac), 0, rings - 2))

    q = segments // 4  # segment index of the top (angle pi/2)
    # Mouth: inset the snout cap, push it into the head: a cavity with thin lips.
    snout_len = 0.03 if form != "cetacean" else 0.06
    ret = bmesh.ops.inset_region(bm, faces=[front], thickness=0.35 * min(w[0], h[0]), depth=0.0)
    mouth = [front]
    lip = {v for fc in ret["faces"] for v in fc.verts}
    if form == "cetacean":
        # A beak: push the whole snout out first.
        pass
    cavity = _extrude(
        bm,
        mouth,
        [
            _tip_move((-1, 0, 0), 0.025, 1.0, 2, taper=0.9),
            _tip_move((-1, 0, 0), 0.025, 1.0, 2, taper=0.8),
        ],
    )
    parts["mouth"] = list(lip) + cavity + [v for ring in ring_verts[:1] for v in ring]
    del snout_len

    fins = f["fins"]
    if "D" in fins:
        start, end = (0.4, 0.56) if form != "eel" else (0.35, 0.9)
        top = faces_at(range(ring_of(start), ring_of(end)), [q - 1, q])
        height = {"deep": 0.1, "flat": 0.05, "eel": 0.03}.get(form, 0.1)
        parts["fin_dorsal"] = _extrude(
            bm, top, [_tip_move((0, 0, 1), height / 3, 0.35, 1, taper=0.85, sweep=(-0.3, 0, 0))] * 3
        )
    if "A" in fins:
        start, end = (0.6, 0.7) if form != "eel" else (0.5, 0.9)
        bottom = faces_at(range(ring_of(start), ring_of(end)), [3 * q - 1, 3 * q])
        height = 0.06 if form != "eel" else 0.025
        parts["fin_anal"] = _extrude(
            bm,
            bottom,
            [_tip_move((0, 0, -1), height / 3, 0.35, 1, taper=0.85, sweep=(-0.3, 0, 0))] * 3,
        )
    if "P" in fins:
        at = {"eel": 0.12, "cetacean": 0.24}.get(form, 0.28)
        length = {"eel": 0.04, "cetacean": 0.13, "shark": 0.16, "flat": 0.12}.get(form, 0.1)
        droop = {"cetacean": -0.5, "shark": -0.35}.get(form, -0.15)
        for side, k in ((1, 15 * segments // 16), (-1, 7 * segments // 16)):
            patch = faces_at(range(ring_of(at), ring_of(at) + 2), [k])
            parts["fin_pectoral"] += _extrude(
                bm,
                patch,
                [_tip_move((0, side, droop), length / 3, 0.35, 2, taper=0.8, sweep=(-0.35, 0, 0))]
                * 3,
            )
    if "V" in fins:
        at = 0.45
        for side, k in ((1, 13 * segments // 16), (-1, 10 * segments // 16)):
            patch = faces_at(range(ring_of(at), ring_of(at) + 1), [k])
            parts["fin_pelvic"] += _extrude(
                bm,
                patch,
                [_tip_move((0, 0.4 * side, -1), 0.02, 0.35, 1, taper=0.8, sweep=(-0.5, 0, 0))] * 3,
            )
    if f["tail"] in ("caudal", "fluke"):
        # Peduncle cap → a blade behind the body, spread tall (caudal fin: z) or wide
        # (cetacean fluke: y) over its last extrusions.
        fluke = f["tail"] == "fluke"
        mode = 2 if fluke else 1
        parts["fin_caudal"] = _extrude(
            bm,
            [back],
            [
                _tip_move((-1, 0, 0), 0.02, 1.0, mode, taper=1.0),
                _tip_move((-1, 0, 0), 0.04, 0.5, mode, taper=1.0),
                _tip_move((-1, 0, 0), 0.04, 0.6, mode, taper=1.0),
            ],
        )
        spread, thin = (1, 2) if fluke else (2, 1)
        for v in parts["fin_caudal"]:
            depth = max(0.0, (0.5 - s[-1]) - v.co.x)
            v.co[spread] *= 1.0 + 60.0 * depth
            v.co[thin] *= max(0.3, 1.0 - 8.0 * depth)

    mesh = bpy.data.meshes.new(name or f"{form}_smooth")
    bm.to_mesh(mesh)
    index_of = {v: v.index for v in bm.verts}
    bm.verts.index_update()
    obj = bpy.data.objects.new(name or f"{form}_smooth", mesh)
    bpy.context.scene.collection.objects.link(obj)
    for part, verts in parts.items():
        if verts:
            group = obj.vertex_groups.new(name=f"truth_{part}")
            group.add(sorted({v.index for v in verts}), 1.0, "REPLACE")
    del index_of
    bm.free()
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
    if subdivisions:
        modifier = obj.modifiers.new("Subdivision", "SUBSURF")
        modifier.levels = subdivisions
        modifier.render_levels = subdivisions
        depsgraph = bpy.context.evaluated_depsgraph_get()
        evaluated = obj.evaluated_get(depsgraph)
        smooth = bpy.data.meshes.new_from_object(
            evaluated, preserve_all_data_layers=True, depsgraph=depsgraph
        )
        obj.modifiers.remove(modifier)
        old = obj.data
        obj.data = smooth
        bpy.data.meshes.remove(old)
        smooth.name = name or f"{form}_smooth"
    mesh = obj.data
    mesh.update()
    return obj


def truth_masks(obj):
    """{part: bool mask} of the vertices the builder made for each part (weight > 0.5)."""
    count = len(obj.data.vertices)
    masks = {}
    for group in obj.vertex_groups:
        if not group.name.startswith("truth_"):
            continue
        weight = np.zeros(count)
        for v in obj.data.vertices:
            for g in v.groups:
                if g.group == group.index:
                    weight[v.index] = g.weight
        masks[group.name[len("truth_") :]] = weight > 0.5
    return masks
