"""The bound swim rig of one object: everything read once, evaluated per frame.

Per frame: body control axis from the accumulated phase (native), one FFD deform
into a preallocated array (native, GIL released), each fin's axis motion and
deform on its own vertices, carried by the body's rotation at the fin root.
"""

import hashlib

import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import bulk, native
from . import fins as fin_setup
from . import midline, route

SHAPE_KEY = "Kodawari Swim"  # the swim's shape key before the node route (kept for old files)
TABLE_SEGMENTS = 1024  # the core's frame table (native/include/kodawari/ffd/frame_table.hpp)
# How close an affine row must give a bound coordinate to be computed from the rest position
# instead of stored (docs/algorithms.md §1.6), in body lengths: a tenth of the route's exactness
# bound (1e-5, tests/blender/test_fish_route.py), the rest left to the nodes' float rounding.
AFFINE_TOLERANCE = 1e-6
PROBE_SCALE = (
    0.02  # probe arm length (fraction of body length) for the body's rotation at a fin root
)


def rest_positions(obj):
    """The mesh's rest positions (the reference shape key when the mesh has shape keys)."""
    mesh = obj.data
    keys = mesh.shape_keys
    if keys is not None and keys.reference_key is not None:
        return bulk.shape_key_positions(keys.reference_key)
    return bulk.vertex_positions(mesh)


ROWING_KINDS = fin_setup.ROWING_KINDS


def positions_digest(positions):
    """A digest of float32 (N, 3) rest positions: equal digests, same rest shape."""
    return hashlib.blake2b(np.ascontiguousarray(positions).data, digest_size=16).digest()


def rest_fingerprint(obj):
    """The digest of the rest shape as it is now (reads every rest position once: call it
    when the mesh may have changed, never per frame; reading a mesh's positions through
    Python makes Blender give the original mesh its own copy of them, 12 bytes per vertex)."""
    return positions_digest(rest_positions(obj))


def binding_signature(obj, settings):
    """What the binding depends on; a change means rebuild."""
    fins = tuple(
        (f.vertex_group, f.kind, f.motion, round(f.root_blend, 6), f.enabled) for f in settings.fins
    )
    return (len(obj.data.vertices), settings.head_axis, settings.control_points, fins)


