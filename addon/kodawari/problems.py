"""One broken creature never stops the others: failures of one object in a frame or
load handler are caught here, reported once (console and report area) and kept for
its panel until the object works again.

    try: evaluate(obj)                     except Exception as exc: problems.report(obj, "swim", exc)
    else: problems.clear(obj, "swim")

A handler runs on every frame; a broken object must not print a traceback per frame,
so the same message for the same object is said once.
"""

import bpy
from bpy.app.translations import pgettext_tip as tip_

_messages = {}  # (feature, object name) -> the message shown in the panel
_pending = []  # messages waiting for the report area (a timer shows them)
shown = []  # what the report area was given this session (the UI tests read it)


def _key(obj, feature):
    return (feature, obj.name_full)


def describe(obj, exc):
    """A user's sentence for what broke, with what to do where we know it."""
    swim = getattr(obj, "kodawari_swim", None)
    if swim is not None and getattr(obj, "type", "") == "MESH":
        missing = [f.vertex_group for f in swim.fins if f.vertex_group not in obj.vertex_groups]
        if missing:
            return tip_(
                "fin vertex group '{}' is missing (deleted or renamed): "
                "rename it back, or remove the fin"
            ).format(missing[0])
        for constraint in obj.constraints:
            target = getattr(constraint, "target", None)
            if (
                constraint.type == "FOLLOW_PATH"
                and target is not None
                and target.type == "CURVE"
                and not any(len(s.points) + len(s.bezier_points) for s in target.data.splines)
            ):
                return tip_(
                    "the Follow Path curve '{}' has no points: draw the path, "
                    "or remove the constraint"
                ).format(target.name)
    if isinstance(exc, KeyError):
        return tip_("'{}' is missing (deleted or renamed?)").format(exc.args[0] if exc.args else "")
    text = str(exc)
    return text if isinstance(exc, ValueError) and text else f"{type(exc).__name__}: {text}"


def report(obj, feature, exc):
    """Keep and say (once) that obj's `feature` failed; never raises."""
    try:
        message = describe(obj, exc)
        name = obj.name
    except Exception as inner:  # noqa: BLE001 - the object itself may be gone
        message, name = f"{type(exc).__name__}: {exc} ({inner})", "?"
    key = (feature, name) if name == "?" else _key(obj, feature)
    if _messages.get(key) == message:
        return message
    _messages[key] = message
    line = tip_("Kodawari {}: '{}' stopped: {}").format(feature, name, message)
    print(line)
    if not bpy.app.background:  # headless, the console is where the user looks
        _pending.append(line)
        if not bpy.app.timers.is_registered(_show_pending):
            # Persistent: a file opened meanwhile must not strand the waiting messages.
            bpy.app.timers.register(_show_pending, first_interval=0.1, persistent=True)
    return message


def clear(obj, feature):
    """obj works again: forget its problem (a new failure is reported again)."""
    if _messages:
        _messages.pop(_key(obj, feature), None)


def message(obj, feature):
    """The problem shown in obj's panel, or ''."""
    return _messages.get(_key(obj, feature), "")


def forget_all():
    _messages.clear()


def _show_pending():
    """Timer: a handler cannot report, an operator can; say each problem in the report area."""
    lines = list(_pending)
    _pending.clear()
    for line in lines:
        try:
            bpy.ops.kodawari.report_problem("EXEC_DEFAULT", message=line)
        except RuntimeError:
            pass  # the operator reports by cancelling, which bpy.ops raises on; the message is shown


class KODAWARI_OT_report_problem(bpy.types.Operator):
    """Show a creature's problem in the report area"""

    bl_idname = "kodawari.report_problem"
    bl_label = "Kodawari: Problem"
    bl_options = {"INTERNAL"}

    message: bpy.props.StringProperty(name="Message", description="The problem to show")

    def execute(self, context):
        shown.append(self.message)
        self.report({"ERROR"}, self.message)
        return {"CANCELLED"}
