"""Live evaluation: writes each swimming object's frame (the control axis's frame table
and the fin offsets) into its Fish Swim modifier's helpers, and Blender bends the mesh
in its own evaluation (route.py, docs/algorithms.md §1.6). handlers.py calls it on frame
changes and file loads; a load drops the runtime state so it is rebuilt from the saved
settings. positions() gives the same shape as float32 positions (bake, apply).

Runtime state (the bound rigs) lives only in memory, keyed by object; anything
that could make it stale (undo, a new file, changed binding settings, another
mesh) is detected by a signature and the rig is rebuilt.
"""

import contextlib

import bpy
import mathutils

from .. import native, problems
from . import path, route, timing, visibility
from . import rig as rig_module

SHAPE_KEY = rig_module.SHAPE_KEY

_rigs = {}
_batch_depth = {}
_setup_left_scratch = False  # a route was installed since the last frame


def _key(obj):
    return obj.as_pointer()


def forget(obj=None):
    if obj is None:
        _rigs.clear()
    else:
        _rigs.pop(_key(obj), None)


def get_rig(obj, build=True, known_weights=None, check_rest=False):
    """The object's bound rig, rebuilt when its binding inputs changed. check_rest: also
    compare the rest shape with the bound one (reads every rest position: after edits
    such as Edit Mode or Apply Scale; the frame handler asks when Blender saw the mesh
    change, operators that set up from the rest shape always)."""
    settings = obj.kodawari_swim
    rig = _rigs.get(_key(obj))
    if rig is not None and (
        rig.signature != rig_module.binding_signature(obj, settings)
        or rig.mesh_pointer != obj.data.as_pointer()
        or (check_rest and rig.fingerprint != rig_module.rest_fingerprint(obj))
    ):
        rig = None
    if rig is None and build:
        rig = rig_module.SwimRig(obj, settings, known_weights)
        _rigs[_key(obj)] = rig
    if rig is not None:
        rig.owner = obj
    return rig


def consume_own_update(obj):
    """True once after the route wrote its attributes into the object's mesh (route.install)."""
    rig = _rigs.get(_key(obj))
    if rig is None or not getattr(rig, "own_update", False):
        return False
    rig.own_update = False
    return True


def adopt(obj, rig):
    """Keep a rig bound for obj on trial (Add Fish Swim) instead of binding the mesh again:
    same rest shape and settings. A rig bound with other settings is dropped and get_rig
    binds again."""
    if rig.signature != rig_module.binding_signature(obj, obj.kodawari_swim):
        return
    rig.mesh_pointer = obj.data.as_pointer()
    rig.owner = obj
    _rigs[_key(obj)] = rig


def body_rig(obj, check_rest=False):
    """A rig whose rest shape and body axis are current (its fins may be out of date):
    what checking a new fin needs, without rebinding every fin."""
    rig = _rigs.get(_key(obj))
    if rig is not None and (
        rig.signature[:3] != rig_module.binding_signature(obj, obj.kodawari_swim)[:3]
        or rig.mesh_pointer != obj.data.as_pointer()
        or (check_rest and rig.fingerprint != rig_module.rest_fingerprint(obj))
    ):
        rig = None
    if rig is None:
        return get_rig(obj)
    rig.owner = obj
    return rig


@contextlib.contextmanager
def batch(obj):
    """Suspend per-property refreshes while several settings change together."""
    key = _key(obj)
    _batch_depth[key] = _batch_depth.get(key, 0) + 1
    try:
        yield
    finally:
        _batch_depth[key] -= 1
        if not _batch_depth[key]:
            del _batch_depth[key]


def swim_key_block(obj):
    """The shape key the swim lived in before the node route (an older file), or None."""
    keys = obj.data.shape_keys
    return keys.key_blocks.get(SHAPE_KEY) if keys is not None else None


def has_swim(obj):
    """The object has a live swim set up (its Fish Swim modifier, or an older file's key)."""
    return route.modifier(obj) is not None or swim_key_block(obj) is not None


def is_live(obj):
    # Not in Edit Mode: there the user edits the rest shape (the modifier shows it).
    return (
        obj is not None
        and obj.type == "MESH"
        and obj.mode != "EDIT"
        and visibility.visible(obj)
        and obj.kodawari_swim.baked == "NONE"
        and has_swim(obj)
    )


def drop_swim_key(obj):
    """An older file's swim shape key (and the Basis added with it, when alone) goes: the
    modifier bends the mesh now."""
    block = swim_key_block(obj)
    if block is None:
        return
    obj.shape_key_remove(block)
    keys = obj.data.shape_keys
    if keys is not None and len(keys.key_blocks) == 1:
        obj.shape_key_remove(keys.key_blocks[0])


def ensure_route(obj, rig):
    """The route installed for this rig's binding (installed again after a rebind)."""
    global _setup_left_scratch
    if route.installed_for(obj, rig):
        return
    drop_swim_key(obj)
    route.install(obj, rig)
    visibility.sync(obj)
    # The bind's and the install's scratch (rest positions, closest-point search, packed
    # copies: tens of bytes per vertex, all freed by now) goes back to the system; what the
    # calling operator still holds (its reads of the mesh) is freed only when it returns, so
    # once more on the next frame (release_setup_scratch).
    rig.kn.release_free_memory()
    _setup_left_scratch = True


