"""Find Fins on smooth, welded fish with a mouth (issue 10 items 1 and 8).

The fish are box-modelled the way artists make them (blend_samples/smooth_fish.py):
fins extruded out of the body's faces, a mouth cavity with thin lips, subdivided
(and the same fish low-poly, as game models come). The builder records which
vertices it made for each fin and for the mouth; the finder never sees that.
"""

import bpy
import numpy as np
import pytest
from fish_helpers import activate, smooth_fish

# form -> the fins the finder must find, each in the group of its kind.
EXPECTED = {
    "spindle": ("fin_dorsal", "fin_anal", "fin_pectoral", "fin_caudal"),
    "deep": ("fin_dorsal", "fin_pectoral", "fin_caudal"),
    "flat": ("fin_dorsal", "fin_anal", "fin_pectoral", "fin_caudal"),
    "eel": ("fin_dorsal", "fin_anal", "fin_pectoral"),
    "cetacean": ("fin_dorsal", "fin_pectoral", "fin_caudal"),  # caudal: the flukes
    "shark": ("fin_dorsal", "fin_anal", "fin_pectoral", "fin_caudal"),
}


def _group_masks(obj):
    count = len(obj.data.vertices)
    masks = {g.name: np.zeros(count, dtype=bool) for g in obj.vertex_groups}
    names = {g.index: g.name for g in obj.vertex_groups}
    for v in obj.data.vertices:
        for g in v.groups:
            masks[names[g.group]][v.index] = True
    return masks


def _find_fins(obj):
    """(truth masks, found group masks) after Add Fish Swim and Find Fins."""
    activate(obj)
    truth = smooth_fish.truth_masks(obj)
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    assert bpy.ops.kodawari.swim_add(head_axis="POS_X") == {"FINISHED"}
    assert bpy.ops.kodawari.swim_fin_find() == {"FINISHED"}
    return truth, _group_masks(obj)


def _snout(obj, fraction=0.1):
    co = np.empty(len(obj.data.vertices) * 3)
    obj.data.vertices.foreach_get("co", co)
    x = co.reshape(-1, 3)[:, 0]
    return x > x.max() - fraction * (x.max() - x.min())


@pytest.mark.parametrize(
    "form,subdivisions",
    [(form, 2) for form in sorted(EXPECTED)] + [("shark", 0), ("cetacean", 0)],
)
def test_fin_groups_avoid_the_mouth_and_find_every_fin(empty_scene, form, subdivisions):
    obj = smooth_fish.build_smooth_fish(form, subdivisions=subdivisions)
    truth, found = _find_fins(obj)
    snout = truth["mouth"] | _snout(obj)
    any_fin = np.zeros_like(snout)
    for part, mask in truth.items():
        if part.startswith("fin_"):
            any_fin |= mask
    for name, mask in found.items():
        # No fin group holds the mouth or snout (< 2%), and every group is fin.
        assert (mask & snout).sum() <= 0.02 * mask.sum(), (name, (mask & snout).sum(), mask.sum())
        assert (mask & any_fin).sum() >= 0.9 * mask.sum(), (
            name,
            (mask & any_fin).sum(),
            mask.sum(),
        )
    for part in EXPECTED[form]:
        # Each fin is found, in the group of its kind (flukes: caudal; shark pectorals: pectoral).
        assert part in found, (part, sorted(found))
        recall = (found[part] & truth[part]).sum() / truth[part].sum()
        assert recall > 0.4, (part, recall)
    kinds = {f.kind for f in obj.kodawari_swim.fins}
    assert kinds >= {name[len("fin_") :].upper() for name in EXPECTED[form]}, kinds
