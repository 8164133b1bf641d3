"""Automatic fin finder: the parts of the mesh standing out of the body's cross-section.

The work is the core's (kodawari_native.swim_fin_axis_coordinates, swim_find_fins;
docs/algorithms.md §2.8): each vertex is placed in the body's
cross-section along the swim axis, each cross-section's outline gets a core
ellipse fitted with the fins left out, and vertices well outside it that hang
together along mesh edges are fins, named by where they sit. No per-vertex
Python and no ray casts: a 2 M-vertex mesh takes seconds. FinSearch runs in
steps so the operator can show progress and cancel with Esc; nothing in the
file changes until the caller writes the result.
"""

import numpy as np

from .. import native

KINDS = {1: "CAUDAL", 2: "DORSAL", 3: "ANAL", 4: "PELVIC", 5: "PECTORAL"}
ORDER = ("CAUDAL", "DORSAL", "ANAL", "PELVIC", "PECTORAL")
AXIS_SAMPLES = 64  # the axis polyline the vertices are placed against
CHUNK = 1 << 18  # vertices per step (progress granularity)
MIN_FIN_FRACTION = 1.0 / 2000  # a fin has at least this share of the mesh (and 8 vertices)


def mesh_edges(mesh):
    edges = np.empty((len(mesh.edges), 2), dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges.reshape(-1))
    return edges


class FinSearch:
    """One fin search over an object's rest mesh, in steps: step() until done, then found()."""

    def __init__(self, obj, rig):
        self.kn = native.module()
        self.vertices = np.ascontiguousarray(rig.rest, dtype=np.float32)
        self.edges = mesh_edges(obj.data)
        t = np.linspace(0.0, 1.0, AXIS_SAMPLES)
        self.axis = np.ascontiguousarray(self.kn.curve_points(rig.axis_rest, t))
        self.up = np.asarray(rig.up, dtype=np.float64)
        self.coordinates = np.empty_like(self.vertices)
        self.next_vertex = 0
        self.kinds = None
        self.steps_done = 0

    @property
    def steps(self):
        return (len(self.vertices) + CHUNK - 1) // CHUNK + 1

    @property
    def done(self):
        return self.kinds is not None

    def step(self):
        """Place one chunk of vertices; the last step classifies them all."""
        count = len(self.vertices)
        self.steps_done += 1
        if self.next_vertex < count:
            end = min(count, self.next_vertex + CHUNK)
            self.kn.swim_fin_axis_coordinates(
                self.axis, self.up, self.vertices, self.coordinates, self.next_vertex, end
            )
            self.next_vertex = end
            return
        self.kinds = self.kn.swim_find_fins(
            self.coordinates,
            self.edges,
            min_vertices=max(8, int(count * MIN_FIN_FRACTION)),
        )

    def found(self):
        """[(group name, kind, vertex indices)] of the fins found."""
        out = []
        for kind in ORDER:
            code = next(k for k, v in KINDS.items() if v == kind)
            indices = np.flatnonzero(self.kinds == code)
            if len(indices):
                out.append((f"fin_{kind.lower()}", kind, indices))
        return out


def find_fins(obj, rig):
    """[(group name, kind, vertex indices)] found on the object's rest mesh, in one go."""
    search = FinSearch(obj, rig)
    while not search.done:
        search.step()
    return search.found()
