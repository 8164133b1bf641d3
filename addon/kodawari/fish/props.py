"""Fish swim settings, saved with the object: Object.kodawari_swim.

Every setting is animatable; changing one re-evaluates the current frame, and
the ones that change the binding (head axis, control points, fins) rebuild it.
"""

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    StringProperty,
)

from . import presets

HEAD_AXES = (
    ("POS_X", "+X", "The head points along +X (object space)"),
    ("NEG_X", "-X", "The head points along -X"),
    ("POS_Y", "+Y", "The head points along +Y"),
    ("NEG_Y", "-Y", "The head points along -Y"),
    ("POS_Z", "+Z", "The head points along +Z"),
    ("NEG_Z", "-Z", "The head points along -Z"),
)


def _runtime():
    from . import runtime  # late: runtime imports props

    return runtime


def _refresh(self, context):
    _runtime().refresh(self.id_data)


def _rebind(self, context):
    _runtime().rebind(self.id_data)


def _speed_changed(self, context):
    # Back to swimming on the spot: put the object where it was before it swam off.
    if self.speed_mode == "NONE":
        self.id_data.delta_location = self.rest_delta_location
    _refresh(self, context)


def _preset_changed(self, context):
    obj = self.id_data
    with _runtime().batch(obj):
        presets.apply_body(self, self.preset)
        presets.apply_fins(self, self.preset)
    _runtime().rebind(obj)


class KodawariSwimFin(bpy.types.PropertyGroup):
    """One fin: its vertices (a vertex group), kind and motion."""

    vertex_group: StringProperty(
        name="Vertex Group", description="Vertices of this fin", update=_rebind
    )
    kind: EnumProperty(
        name="Kind",
        items=[(k, k.title(), f"{k.title()} fin") for k in presets.FIN_KINDS],
        default="PECTORAL",
        update=_rebind,
    )
    motion: EnumProperty(
        name="Motion",
        items=[
            (
                "FLAP",
                "Flap",
                "Forward/back about the root, with feathering (blade edge-on on the recovery)",
            ),
            ("UP_DOWN", "Up-Down", "Up and down about the body axis"),
            ("TWIST", "Twist", "Roll about the fin's own axis"),
            ("UNDULATE", "Undulate", "A wave along the fin base (dorsal and anal fins)"),
        ],
        default="FLAP",
        update=_rebind,
    )
    enabled: BoolProperty(name="Enabled", default=True, update=_refresh)
    amplitude: FloatProperty(
        name="Amplitude",
        description="Peak angle (radians) for Flap, Up-Down and Twist; sideways excursion as a fraction of the fin's height for Undulate",
        default=0.3,
        min=0.0,
        soft_max=1.5,
        update=_refresh,
    )
    frequency_ratio: FloatProperty(
        name="Frequency Ratio",
        description="Fin beats per tail beat (1: same frequency as the body)",
        default=1.0,
        min=0.0,
        soft_max=4.0,
        update=_refresh,
    )
    phase_lag: FloatProperty(
        name="Phase Lag",
        description="Lag behind the body wave",
        subtype="ANGLE",
        default=0.0,
        update=_refresh,
    )
    feathering: FloatProperty(
        name="Feathering",
        description="Flap: roll of the blade on the recovery stroke (0 on the power stroke)",
        subtype="ANGLE",
        default=0.0,
        soft_min=-3.1416,
        soft_max=3.1416,
        update=_refresh,
    )
    wavelength: FloatProperty(
        name="Wavelength",
        description="Undulate: wave length in fin-base lengths",
        default=0.8,
        min=0.05,
        soft_max=4.0,
        update=_refresh,
    )
    root_blend: FloatProperty(
        name="Root Blend",
        description="Fraction of the fin, from its root, over which it blends from the body's motion to its own",
        default=0.35,
        min=0.01,
        max=1.0,
        update=_rebind,
    )


