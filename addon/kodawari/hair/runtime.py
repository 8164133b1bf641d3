"""Live simulation per armature: the native RodSystem, an exact per-frame cache,
and what the panel shows (live weights, status).

Frames are simulated in order; every simulated frame caches the full solver state
(inside the native system: no state array crosses into Python per frame), so scrubbing
back is exact and playing on from any cached frame continues exactly. Jumping to (or
before) the start frame resets; jumping past the cached frames plays the skipped frames
in order, so a jump gives the pose playback gives (docs/algorithms.md §3.5). The cache
keeps to a memory budget (add-on preference) by thinning to checkpoints. One crossing
into C++ per frame: the pose-bone matrices the rods need in, all rod-bone rotations
out, through foreach_get/set. Inputs are read from the evaluated object of the
depsgraph being evaluated, so a render (whose depsgraph is not the viewport's) sees the
pose it renders.
"""

import numpy as np

from .. import bulk, native, problems
from . import chains, predict

# The solver state of the last evaluated frame is saved into the .blend (save_pre)
# so that a reloaded file continues exactly where it stopped.
STATE_PROPERTY = "kodawari_hair_state"
STATE_FRAME_PROPERTY = "kodawari_hair_state_frame"
NO_CAMERA = "No active camera: view keys fall back to the base shape"

_runtimes = {}  # by obj.as_pointer(): a rename keeps the simulation (CONTRIBUTING.md)
# The native RodSystem's codes for a key's condition (Condition in rod_system.hpp).
CONDITION_CODES = {"VIEW": 0, "POSE": 1, "SPEED": 2}
# True while evaluate() plays skipped frames through scene.frame_set (their handlers
# must simulate them in order, not jump again).
_replaying = False
DEFAULT_CACHE_MEGABYTES = 256
# Replays of at least this many frames show their progress on the mouse cursor.
REPLAY_PROGRESS_FRAMES = 24


def cache_budget_bytes():
    """The frame-cache budget from the add-on preferences (default 256 MB)."""
    import bpy

    from ..preferences import addon_package

    addon = bpy.context.preferences.addons.get(addon_package())
    megabytes = getattr(
        getattr(addon, "preferences", None), "hair_cache_megabytes", DEFAULT_CACHE_MEGABYTES
    )
    return int(megabytes) << 20


def active_camera(scene, frame):
    """The camera of `frame`: markers bound to cameras decide (as Blender's camera switching
    does: the last such marker at or before the frame, else the first one), else scene.camera.
    Read here because scene.frame_set() switches the camera only after the frame handlers ran."""
    markers = [m for m in scene.timeline_markers if m.camera is not None]
    if not markers:
        return scene.camera
    before = [m for m in markers if m.frame <= frame]
    if before:
        return max(before, key=lambda m: m.frame).camera
    return min(markers, key=lambda m: m.frame).camera


# The next frame is solved ahead, while Blender evaluates this one (_start_ahead), on every
# core but one: Blender's pass of a pose keeps 1.3-1.5 cores busy (16,000 bones: 31-36 ms of
# processor time in 21-24 ms), and the step runs beside it where a core is free. Only on rigs
# of at least AHEAD_MIN_ROD_BONES rod bones: below, Blender's pass (under 1 ms at 1,600 bones)
# is too short to hide a step in, and handing the step to another thread and back measured no
# faster at 160 and 1,600 bones (tests/bench/bench_hair.py, docs/algorithms.md §3.7).
AHEAD_MIN_ROD_BONES = 4096
# When the next frame's handler had to step more than this share of the rods itself, the thread
# found no core to spare during Blender's pass (a machine busy with other work): it only slowed
# the pass down, so the frames are solved in place for AHEAD_PAUSE_FRAMES, then tried again.
AHEAD_MAX_CALLER_SHARE = 0.5
AHEAD_PAUSE_FRAMES = 24


def _ahead_threads():
    import os

    return max(1, (os.cpu_count() or 2) - 1)


# Reading a few bones one by one beats a foreach_get over all of them when they are
# fewer than 1 in this many (~5 us per bone against ~0.03 us per bone in bulk).
SPARSE_READ_RATIO = 256


def _tag(obj):
    """foreach_set bypasses RNA updates (in 3.4): tag the armature so its pose is re-evaluated.
    Blender copies the whole armature object again (copy-on-write: every component of an
    object asks for it on a tag) and evaluates all of it: Blender's own price, measured as
    bare_retag in tests/bench/bench_hair.py (docs/algorithms.md §3.7). The object tag is the
    cheapest that works (16k bones, Blender 3.4: the data, time, untyped and armature-data tags
    cost 1.15-2.4x its second evaluation). test_the_blender_pose_follows_the_solver... fails
    without a working tag."""
    obj.update_tag(refresh={"OBJECT"})


