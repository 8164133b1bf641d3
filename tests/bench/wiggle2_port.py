"""A PORT of Wiggle 2's bone-tail algorithm, for the hair benchmark only (not Wiggle 2 itself:
that add-on cannot be downloaded on this machine).

Written here from a reading of Wiggle 2's public source (Steve Miller, github.com/shteeve3d/
blender-wiggle-2, wiggle_2.py, version 2.1), keeping what decides its cost per frame:

- per-bone settings are registered RNA properties on PoseBone (mass, stiffness, stretch,
  damping, gravity, wind, chain, collider settings; Wiggle 2's defaults), and the simulation
  state (tail position, last position, velocity, a 4x4 world matrix) lives in a registered
  PropertyGroup on each pose bone, read and written through RNA every step;
- frame_change_pre: every wiggling bone's location / rotations / scale reset to rest, then a
  full `view_layer.update()` so the parents' evaluated matrices are current;
- frame_change_post: dt from the frames elapsed; wind summed over the scene's force fields;
  per bone a Verlet move (damped velocity, gravity + wind, pin to a Damped Track target if
  any, collide against the bone's colliders if any) and a matrix update; then ITERATIONS
  (Wiggle 2's default "Quality" 2) sweeps of constraints per bone (spring towards the rest
  direction under the parent's simulated matrix, then length / stretch, each split between
  the bone and its parent by mass in a chain) with a matrix update after each; finally the
  velocities from the positions. Each matrix update writes `PoseBone.matrix`.

Only what the benchmark uses is ported: tail wiggle (Wiggle 2's "Bone Tail") on connected
chains, chain mode on, no head wiggle, no colliders present (the checks still run), no bake.
"""

import bpy
from mathutils import Matrix, Vector

ITERATIONS = 2  # Wiggle 2's default "Quality"
PREFIX = "kbw_"  # our property names: nothing here claims to be Wiggle 2's own


def _relative(m1, m2):
    """m2 expressed in m1's space, computed the way the original does (two inversions)."""
    return (m2.inverted() @ m1).inverted()


def _flatten(matrix):
    return [matrix[j][i] for i in range(4) for j in range(4)]


class KbwState(bpy.types.PropertyGroup):
    matrix: bpy.props.FloatVectorProperty(size=16, subtype="MATRIX")
    position: bpy.props.FloatVectorProperty(subtype="TRANSLATION")
    position_last: bpy.props.FloatVectorProperty(subtype="TRANSLATION")
    velocity: bpy.props.FloatVectorProperty(subtype="VELOCITY")
    collision_normal: bpy.props.FloatVectorProperty(subtype="TRANSLATION")
    collision_object: bpy.props.PointerProperty(type=bpy.types.Object)


_SETTINGS = {
    "tail": bpy.props.BoolProperty(default=False),
    "mass": bpy.props.FloatProperty(min=0.01, default=1.0),
    "stiff": bpy.props.FloatProperty(min=0.0, default=400.0),
    "stretch": bpy.props.FloatProperty(min=0.0, max=1.0, default=0.0),
    "damp": bpy.props.FloatProperty(min=0.0, default=1.0),
    "gravity": bpy.props.FloatProperty(default=1.0),
    "wind": bpy.props.FloatProperty(default=1.0),
    "chain": bpy.props.BoolProperty(default=True),
    "collider_type": bpy.props.EnumProperty(
        items=[("Object", "Object", ""), ("Collection", "Collection", "")]
    ),
    "collider": bpy.props.PointerProperty(type=bpy.types.Object),
    "collider_collection": bpy.props.PointerProperty(type=bpy.types.Collection),
    "radius": bpy.props.FloatProperty(min=0.0, default=0.0),
    "bounce": bpy.props.FloatProperty(min=0.0, default=0.5),
}
_registered = False


