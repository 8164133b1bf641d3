"""Finding a quadruped's four legs and the bone that carries its root motion, by bone
names (every common naming convention) or from four selected foot bones. Set-up time
only: reads the armature's rest data, changes nothing (docs/algorithms.md §4.11)."""

import re

import numpy as np

from .props import LEG_NAMES

# Names are split into words at separators, case changes and digits:
# "mixamorig:LeftUpLeg" -> mixamorig, left, up, leg; "Bip01 L Thigh" -> bip, 01, l, thigh;
# "b_LeftUpperArm_09" -> b, left, upper, arm, 09; "f_toe.L" -> f, toe, l.
_WORDS = re.compile(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+")
_LEFT, _RIGHT = {"left", "l", "lft"}, {"right", "r", "rgt", "rt"}
# A word that says the bone is a fore limb wins over one that says "leg" ("front_thigh",
# "forefoot", "f_toe": Rigify's fore paws and hooves reuse the hind words).
_FORE = {
    "fore",
    "front",
    "f",
    "arm",
    "upperarm",
    "forearm",
    "lowerarm",
    "hand",
    "humerus",
    "radius",
    "ulna",
    "scapula",
    "wrist",
    "forefoot",
    "carpus",
    "carpal",
    "metacarpus",
    "elbow",
    "frontleg",
    "foreleg",
}
_HIND = {
    "hind",
    "back",
    "rear",
    "thigh",
    "shin",
    "calf",
    "leg",
    "upleg",
    "foot",
    "toe",
    "toes",
    "toebase",
    "hoof",
    "femur",
    "tibia",
    "fibula",
    "hock",
    "tarsus",
    "metatarsus",
    "ball",
    "knee",
    "ankle",
    "paw",
    "cannon",
    "pastern",
    "hindleg",
    "backleg",
    "hip",
}
# Bones that are never a leg's: digits of a hand, rig helpers, generated mechanism bones,
# the girdles (a clavicle or Rigify's pelvis.L runs from the spine to the hip sideways).
_NOT_LEG = {
    "finger",
    "thumb",
    "index",
    "middle",
    "ring",
    "pinky",
    "twist",
    "roll",
    "ik",
    "pole",
    "target",
    "mch",
    "org",
    "vis",
    "tweak",
    "ctrl",
    "nub",
    "end",
    "helper",
    "breast",
    "clavicle",
    "shoulder",
    "pelvis",
    "heel",
    "palm",
    "hips",
    "spine",
    "ear",
    "eye",
    "lid",
    "brow",
    "lip",
    "cheek",
    "nose",
    "tail",
}
_EXPLICIT = {
    "fore",
    "front",
    "hind",
    "back",
    "rear",
}  # these make any bone a leg bone ("fore_scapula")


def words(name):
    return [w.lower() for w in _WORDS.findall(name)]


def side_of(name):
    """ "L", "R" or None from the name: whole words left/right win, else the last lone l/r
    ("r_toe.L" is a left rear toe)."""
    w = words(re.sub(r"\.\d+$", "", name))
    if "left" in w or "lft" in w:
        return "L"
    if "right" in w or "rgt" in w:
        return "R"
    for word in reversed(w):
        if word in ("l", "r"):
            return word.upper()
    return None


def end_of(name):
    """ "F" (fore), "H" (hind) or None when the name does not name a leg bone."""
    w = set(words(name)) - {"l", "r", "left", "right"} | (
        {"f"} if re.match(r"f[._]", name.lower()) else set()
    )
    if not w & _EXPLICIT and w & _NOT_LEG:
        return None
    if w & _FORE:
        return "F"
    if w & _HIND or {"r"} & set(words(name)[:1]):
        return "H"
    return None


def _depth(bone, members):
    kids = [c for c in bone.children if c.name in members]
    return 1 + (max(_depth(c, members) for c in kids) if kids else 0)


def _chain_in(bones, members):
    """The longest parent-to-child run of bones among `members`."""
    best = []
    for bone in bones:
        if bone.name not in members or (bone.parent is not None and bone.parent.name in members):
            continue
        chain = [bone]
        while True:
            kids = [c for c in chain[-1].children if c.name in members]
            if not kids:
                break
            chain.append(max(kids, key=lambda c: _depth(c, members)))
        if len(chain) > len(best):
            best = chain
    return best


def find_legs_by_name(armature):
    """{leg: [bone names root..foot]} for the legs whose bone names say side and end."""
    groups = {}
    for bone in armature.bones:
        side, end = side_of(bone.name), end_of(bone.name)
        if side and end:
            groups.setdefault(side + end, set()).add(bone.name)
    legs = {}
    for leg in LEG_NAMES:
        chain = _chain_in(armature.bones, groups.get(leg[0] + leg[1], set()))
        if chain:
            legs[leg] = [b.name for b in chain]
    return legs


def _up_forward(armature, feet):
    """(up, forward) in armature space from four foot points (4, 3): up is armature +Z
    (the gait frame makes it the world's up), forward the feet's long horizontal axis,
    pointed at a bone named head/neck/skull if there is one, else at -Y (Blender's front)."""
    up = np.array([0.0, 0.0, 1.0])
    flat = feet - feet.mean(axis=0)
    flat[:, 2] = 0
    _, _, vt = np.linalg.svd(flat)
    axis = vt[0] * np.array([1.0, 1.0, 0.0])
    axis /= max(np.linalg.norm(axis), 1e-12)
    heads = [b for b in armature.bones if {"head", "neck", "skull"} & set(words(b.name))]
    if heads:
        toward = np.array(heads[0].head_local) - feet.mean(axis=0)
    else:
        toward = np.array([0.0, -1.0, 0.0])
    return up, axis if axis @ toward >= 0 else -axis


def find_legs_from_feet(armature, foot_names):
    """Four selected foot bones -> {leg: chain}. Each chain climbs from its foot while the
    parent is not an ancestor of another selected foot (that is the spine or pelvis where
    the legs branch off), drops leading girdle bones that start on the body's mid-plane,
    and keeps at most the lowest 6 bones. Fore and hind, left and right come from where
    the feet stand: fore along the body's forward axis; in each pair the foot on the left
    of the mid-plane (the armature's forward frame) is the left leg."""
    feet = [armature.bones[n] for n in foot_names]
    ancestors = [{p.name for p in f.parent_recursive} for f in feet]
    tips = np.array([f.tail_local for f in feet], dtype=np.float64)
    up, forward = _up_forward(armature, tips)
    lateral = np.cross(up, forward)  # the animal's left
    centre = tips.mean(axis=0)
    chains = []
    for i, foot in enumerate(feet):
        others = set().union(*(a for j, a in enumerate(ancestors) if j != i))
        chain = [foot]
        while chain[-1].parent is not None and chain[-1].parent.name not in others:
            chain.append(chain[-1].parent)
        chain.reverse()
        side = abs(float((tips[i] - centre) @ lateral))
        while (
            len(chain) > 2
            and abs(float((np.array(chain[0].head_local) - centre) @ lateral)) < 0.3 * side
        ):
            chain.pop(0)  # a girdle bone from the mid-plane (Rigify's pelvis.L)
        chains.append(chain[-6:])
    along = tips @ forward
    order = np.argsort(-along)  # fore feet first
    legs = {}
    for end, pair in (("F", order[:2]), ("H", order[2:])):
        a, b = pair
        left, right = (a, b) if (tips[a] - tips[b]) @ lateral > 0 else (b, a)
        legs["L" + end] = [bone.name for bone in chains[left]]
        legs["R" + end] = [bone.name for bone in chains[right]]
    return legs


def with_shoulders(armature, legs):
    """Each fore leg takes in its shoulder blade where the rig has one (docs/algorithms.md
    §4.11): the bone its chain hangs from, when no other leg hangs from it (the spine and
    chest are shared) and the leg's root lies below its head (a scapula or clavicle runs
    down to the shoulder joint; a bone running sideways or up is not one), while the
    chain stays within 6 bones. A small animal's fore leg swings through a wide angle in
    a few frames; its shoulder blade carries part of that turn and keeps the leg below it
    off full stretch, as a quadruped's mobile scapula does. Returns a new dict."""
    out = dict(legs)
    roots = {k: armature.bones[chain[0]] for k, chain in legs.items()}
    for k in ("LF", "RF"):
        if k not in legs or len(legs[k]) >= 6:
            continue
        root = roots[k]
        blade = root.parent
        if blade is None:
            continue
        shared = any(
            other is blade or blade in other.parent_recursive
            for j, other in roots.items()
            if j != k
        )
        head, joint = np.array(blade.head_local), np.array(root.head_local)
        drop = float(head[2] - joint[2])
        if shared or drop <= 0.25 * float(np.linalg.norm(joint - head)):
            continue
        out[k] = [blade.name] + legs[k]
    return out


def find_body(armature, legs):
    """The bone that carries root motion: the deepest common parent of every leg root,
    climbed up past connected bones (Blender ignores location keys on a connected bone)
    to the first one whose location Blender applies. None when the legs share no parent."""
    roots = [armature.bones[chain[0]] for chain in legs.values()]
    if not roots:
        return None
    common = None
    for root in roots:
        ancestors = [p.name for p in root.parent_recursive]
        common = ancestors if common is None else [a for a in common if a in ancestors]
    if not common:
        return None
    bone = armature.bones[common[0]]
    while bone.use_connect and bone.parent is not None:
        bone = bone.parent
    return bone.name
