"""One bake lifecycle for every feature: the BakeJob protocol and the operator base
that drives it (progress, status-bar hint, Esc, failures, the frame-range rule).

A job does the feature's work; BakeOperator owns everything a user sees while it runs.

    job.prepare()   validate and snapshot what the bake will touch; raise BakeError to
                    refuse (nothing may have changed when it does)
    job.step()      do the next piece of work; return the fraction done (1.0: all done)
    job.finish()    write the result; return the report line
    job.cancel()    put back everything prepare/step/finish touched; safe at any point
                    after prepare started (Esc, a failure, a file load mid-bake)

In a window the operator runs the job modally (a timer, a time budget per tick);
headless (`blender -b`, the bpy module, scripts) the same job runs to the end at once.
"""

import time
import traceback

import bpy
from bpy.app.translations import pgettext_tip as tip_
from bpy.props import IntProperty

from . import problems


class BakeError(Exception):
    """A bake refused or failed; the message is written for the user's report area."""


class BakeJob:
    """The protocol (see the module docstring). `title` names the bake in progress text."""

    title = "Bake"

    def prepare(self):
        pass

    def step(self):
        raise NotImplementedError

    def finish(self):
        raise NotImplementedError

    def cancel(self):
        pass


def frame_range(operator, scene):
    """The one frame-range rule: a frame the caller left unset is the scene's; an end
    before the start is refused. The range used is written back for the redo panel."""
    props = operator.properties
    start = operator.frame_start if props.is_property_set("frame_start") else scene.frame_start
    end = operator.frame_end if props.is_property_set("frame_end") else scene.frame_end
    if end < start:
        raise BakeError(
            tip_("End frame {} is before start frame {}: set an end at or after the start").format(
                end, start
            )
        )
    operator.frame_start, operator.frame_end = start, end
    return start, end


def failure_message(job, exc):
    """What the report area says about an exception that stopped a bake."""
    if isinstance(exc, BakeError):
        return str(exc)
    if isinstance(exc, OSError) and exc.strerror:
        where = f" '{exc.filename}'" if exc.filename else ""
        return tip_("{} failed and was undone: {}{}").format(tip_(job.title), exc.strerror, where)
    if not isinstance(exc, (ValueError, KeyError, AttributeError, IndexError, RuntimeError)):
        traceback.print_exc()  # an unexpected failure: the console keeps the details for a bug report
    try:  # the creature's own words for what broke (a deleted fin group, an empty path...)
        detail = problems.describe(job.obj, exc)
    except Exception:  # noqa: BLE001 - a job without an object, or the object is gone
        detail = f"{type(exc).__name__}: {exc}"
    return tip_("{} failed and was undone: {}").format(tip_(job.title), detail)


def cancel_quietly(job):
    """Restore after a failure; a failing restore is printed, never raised over the first error."""
    try:
        job.cancel()
    except Exception:  # noqa: BLE001 - the original failure is what the user must see
        print(f"Kodawari: could not fully undo the failed {job.title.lower()}:")
        traceback.print_exc()


def prepare(job):
    try:
        job.prepare()
    except Exception as exc:
        cancel_quietly(job)
        raise BakeError(failure_message(job, exc)) from exc


def run(job, progress=None):
    """Run a job to the end at once (headless, scripts, bake_all). Returns the report line;
    on any failure the job is cancelled (everything restored) and BakeError raised."""
    prepare(job)
    try:
        fraction = 0.0
        while fraction < 1.0:
            fraction = job.step()
            if progress is not None:
                progress(fraction)
        return job.finish()
    except Exception as exc:
        cancel_quietly(job)
        raise BakeError(failure_message(job, exc)) from exc


# The bakes running modally now: operator id -> status-bar text (shown to tests and panels).
_running = {}

