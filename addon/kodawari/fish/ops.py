"""Operators: add / remove the swim, add / find fins, flip the head, bake."""

import types

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_
from bpy.props import EnumProperty, FloatProperty, IntProperty, StringProperty

from .. import bulk, cache_paths, editable, fcurves, native
from ..bake_job import BakeError, BakeOperator, frame_range
from . import bake, finder, midline, presets, route, runtime, validate
from . import fins as fin_setup
from . import rig as rig_module
from .props import HEAD_AXES


def _active_mesh(context):
    return (
        context.active_object
        if context.active_object is not None
        else getattr(context, "object", None)
    )


class KODAWARI_OT_swim_add(bpy.types.Operator):
    """Make the active mesh swim: bind it to a control axis along its mid-line"""

    bl_idname = "kodawari.swim_add"
    bl_label = "Add Fish Swim"
    bl_options = {"REGISTER", "UNDO"}

    head_axis: EnumProperty(
        name="Head Axis",
        items=[("AUTO", "Auto", "Guess from the shape (reported)")] + list(HEAD_AXES),
        default="AUTO",
        description="Which way the head points (Auto: guessed from the shape)",
    )
    preset: EnumProperty(
        name="Preset",
        items=[(k, *presets.LABELS[k]) for k in presets.ORDER],
        default="CARANGIFORM",
        description="A kind of swimmer: sets the body wave and the fins' motions",
    )
    frequency: FloatProperty(
        name="Frequency", description="Tail beats per second (0: the preset's)", default=0.0
    )

    def execute(self, context):
        obj = _active_mesh(context)
        if (
            obj is not None
            and obj.type == "MESH"
            and (
                obj.kodawari_swim.enabled
                or obj.kodawari_swim.baked != "NONE"
                or runtime.has_swim(obj)
            )
        ):
            error = f"'{obj.name}' already swims: tune it in the Modifier tab, or remove it first"
        else:
            error = (
                editable.why_not(obj, tip_("swim"))
                or validate.swim_target(obj)
                or validate.frequency(self.frequency)
            )
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        if self.head_axis == "AUTO":
            head_axis, guess = midline.guess_head_axis(bulk.vertex_positions(obj.data))
        else:
            head_axis, guess = (
                self.head_axis,
                f"head axis {midline.LABEL[self.head_axis]} (as given)",
            )
        # Bind once on trial before anything changes: a degenerate mesh fails here.
        trial = types.SimpleNamespace(
            head_axis=head_axis, control_points=obj.kodawari_swim.control_points, fins=[]
        )
        try:
            trial_rig = rig_module.SwimRig(obj, trial)
        except ValueError as exc:
            self.report(
                {"ERROR"}, tip_("Cannot bind '{}' to a swim axis: {}").format(obj.name, exc)
            )
            return {"CANCELLED"}

        settings = obj.kodawari_swim
        with runtime.batch(obj):
            settings.head_axis = head_axis
            settings.head_guess = guess
            settings.preset = self.preset
            presets.apply_body(settings, self.preset)
            if self.frequency > 0:
                settings.frequency = self.frequency
            settings.rest_delta_location = obj.delta_location
            settings.baked = "NONE"
            settings.enabled = True
        # The handler writes the modifier's frame on frame changes; renders must wait for it.
        context.scene.render.use_lock_interface = True
        runtime.forget(obj)
        runtime.adopt(obj, trial_rig)  # the trial bind is the binding: no second one
        runtime.ensure_route(obj, runtime.get_rig(obj))
        runtime.evaluate(obj, context.scene)
        self.report(
            {"INFO"},
            tip_("Fish Swim on '{}': {}; preset {}").format(
                obj.name, guess, tip_(presets.LABELS[self.preset][0])
            ),
        )
        return {"FINISHED"}


