"""Object.kodawari_gait: everything a gait bake needs, saved with the .blend."""

import bpy

GAIT_ITEMS = (
    ("AUTO", "Auto", "Choose the gait by speed (with hysteresis), or by Froude number"),
    ("WALK", "Walk", "Four-beat walk"),
    ("TROT", "Trot", "Diagonal pairs"),
    ("CANTER", "Canter", "Three-beat canter"),
    (
        "GALLOP",
        "Gallop",
        "Transverse gallop: hind feet then fore feet, each pair in the same order",
    ),
    (
        "GALLOP_ROTARY",
        "Rotary Gallop",
        "Rotary gallop: the feet land in a circle (hind left, hind right, fore right, fore left)",
    ),
)
GAIT_NAMES = tuple(item[0] for item in GAIT_ITEMS[1:])  # the core's kodawari_native.GAIT_NAMES
LEG_NAMES = ("LF", "RF", "LH", "RH")  # the core's kodawari_native.LEG_NAMES (a test checks both)
ROOT_MOTION_ITEMS = (
    (
        "BONE",
        "Body Bone",
        "Key root motion on the body bone (the topmost bone whose location Blender applies)",
    ),
    ("OBJECT", "Armature Object", "Key root motion on the armature object's delta transforms"),
)


class KodawariGaitBone(bpy.types.PropertyGroup):
    """One bone of a leg: its hinge range (degrees from the rest pose) and stiffness."""

    name: bpy.props.StringProperty(name="Bone", description="Bone name in the armature")
    limit_min: bpy.props.FloatProperty(
        name="Min (°)",
        description="Lowest bend from the rest pose, in degrees (positive swings the tip backward)",
        default=-60.0,
        min=-180.0,
        max=180.0,
    )
    limit_max: bpy.props.FloatProperty(
        name="Max (°)",
        description="Highest bend from the rest pose, in degrees",
        default=60.0,
        min=-180.0,
        max=180.0,
    )
    stiffness: bpy.props.FloatProperty(
        name="Stiffness",
        description="How readily this joint bends to reach the ground "
        "(a horse: low at the hip, full at the hoof)",
        subtype="FACTOR",
        default=1.0,
        min=0.01,
        max=1.0,
    )


class KodawariGaitLeg(bpy.types.PropertyGroup):
    name: bpy.props.StringProperty(name="Leg", description="Which leg: left or right, fore or hind")
    bones: bpy.props.CollectionProperty(
        type=KodawariGaitBone, name="Bones", description="The leg's bones, hip to hoof"
    )


