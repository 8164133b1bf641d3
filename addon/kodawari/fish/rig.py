"""The bound swim rig of one object: everything read once, evaluated per frame.

Per frame: body control axis from the accumulated phase (native), one FFD deform
into a preallocated array (native, GIL released), each fin's axis motion and
deform on its own vertices, carried by the body's rotation at the fin root.
"""

import numpy as np

from .. import bulk, native
from . import fins as fin_setup
from . import midline

SHAPE_KEY = "Kodawari Swim"
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


def binding_signature(obj, settings):
    """What the binding depends on; a change means rebuild."""
    fins = tuple(
        (f.vertex_group, f.kind, f.motion, round(f.root_blend, 6), f.enabled) for f in settings.fins
    )
    return (len(obj.data.vertices), settings.head_axis, settings.control_points, fins)


class SwimRig:
    def __init__(self, obj, settings):
        kn = native.module()
        self.kn = kn
        self.signature = binding_signature(obj, settings)
        self.mesh_pointer = obj.data.as_pointer()
        self.rest = rest_positions(obj)
        self.count = len(self.rest)
        self.head, self.up, self.side = midline.body_frame(settings.head_axis)
        self.axis_rest, self.body_length = midline.midline_points(
            self.rest, settings.head_axis, settings.control_points
        )
        self.binding = kn.ffd_bind(self.axis_rest, self.rest, up=self.up)
        self.positions = np.empty_like(self.rest)
        self.axis = self.axis_rest.copy()
        self.parts = []
        weights = {
            f.vertex_group: bulk.vertex_group_weights(obj, f.vertex_group)
            for f in settings.fins
            if f.enabled
        }
        in_fin = np.zeros(self.count, dtype=bool)
        for w in weights.values():
            in_fin |= w > 0
        body_points = self.rest[~in_fin].astype(np.float64)
        for index, fin in enumerate(settings.fins):
            if fin.enabled:
                self.parts.extend(
                    fin_setup.build_parts(
                        index,
                        fin,
                        weights[fin.vertex_group],
                        self.rest,
                        self.axis_rest,
                        self.up,
                        kn,
                        body_points,
                    )
                )
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
        if probes:
            self.probes_rest = np.ascontiguousarray(probes, dtype=np.float32)
            self.probe_binding = kn.ffd_bind(self.axis_rest, self.probes_rest, up=self.up)
            self.probes_out = np.empty_like(self.probes_rest)

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

    def _root_rotations(self):
        """Rotation (3, 3) of the body at each fin part's root, rest → now."""
        p = self.probes_out.astype(np.float64).reshape(-1, 4, 3)
        rest = self.probes_rest.astype(np.float64).reshape(-1, 4, 3)
        rotations = []
        for k in range(len(p)):
            moved = (p[k, 1:] - p[k, 0]).T  # columns: tangent, side, up after the bend
            before = (rest[k, 1:] - rest[k, 0]).T
            # Nearest rotation to moved · before⁻¹ (polar decomposition by SVD).
            u, _, vt = np.linalg.svd(moved @ np.linalg.inv(before))
            r = u @ vt
            if np.linalg.det(r) < 0:
                u[:, -1] *= -1
                r = u @ vt
            rotations.append(r)
        return rotations

    def evaluate(self, settings, phase, rest_axis=None):
        """Deformed positions float32 (N, 3) for the phase (radians, accumulated); `rest_axis`
        replaces the straight rest axis (a spine bent along a path) before the wave."""
        kn = self.kn
        self.axis = self.body_axis(settings, phase, rest_axis)
        self.binding.deform(self.axis, self.positions)
        if not self.parts:
            return self.positions
        self.probe_binding.deform(self.axis, self.probes_out)
        rotations = self._root_rotations()
        for part, rotation in zip(self.parts, rotations):
            fin = settings.fins[part.fin_index]
            if fin.amplitude == 0.0:
                continue
            fin_phase = phase * fin.frequency_ratio - fin.phase_lag
            points, twist = kn.swim_fin_axis(
                part.axis,
                part.tangent,
                part.side,
                part.up,
                fin.motion,
                fin.amplitude * part.amplitude_scale,
                fin_phase,
                feathering=fin.feathering * part.feather_sign,
                wavelength=fin.wavelength,
                fixed_count=3,
                feather_on_power=part.feather_on_power,
            )
            part.binding.deform(points, part.out, twist=twist)
            # The fin's own motion (rest space), turned with the body at its root and
            # faded in from the root: root vertices keep the body's position exactly.
            np.subtract(part.out, part.rest, out=part.shift)
            np.matmul(part.shift, rotation.T.astype(np.float32), out=part.out)
            part.out *= part.weights
            self.positions[part.indices] += part.out
        return self.positions