def remove_swim(obj):
    """Undo everything swim_add, swim_fin_add and swim_bake did to the object."""
    settings = obj.kodawari_swim
    runtime.forget(obj)
    route.uninstall(obj)
    modifier = obj.modifiers.get(bake.CACHE_MODIFIER)
    if modifier is not None:
        obj.modifiers.remove(modifier)
    bake.free_bake_keys(obj)  # baked keys, and the Basis a bake added
    runtime.drop_swim_key(obj)  # an older file's swim key, and the Basis added with it
    anim = obj.animation_data
    if anim is not None and anim.action is not None:
        for fcurve in fcurves.action_fcurves(anim.action, obj):
            if fcurve.group is not None and fcurve.group.name == "Kodawari Swim":
                fcurves.remove_fcurve(anim.action, obj, fcurve)
    obj.delta_location = settings.rest_delta_location
    settings.enabled = False
    settings.baked = "NONE"
    settings.fins.clear()
    settings.head_guess = ""


class KODAWARI_OT_swim_remove(bpy.types.Operator):
    """Remove the swim and restore the original mesh exactly"""

    bl_idname = "kodawari.swim_remove"
    bl_label = "Remove Fish Swim"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = _active_mesh(context)
        if obj is None or obj.type != "MESH":
            self.report({"ERROR"}, tip_("Select the swimming mesh object first"))
            return {"CANCELLED"}
        settings = obj.kodawari_swim
        if not settings.enabled and settings.baked == "NONE" and not runtime.has_swim(obj):
            self.report({"ERROR"}, tip_("'{}' has no Fish Swim to remove").format(obj.name))
            return {"CANCELLED"}
        error = editable.why_not(obj, tip_("lose its swim"))
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        with runtime.batch(obj):
            remove_swim(obj)
        self.report(
            {"INFO"}, tip_("Fish Swim removed from '{}'; its mesh is as it was").format(obj.name)
        )
        return {"FINISHED"}


def _fin_kind_items():
    return [(k, k.title(), f"{k.title()} fin") for k in presets.FIN_KINDS]


def _check_fin(obj, group_name, kind, known_weights=None, reach=None):
    """(error, None) or (None, weights) for a new fin, validated by binding it on trial.
    known_weights: {group: weights} already in hand (Find Fins), read from the mesh
    otherwise; reach: fin_setup.fin_reach over every fin, when already computed."""
    known_weights = known_weights or {}
    error, weights = validate.fin_group(
        obj, group_name, obj.kodawari_swim.fins, known_weights.get(group_name)
    )
    if error:
        return error, None
    settings = obj.kodawari_swim
    motion = presets.fin_defaults(settings.preset, kind)[0]
    trial = types.SimpleNamespace(
        vertex_group=group_name, kind=kind, motion=motion, root_blend=0.35
    )
    try:
        rig = runtime.body_rig(obj, check_rest=True)
        kn = native.module()
        if reach is None:
            in_fin = weights > 0
            for fin in settings.fins:
                other = known_weights.get(fin.vertex_group)
                if other is None:
                    other = bulk.vertex_group_weights(obj, fin.vertex_group)
                in_fin |= other > 0
            reach = fin_setup.fin_reach(
                rig.rest, finder.mesh_edges(obj.data), in_fin, rig.body_length, kn
            )
        fin_setup.build_parts(0, trial, weights, rig.rest, rig.axis_rest, rig.up, kn, reach)
    except ValueError as exc:
        return tip_("Cannot bind fin '{}': {}").format(group_name, exc), None
    return None, weights


def add_fin(obj, group_name, kind, rebind=True):
    settings = obj.kodawari_swim
    motion, amplitude, lag, feathering = presets.fin_defaults(settings.preset, kind)
    with runtime.batch(obj):
        fin = settings.fins.add()
        fin.name = group_name
        fin.vertex_group = group_name
        fin.kind = kind
        fin.motion = motion
        fin.amplitude = amplitude
        fin.phase_lag = lag
        fin.feathering = feathering
        settings.fin_index = len(settings.fins) - 1
    if rebind:
        runtime.rebind(obj)
    return fin


def _needs_swim(obj):
    if obj is None or obj.type != "MESH":
        return tip_("Select the swimming mesh object first")
    if not runtime.has_swim(obj):  # hidden in the viewport (enabled off) still swims
        return tip_("'{}' does not swim yet: Add Fish Swim first").format(obj.name)
    return editable.why_not(obj, tip_("change its swim"))