class ArmatureRuntime:
    def __init__(self, obj):
        kn = native.module()
        settings = obj.kodawari_hair
        pose_bones = obj.pose.bones
        self.pointer = obj.as_pointer()
        self.data_pointer = obj.data.as_pointer()
        self.bone_count = len(pose_bones)
        index = {pb.name: i for i, pb in enumerate(pose_bones)}
        self.system = kn.RodSystem(self.bone_count, 0)
        self.system.cache_budget = cache_budget_bytes()
        self.rod_slots = {}  # index in settings.rods -> index in the native system
        self.rod_chains = {}  # index in settings.rods -> chain bone names
        rod_bones = []
        rod_starts = []  # where each rod's chain begins in rod_bones
        errors = []
        for i, rod in enumerate(settings.rods):
            try:
                parent, reference, chain = chains.resolve_rod(obj, rod)
                offsets, rest = chains.chain_geometry(parent, chain)
                n, m = len(chain), len(rod.keys)
                shapes = np.zeros((m, n, 4))
                for j, key in enumerate(rod.keys):
                    if len(key.shape) != n:
                        raise chains.ChainError(
                            f"Key '{key.name}' of rod '{rod.root_bone}' has {len(key.shape)} "
                            f"joints, the chain has {n}: re-key it"
                        )
                    for k, joint in enumerate(key.shape):
                        shapes[j, k] = joint.rotation
                slot = self.system.add_rod(
                    index[parent.name],
                    index[reference.name],
                    np.array([index[b.name] for b in chain], np.int32),
                    offsets,
                    rest,
                    stiffness=rod.stiffness,
                    damping=rod.damping,
                    gravity=rod.gravity,
                    substeps=rod.substeps,
                    iterations=rod.iterations,
                    radius=rod.radius,
                    wind=np.array(rod.wind, np.float64),
                    key_conditions=np.array(
                        [CONDITION_CODES[k.condition] for k in rod.keys], np.int32
                    ),
                    key_directions=np.array(
                        [tuple(k.direction) for k in rod.keys], np.float64
                    ).reshape(m, 3),
                    key_rotations=np.array(
                        [tuple(k.rotation) for k in rod.keys], np.float64
                    ).reshape(m, 4),
                    key_speeds=np.array([k.speed for k in rod.keys], np.float64),
                    key_influences=np.array([k.influence for k in rod.keys], np.float64),
                    key_shapes=shapes.reshape(m * n, 4),
                )
            except ValueError as exc:  # ChainError is a ValueError, as are the solver's refusals
                errors.append(str(exc))
                continue
            self.rod_slots[i] = slot
            self.rod_chains[i] = [b.name for b in chain]
            rod_starts.append(len(rod_bones))
            rod_bones.extend(index[b.name] for b in chain)
        colliders = [c for c in settings.colliders if c.bone in index]
        errors.extend(
            f"Collider bone '{c.bone}' is missing"
            for c in settings.colliders
            if c.bone not in index
        )
        self.system.set_colliders(
            np.array([index[c.bone] for c in colliders], np.int32),
            np.array([1 if c.shape == "CAPSULE" else 0 for c in colliders], np.int32),
            np.array([tuple(c.offset) for c in colliders], np.float64).reshape(-1, 3),
            np.array([c.radius for c in colliders], np.float64),
            np.array([c.length for c in colliders], np.float64),
        )
        self.error = "; ".join(errors)
        self.status = ""
        self.rod_bones = np.array(rod_bones, dtype=np.int64)
        self.rod_starts = np.array(rod_starts, dtype=np.int64)
        self.rod_view_rows = None  # rod_bones' rows in the pose view (_first_changed_rows)
        self.rod_of_bone = None
        self.matrices = np.zeros((self.bone_count, 16), np.float32)
        self.rotations = np.empty((self.bone_count, 4), np.float32)
        self.held = np.empty((self.bone_count, 4), np.float32)  # rotations a pose holds now
        # Evaluated matrices before and after a pass (_write_evaluated, _was_evaluated).
        self.matrices_before = np.empty((self.bone_count, 4, 4), np.float32)
        self.matrices_after = np.empty((self.bone_count, 4, 4), np.float32)
        # (depsgraph, frame, "view" or "rna", matrices before, the rows they are of) after
        # _write_evaluated, until checked.
        self.pending = None
        # The solver reads only the matrices of parents, reference bones and colliders, and
        # writes every rod bone's rotation: in a hair rig both other sets are small, so they
        # are read one by one there instead of in bulk over every bone.
        read = set()
        for i, rod in enumerate(settings.rods):
            if i in self.rod_slots:
                parent, reference, _chain = chains.resolve_rod(obj, rod)
                read.update((index[parent.name], index[reference.name]))
        read.update(index[c.bone] for c in colliders)
        self.input_bones = sorted(read)  # what a prediction must know (predict.py)
        self.view_keys = any(
            k.condition == "VIEW"
            for i, rod in enumerate(settings.rods)
            if i in self.rod_slots
            for k in rod.keys
        )
        self.written_bones = sorted(set(rod_bones))
        self.predictor = None  # built at the first new frame (predict.PosePredictor)
        self.prediction_off = None  # why this rig's frames are not predicted, once known
        self.predicted = None  # the prediction made before the pass, until checked after it
        # The next frame solved ahead on native threads (_start_ahead): native.RodStepAhead,
        # its bone matrices, and what it was started from, until _take_ahead looks at it.
        self.ahead = None
        self.ahead_matrices = None
        self.ahead_inputs = None
        self.ahead_paused = range(0)  # frames not solved ahead (_take_ahead found no core to spare)
        self.rotation_view = None  # bulk.PoseRotationView once built, False when refused
        # The same of the viewport's evaluated copy (_evaluated_view): built once that copy's
        # channels stayed in place from one frame to the next, dropped when they move.
        self.evaluated_view = None
        self.evaluated_channels = None  # (pose, first, last) of the copy last looked at
        # (frame, rod bones' rotations) show_cached() wrote into the original pose, until _write
        self.original_written = None
        self.matrix_bones = (
            sorted(read) if len(read) * SPARSE_READ_RATIO <= self.bone_count else None
        )
        others = sorted(set(range(self.bone_count)) - set(rod_bones))
        self.other_bones = others if len(others) * SPARSE_READ_RATIO <= self.bone_count else None
        self.last_frame = None
        self.counted = None  # the frame whose pre-evaluation handler counted the bones (get)

    # -- one frame -------------------------------------------------------------
    def _read_matrices(self, pose_bones):
        if self.matrix_bones is None:
            pose_bones.foreach_get("matrix", self.matrices.reshape(-1))
            return
        for i in self.matrix_bones:
            # Matrix rows are row-major; the solver takes foreach_get's column-major rows.
            self.matrices[i] = np.array(pose_bones[i].matrix, np.float32).T.reshape(-1)

    def _read_other_rotations(self, pose_bones):
        """The current rotations of the bones the solver does not write (foreach_set writes all)."""
        if self.other_bones is None:
            pose_bones.foreach_get("rotation_quaternion", self.rotations.reshape(-1))
            return
        for i in self.other_bones:
            self.rotations[i] = pose_bones[i].rotation_quaternion

    def _inputs(self, obj, scene, frame, depsgraph):
        evaluated = _evaluated(obj, depsgraph)
        pose_bones = evaluated.pose.bones
        self._read_matrices(pose_bones)
        self._read_other_rotations(pose_bones)
        camera = active_camera(scene, frame)
        self.status = "" if camera is not None else NO_CAMERA
        camera_position = None
        if camera is not None:
            camera_position = np.array(
                _evaluated(camera, depsgraph).matrix_world.translation, np.float64
            )
        gravity = _gravity(scene)
        armature_matrix = np.array([tuple(row) for row in evaluated.matrix_world], np.float64)
        return armature_matrix, camera_position, gravity

    def _holds(self, pose_bones):
        """True when these pose bones hold exactly the rotations to write."""
        bulk.pose_rotations(pose_bones, self.held)
        return np.array_equal(self.held, self.rotations)

    def _write(self, obj, depsgraph=None):
        """Writes the rotations into the armature; Blender evaluates it again (a tag: a copy of
        the whole object and a second evaluation, §3.7) only when the pose `depsgraph` has just
        evaluated was not already made from them, e.g. a frame show_cached() wrote before the
        evaluation or a chain at rest. Without a depsgraph the tag is unconditional."""
        view = self._original_view(obj)
        written, self.original_written = self.original_written, None
        mine = None  # rotations[view.indices], once gathered
        if view is not None:
            # What show_cached() wrote into the original before this frame's pass is still there
            # (Blender's pass writes back pose matrices, not rotations; animated rotations would
            # show in the evaluated copy, checked below): the memory is read again only when the
            # rotations are not the ones written for this very frame.
            # (Every row compared first, a copy without a gather: rows of other bones read since
            # from the evaluated pose may differ, and then the rod bones' rows alone decide.)
            if written is not None and written[0] == self.last_frame:
                if np.array_equal(written[1], self.rotations):
                    holds, mine = True, written[2]  # the rows written, gathered then
                else:
                    mine = self.rotations[view.indices]
                    holds = np.array_equal(written[1][view.indices], mine)
            else:
                holds = False
            if not holds:
                mine = self.rotations[view.indices] if mine is None else mine
                holds = np.array_equal(view.read(), mine)
        else:
            holds = self._holds(obj.pose.bones)
        if not holds:
            self.pending = None
            if view is not None:
                view.write(self.rotations)
            else:
                bulk.set_pose_rotations(obj.pose.bones, self.rotations)
            _tag(obj)
            return
        evaluated = _evaluated(obj, depsgraph)
        held = (
            depsgraph is not None
            and evaluated.pose is not None
            and self._evaluated_holds(evaluated.pose, view, mine)
        )
        if not (
            held and self._was_evaluated(obj, evaluated.pose.bones, depsgraph, self.last_frame)
        ):
            self.pending = None
            if view is not None and not np.array_equal(view.read(), self.rotations[view.indices]):
                view.write(self.rotations)  # the read skipped above was needed after all
            _tag(obj)

    def _evaluated_holds(self, pose, original_view, rows=None):
        """True when the evaluated pose holds the rotations to write: its rod bones read in its
        own memory (_evaluated_view) where that is confirmed, else every bone through RNA.
        `rows`: rotations[original_view.indices] when already gathered (the same bones)."""
        view = self._evaluated_view(pose, original_view)
        if view is None:
            return self._holds(pose.bones)
        return np.array_equal(view.read(), self.rotations[view.indices] if rows is None else rows)

    def _evaluated_view(self, pose, original_view):
        """The rod bones' rotations in the memory of an evaluated copy's `pose`
        (bulk.PoseRotationView), or None: then RNA. Reading and writing there instead of a
        foreach_get or foreach_set over every bone saves ~1.5 ms a frame at 16,000 bones (§3.7).
        The copy's channels are new whenever Blender copies the object again, so a view is built
        only once the same channels are seen on two frames in a row (a copy made afresh every
        frame keeps to RNA instead of paying the view's set-up each time), and it is checked
        against the channel list and RNA (first and last rod bone) before every use, as the
        original's is. Only where the original's view stands (the same layout)."""
        if original_view is None:
            return None
        view = self.evaluated_view
        if view is not None:
            if view.current(pose) and view.same_channels(pose) and view.agrees(pose):
                return view
            self.evaluated_view = None  # Blender copied the object afresh: new channels
        channels = bulk.PoseRotationView._chanbase(pose)
        seen, self.evaluated_channels = self.evaluated_channels, channels
        if seen != channels:
            return None
        view = bulk.PoseRotationView.create(pose, self.written_bones)
        if view is None or not view.agrees(pose):
            self.evaluated_channels = None  # refused: not tried again until the copy moves
            return None
        self.evaluated_view = view
        return view

    def show_cached(self, obj, scene, frame):
        """Before Blender evaluates `frame` (frame_change_pre): a frame the cache holds, or a new
        frame whose inputs can be predicted (_predict), needs no evaluated input, so its rotations
        go into the armature now and Blender evaluates the frame once, with them, instead of
        twice (§3.7). Returns whether the frame was written."""
        self.original_written = None
        if frame <= scene.frame_start or self.system.rod_count == 0:
            return False
        pose_bones = obj.pose.bones
        self._read_other_rotations(pose_bones)
        cached = self.system.recall_frame(
            frame, self.rotations, load_state=self.last_frame != frame
        )
        if not (cached or self._predict(obj, scene, frame)):
            return False
        self.last_frame = frame
        view = self._original_view(obj)
        if view is not None:
            # The rod bones' rotations in Blender's memory (no RNA: nothing tagged, no update).
            rows = self.rotations[view.indices]  # gathered once, written and kept as is
            changed = np.zeros(self.bone_count, bool)
            changed[view.indices] = np.any(view.read() != rows, axis=1)
            if changed.any():
                view.write_rows(rows)
            self.original_written = (frame, self.rotations.copy(), rows)
            self._write_evaluated(obj, frame, changed, view, rows)
            return True
        if not self._holds(pose_bones):
            bulk.set_pose_rotations(pose_bones, self.rotations)
            if bulk.POSE_WRITE_TAGS:
                # Blender copies the armature from these in the coming evaluation anyway: a
                # write into its current copy would be lost. The tag makes sure of the copy.
                self.pending = None
                _tag(obj)
                return True
        self._write_evaluated(obj, frame)
        return True

    def _original_view(self, obj):
        """The rod bones' rotations in the original pose's memory (bulk.PoseRotationView), or
        None where it is refused or out of date: then RNA. Without RNA, a write runs no update,
        so in Blender 4.x it no longer has Blender copy the whole armature in the coming
        evaluation, and in every Blender it skips a pass over every pose bone (§3.7). Checked
        against the pose's channel list and against RNA (first and last rod bone) before use."""
        view = self.rotation_view
        if view is False:
            return None
        pose = obj.pose
        if pose is None:
            return None
        if view is None:
            view = self.rotation_view = (
                bulk.PoseRotationView.create(pose, self.written_bones) or False
            )
            if view is False:
                return None
        if not (view.current(pose) and view.agrees(pose)):
            self.rotation_view = False  # the memory is not what RNA shows: RNA from now on
            return None
        return view

    def _previous_frame(self, frame):
        """The frame `frame` steps on from: the solver's own state when it was the last one
        simulated (the budget may already have dropped it from the cache), else the latest
        cached one."""
        if self.last_frame == frame - 1:
            return self.last_frame
        return self.system.latest_cached_frame_before(frame)

    def _predict(self, obj, scene, frame):
        """Solves the frame after the last simulated one from inputs predicted before Blender
        evaluates it (predict.py); evaluate() checks them against Blender's after the pass.
        False (nothing changed) when this rig's or this frame's inputs cannot be predicted.
        The next frame is then solved ahead, on native threads, while Blender evaluates this
        one (_start_ahead); the next call takes that result when it is what it would solve."""
        if self.predicted is not None:
            return False  # an earlier prediction was never checked: evaluate() sorts it out
        previous = self._previous_frame(frame)
        if previous != frame - 1 or self.prediction_off is not None or scene.frame_subframe:
            return False
        if self.predictor is None:
            try:
                self.predictor = predict.PosePredictor(obj, self.input_bones, self.written_bones)
            except predict.Unpredictable as exc:
                self.prediction_off = str(exc)
                return False
        inputs = self._predicted_inputs(scene, frame, scene.frame_current_final)
        if inputs is None:
            return False
        matrices, armature_matrix, camera_position, gravity = inputs
        self.matrices[self.input_bones] = matrices
        fps = _fps(scene)
        if not self._take_ahead(frame, previous, inputs, fps):
            self._step(scene, previous, frame, armature_matrix, camera_position, gravity)
        self.predicted = predict.Prediction(
            frame,
            previous,
            matrices,
            armature_matrix,
            camera_position,
            gravity,
            self.rotations,
            self.view_keys,
        )
        self.status = "" if active_camera(scene, frame) is not None else NO_CAMERA
        self._start_ahead(scene, frame + 1, fps)
        return True

    def _predicted_inputs(self, scene, frame, time, ahead=False):
        """(input bone matrices, armature matrix, camera position, gravity) predicted for
        `frame` at scene time `time`, or None when this frame's camera cannot be predicted or
        the rig turns out unpredictable (then prediction_off says why, unless only looking
        `ahead`: the frame itself will find out if it is ever played)."""
        camera = active_camera(scene, frame)
        camera_position = None
        if camera is not None and self.view_keys:
            camera_position = self.predictor.camera_position(camera, time)
            if camera_position is None:
                return None  # a camera moved by more than its own action: this frame only
        elif camera is not None:  # no view keys: the camera's position changes nothing
            camera_position = np.array(camera.matrix_world.translation, np.float64)
        try:
            matrices, armature_matrix = self.predictor.predict(time)
        except (predict.Unpredictable, ValueError) as exc:
            if not ahead:
                self.prediction_off = str(exc)
            return None
        return matrices, armature_matrix, camera_position, _gravity(scene)

    def _start_ahead(self, scene, frame, fps, after_reset=False):
        """Starts solving `frame` (the one after the frame just solved) on native threads from
        its predicted inputs, while Blender evaluates the frame just written (docs/algorithms.md
        §3.7). Nothing of it is used unless _take_ahead finds it is exactly what `frame` would
        solve. Skipped past the scene's end (playback wraps to the start, which resets).
        `after_reset`: started after the pass of the start frame (_start_after_reset), whose
        state is already cached: no snapshot, and its caller share says nothing of the cores."""
        self.ahead_inputs = None
        if frame > scene.frame_end or len(self.rod_bones) < AHEAD_MIN_ROD_BONES:
            return
        if frame in self.ahead_paused:
            return  # no core to spare lately (_take_ahead): solved in place for a while
        inputs = self._predicted_inputs(scene, frame, float(frame), ahead=True)
        if inputs is None:
            return
        matrices, armature_matrix, camera_position, gravity = inputs
        if self.ahead is None:
            self.ahead = native.module().RodStepAhead(_ahead_threads())
            self.ahead_matrices = self.matrices.copy()
        self.ahead_matrices[self.input_bones] = matrices  # the rods read these rows only
        try:
            self.ahead.start(
                self.system,
                self.ahead_matrices,
                armature_matrix,
                camera_position,
                gravity,
                frame / fps,
                1 / fps,
                # the frame just solved: cached from the thread's snapshot (_store); after a
                # reset it is cached already
                None if after_reset else self.rotations,
            )
        except ValueError:
            return  # inputs the solver refuses: the frame itself says so if it is ever played
        # stepped from the frame just solved
        self.ahead_inputs = (frame, frame - 1, inputs, fps, after_reset)

    def _take_ahead(self, frame, previous, inputs, fps):
        """True when the frame solved ahead (_start_ahead) is `frame`, stepped from the state this
        system holds (`previous`, unchanged since: the native side checks its state revision)
        with exactly these inputs: its rotations are then in self.rotations and its state is the
        system's, bit for bit what _step would have made. False otherwise (it is dropped)."""
        ahead, self.ahead_inputs = self.ahead_inputs, None
        if ahead is None:
            return False
        ahead_frame, ahead_previous, ahead_inputs, ahead_fps, after_reset = ahead
        if (
            ahead_frame != frame
            or ahead_previous != previous
            or self.last_frame != previous
            or ahead_fps != fps
            or not _same_inputs(ahead_inputs, inputs)
        ):
            return False
        finished = self.ahead.finish(self.rotations)
        # Started after the start frame's pass, the step had no pass to hide in, only what came
        # after it (in playback, the wait for the next frame): its share is no sign of a busy
        # machine.
        if not after_reset and self.ahead.caller_share > AHEAD_MAX_CALLER_SHARE:
            self.ahead_paused = range(frame + 1, frame + 1 + AHEAD_PAUSE_FRAMES)
        return finished and self.ahead.adopt(self.system)

    def _step(self, scene, previous, frame, armature_matrix, camera, gravity):
        """Simulates from the stored frame `previous` (recalled unless it is the state held)
        to `frame`, self.matrices holding the frame's bones; into self.rotations."""
        if self.last_frame != previous:
            self.system.recall_frame(previous)
        fps = _fps(scene)
        self.system.step(
            self.matrices,
            armature_matrix,
            camera,
            gravity,
            frame / fps,
            (frame - previous) / fps,
            self.rotations,
        )

    def _confirm(self, prediction, obj, scene, frame, depsgraph):
        """After the pass that follows a prediction: the frame stands when Blender's inputs are
        the predicted ones; otherwise it is solved again from Blender's (the state before the
        step restored, written and tagged: a second pass) and this rig's frames are no longer
        predicted until playback restarts. Returns False when the pass was of another frame."""
        if prediction.frame != frame or self.last_frame != frame:
            self.system.recall_frame(prediction.previous)  # undo the step nobody evaluated
            self.last_frame = prediction.previous
            return False
        armature_matrix, camera, gravity = self._inputs(obj, scene, frame, depsgraph)
        if self.other_bones is None:
            # Every bone's rotation was just read (a rig mostly of other bones): the rod bones'
            # rows back to the predicted frame's. Read one by one, the other bones' rows only
            # were touched, and the rod bones' rows are still the prediction's.
            rods = self.rod_bones
            self.rotations[rods] = prediction.rotations[rods]
        wrong = prediction.mismatch(
            self.matrices[self.input_bones], armature_matrix, camera, gravity
        )
        if wrong is not None:
            self.prediction_off = wrong
            self._step(scene, prediction.previous, frame, armature_matrix, camera, gravity)
        self._store(frame)
        self._write(obj, depsgraph)
        return True

    def _store(self, frame):
        """Caches `frame`, the state the system holds: with the snapshot the step ahead made of
        this very state on its own thread (off this frame's path) when there is one, else now."""
        ahead = self.ahead_inputs
        if ahead is None or ahead[1] != frame or not self.ahead.store(self.system, frame):
            self.system.store_frame(frame, self.rotations)

    def _write_evaluated(self, obj, frame, changed=None, view=None, gathered=None):
        """Writes the rotations into the viewport's evaluated armature too: when the frame change
        re-evaluates the pose (an animated parent), it does so with them and without copying the
        whole object again. Whether it did is checked after the evaluation (_was_evaluated);
        without an evaluated copy to write, the armature is tagged (copied, evaluated once).
        `changed`: the bones whose rotation the original pose just changed (the evaluated copy
        held what the original held), instead of reading the copy's rotations. `view`: the
        original pose's memory (bulk.PoseRotationView), whose pose matrices Blender's pass in
        the viewport's depsgraph refreshes: read there, not through RNA, when it found them.
        `gathered`: the rotations of the view's bones, already gathered (rotations[view.indices])."""
        import bpy

        if self.pending is not None:  # an earlier write nobody evaluated: let Blender copy afresh
            self.pending = None
            _tag(obj)
            return
        view_layer = bpy.context.view_layer
        depsgraph = view_layer.depsgraph if view_layer is not None else None
        evaluated = _evaluated(obj, depsgraph)
        if depsgraph is None or evaluated == obj or evaluated.pose is None:
            _tag(obj)
            return
        pose_bones = evaluated.pose.bones
        if changed is None:
            if self._holds(pose_bones):
                return
            changed = np.any(self.held != self.rotations, axis=1)
        elif not changed.any():
            return  # evaluate() checks after the evaluation that the copy holds them
        if view is not None and view.matrix_index is not None:
            rows = self._first_changed_rows(view, changed[view.indices])
            before = ("view", view.read_matrices(rows), rows)
        else:
            before = ("rna", bulk.pose_bone_matrices(pose_bones, self.matrices_before), changed)
        evaluated_view = self._evaluated_view(evaluated.pose, view)
        if evaluated_view is not None and gathered is not None:
            evaluated_view.write_rows(gathered)  # the same bones as the original's view
        elif evaluated_view is not None:
            evaluated_view.write(self.rotations)  # its rod bones; no RNA update, nothing tagged
        else:
            bulk.set_pose_rotations(pose_bones, self.rotations)
        self.pending = (depsgraph.as_pointer(), frame, *before)

    def _first_changed_rows(self, view, changed_rows):
        """The view's rows (of bulk.PoseRotationView) of the first bone of each rod, in chain
        order, whose rotation changed. Blender evaluates a bone together with every bone below
        it (each bone's evaluation waits for its parent's), so when these got new matrices, so
        did every changed bone: at 16,000 bones one pose matrix a rod is read, not one a bone.
        (3.4, 4.5 and 5.0 evaluate the whole pose once an action moves any bone of it; a rig
        nothing animates is not evaluated at all: test_hair_whole_frame.py.)"""
        if self.rod_view_rows is None:
            self.rod_view_rows = np.searchsorted(view.indices, self.rod_bones)
            # which rod each of rod_bones belongs to, once (not a search over every hit a frame)
            self.rod_of_bone = (
                np.searchsorted(self.rod_starts, np.arange(len(self.rod_bones)), side="right") - 1
            )
        hits = np.flatnonzero(changed_rows[self.rod_view_rows])
        if not len(hits):
            return hits
        rods = self.rod_of_bone[hits]
        first = np.flatnonzero(np.diff(rods, prepend=-1))
        return self.rod_view_rows[hits[first]]

    def _was_evaluated(self, obj, pose_bones, depsgraph, frame):
        """After an evaluation that follows _write_evaluated: did Blender evaluate the pose with
        the rotations written into its copy? Every bone whose rotation changed must have a new
        matrix (a pose nothing animates is not evaluated again on a frame change). A write into
        another depsgraph's copy (the viewport's, while a render evaluates its own) is never
        confirmed: False, so the caller's tag has Blender copy that armature afresh. Matrices
        read from the original pose's memory are the ones Blender copies back there after a
        pass of the viewport's depsgraph, which is the one written (checked above)."""
        pending, self.pending = self.pending, None
        if pending is None:
            return True  # nothing was written into an evaluated copy
        if pending[0] != depsgraph.as_pointer() or pending[1] != frame:
            return False
        _, _, source, before, changed = pending
        if source == "view":
            view = self.rotation_view
            if not view or obj.pose is None or not view.current(obj.pose):
                return False
            return bool(np.all(np.any(view.read_matrices(changed) != before, axis=1)))
        after = bulk.pose_bone_matrices(pose_bones, self.matrices_after)
        return bool(np.all(np.any(after[changed] != before[changed], axis=(1, 2))))

    @property
    def cached_frames(self):
        return self.system.cached_frames()

    def cached_rotations(self, frame):
        """Rotations (rod bones, 4) written at a cached frame, rod by rod, root first."""
        return self.system.cached_rotations(frame)

    def evaluate(self, obj, scene, frame, depsgraph=None):
        """Simulates (or recalls) `frame` and writes the rod bones' rotations."""
        if self.system.rod_count == 0:
            self.status = ""
            return
        prediction, self.predicted = self.predicted, None
        if prediction is not None and self._confirm(prediction, obj, scene, frame, depsgraph):
            return
        if frame > scene.frame_start:
            self._read_other_rotations(_evaluated(obj, depsgraph).pose.bones)
            if self.system.recall_frame(frame, self.rotations, load_state=self.last_frame != frame):
                self.last_frame = frame
                self.status = "" if active_camera(scene, frame) is not None else NO_CAMERA
                self._write(obj, depsgraph)
                return
        previous = self._previous_frame(frame)
        if (
            frame > scene.frame_start
            and (previous is None or previous < frame - 1)
            and _can_replay(depsgraph)
        ):
            # A jump past the cached frames (or to a dropped one): play the frames in between
            # as playback would, each evaluated by Blender and simulated by this handler.
            _replay(scene, scene.frame_start if previous is None else previous + 1, frame)
            return
        armature_matrix, camera, gravity = self._inputs(obj, scene, frame, depsgraph)
        reset = frame <= scene.frame_start or previous is None
        if reset:
            self.predictor, self.prediction_off = None, None  # looked at afresh from the start
            self.system.clear_cache()
            self.system.reset(
                self.matrices, armature_matrix, camera, gravity, frame / _fps(scene), self.rotations
            )
        else:
            self._step(scene, previous, frame, armature_matrix, camera, gravity)
        self.system.store_frame(frame, self.rotations)
        self.last_frame = frame
        self._write(obj, depsgraph)
        if reset and frame == scene.frame_start:
            try:
                self._start_after_reset(obj, scene, frame, depsgraph)
            except Exception:  # noqa: BLE001 - only a head start: the next frame's own path runs
                self.ahead_inputs = None  # and reports what is wrong (show_cached_frames alike)

    def _start_after_reset(self, obj, scene, frame, depsgraph):
        """After the start frame's pass (playback starting or looping): the next frame is started
        ahead now, on native threads, so that it is solved while the start frame shows and
        playback waits for the next frame's time, not on that frame's path (docs/algorithms.md
        §3.7). The rig is looked at for the prediction here (PosePredictor), once a playback, as
        the next frame would do. Only where the next frame would be solved ahead anyway (big
        rigs, the viewport's own evaluation, whole frames)."""
        if (
            len(self.rod_bones) < AHEAD_MIN_ROD_BONES
            or scene.frame_subframe
            or not _can_replay(depsgraph)
            or self.prediction_off is not None
        ):
            return
        if self.predictor is None:
            try:
                self.predictor = predict.PosePredictor(obj, self.input_bones, self.written_bones)
            except predict.Unpredictable as exc:
                self.prediction_off = str(exc)
                return
        self._start_ahead(scene, frame + 1, _fps(scene), True)  # after_reset

    def weights(self, rod_index):
        slot = self.rod_slots.get(rod_index)
        if slot is None or self.last_frame is None:
            return None
        return self.system.weights(slot)


