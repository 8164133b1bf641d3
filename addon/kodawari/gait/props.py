"""Object.kodawari_gait: everything a gait bake needs, saved with the .blend."""

import bpy

GAIT_ITEMS = (
    ("AUTO", "Auto", "Choose the gait by speed (with hysteresis), or by Froude number"),
    ("WALK", "Walk", "Four-beat walk"),
    ("TROT", "Trot", "Diagonal pairs"),
    ("CANTER", "Canter", "Three-beat canter"),
    ("GALLOP", "Gallop", "Transverse gallop (LH, RH, LF, RF)"),
    ("GALLOP_ROTARY", "Rotary Gallop", "Rotary gallop (LH, RH, RF, LF)"),
)
GAIT_NAMES = tuple(item[0] for item in GAIT_ITEMS[1:])  # the core's kodawari_native.GAIT_NAMES
LEG_NAMES = ("LF", "RF", "LH", "RH")  # the core's kodawari_native.LEG_NAMES (checked in native.py tests)
ROOT_MOTION_ITEMS = (
    ("BONE", "Body Bone", "Key root motion on the body bone (the topmost bone whose location Blender applies)"),
    ("OBJECT", "Armature Object", "Key root motion on the armature object itself"),
)


class KodawariGaitBone(bpy.types.PropertyGroup):
    """One bone of a leg: its hinge range (degrees from the rest pose) and stiffness."""

    name: bpy.props.StringProperty(name="Bone", description="Bone name in the armature")
    limit_min: bpy.props.FloatProperty(name="Min", description="Lowest hinge angle from the rest pose, degrees "
                                       "(positive swings the tip backward)", default=-60.0, min=-180.0, max=180.0)
    limit_max: bpy.props.FloatProperty(name="Max", description="Highest hinge angle from the rest pose, degrees",
                                       default=60.0, min=-180.0, max=180.0)
    stiffness: bpy.props.FloatProperty(name="Stiffness", description="Share of each CCD turn this joint takes "
                                       "(seed: 0.1, 0.3, 0.5, 1.0 from hip to hoof)", default=1.0, min=0.01, max=1.0)


class KodawariGaitLeg(bpy.types.PropertyGroup):
    name: bpy.props.StringProperty(name="Leg", description="LF, RF, LH or RH")
    bones: bpy.props.CollectionProperty(type=KodawariGaitBone)


class KodawariGaitEntry(bpy.types.PropertyGroup):
    """One row of the gait table."""

    name: bpy.props.StringProperty(name="Gait")
    duty_factor: bpy.props.FloatProperty(name="Duty Factor", description="Stance time / cycle time",
                                         default=0.5, min=0.05, max=0.95)
    phase_fore_hind: bpy.props.FloatProperty(name="Fore-Hind Phase", description="LF lifts off this share of a "
                                             "cycle after LH (seed D1)", default=0.5, min=0.0, max=1.0)
    phase_left_right: bpy.props.FloatProperty(name="Left-Right Phase", description="RH lifts off this share of a "
                                              "cycle after LH (seed D2)", default=0.5, min=0.0, max=1.0)
    swing_time: bpy.props.FloatProperty(name="Swing Time", description="Seconds a foot is in the air",
                                        default=0.3, min=0.05, max=5.0, unit="TIME_ABSOLUTE")
    swing_height: bpy.props.FloatProperty(name="Swing Height", description="Peak foot lift",
                                          default=0.15, min=0.0, unit="LENGTH")
    swing_peak: bpy.props.FloatProperty(name="Swing Peak", description="Where in the swing the foot is highest",
                                        default=0.4, min=0.05, max=0.95)
    bob: bpy.props.FloatProperty(name="Body Bob", description="How far the body dips", default=0.03, min=0.0,
                                 unit="LENGTH")
    bobs_per_cycle: bpy.props.FloatProperty(name="Bobs per Cycle", default=2.0, min=0.0, max=8.0)
    speed_max: bpy.props.FloatProperty(name="Top Speed", description="AUTO: top of this gait's band (m/s)",
                                       default=2.0, min=0.0, unit="VELOCITY")
    froude_max: bpy.props.FloatProperty(name="Top Froude", description="AUTO with Froude: top of the band as "
                                        "v²/(g·leg length)", default=0.35, min=0.0)
    use_in_auto: bpy.props.BoolProperty(name="In Auto", description="AUTO may choose this gait", default=True)
    duty_factor_top: bpy.props.FloatProperty(name="Duty Factor at Top", description="Duty factor at the top of the "
                                             "gait's speed band; it changes linearly from Duty Factor at the band's "
                                             "bottom (gallops: the stance shortens with speed)",
                                             default=0.5, min=0.05, max=0.95)


class KodawariGaitSettings(bpy.types.PropertyGroup):
    speed: bpy.props.FloatProperty(name="Speed", description="How fast the animal goes, m/s (key it to direct "
                                   "the run)", default=1.5, min=-100.0, max=100.0, unit="VELOCITY",
                                   options={"ANIMATABLE"})
    gait: bpy.props.EnumProperty(name="Gait", items=GAIT_ITEMS, default="AUTO")
    table: bpy.props.CollectionProperty(type=KodawariGaitEntry, description="The gait table, one row per gait")
    use_froude: bpy.props.BoolProperty(name="Froude Bands", description="AUTO chooses by Froude number "
                                       "v²/(g·leg length) instead of speed", default=False)
    hysteresis: bpy.props.FloatProperty(name="Hysteresis", description="AUTO leaves a gait only this far (m/s) "
                                        "past its band, so it does not flicker", default=0.15, min=0.0,
                                        unit="VELOCITY")
    reach: bpy.props.FloatProperty(name="Reach", description="How far a foot may go fore and aft of its leg root, "
                                   "as a share of the leg length (horse: 0.8 m of 1.6 m)", default=0.5,
                                   min=0.05, max=1.0)
    legs: bpy.props.CollectionProperty(type=KodawariGaitLeg)
    body_bone: bpy.props.StringProperty(name="Body Bone", description="The bone carrying root motion")
    root_motion: bpy.props.EnumProperty(name="Root Motion", items=ROOT_MOTION_ITEMS, default="BONE",
                                        description="Where the bake keys the animal's travel")
    ccd_iterations: bpy.props.IntProperty(name="CCD Iterations", default=64, min=1, max=1000)
    acceleration: bpy.props.FloatProperty(name="Acceleration", description="Largest change of speed, m/s²",
                                          default=3.0, min=0.01, max=1000.0)
    ground: bpy.props.PointerProperty(name="Ground", type=bpy.types.Object,
                                      description="Optional mesh the feet follow (ray casts)",
                                      poll=lambda self, obj: obj.type == "MESH")
    path: bpy.props.PointerProperty(name="Path", type=bpy.types.Object,
                                    description="Optional curve the animal follows",
                                    poll=lambda self, obj: obj.type == "CURVE")