class KODAWARI_OT_swim_fin_add(bpy.types.Operator):
    """Add a fin whose vertices are a vertex group"""

    bl_idname = "kodawari.swim_fin_add"
    bl_label = "Add Fin"
    bl_options = {"REGISTER", "UNDO"}

    vertex_group: StringProperty(name="Vertex Group", description="The fin's vertices")
    kind: EnumProperty(
        name="Kind", items=_fin_kind_items(), default="PECTORAL", description="Which fin this is"
    )

    def invoke(self, context, event):
        obj = _active_mesh(context)
        if not self.vertex_group and obj is not None and obj.vertex_groups.active is not None:
            self.vertex_group = obj.vertex_groups.active.name
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context):
        obj = _active_mesh(context)
        if obj is not None:
            self.layout.prop_search(self, "vertex_group", obj, "vertex_groups")
        self.layout.prop(self, "kind")

    def execute(self, context):
        obj = _active_mesh(context)
        error = _needs_swim(obj)
        if error is None:
            error, _ = _check_fin(obj, self.vertex_group, self.kind)
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        add_fin(obj, self.vertex_group, self.kind)
        self.report(
            {"INFO"},
            tip_("Fin '{}' ({}) added to '{}'").format(
                self.vertex_group, self.kind.lower(), obj.name
            ),
        )
        return {"FINISHED"}


class KODAWARI_OT_swim_fin_remove(bpy.types.Operator):
    """Remove the active fin (its vertices follow the body again)"""

    bl_idname = "kodawari.swim_fin_remove"
    bl_label = "Remove Fin"
    bl_options = {"REGISTER", "UNDO"}

    index: IntProperty(name="Index", default=-1, description="Fin to remove (-1: the active one)")

    def execute(self, context):
        obj = _active_mesh(context)
        error = _needs_swim(obj)
        settings = obj.kodawari_swim if error is None else None
        index = self.index if self.index >= 0 else (settings.fin_index if settings else -1)
        if error is None and not 0 <= index < len(settings.fins):
            error = f"'{obj.name}' has no fin number {index}"
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        settings.fins.remove(index)
        settings.fin_index = max(0, min(settings.fin_index, len(settings.fins) - 1))
        runtime.rebind(obj)
        return {"FINISHED"}


