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

from .. import cache_paths
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
        description="Which fin this is; it sets the default motion and where the fin's root is",
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
        description="How the fin moves",
    )
    enabled: BoolProperty(
        name="Enabled",
        default=True,
        update=_refresh,
        description="Move this fin (off: it follows the body only)",
    )
    amplitude: FloatProperty(
        name="Amplitude",
        description="How far the fin swings to each side. Undulate: the sideways reach as a share of the fin's height (1 rad = 1 height)",
        subtype="ANGLE",
        default=0.3,
        min=0.0,
        soft_max=1.5,
        update=_refresh,
    )
    frequency_ratio: FloatProperty(
        name="Beat Ratio",
        description="Fin beats per tail beat (1: same frequency as the body)",
        default=1.0,
        min=0.0,
        soft_max=4.0,
        update=_refresh,
    )
    phase_lag: FloatProperty(
        name="Phase Lag",
        description="How far the fin's beat lags behind the body's",
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
        description="Undulate: length of the wave along the fin, in fin-base lengths",
        default=0.8,
        min=0.05,
        soft_max=4.0,
        update=_refresh,
    )
    root_blend: FloatProperty(
        name="Root Blend",
        description="Share of the fin, from its root, that blends from the body's motion into its own",
        subtype="FACTOR",
        default=0.35,
        min=0.01,
        max=1.0,
        update=_rebind,
    )


class KodawariSwimSettings(bpy.types.PropertyGroup):
    """The fish swim deformer of one mesh object."""

    enabled: BoolProperty(
        name="Show in Viewport",
        description="Show the swim in the viewport (off: the fish keeps its rest shape there)",
        default=False,
        update=_refresh,
    )
    show_render: BoolProperty(
        name="Show in Render",
        description="Use the swim when rendering (off: the fish renders in its rest shape)",
        default=True,
        update=_refresh,
    )
    preset: EnumProperty(
        name="Preset",
        items=[(k, *presets.LABELS[k]) for k in presets.ORDER],
        default="CARANGIFORM",
        update=_preset_changed,
        description="A kind of swimmer: sets the body wave and the fins' motions (you can tune them after)",
    )
    head_axis: EnumProperty(
        name="Head Axis",
        items=HEAD_AXES,
        default="POS_X",
        update=_rebind,
        description="Object axis the head points along",
    )
    control_points: IntProperty(
        name="Axis Points",
        description="How many points bend the body: more follow a long body's wave more closely",
        default=8,
        # 4-5 points (one or two B-spline spans) cannot carry a travelling wave
        min=6,
        max=32,
        update=_rebind,
    )
    frequency: FloatProperty(
        name="Frequency",
        description="Tail beats per second",
        default=2.0,
        min=0.0,
        soft_max=10.0,
        update=_refresh,
    )
    wavelength: FloatProperty(
        name="Wavelength",
        description="Length of the body wave, in body lengths (short: eel-like, long: tuna-like)",
        default=1.0,
        min=0.05,
        soft_max=4.0,
        update=_refresh,
    )
    amplitude: FloatProperty(
        name="Amplitude",
        description="How far the tail tip swings to each side, as a share of the body length",
        subtype="FACTOR",
        precision=3,
        default=0.06,
        min=0.0,
        soft_max=0.3,
        max=1.0,
        update=_refresh,
    )
    amplitude_head: FloatProperty(
        name="Snout Swing",
        description="How far the snout swings to each side, as a share of the body length",
        subtype="FACTOR",
        precision=3,
        default=0.006,
        min=0.0,
        soft_max=0.3,
        max=1.0,
        update=_refresh,
    )
    envelope_start: FloatProperty(
        name="Swing Starts",
        description="Where along the body, from the snout, the swing starts to grow toward the tail",
        default=0.45,
        min=0.0,
        max=0.99,
        subtype="FACTOR",
        update=_refresh,
    )
    envelope_power: FloatProperty(
        name="Swing Ramp",
        description="How the swing grows toward the tail: 1 evenly, higher keeps it near the tail",
        default=1.6,
        min=0.1,
        soft_max=5.0,
        update=_refresh,
    )
    bend: EnumProperty(
        name="Bend",
        items=[
            ("LATERAL", "Lateral", "Side to side (most fish)"),
            ("DORSOVENTRAL", "Up and Down", "Up and down (whales, dolphins)"),
        ],
        default="LATERAL",
        description="Which way the body bends",
        update=_refresh,
    )
    preserve_length: BoolProperty(
        name="Preserve Length",
        description="Keep the body's length while it bends",
        default=True,
        update=_refresh,
    )
    phase_offset: FloatProperty(
        name="Time Shift",
        description="Shifts the wave in time, so fish in a school do not swim in step",
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
                "From Tail Beat",
                (
                    "Faster with a faster tail beat, as measured on real fish (Bainbridge 1958: "
                    "V = L(3f - 4)/4, fitted above about 5 Hz; where it leaves Strouhal 0.2-0.4, "
                    "the Strouhal speed). Fin swimmers: half a body length per fin beat"
                ),
            ),
            (
                "STROUHAL",
                "From Tail Swing",
                (
                    "Faster with a wider, faster tail swing (Strouhal number). Fin swimmers (no body "
                    "wave): half a body length per fin beat"
                ),
            ),
        ],
        default="NONE",
        description="Whether and how the fish moves forward as it swims",
        update=_speed_changed,
    )
    strouhal: FloatProperty(
        name="Strouhal",
        description="Lower swims faster for the same tail beat (real fish: 0.2 to 0.4)",
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
    fins: CollectionProperty(
        type=KodawariSwimFin, name="Fins", description="The fins that move on their own"
    )
    fin_index: IntProperty(name="Active Fin", default=0, description="The fin shown below the list")
    show_axis: BoolProperty(
        name="Show Axis", description="Draw the control axis in the viewport", default=True
    )

    # Book-keeping (not shown): what swim_add found and what it must restore.
    head_guess: StringProperty(
        name="Head Guess", description="Which way Add Fish Swim guessed the head points, and why"
    )
    rest_delta_location: FloatVectorProperty(
        name="Rest Delta Location",
        size=3,
        subtype="TRANSLATION",
        description="Where the fish was before it swam off (restored when the swim is removed)",
    )
    baked: EnumProperty(
        name="Baked",
        items=[
            ("NONE", "Live", "Evaluated live"),
            ("MESH_CACHE", "Mesh Cache", "Baked to a PC2 point cache"),
            ("SHAPE_KEYS", "Shape Keys", "Baked to shape keys"),
        ],
        default="NONE",
        description="Whether the swim is live or baked, and to what",
    )
    cache_path: StringProperty(
        name="Cache Path",
        subtype="FILE_PATH",
        options=cache_paths.RELATIVE_PATH_OPTIONS,
        description="The baked point cache file",
    )