# Events a running bake lets through: looking around the viewport changes no data.
NAVIGATION_EVENTS = {
    "MIDDLEMOUSE",
    "WHEELUPMOUSE",
    "WHEELDOWNMOUSE",
    "WHEELINMOUSE",
    "WHEELOUTMOUSE",
    "TRACKPADPAN",
    "TRACKPADZOOM",
    "MOUSEMOVE",
    "INBETWEEN_MOUSEMOVE",
    "NDOF_MOTION",
}
# Work per timer tick: at least MIN, four times what the window spent between ticks
# (redraws, events) so the bake gets most of the time, at most MAX so Esc answers quickly.
# Why adaptive: a slow redraw (Xvfb's software drawing here, ~1 s a window) made a fixed
# 0.05 s tick bake 300 fish frames in 12.9 s; the same bake headless takes 0.75 s.
MIN_SECONDS_PER_TICK = 0.05
MAX_SECONDS_PER_TICK = 0.25


def running_bakes():
    """Status texts of the bakes now running in a window (empty when none runs)."""
    return list(_running.values())


def status_text(job, fraction):
    return tip_("{}: {}%   Esc cancels").format(tip_(job.title), int(fraction * 100))


class BakeOperator:
    """Mixin for a bake operator: subclasses define make_job(context) -> BakeJob (raise
    BakeError to refuse). Frames left unset bake the scene's range (frame_range)."""

    bl_options = {"REGISTER", "UNDO"}
    _job = None
    _timer = None
    _workspace = None
    _last_tick_end = 0.0

    frame_start: IntProperty(
        name="Start", description="First frame to bake (unset: the scene's start)", default=1
    )
    frame_end: IntProperty(
        name="End", description="Last frame to bake (unset: the scene's end)", default=250
    )

    def make_job(self, context):
        raise NotImplementedError

    def execute(self, context):
        wm = context.window_manager
        try:
            job = self.make_job(context)
            wm.progress_begin(0, 1000)
            try:
                message = run(job, lambda fraction: wm.progress_update(int(fraction * 1000)))
            finally:
                wm.progress_end()
        except BakeError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self.report({"INFO"}, message)
        return {"FINISHED"}

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            job = self.make_job(context)
            prepare(job)
        except BakeError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self._job = job
        self._fraction = 0.0
        self._workspace = context.workspace
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        self._timer = wm.event_timer_add(0.001, window=context.window)
        wm.modal_handler_add(self)
        self._show(context)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC":
            self._end(context)
            cancel_quietly(job)
            self.report(
                {"WARNING"}, tip_("{} cancelled: nothing was changed").format(tip_(job.title))
            )
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"} if event.type in NAVIGATION_EVENTS else {"RUNNING_MODAL"}
        try:
            now = time.monotonic()
            between = now - self._last_tick_end if self._last_tick_end else 0.0
            budget = min(MAX_SECONDS_PER_TICK, max(MIN_SECONDS_PER_TICK, 4.0 * between))
            while self._fraction < 1.0 and time.monotonic() < now + budget:
                self._fraction = job.step()
            self._last_tick_end = time.monotonic()
            if self._fraction >= 1.0:
                self._end(context)
                message = job.finish()
                self.report({"INFO"}, message)
                return {"FINISHED"}
        except Exception as exc:  # noqa: BLE001 - any failure mid-bake is undone and reported
            self._end(context)
            cancel_quietly(job)
            self.report({"ERROR"}, failure_message(job, exc))
            return {"CANCELLED"}
        self._show(context)
        return {"RUNNING_MODAL"}

    def cancel(self, context):
        """Blender ends the modal bake (a file opens, the window closes): restore."""
        if getattr(self, "_job", None) is not None and id(self) in _running:
            self._end(context)
            cancel_quietly(self._job)

    def _show(self, context):
        text = status_text(self._job, self._fraction)
        _running[id(self)] = text
        context.window_manager.progress_update(int(self._fraction * 1000))
        if self._workspace is not None:
            self._workspace.status_text_set(text)

    def _end(self, context):
        _running.pop(id(self), None)
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        if self._workspace is not None:
            try:
                self._workspace.status_text_set(None)
            except ReferenceError:
                pass  # the workspace went with a file load