class KodawariSwimSettings(bpy.types.PropertyGroup):
    """The fish swim deformer of one mesh object."""

    enabled: BoolProperty(
        name="Enabled",
        description="Evaluate the swim on frame changes",
        default=False,
        update=_refresh,
    )
    preset: EnumProperty(
        name="Preset",
        items=[(k, *presets.LABELS[k]) for k in presets.ORDER],
        default="CARANGIFORM",
        update=_preset_changed,
    )
    head_axis: EnumProperty(
        name="Head Axis",
        items=HEAD_AXES,
        default="POS_X",
        update=_rebind,
        description="Object axis the head points along",
    )
    control_points: IntProperty(
        name="Control Points",
        description="Control points of the body axis",
        default=8,
        min=4,
        max=32,
        update=_rebind,
    )
    frequency: FloatProperty(
        name="Frequency",
        description="Tail beats per second (Hz)",
        default=2.0,
        min=0.0,
        soft_max=10.0,
        update=_refresh,
    )
    wavelength: FloatProperty(
        name="Wavelength",
        description="Body wave length in body lengths",
        default=1.0,
        min=0.05,
        soft_max=4.0,
        update=_refresh,
    )
    amplitude: FloatProperty(
        name="Amplitude",
        description="Tail-tip peak amplitude as a fraction of body length",
        default=0.06,
        min=0.0,
        soft_max=0.3,
        max=1.0,
        update=_refresh,
    )
    amplitude_head: FloatProperty(
        name="Head Amplitude",
        description="Snout peak amplitude as a fraction of body length",
        default=0.006,
        min=0.0,
        soft_max=0.3,
        max=1.0,
        update=_refresh,
    )
    envelope_start: FloatProperty(
        name="Envelope Start",
        description="Where, from the snout (fraction of the body), the amplitude starts to grow",
        default=0.45,
        min=0.0,
        max=0.99,
        subtype="FACTOR",
        update=_refresh,
    )
    envelope_power: FloatProperty(
        name="Envelope Power",
        description="How the amplitude grows toward the tail (1 linear, 2 quadratic...)",
        default=1.6,
        min=0.1,
        soft_max=5.0,
        update=_refresh,
    )
    bend: EnumProperty(
        name="Bend",
        items=[
            ("LATERAL", "Lateral", "Side to side (most fish)"),
            ("DORSOVENTRAL", "Dorsoventral", "Up and down (marine mammals)"),
        ],
        default="LATERAL",
        update=_refresh,
    )
    preserve_length: BoolProperty(
        name="Preserve Length",
        description="Keep the body's length while it bends",
        default=True,
        update=_refresh,
    )
    phase_offset: FloatProperty(
        name="Phase Offset",
        description="Shift of the wave",
        subtype="ANGLE",
        default=0.0,
        update=_refresh,
    )
    speed_mode: EnumProperty(
        name="Speed",
        items=[
            ("NONE", "None", "Swim on the spot"),
            (
                "BAINBRIDGE",
                "Bainbridge",
                (
                    "V = L(3f - 4)/4 (Bainbridge 1958), fitted above about 5 Hz: elsewhere the "
                    "speed is held to Strouhal 0.2-0.4. Fin swimmers: half a body length per fin beat"
                ),
            ),
            (
                "STROUHAL",
                "Strouhal",
                (
                    "U = f A / St, A the tail's peak-to-peak excursion. Fin swimmers (no body "
                    "wave): half a body length per fin beat"
                ),
            ),
        ],
        default="NONE",
        update=_speed_changed,
    )
    strouhal: FloatProperty(
        name="Strouhal",
        description="Strouhal number St = f A / U (0.2-0.4 in nature)",
        default=0.3,
        min=0.05,
        max=2.0,
        update=_refresh,
    )
    path_start: FloatProperty(
        name="Path Start",
        description="Along a Follow Path curve: where the swim starts (fraction of the path)",
        default=0.0,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
        update=_refresh,
    )
    fins: CollectionProperty(type=KodawariSwimFin)
    fin_index: IntProperty(name="Active Fin", default=0)
    show_axis: BoolProperty(
        name="Show Axis", description="Draw the control axis in the viewport", default=True
    )

    # Book-keeping (not shown): what swim_add found and what it must restore.
    head_guess: StringProperty(
        name="Head Guess", description="What Add Fish Swim guessed for the head axis"
    )
    rest_delta_location: FloatVectorProperty(
        name="Rest Delta Location", size=3, subtype="TRANSLATION"
    )
    baked: EnumProperty(
        name="Baked",
        items=[
            ("NONE", "Live", "Evaluated live"),
            ("MESH_CACHE", "Mesh Cache", "Baked to a PC2 point cache"),
            ("SHAPE_KEYS", "Shape Keys", "Baked to shape keys"),
        ],
        default="NONE",
    )
    cache_path: StringProperty(name="Cache Path", subtype="FILE_PATH")
