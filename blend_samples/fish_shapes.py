"""Procedural fish meshes for the fish swim demo, tests and benchmark.

A body is a loft of super-ellipse cross-sections along the head axis (snout at
+X by default); fins are thin plates whose base row sits exactly on body
vertices, each fin in its own vertex group ("fin_dorsal", "fin_pectoral", ...).
Body length is 1 object unit before `scale`.
"""

import math

import bpy
import numpy as np

# profile(s): half-width, half-height at body fraction s (0 snout, 1 tail tip), superellipse power,
# fins: kind -> plate description.
SPECS = {
    "tuna": {
        "width": 0.085,
        "height": 0.11,
        "peak": 0.38,
        "peduncle": 0.012,
        "power": 2.0,
        "bulge": 0.55,
        "fins": {
            "dorsal": {"start": 0.42, "end": 0.55, "height": 0.09, "sweep": 0.08},
            "anal": {"start": 0.58, "end": 0.68, "height": 0.07, "sweep": 0.06},
            "pectoral": {"at": 0.3, "span": 0.06, "length": 0.14, "droop": 0.3, "sweep": 0.8},
            "caudal": {"height": 0.30, "length": 0.16, "fork": 0.7},
        },
    },
    "eel": {
        "width": 0.03,
        "height": 0.035,
        "peak": 0.25,
        "peduncle": 0.01,
        "power": 2.0,
        "bulge": 0.9,
        "fins": {
            "dorsal": {"start": 0.35, "end": 0.97, "height": 0.03, "sweep": 0.0},
            "anal": {"start": 0.5, "end": 0.97, "height": 0.025, "sweep": 0.0},
            "pectoral": {"at": 0.13, "span": 0.02, "length": 0.035, "droop": 0.0, "sweep": 0.6},
        },
    },
    "boxfish": {
        "width": 0.14,
        "height": 0.16,
        "peak": 0.45,
        "peduncle": 0.03,
        "power": 5.0,
        "bulge": 0.3,
        "tail_start": 0.8,
        "fins": {
            "pectoral": {"at": 0.33, "span": 0.06, "length": 0.09, "droop": 0.1, "sweep": 0.7},
            "caudal": {"height": 0.22, "length": 0.2, "fork": 0.0},
            "dorsal": {"start": 0.66, "end": 0.74, "height": 0.06, "sweep": 0.05},
            "anal": {"start": 0.66, "end": 0.74, "height": 0.05, "sweep": 0.05},
        },
    },
    "filefish": {
        "width": 0.04,
        "height": 0.22,
        "peak": 0.42,
        "peduncle": 0.02,
        "power": 2.0,
        "bulge": 0.45,
        "fins": {
            "dorsal": {"start": 0.5, "end": 0.82, "height": 0.08, "sweep": 0.02},
            "anal": {"start": 0.5, "end": 0.82, "height": 0.08, "sweep": 0.02},
            "pectoral": {"at": 0.36, "span": 0.05, "length": 0.06, "droop": 0.0, "sweep": 0.6},
            "caudal": {"height": 0.16, "length": 0.12, "fork": 0.0},
        },
    },
    "pufferfish": {
        "width": 0.22,
        "height": 0.2,
        "peak": 0.45,
        "peduncle": 0.03,
        "power": 2.0,
        "bulge": 0.35,
        "fins": {
            "pectoral": {"at": 0.4, "span": 0.1, "length": 0.14, "droop": 0.0, "sweep": 0.5},
            "dorsal": {"start": 0.72, "end": 0.8, "height": 0.06, "sweep": 0.04},
            "anal": {"start": 0.72, "end": 0.8, "height": 0.05, "sweep": 0.04},
            "caudal": {"height": 0.16, "length": 0.12, "fork": 0.0},
        },
    },
    "dolphin": {
        "width": 0.08,
        "height": 0.09,
        "peak": 0.35,
        "peduncle": 0.018,
        "power": 2.0,
        "bulge": 0.6,
        "fins": {
            "dorsal": {"start": 0.42, "end": 0.56, "height": 0.1, "sweep": 0.12},
            "pectoral": {"at": 0.24, "span": 0.05, "length": 0.13, "droop": 0.6, "sweep": 0.8},
            "fluke": {"width": 0.32, "length": 0.12, "fork": 0.5},
        },
    },
}