class KodawariGaitEntry(bpy.types.PropertyGroup):
    """One row of the gait table."""

    name: bpy.props.StringProperty(name="Gait", description="Which gait this row is")
    duty_factor: bpy.props.FloatProperty(
        name="Duty Factor",
        description="Share of a stride each foot is on the ground",
        subtype="FACTOR",
        default=0.5,
        min=0.05,
        max=0.95,
    )
    phase_fore_hind: bpy.props.FloatProperty(
        name="Fore-Hind",
        description="How long after the left hind foot the "
        "left fore foot lifts, as a share of a stride",
        subtype="FACTOR",
        default=0.5,
        min=0.0,
        max=1.0,
    )
    phase_left_right: bpy.props.FloatProperty(
        name="Left-Right",
        description="How long after the left hind foot "
        "the right hind foot lifts, as a share of a stride",
        subtype="FACTOR",
        default=0.5,
        min=0.0,
        max=1.0,
    )
    swing_time: bpy.props.FloatProperty(
        name="Swing Time",
        description="Seconds a foot is in the air",
        default=0.3,
        min=0.05,
        max=5.0,
        unit="TIME_ABSOLUTE",
    )
    swing_height: bpy.props.FloatProperty(
        name="Swing Height",
        description="How high a foot lifts",
        subtype="DISTANCE",
        default=0.15,
        min=0.0,
        unit="LENGTH",
    )
    swing_peak: bpy.props.FloatProperty(
        name="Swing Peak",
        description="When in its swing the foot is highest",
        subtype="FACTOR",
        default=0.4,
        min=0.05,
        max=0.95,
    )
    bob: bpy.props.FloatProperty(
        name="Body Bob",
        description="How far the body dips",
        default=0.03,
        min=0.0,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    bobs_per_cycle: bpy.props.FloatProperty(
        name="Bob Count",
        default=2.0,
        min=0.0,
        max=8.0,
        description="How many times the body dips in one stride",
    )
    speed_max: bpy.props.FloatProperty(
        name="Top Speed",
        description="Auto: the fastest speed at which this gait is chosen",
        default=2.0,
        min=0.0,
        unit="VELOCITY",
    )
    froude_max: bpy.props.FloatProperty(
        name="Top Froude",
        description="Auto by Froude number: the fastest speed, "
        "relative to leg length, at which this gait is chosen",
        default=0.35,
        min=0.0,
    )
    use_in_auto: bpy.props.BoolProperty(
        name="In Auto", description="Auto may choose this gait", default=True
    )
    duty_factor_top: bpy.props.FloatProperty(
        name="Duty at Top",
        description="Share of a stride each foot is "
        "on the ground at the top of the gait's speed band (gallops: the stance "
        "shortens with speed)",
        subtype="FACTOR",
        default=0.5,
        min=0.05,
        max=0.95,
    )


class KodawariGaitSettings(bpy.types.PropertyGroup):
    speed: bpy.props.FloatProperty(
        name="Speed",
        description="How fast the animal goes (key it to direct the run)",
        default=1.5,
        min=-100.0,
        max=100.0,
        unit="VELOCITY",
        options={"ANIMATABLE"},
    )
    gait: bpy.props.EnumProperty(
        name="Gait",
        items=GAIT_ITEMS,
        default="AUTO",
        description="Which gait to use (Auto: chosen by speed)",
    )
    table: bpy.props.CollectionProperty(
        type=KodawariGaitEntry, description="The gait table, one row per gait"
    )
    use_froude: bpy.props.BoolProperty(
        name="Froude Bands",
        description="Auto chooses by speed relative to leg length "
        "(Froude number), so small and large animals change gait alike",
        default=False,
    )
    hysteresis: bpy.props.FloatProperty(
        name="Hysteresis",
        description="Auto changes gait only this far past "
        "its speed band, so it does not flicker between two",
        default=0.15,
        min=0.0,
        unit="VELOCITY",
    )
    reach: bpy.props.FloatProperty(
        name="Reach",
        description="How far a foot may go fore and aft of its leg root, "
        "as a share of the leg length (horse: 0.8 m of 1.6 m)",
        default=0.5,
        subtype="FACTOR",
        min=0.05,
        max=1.0,
    )
    legs: bpy.props.CollectionProperty(
        type=KodawariGaitLeg, name="Legs", description="The four legs Gait Setup found"
    )
    body_bone: bpy.props.StringProperty(
        name="Body Bone",
        description="The bone that carries the animal forward (the legs' common parent)",
    )
    root_motion: bpy.props.EnumProperty(
        name="Root Motion",
        items=ROOT_MOTION_ITEMS,
        default="BONE",
        description="Where the bake keys the animal's travel",
    )
    ccd_iterations: bpy.props.IntProperty(
        name="Iterations",
        default=64,
        min=1,
        max=1000,
        description="How hard each leg tries to reach its foot target",
    )
    acceleration: bpy.props.FloatProperty(
        name="Acceleration",
        description="How quickly the speed may change",
        default=3.0,
        min=0.01,
        max=1000.0,
        unit="ACCELERATION",
    )
    ground: bpy.props.PointerProperty(
        name="Ground",
        type=bpy.types.Object,
        description="Optional mesh the feet follow (ray casts)",
        poll=lambda self, obj: obj.type == "MESH",
    )
    path: bpy.props.PointerProperty(
        name="Path",
        type=bpy.types.Object,
        description="Optional curve the animal follows",
        poll=lambda self, obj: obj.type == "CURVE",
    )
