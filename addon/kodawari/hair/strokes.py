"""The artist's stroke for rod_fit_stroke: the newest annotation or grease-pencil stroke.

Annotation data differs by Blender version (scene.grease_pencil in 3.4-4.5, a legacy
GreasePencil; scene.annotation in 5.0, an Annotation), but both keep
layers -> frames -> strokes -> points[].co in world space. Grease-pencil objects are
legacy (3.4: same layout, object space) or GPv3 (4.3+: frame.drawing.strokes[].points[].position).
"""

from mathutils import Vector


def _frame_at(layer, frame_number):
    frames = list(layer.frames)
    if not frames:
        return None
    best = None
    for frame in frames:
        if frame.frame_number <= frame_number and (
            best is None or frame.frame_number >= best.frame_number
        ):
            best = frame
    return best or frames[0]


def _layers_newest_first(data):
    layers = list(data.layers)
    active = getattr(data.layers, "active", None)
    if active is not None and active in layers:
        layers.remove(active)
        layers.append(active)
    return reversed(layers)


def _last_stroke_points(data, frame_number, matrix=None):
    for layer in _layers_newest_first(data):
        frame = _frame_at(layer, frame_number)
        if frame is None:
            continue
        drawing = getattr(frame, "drawing", None)
        if drawing is not None:  # GPv3
            strokes = list(drawing.strokes)
            points = [Vector(p.position) for p in strokes[-1].points] if strokes else []
        else:
            strokes = list(frame.strokes)
            points = [Vector(p.co) for p in strokes[-1].points] if strokes else []
        if points:
            return [matrix @ p for p in points] if matrix is not None else points
    return None


def find_stroke(context, exclude=None):
    """World-space points of the newest stroke, and where it came from; (None, None) if none."""
    scene = context.scene
    annotation = getattr(scene, "annotation", None) or getattr(scene, "grease_pencil", None)
    if annotation is not None:
        points = _last_stroke_points(annotation, scene.frame_current)
        if points:
            return points, f"annotation '{annotation.name}'"
    candidates = (
        [o for o in context.selected_objects if o is not exclude]
        if context.selected_objects
        else []
    )
    candidates += [o for o in scene.objects if o not in candidates and o is not exclude]
    for obj in candidates:
        if obj.type not in {"GPENCIL", "GREASEPENCIL"}:
            continue
        points = _last_stroke_points(obj.data, scene.frame_current, obj.matrix_world)
        if points:
            return points, f"grease pencil '{obj.name}'"
    return None, None