def _same_inputs(a, b):
    """Two frames' predicted inputs (matrices, armature matrix, camera or None, gravity) are
    bit for bit the same."""
    if (a[2] is None) != (b[2] is None):
        return False
    return all(x is None or np.array_equal(x, y) for x, y in zip(a, b))


def _fps(scene):
    return scene.render.fps / scene.render.fps_base


def _gravity(scene):
    return np.array(scene.gravity if scene.use_gravity else (0.0, 0.0, 0.0), np.float64)


def _evaluated(obj, depsgraph):
    """The object as `depsgraph` evaluated it (a render's own copy during a render)."""
    return obj.evaluated_get(depsgraph) if depsgraph is not None else obj


def _can_replay(depsgraph):
    """Skipped frames are played through scene.frame_set, which only the viewport's own
    evaluation may do (not a render's depsgraph, not a nested replay)."""
    return not _replaying and (depsgraph is None or depsgraph.mode != "RENDER")


def _replay(scene, first, last):
    """Plays first..last in order; a long replay shows its progress on the cursor."""
    import bpy

    global _replaying
    _replaying = True
    wm = bpy.context.window_manager if last - first >= REPLAY_PROGRESS_FRAMES else None
    if wm is not None:
        wm.progress_begin(first, last)
    try:
        for frame in range(first, last + 1):
            scene.frame_set(frame)  # frame_change_post simulates it (previous frame cached)
            if wm is not None:
                wm.progress_update(frame)
    finally:
        _replaying = False
        if wm is not None:
            wm.progress_end()