def register():
    global _registered
    if _registered:
        return
    bpy.utils.register_class(KbwState)
    bpy.types.PoseBone.kbw_state = bpy.props.PointerProperty(type=KbwState)
    for name, prop in _SETTINGS.items():
        setattr(bpy.types.PoseBone, PREFIX + name, prop)
    _registered = True


def _get(b, name):
    return getattr(b, PREFIX + name)


class WigglePort:
    def __init__(self, scene, obj, bones):
        register()
        self.scene, self.obj = scene, obj
        self.names = [b.name for b in bones]
        for b in bones:
            setattr(b, PREFIX + "tail", True)
        self.dt = 0.0
        self.last_frame = scene.frame_start
        self.wind = Vector((0.0, 0.0, 0.0))
        self._pre = lambda scene, *args: self.pre(scene)
        self._post = lambda scene, *args: self.post(scene)

    # -- installation as frame handlers, as the add-on does ---------------------------------
    def install(self):
        if self._pre not in bpy.app.handlers.frame_change_pre:
            bpy.app.handlers.frame_change_pre.append(self._pre)
            bpy.app.handlers.frame_change_post.append(self._post)

    def uninstall(self):
        if self._pre in bpy.app.handlers.frame_change_pre:
            bpy.app.handlers.frame_change_pre.remove(self._pre)
            bpy.app.handlers.frame_change_post.remove(self._post)

    def bones(self):
        pose = self.obj.pose.bones
        return [pose[name] for name in self.names]

    def reset(self):
        world = self.obj.matrix_world
        for b in self.bones():
            state = b.kbw_state
            state.position = state.position_last = (world @ Matrix.Translation(b.tail)).translation
            state.velocity = state.collision_normal = Vector((0.0, 0.0, 0.0))
            state.matrix = _flatten(world @ b.matrix)
        self.last_frame = self.scene.frame_current

    # -- the algorithm -------------------------------------------------------------------
    def sim_parent(self, b):
        """The nearest ancestor that wiggles (tail), or None."""
        p = b.parent
        while p is not None and not _get(p, "tail"):
            p = p.parent
        return p

    def length_world(self, b):
        world = self.obj.matrix_world
        return (world @ b.head - world @ b.tail).length

    def collide(self, b):
        colliders = []
        kind, single, group = (
            _get(b, "collider_type"),
            _get(b, "collider"),
            _get(b, "collider_collection"),
        )
        if kind == "Object" and single and single.name in self.scene.objects:
            colliders = [single]
        if kind == "Collection" and group and group in self.scene.collection.children_recursive:
            colliders = [o for o in group.objects if o.type == "MESH"]
        position = b.kbw_state.position
        for collider in colliders:  # none in the benchmark; kept so the checks cost what they cost
            world = collider.matrix_world
            hit = collider.closest_point_on_mesh(world.inverted() @ position)
            normal = (world.to_quaternion().to_matrix().to_4x4() @ hit[2]).normalized()
            point = world @ hit[1]
            if normal.dot((point - position).normalized()) > 0.01:
                position = point + normal * _get(b, "radius")
                b.kbw_state.collision_normal = normal
        if colliders:
            b.kbw_state.position = position
        else:
            b.kbw_state.collision_object = None

    def pin(self, b):
        for c in b.constraints:
            if c.type == "DAMPED_TRACK" and c.target and not c.mute:
                state = b.kbw_state
                state.position = (
                    state.position * (1 - c.influence) + c.target.location * c.influence
                )
                break

    def update_matrix(self, b):
        state = b.kbw_state
        p = self.sim_parent(b)
        if p is not None:
            mat = p.kbw_state.matrix @ _relative(p.matrix, b.matrix)
        else:
            mat = self.obj.matrix_world @ b.matrix
        frame = mat
        direction = _relative(frame, Matrix.Translation(state.position)).translation
        rotation = direction.to_track_quat("Y", "Z").to_matrix().to_4x4()
        stretch = (
            _relative(mat, Matrix.Translation(state.position)).translation.length / b.bone.length
        )
        scale = Matrix.Scale(stretch, 4, Vector((0.0, 1.0, 0.0)))
        b.matrix = b.matrix @ rotation @ scale
        state.matrix = _flatten(frame @ rotation @ scale)

    def move(self, b):
        dt = self.dt
        state = b.kbw_state
        damp = max(min(1 - _get(b, "damp") * dt, 1), 0)
        state.velocity = state.velocity * damp
        force = self.scene.gravity * _get(b, "gravity") + self.wind * _get(b, "wind") / _get(
            b, "mass"
        )
        state.position += state.velocity + force * dt * dt
        self.pin(b)
        self.collide(b)
        self.update_matrix(b)

    def constrain(self, b, sweep):
        dt = self.dt
        state = b.kbw_state
        p = self.sim_parent(b)
        if p is not None:
            mat = p.kbw_state.matrix @ _relative(p.matrix, b.matrix)
        else:
            mat = self.obj.matrix_world @ b.matrix
        loc, rot, _ = mat.decompose()
        mat = Matrix.LocRotScale(loc, rot, b.matrix.decompose()[2])
        chained = p is not None and _get(b, "chain")

        def share(pull):
            # split a correction between the bone's tail and its parent's tail, by mass
            if chained:
                mass, parent_mass = _get(b, "mass"), _get(p, "mass")
                fac = (
                    (0.5 if mass == parent_mass else mass / (mass + parent_mass))
                    if sweep
                    else _get(p, "stretch")
                )
                p.kbw_state.position -= pull * fac
                state.position += pull * (1 - fac)
            else:
                state.position += pull

        # spring towards the rest direction under the parent
        target = mat @ Vector((0.0, b.bone.length, 0.0))
        share((target - state.position) * _get(b, "stiff") / ITERATIONS * dt * dt)
        # length (stretch)
        head = mat.translation
        target = head + (state.position - head).normalized() * self.length_world(b)
        share((target - state.position) * (1 - _get(b, "stretch")))
        if chained:
            self.collide(p)
            self.update_matrix(p)
        self.pin(b)
        self.collide(b)
        self.update_matrix(b)

    # -- handlers ------------------------------------------------------------------------
    def pre(self, scene):
        if scene != self.scene:
            return
        for b in self.bones():
            b.location = Vector((0.0, 0.0, 0.0))
            b.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
            b.rotation_euler = Vector((0.0, 0.0, 0.0))
            b.scale = Vector((1.0, 1.0, 1.0))
        bpy.context.view_layer.update()

    def post(self, scene):
        if scene != self.scene:
            return
        frame = scene.frame_current
        if frame >= self.last_frame:
            elapsed = frame - self.last_frame
        else:
            elapsed = min(
                (scene.frame_end - self.last_frame) + (frame - scene.frame_start) + 1,
                self.last_frame - frame,
            )
        if elapsed > 4:
            elapsed = 1
        self.dt = elapsed / scene.render.fps
        self.last_frame = frame
        self.wind = Vector((0.0, 0.0, 0.0))
        for o in scene.objects:
            if o.field and o.field.type == "WIND":
                self.wind += o.matrix_world @ Vector((0.0, 0.0, o.field.strength))
        if not self.dt:
            return
        bones = self.bones()
        for b in bones:
            b.kbw_state.collision_normal = Vector((0.0, 0.0, 0.0))
            self.move(b)
        for i in range(ITERATIONS):
            for b in bones:
                self.constrain(b, ITERATIONS - 1 - i)
        for b in bones:
            state = b.kbw_state
            bounce = Vector((0.0, 0.0, 0.0))
            if state.collision_normal.length:
                bounce = state.velocity.reflect(state.collision_normal).project(
                    state.collision_normal
                ) * _get(b, "bounce")
            state.velocity = (state.position - state.position_last) / max(elapsed, 1) + bounce
            state.position_last = state.position