class SwimRig:
    def __init__(self, obj, settings, known_weights=None):
        """known_weights: {vertex group: float32 (N,)} already in hand (Find Fins), read
        from the mesh otherwise."""
        kn = native.module()
        self.kn = kn
        self.signature = binding_signature(obj, settings)
        self.mesh_pointer = obj.data.as_pointer()
        # The rest shape and the deformed positions are not kept: the binding holds what a
        # frame needs, and a frame deforms straight into the shape key (runtime.evaluate).
        # Two (N, 3) copies less per fish (memory, issue 13); `rest` re-reads on request.
        self.owner = obj  # refreshed by runtime.get_rig/body_rig before every use
        self.positions = None  # allocated only for a caller without an `out`
        rest = rest_positions(obj)
        self.fingerprint = positions_digest(rest)
        self.count = len(rest)
        self.head, self.up, self.side = midline.body_frame(settings.head_axis)
        self.axis_rest, self.body_length = midline.midline_points(
            rest, settings.head_axis, settings.control_points
        )
        self.binding = kn.ffd_bind(self.axis_rest, rest, up=self.up)
        # Which of the bound (s, u, v) are n . P + c of the rest position, measured on every
        # vertex (docs/algorithms.md §1.6): the route computes those from Position.
        self.affine_rows, self.affine_holds, self.affine_worst = self.binding.affine_coordinates(
            rest, self.end_scale, AFFINE_TOLERANCE
        )
        self.axis = self.axis_rest.copy()
        self.parts = []
        known_weights = known_weights or {}
        weights = {
            f.vertex_group: known_weights[f.vertex_group]
            if f.vertex_group in known_weights
            else bulk.vertex_group_weights(obj, f.vertex_group)
            for f in settings.fins
            if f.enabled
        }
        in_fin = np.zeros(self.count, dtype=bool)
        for w in weights.values():
            in_fin |= w > 0
        reach = None
        if in_fin.any() and not in_fin.all():
            edges = np.empty((len(obj.data.edges), 2), dtype=np.int32)
            obj.data.edges.foreach_get("vertices", edges.reshape(-1))
            reach = fin_setup.fin_reach(rest, edges, in_fin, self.body_length, kn)
        self.parts = self._build_parts(settings, weights, rest, reach)
        # Swinging fins (FLAP, UP_DOWN) fade in over a reach squashed along their motion
        # (docs/algorithms.md §2.4): bound again with it, same roots and tips.
        squash = fin_setup.swing_squash(self.parts, settings.fins, self.count)
        if reach is not None and squash is not None:
            swing_reach = fin_setup.fin_reach(rest, edges, in_fin, self.body_length, kn, squash)
            self.parts = self._build_parts(settings, weights, rest, reach, swing_reach)
        # Four probe points per fin part (root and one step along its tangent, side, up):
        # deformed with the body they give the body's rotation at the root.
        arm = PROBE_SCALE * self.body_length
        probes = []
        for part in self.parts:
            probes += [
                part.root,
                part.root + arm * part.tangent,
                part.root + arm * part.side,
                part.root + arm * part.up,
            ]
        self.probe_arm = arm
        # The route (route.py) reads fin offsets per fin vertex: every part's vertices, once.
        self.fin_vertices = None
        if self.parts:
            self.fin_vertices = np.unique(np.concatenate([p.indices for p in self.parts]))
            for part in self.parts:
                part.slots = np.searchsorted(self.fin_vertices, part.indices)
            self.fin_offsets = np.zeros((len(self.fin_vertices), 3), dtype=np.float32)
        self.table = np.empty((8 * TABLE_SEGMENTS, 3), dtype=np.float32)
        if probes:
            self.probes_rest = np.ascontiguousarray(probes, dtype=np.float32)
            self.probe_binding = kn.ffd_bind(self.axis_rest, self.probes_rest, up=self.up)
            self.probes_out = np.empty_like(self.probes_rest)

    def _build_parts(self, settings, weights, rest, reach, swing_reach=None):
        parts = []
        for index, fin in enumerate(settings.fins):
            if fin.enabled:
                parts.extend(
                    fin_setup.build_parts(
                        index,
                        fin,
                        weights[fin.vertex_group],
                        rest,
                        self.axis_rest,
                        self.up,
                        self.kn,
                        reach,
                        swing_reach,
                    )
                )
        return parts

    @property
    def rest(self):
        """float32 (N, 3) rest positions, read from the mesh (set-up work only, e.g. a fin search)."""
        return rest_positions(self.owner)

    def bend_direction(self, settings):
        return self.up if settings.bend == "DORSOVENTRAL" else self.side

    def body_axis(self, settings, phase, rest_axis=None):
        return self.kn.swim_body_axis(
            self.axis_rest if rest_axis is None else rest_axis,
            self.bend_direction(settings),
            self.body_length,
            phase,
            wavelength=settings.wavelength,
            amplitude=settings.amplitude,
            amplitude_head=settings.amplitude_head,
            envelope_start=settings.envelope_start,
            envelope_power=settings.envelope_power,
            phase_offset=settings.phase_offset,
            preserve_length=settings.preserve_length,
        )

    @property
    def end_scale(self):
        """How w beyond the body's ends is packed into s (docs/algorithms.md §1.6): one
        table segment per 1/1024 of the body length, as along it."""
        return TABLE_SEGMENTS / max(float(self.body_length), 1e-12)

    def packed_coordinates(self):
        """float32 (N, 3): each vertex's (s, u, v), the route's bound attributes (read back
        from the mesh once the binding released its own copy; a coordinate the route computes
        from the rest position is computed the same way here)."""
        if not self.binding.released:
            return self.binding.packed_coordinates(self.end_scale)
        out = np.empty((self.count, 3), dtype=np.float32)
        column = np.empty(self.count, dtype=np.float32)
        mesh = self.owner.data
        computed = [not route.has_attribute(mesh, name) for name in route.COORDINATES]
        for k, name in enumerate(route.COORDINATES):
            if not computed[k]:
                mesh.attributes[name].data.foreach_get("value", column)
                out[:, k] = column
        if any(computed):
            if not all(h for h, c in zip(self.affine_holds, computed) if c):
                raise ValueError(
                    tip_("the swim's bound attributes are missing: add the Fish Swim again")
                )
            self.kn.ffd_fill_affine_coordinates(self.affine_rows, computed, self.rest, out)
        return out

    def release_coordinates(self):
        """The packed attribute holds the binding now: free the core's per-vertex copy (20
        bytes per vertex; issue 13 item 4). Bake and Apply read the attribute instead."""
        self.binding.release_coordinates()

    def rest_table(self):
        """The frame table of the rest axis (the route's rest shape, for shape-key offsets)."""
        table = np.empty_like(self.table)
        self.binding.frame_table(self.axis_rest, table)
        return table

    def frame(self, settings, phase, rest_axis=None):
        """What the route needs for one frame: the frame table (float32 (8 * 1024, 3)) and
        the fin vertices' offsets (float32 (M, 3), or None without fins), the same the
        core's deform and fin displacement give evaluate()."""
        self.axis = self.body_axis(settings, phase, rest_axis)
        self.binding.frame_table(self.axis, self.table)
        if not self.parts:
            return self.table, None
        self.fin_offsets[:] = 0.0
        for part in self._moving_parts(settings, phase):
            self.fin_offsets[part.slots] += part.out
        return self.table, self.fin_offsets

    def evaluate(self, settings, phase, rest_axis=None, out=None):
        """Deformed positions float32 (N, 3) for the phase (radians, accumulated), written into
        `out` (e.g. the shape key's memory) or the rig's own buffer; `rest_axis` replaces the
        straight rest axis (a spine bent along a path) before the wave."""
        if out is None:
            if self.positions is None:
                self.positions = np.empty((self.count, 3), dtype=np.float32)
            out = self.positions
        positions = out
        self.axis = self.body_axis(settings, phase, rest_axis)
        if self.binding.released:
            # What the modifier computes, in the core (docs/algorithms.md §1.6).
            self.binding.frame_table(self.axis, self.table)
            self.kn.ffd_deform_packed(
                self.table, self.packed_coordinates(), self.end_scale, positions
            )
        else:
            self.binding.deform(self.axis, positions)
        if not self.parts:
            return positions
        for part in self._moving_parts(settings, phase):
            positions[part.indices] += part.out
        return positions

    def _moving_parts(self, settings, phase):
        """Each moving fin part, its displacement for the phase just written to part.out."""
        self.probe_binding.deform(self.axis, self.probes_out)
        for k, part in enumerate(self.parts):
            fin = settings.fins[part.fin_index]
            if fin.amplitude == 0.0 and (fin.motion != "FLAP" or fin.feathering == 0.0):
                continue
            feathering = fin.feathering * part.feather_sign
            # Only paired fins row; a feathered dorsal, anal or caudal fin would yaw its
            # long base (docs/algorithms.md §2.4): held like a twist. A rowing blade turns
            # further, held only where its fade is short beside its width (a stubby fin).
            rowing = fin.kind in ROWING_KINDS
            limit = part.binding.max_feather if rowing else part.binding.max_roll
            feathering = max(-limit, min(limit, feathering))
            # The core swings each vertex about its own root, faded in from the body, and
            # turns the result with the body's rotation at the root (from the probes).
            part.binding.displace(
                fin.motion,
                fin.amplitude,
                phase * fin.frequency_ratio - fin.phase_lag,
                feathering,
                fin.wavelength,
                part.feather_on_power,
                self.probes_rest[4 * k : 4 * k + 4],
                self.probes_out[4 * k : 4 * k + 4],
                part.out,
            )
            yield part