AXES = {
    "POS_X": (0, 1, 2, 1),
    "NEG_X": (0, 1, 2, -1),
    "POS_Y": (1, 0, 2, 1),
    "NEG_Y": (1, 0, 2, -1),
}


def _profile(spec, s):
    """Half-width and half-height of the body at fractions s."""
    peak, bulge = spec["peak"], spec["bulge"]
    tail_start = spec.get("tail_start", 0.0)
    # Round snout, widest at `peak`, narrowing to the peduncle at the tail.
    front = np.sqrt(np.clip(s / peak, 0, 1))
    back = np.clip((1 - s) / (1 - peak), 0, 1) ** (1.0 / max(bulge, 1e-3) * 0.6)
    if tail_start:
        # A box: full size from the peak to tail_start, then a short taper to the peduncle.
        back = np.where(s < tail_start, 1.0, np.clip((1 - s) / (1 - tail_start), 0, 1) ** 0.5)
    shape = np.where(s < peak, front, back)
    scale = np.clip(shape, 0, 1)
    w = spec["peduncle"] + (spec["width"] - spec["peduncle"]) * scale
    h = spec["peduncle"] + (spec["height"] - spec["peduncle"]) * scale
    return w, h


def _ring_angles(segments):
    return np.linspace(0.0, 2 * math.pi, segments, endpoint=False)


def _superellipse(angle, w, h, power):
    c, s = np.cos(angle), np.sin(angle)
    return w * np.sign(c) * np.abs(c) ** (2.0 / power), h * np.sign(s) * np.abs(s) ** (2.0 / power)