def release_setup_scratch():
    """Once after a route was installed, from the frame handler: the memory the setup freed
    since (25 MB at 1 M vertices) goes back to the system instead of staying resident."""
    global _setup_left_scratch
    if _setup_left_scratch:
        _setup_left_scratch = False
        native.module().release_free_memory()


def travel_direction(obj, rig):
    """Head direction in the object's parent space (object scale included)."""
    return obj.matrix_basis.to_3x3() @ mathutils.Vector(rig.head)


def apply_travel(obj, rig, distance):
    """Advance the object along its head direction; returns nothing (see evaluate for paths)."""
    rest = mathutils.Vector(obj.kodawari_swim.rest_delta_location)
    obj.delta_location = rest + travel_direction(obj, rig) * distance


def _pose(obj, scene, frame, check_rest):
    """(rig, settings, phase, rest axis or None) for a frame, the object placed on its
    travel or path."""
    settings = obj.kodawari_swim
    rig = get_rig(obj, check_rest=check_rest)
    if frame is None:
        frame = scene.frame_current + scene.frame_subframe
    phase, distance = timing.phase_and_distance(obj, settings, scene, frame, rig.body_length)
    rest_axis = None
    follow = path.follow_path(obj) if settings.speed_mode != "NONE" else None
    if follow is not None:
        # Along a curve: place the fish on it and bend the spine into its turns.
        scale = float(obj.matrix_world.to_3x3().to_scale()[0])
        points, arc = path.polyline(follow.target)
        start = float(settings.path_start) * arc[-1]
        path.place(obj, follow, settings.head_axis, start + distance * scale, points, arc)
        rest_axis = path.bent_rest_axis(
            rig.axis_rest, rig.head, rig.up, rig.side, scale, start + distance * scale, points, arc
        )
    elif settings.speed_mode != "NONE":
        apply_travel(obj, rig, distance)
    return rig, settings, phase, rest_axis


def evaluate(obj, scene, frame=None, check_rest=False):
    """Pose one object for a frame (the scene's current frame by default): its frame table
    and fin offsets go into the Fish Swim modifier's helpers, and Blender bends the mesh
    when it evaluates it (route.py). Installs the route when the binding changed;
    check_rest: see get_rig."""
    rig, settings, phase, rest_axis = _pose(obj, scene, frame, check_rest)
    ensure_route(obj, rig)
    table, fin_offsets = rig.frame(settings, phase, rest_axis)
    route.write_frame(obj, table, fin_offsets)


def positions(obj, scene, frame=None, check_rest=True):
    """The shape the modifier gives at a frame, as float32 (N, 3) positions computed by the
    core (bake, apply): the rig's buffer, copy it to keep it."""
    rig, settings, phase, rest_axis = _pose(obj, scene, frame, check_rest)
    return rig.evaluate(settings, phase, rest_axis)


def refresh(obj):
    """Re-evaluate after a setting changed (no-op while batched or not live)."""
    visibility.sync(obj)  # the viewport/render toggles may have changed
    if _key(obj) in _batch_depth or not is_live(obj):
        return
    scene = bpy.context.scene
    try:
        evaluate(obj, scene)
    except Exception as exc:  # noqa: BLE001 - e.g. a fin group emptied: say so, keep the last frame
        problems.report(obj, "swim", exc)
    else:
        problems.clear(obj, "swim")


def rebind(obj, known_weights=None):
    if _key(obj) in _batch_depth:
        # Several settings change together (Find Fins adds fins one by one): the rig's
        # signature tells get_rig to rebuild once they are done; body_rig keeps serving
        # the rest shape meanwhile instead of rebuilding it per fin.
        return
    forget(obj)
    if known_weights and is_live(obj):
        get_rig(obj, known_weights=known_weights)
    refresh(obj)


def separate_linked_duplicates(scene):
    """Linked duplicates (Alt-D) share one mesh and its bound attributes, and a duplicate
    (Shift-D) shares the Fish Swim node group and its helpers: each would overwrite the
    other's frame. Give every live swimmer after the first its own copy of the mesh (what
    Object > Relations > Make Single User does) or of the route, so each swims with its
    own settings, and say so in the console."""
    owners = {}
    groups = {}
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj.type != "MESH" or not is_live(obj) or obj.data.library is not None:
            continue
        mod = route.modifier(obj)
        if mod is not None:
            group_owner = groups.setdefault(mod.node_group.as_pointer(), obj)
            if group_owner is not obj:
                forget(obj)  # its next evaluate installs its own group and helpers
                print(
                    f"Kodawari Swim: '{obj.name}' shared its Fish Swim helpers with "
                    f"'{group_owner.name}' (a duplicate); it now has its own"
                )
        owner = owners.setdefault(obj.data.as_pointer(), obj)
        if owner is not obj:
            try:
                obj.data = obj.data.copy()
            except (RuntimeError, AttributeError) as exc:  # e.g. a write-protected object
                problems.report(obj, "swim", exc)
                continue
            forget(obj)
            print(
                f"Kodawari Swim: '{obj.name}' shared its mesh with '{owner.name}' (a linked "
                f"duplicate); it now has its own copy so each swims with its own settings"
            )