class KODAWARI_OT_swim_fin_find(bpy.types.Operator):
    """Find fins from the geometry (parts standing out of the body's cross-section), make vertex groups and add them"""

    bl_idname = "kodawari.swim_fin_find"
    bl_label = "Find Fins"
    bl_options = {"REGISTER", "UNDO"}

    _search = None
    _timer = None

    def _start(self, context):
        obj = _active_mesh(context)
        error = _needs_swim(obj)
        if error:
            self.report({"ERROR"}, error)
            return None
        return finder.FinSearch(obj, runtime.get_rig(obj, check_rest=True))

    def _finish(self, context):
        obj = _active_mesh(context)
        found = self._search.found()
        if not found:
            self.report(
                {"WARNING"},
                tip_("No fins found on '{}': nothing stands out of the body").format(obj.name),
            )
            return {"CANCELLED"}
        added = []
        known = {}
        count = len(obj.data.vertices)
        for name, _kind, indices in found:
            group = obj.vertex_groups.get(name)
            if group is not None:  # a search run again replaces what it found before
                obj.vertex_groups.remove(group)
            obj.vertex_groups.new(name=name).add(indices.tolist(), 1.0, "REPLACE")
            known[name] = np.zeros(count, dtype=np.float32)
            known[name][indices] = 1.0
        # The groups' weights are known: bind once at the end, never re-read per vertex;
        # every fin's reach across itself comes from one pass over all of them.
        rig = runtime.body_rig(obj, check_rest=True)
        in_fin = np.zeros(count, dtype=bool)
        for weights in known.values():
            in_fin |= weights > 0
        for fin in obj.kodawari_swim.fins:
            if fin.vertex_group not in known:
                in_fin |= bulk.vertex_group_weights(obj, fin.vertex_group) > 0
        reach = fin_setup.fin_reach(
            rig.rest, self._search.edges, in_fin, rig.body_length, native.module()
        )
        with runtime.batch(obj):
            for name, kind, indices in found:
                if not any(f.vertex_group == name for f in obj.kodawari_swim.fins):
                    error, _ = _check_fin(obj, name, kind, known, reach)
                    if error is None:
                        add_fin(obj, name, kind, rebind=False)
                added.append(f"{name} ({len(indices)} vertices)")
        runtime.rebind(obj, known)
        self.report(
            {"INFO"},
            tip_("Found {} fin(s) on '{}': {}").format(len(found), obj.name, ", ".join(added)),
        )
        return {"FINISHED"}

    def execute(self, context):
        self._search = self._start(context)
        if self._search is None:
            return {"CANCELLED"}
        while not self._search.done:
            self._search.step()
        return self._finish(context)

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        self._search = self._start(context)
        if self._search is None:
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, self._search.steps)
        self._timer = wm.event_timer_add(0.001, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._end(context)
            self.report({"WARNING"}, tip_("Find Fins cancelled: nothing was changed"))
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        try:
            self._search.step()
        except ValueError as exc:
            self._end(context)
            self.report({"ERROR"}, tip_("Find Fins failed, nothing was changed: {}").format(exc))
            return {"CANCELLED"}
        context.window_manager.progress_update(self._search.steps_done)
        if context.area:
            context.area.header_text_set(
                f"Finding fins: {self._search.next_vertex:,}/{len(self._search.vertices):,} vertices"
                " (Esc cancels)"
            )
        if not self._search.done:
            return {"RUNNING_MODAL"}
        self._end(context)
        return self._finish(context)

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.area:
            context.area.header_text_set(None)


class KODAWARI_OT_swim_flip_head(bpy.types.Operator):
    """Flip which end is the head (the fish swam backward)"""

    bl_idname = "kodawari.swim_flip_head"
    bl_label = "Flip Head"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = _active_mesh(context)
        error = _needs_swim(obj)
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        settings = obj.kodawari_swim
        settings.head_axis = midline.OPPOSITE[settings.head_axis]
        self.report({"INFO"}, tip_("Head now along {}").format(midline.LABEL[settings.head_axis]))
        return {"FINISHED"}


class KODAWARI_OT_swim_bake(BakeOperator, bpy.types.Operator):
    """Bake the swim to a PC2 point cache (Mesh Cache modifier) or to shape keys"""

    bl_idname = "kodawari.swim_bake"
    bl_label = "Bake Fish Swim"
    bl_options = {"REGISTER", "UNDO"}

    target: EnumProperty(
        name="Target",
        items=[
            (
                "MESH_CACHE",
                "Mesh Cache",
                "PC2 point cache beside the .blend, played by a Mesh Cache modifier",
            ),
            ("SHAPE_KEYS", "Shape Keys", "One shape key per frame, keyed on at its frame"),
        ],
        default="MESH_CACHE",
        description="Where the baked swim goes",
    )
    filepath: StringProperty(
        name="File",
        description="PC2 file (empty: in the folder blendcache_<file name> beside the .blend)",
        subtype="FILE_PATH",
        options=cache_paths.RELATIVE_PATH_OPTIONS,
    )

    def make_job(self, context):
        obj = _active_mesh(context)
        error = _needs_swim(obj)
        if error:
            raise BakeError(error)
        start, end = frame_range(self, context.scene)
        return bake.SwimBakeJob(obj, context.scene, start, end, self.target, self.filepath)


class KODAWARI_OT_swim_free_bake(bpy.types.Operator):
    """Free the bake and swim live again; the setup (fins, preset, bend, timing) is kept"""

    bl_idname = "kodawari.swim_free_bake"
    bl_label = "Free Bake"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = _active_mesh(context)
        if obj is None or obj.type != "MESH" or obj.kodawari_swim.baked == "NONE":
            self.report({"ERROR"}, tip_("Select a fish with a baked swim first"))
            return {"CANCELLED"}
        error = editable.why_not(obj, tip_("free its bake"))
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        with runtime.batch(obj):
            bake.free_bake(obj)
        runtime.forget(obj)
        if runtime.is_live(obj):
            runtime.evaluate(obj, context.scene)
        self.report(
            {"INFO"},
            tip_("Freed the bake of '{}': it swims live again with the same setup").format(
                obj.name
            ),
        )
        return {"FINISHED"}