def get(obj, build=True, counted=None):
    """The runtime of an armature object, built (or rebuilt after a change) on demand.
    `counted`: a token (the frame being set) under which the bones were already counted: a
    frame's post-evaluation handler does not count them again after its pre-evaluation one
    (Blender's pass adds or removes no bones; counting walks the channel list: 0.3 ms at 16,000
    bones)."""
    key = obj.as_pointer()
    rt = _runtimes.get(key)
    if rt is not None and (
        rt.data_pointer != obj.data.as_pointer()
        or ((counted is None or rt.counted != counted) and rt.bone_count != len(obj.pose.bones))
    ):
        rt = None  # another armature at a freed object's address, or bones added/removed: rebuild
    if rt is not None:
        rt.counted = None
    if rt is None and build:
        rt = ArmatureRuntime(obj)
        _runtimes[key] = rt
    return rt


def invalidate(obj):
    """Settings changed: rebuild at the next frame (the simulation restarts there)."""
    if obj is not None:
        _runtimes.pop(obj.as_pointer(), None)


def clear():
    _runtimes.clear()


def hair_armatures(scene):
    for obj in scene.objects:
        if obj.type == "ARMATURE":
            settings = getattr(obj, "kodawari_hair", None)
            if settings is not None and settings.enabled and len(settings.rods):
                yield obj