def build_arrays(kind, rings=48, segments=24, fin_rows=5, midline_sag=0.0):
    """(vertices float64 (V, 3), faces list, {fin name: vertex indices}, body vertex count) with snout at +X."""
    spec = SPECS[kind]
    s = np.linspace(0.02, 1.0, rings)
    w, h = _profile(spec, s)
    angles = _ring_angles(segments)
    x = 0.5 - s  # snout at +0.5, tail tip at -0.5
    sag = midline_sag * np.sin(math.pi * s)  # a curved mid-line (belly down in the middle)
    ring_y, ring_z = _superellipse(angles[None, :], w[:, None], h[:, None], spec["power"])
    body = np.stack(
        [np.repeat(x[:, None], segments, 1), ring_y, ring_z - sag[:, None]], axis=-1
    ).reshape(-1, 3)
    verts = [
        body,
        np.array([[0.5 + 0.02, 0.0, -sag[0]]]),
        np.array([[x[-1] - 0.002, 0.0, -sag[-1]]]),
    ]
    snout, tail = len(body), len(body) + 1
    faces = []
    for r in range(rings - 1):
        for k in range(segments):
            a, b = r * segments + k, r * segments + (k + 1) % segments
            faces.append((a, a + segments, b + segments, b))  # outward normals
    for k in range(segments):
        faces.append((snout, k, (k + 1) % segments))
        last = (rings - 1) * segments
        faces.append((tail, last + (k + 1) % segments, last + k))
    count = snout + 2
    groups = {}

    def ring_vertex(ring, angle):
        k = round(angle / (2 * math.pi) * segments) % segments
        return ring * segments + k

    def add_plate(name, base_idx, outward):
        """Plate rows: row 0 = the given body vertices; row j = base + outward[j](base index)."""
        nonlocal count
        base = body[base_idx]
        cols = len(base_idx)
        rows = [base]
        for j in range(1, fin_rows + 1):
            rows.append(base + outward(j / fin_rows, np.arange(cols)))
        grid = np.stack(rows[1:])  # (fin_rows, cols, 3)
        start = count
        verts.append(grid.reshape(-1, 3))
        count += grid.shape[0] * grid.shape[1]
        index = np.full((fin_rows + 1, cols), -1, dtype=np.int64)
        # The fin's root row: its own vertices, coincident with the body's (not welded).
        root_start = count
        verts.append(base.copy())
        count += cols
        index[0] = np.arange(root_start, root_start + cols)
        index[1:] = np.arange(start, start + grid.shape[0] * cols).reshape(fin_rows, cols)
        for j in range(fin_rows):
            for c in range(cols - 1):
                faces.append((index[j, c], index[j, c + 1], index[j + 1, c + 1], index[j + 1, c]))
        groups.setdefault(name, []).extend(index.reshape(-1).tolist())

    ring_of = lambda frac: int(np.clip(np.searchsorted(s, frac), 0, rings - 1))
    for fin_name, fin in spec["fins"].items():
        if fin_name in ("dorsal", "anal"):
            r0, r1 = ring_of(fin["start"]), ring_of(fin["end"])
            rr = np.arange(r0, r1 + 1)
            angle = math.pi / 2 if fin_name == "dorsal" else 3 * math.pi / 2
            base_idx = np.array([ring_vertex(r, angle) for r in rr])
            sign = 1.0 if fin_name == "dorsal" else -1.0
            n = len(rr)
            profile = np.sin(np.linspace(0.15, math.pi - 0.15, n)) ** 0.7
            height, sweep = fin["height"], fin["sweep"]

            def outward(t, c, profile=profile, height=height, sweep=sweep, sign=sign):
                lift = height * t * profile[c]
                return np.stack(
                    [
                        -sweep * t * profile[c] * np.ones_like(lift),
                        np.zeros_like(lift),
                        sign * lift,
                    ],
                    axis=-1,
                )

            add_plate(f"fin_{fin_name}", base_idx, outward)
        elif fin_name == "pectoral":
            for side in (1.0, -1.0):
                r0, r1 = ring_of(fin["at"]), ring_of(fin["at"] + fin["span"])
                rr = np.arange(r0, max(r1, r0 + 2) + 1)
                angle = -0.35 if side > 0 else math.pi + 0.35
                base_idx = np.array([ring_vertex(r, angle % (2 * math.pi)) for r in rr])
                n = len(rr)
                taper = np.linspace(1.0, 0.55, n)
                length, droop, sweep = fin["length"], fin["droop"], fin["sweep"]

                def outward(t, c, side=side, taper=taper, length=length, droop=droop, sweep=sweep):
                    reach = length * t * taper[c]
                    return np.stack([-sweep * reach, side * reach, -droop * reach], axis=-1)

                add_plate("fin_pectoral", base_idx, outward)
        elif fin_name == "caudal":
            last = rings - 1
            top, bottom = ring_vertex(last, math.pi / 2), ring_vertex(last, 3 * math.pi / 2)
            base = np.linspace(body[bottom], body[top], 7)
            body_extra = len(body)
            # The base column between the last ring's bottom and top vertices.
            height, length, fork = fin["height"], fin["length"], fin["fork"]
            cols = len(base)
            v = np.linspace(-1, 1, cols)
            rows = [base]
            for j in range(1, fin_rows + 1):
                t = j / fin_rows
                spread = 1.0 + (height / max(2 * abs(base[-1, 2] - base[0, 2]) / 2, 1e-3) - 1.0) * t
                z_mid = 0.5 * (base[0, 2] + base[-1, 2])
                z = z_mid + (base[:, 2] - z_mid) * spread
                back = length * t * (1.0 - fork * (1 - np.abs(v)) * t)
                rows.append(np.stack([base[:, 0] - back, np.zeros(cols), z], axis=-1))
            grid = np.stack(rows)
            start = count
            verts.append(grid.reshape(-1, 3))
            count += grid.size // 3
            index = np.arange(start, start + grid.size // 3).reshape(fin_rows + 1, cols)
            for j in range(fin_rows):
                for c in range(cols - 1):
                    faces.append(
                        (index[j, c], index[j, c + 1], index[j + 1, c + 1], index[j + 1, c])
                    )
            groups["fin_caudal"] = index.reshape(-1).tolist()
            del body_extra
        elif fin_name == "fluke":
            last = rings - 1
            left, right = ring_vertex(last, 0.0), ring_vertex(last, math.pi)
            base = np.linspace(body[right], body[left], 7)
            cols = len(base)
            v = np.linspace(-1, 1, cols)
            rows = [base]
            width, length, fork = fin["width"], fin["length"], fin["fork"]
            for j in range(1, fin_rows + 1):
                t = j / fin_rows
                y = base[:, 1] + v * (width / 2) * t
                back = length * t * (1.0 - fork * (1 - np.abs(v)) * t)
                rows.append(np.stack([base[:, 0] - back, y, base[:, 2]], axis=-1))
            grid = np.stack(rows)
            start = count
            verts.append(grid.reshape(-1, 3))
            count += grid.size // 3
            index = np.arange(start, start + grid.size // 3).reshape(fin_rows + 1, cols)
            for j in range(fin_rows):
                for c in range(cols - 1):
                    faces.append(
                        (index[j, c], index[j, c + 1], index[j + 1, c + 1], index[j + 1, c])
                    )
            groups["fin_caudal"] = index.reshape(-1).tolist()
    return np.concatenate(verts), faces, groups, len(body)


def body_face_count(rings=48, segments=24):
    return (rings - 1) * segments + 2 * segments


def build_fish(
    kind,
    name=None,
    head_axis="POS_X",
    scale=1.0,
    location=(0.0, 0.0, 0.0),
    rings=48,
    segments=24,
    fin_rows=5,
    midline_sag=0.0,
    collection=None,
    materials=None,
):
    """A mesh object for `kind` with one vertex group per fin; returns the object."""
    verts, faces, groups, _ = build_arrays(kind, rings, segments, fin_rows, midline_sag)
    a, b, c, sign = AXES[head_axis]
    placed = np.zeros_like(verts)
    placed[:, a] = sign * verts[:, 0]
    placed[:, b] = sign * verts[:, 1]
    placed[:, c] = verts[:, 2]
    placed *= scale
    mesh = bpy.data.meshes.new(name or kind)
    mesh.from_pydata(placed.tolist(), [], [tuple(int(i) for i in f) for f in faces])
    if materials:
        for material in materials:
            mesh.materials.append(material)
        index = np.zeros(len(mesh.polygons), dtype=np.int32)
        index[body_face_count(rings, segments) :] = len(materials) - 1  # fins use the last material
        mesh.polygons.foreach_set("material_index", index)
        mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
    mesh.update()
    obj = bpy.data.objects.new(name or kind, mesh)
    obj.location = location
    (collection or bpy.context.scene.collection).objects.link(obj)
    for group_name, indices in groups.items():
        group = obj.vertex_groups.new(name=group_name)
        group.add(sorted({int(i) for i in indices}), 1.0, "REPLACE")
    return obj


def fin_root_pairs(kind, rings=48, segments=24, fin_rows=5):
    """(fin root vertex, coincident body vertex) index pairs of the plate fins (dorsal, anal, pectoral)."""
    verts, _, groups, body_count = build_arrays(kind, rings, segments, fin_rows)
    body = verts[:body_count]
    pairs = []
    for name in ("fin_dorsal", "fin_anal", "fin_pectoral"):
        for i in groups.get(name, []):
            d = np.linalg.norm(body - verts[i], axis=1)
            j = int(np.argmin(d))
            if d[j] == 0.0:
                pairs.append((int(i), j))
    return pairs