def evaluate_scene(scene, depsgraph=None):
    for obj in hair_armatures(scene):
        rt = None
        try:
            rt = get(obj, counted=(scene.as_pointer(), scene.frame_current))
            rt.evaluate(obj, scene, scene.frame_current, depsgraph)
        except ValueError as exc:  # e.g. a collapsed (zero-scale) armature: say why, keep the pose
            if rt is not None:
                rt.status = f"Hair not simulated: {exc}"
            else:
                problems.report(obj, "hair", exc)
        except Exception as exc:  # noqa: BLE001 - one broken rig never stops the others
            problems.report(obj, "hair", exc)
            if rt is not None:
                rt.status = f"Hair not simulated: {problems.message(obj, 'hair')}"
        else:
            if rt.error:  # a rod could not be built (its bones deleted or renamed): say so, once
                problems.report(obj, "hair", ValueError(rt.error))
            else:
                problems.clear(obj, "hair")


def show_cached_frames(scene):
    """frame_change_pre: writes the frames the caches hold, and new frames whose inputs can be
    predicted (also while a jump replays the skipped frames), before Blender evaluates them."""
    for obj in hair_armatures(scene):
        rt = get(obj, build=False)
        if rt is None:
            continue
        rt.counted = (scene.as_pointer(), scene.frame_current)  # for this frame's evaluate_scene
        try:
            rt.show_cached(obj, scene, scene.frame_current)
        except Exception:  # noqa: BLE001 - frame_change_post evaluates this frame again and reports
            continue


def store_state(obj):
    """Saves the last evaluated frame's solver state into the object (for reload)."""
    rt = get(obj, build=False)
    if rt is None or rt.last_frame is None:
        return
    state = rt.system.cached_state(rt.last_frame)
    if state is None:
        return
    obj[STATE_PROPERTY] = state.tolist()
    obj[STATE_FRAME_PROPERTY] = rt.last_frame


def restore_state(obj):
    """After a file opens: rebuild and seed the cache with the saved frame's state."""
    if STATE_PROPERTY not in obj.keys():
        return
    rt = get(obj)
    state = np.array(obj[STATE_PROPERTY], dtype=np.float64)
    frame = int(obj.get(STATE_FRAME_PROPERTY, 0))
    try:
        rt.system.load_state(state)
    except ValueError:
        return  # the rods changed since the state was saved: simulate afresh
    obj.pose.bones.foreach_get("rotation_quaternion", rt.rotations.reshape(-1))
    rt.system.store_frame(frame, rt.rotations)
    rt.last_frame = frame
