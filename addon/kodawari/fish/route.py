"""Fish Swim as a Geometry Nodes modifier (docs/algorithms.md §1.6).

The live swim bends the fish inside Blender's own evaluation: a "Fish Swim" Geometry
Nodes modifier, first in the stack, reads each vertex's bound FFD coordinates (float
attributes, bound once; a coordinate the rest axis makes affine in the rest position is
computed from Position instead, measured at bind time) and the current frame table (1024 segments x 8 vectors
and the tail's frame, written per frame into a small helper mesh) and sets the bent
positions with Sample Index nodes. Moving fins add a per-vertex offset the core computes per frame for the
fin vertices only, written into a second helper mesh and read by an index attribute.

The helpers (node group, helper objects and meshes) are named with a leading dot, Blender's
mark for data not meant for the user's lists; the helper objects belong to no collection,
so the Outliner's scene views do not show them (its Blender File view does). They are reached from the modifier alone (no
name lookups), save with the .blend, and go with Remove Fish Swim. The node tree is built
here in code from nodes Blender 3.4 already has (no rotation or matrix sockets).
"""

import bpy
import numpy as np

MODIFIER = "Fish Swim"
GROUP = ".Kodawari Fish Swim"
TABLE = ".Kodawari Fish Swim Frames"
FINS = ".Kodawari Fish Swim Fins"
# Per vertex (s, u, v) as three float attributes (docs/algorithms.md §1.6): each read is a
# field over the attribute's own array, where one float3 needed a Separate XYZ per frame.
COORDINATES = (".kodawari_swim_s", ".kodawari_swim_u", ".kodawari_swim_v")
PACKED = ".kodawari_swim_ffd"  # the same as one float3: files saved before, bound again
FIN_INDEX = ".kodawari_swim_fin"  # int per vertex: its row in the fin helper, -1 off the fins
FIN_OFFSET = "offset"
SEGMENTS = 1024
ROWS = SEGMENTS + 1  # one more row: the tail's frame, read at s = 1024 with no change after it
FIELDS = ("o", "do", "e1", "de1", "e2", "de2", "e3", "de3")  # rows of AxisBinding.frame_table
REST = "rest_"  # the rest table's fields, read only when the mesh has shape keys


def sampled_fields(with_ends):
    """The table's fields the tree samples: e1 and its change only where some vertex lies
    past an end of the axis (w != 0); the helper holds and the handler writes only these."""
    return FIELDS if with_ends else tuple(f for f in FIELDS if not f.endswith("e1"))


def modifier(obj):
    """The object's Fish Swim modifier: the Geometry Nodes modifier running our group (found
    by the group's mark, so a renamed modifier is still the swim)."""
    for mod in obj.modifiers:
        if (
            mod.type == "NODES"
            and mod.node_group is not None
            and mod.node_group.get("kodawari_swim")
        ):
            return mod
    return None


def _helper(group, label):
    node = group.nodes.get(label)
    return node.inputs[0].default_value if node is not None else None


def helpers(mod):
    """(frame table mesh, fin offset mesh or None) of a Fish Swim modifier."""
    table = _helper(mod.node_group, "frames")
    fins = _helper(mod.node_group, "fins")
    return (
        table.data if table is not None else None,
        fins.data if fins is not None else None,
    )


# ----------------------------------------------------------------------------- the tree


def _new_socket(group, name, in_out):
    if hasattr(group, "interface"):  # 4.0+
        group.interface.new_socket(name=name, in_out=in_out, socket_type="NodeSocketGeometry")
    else:  # 3.x
        (group.inputs if in_out == "INPUT" else group.outputs).new("NodeSocketGeometry", name)


def _enabled(sockets, name=None):
    return next(s for s in sockets if s.enabled and (name is None or s.name == name))


class _Tree:
    def __init__(self, group):
        self.nodes, self.links = group.nodes, group.links

    def node(self, kind, **props):
        node = self.nodes.new(kind)
        for key, value in props.items():
            setattr(node, key, value)
        return node

    def named(self, name, data_type):
        node = self.node("GeometryNodeInputNamedAttribute", data_type=data_type)
        node.inputs["Name"].default_value = name
        return _enabled(node.outputs)

    def math(self, operation, a, b):
        node = self.node("ShaderNodeMath", operation=operation)
        for socket, value in zip(node.inputs, (a, b)):
            if isinstance(value, float):
                socket.default_value = value
            else:
                self.links.new(value, socket)
        return node.outputs[0]

    def multiply_add(self, a, scalar, c):
        node = self.node("ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        self.links.new(a, node.inputs[0])
        self.links.new(scalar, node.inputs[1])  # a float into a vector socket: (s, s, s)
        self.links.new(c, node.inputs[2])
        return node.outputs[0]

    def affine(self, position, row, constant=True):
        """row[:3] . position (+ row[3]): a bound coordinate from the rest position."""
        dot = self.node("ShaderNodeVectorMath", operation="DOT_PRODUCT")
        self.links.new(position, dot.inputs[0])
        dot.inputs[1].default_value = tuple(float(x) for x in row[:3])
        value = _enabled(dot.outputs)
        return self.math("ADD", value, float(row[3])) if constant else value

    def sample(self, geometry, attribute, index):
        node = self.node("GeometryNodeSampleIndex", data_type="FLOAT_VECTOR", domain="POINT")
        self.links.new(geometry, node.inputs["Geometry"])
        self.links.new(self.named(attribute, "FLOAT_VECTOR"), _enabled(node.inputs, "Value"))
        self.links.new(index, node.inputs["Index"])
        return _enabled(node.outputs)

    def object_geometry(self, label, obj):
        info = self.node("GeometryNodeObjectInfo", name=label, label=label)
        info.inputs["Object"].default_value = obj
        return info.outputs["Geometry"]


def build_group(
    table_obj, fins_obj, end_scale, with_keys=False, with_ends=True, rows=None, computed=None
):
    """P' = (O + u e2 + v e3 + w e1) + f (dO + u de2 + v de3 + w de1) [+ fin offset], the
    core's deform_vertex (docs/algorithms.md §1.4, §1.6) in nodes. with_ends: some vertex
    lies past an end of the axis (w != 0); without, the w terms are left out. computed[k]:
    coordinate k (of s, u, v) is rows[k][:3] . Position + rows[k][3] (the rest position:
    never with the user's shape keys), not a stored attribute; for u and v the constant
    rows[k][3] rides in the frame table's origins instead (write_frame)."""
    computed = computed or (False, False, False)
    group = bpy.data.node_groups.new(GROUP, "GeometryNodeTree")
    group["kodawari_swim"] = 1
    group["kodawari_stored"] = stored_letters(computed)
    group["kodawari_offsets"] = [float(rows[k][3]) if computed[k] else 0.0 for k in (1, 2)]
    # A computed u or v whose row is an object axis (the set-up's head, up and side are)
    # is that axis's coordinate of Position, from one Separate XYZ: cheaper than a Dot
    # Product each; the row's sign rides in the table's e2 or e3 (write_frame).
    axes = [_object_axis(rows[k]) if computed[k] else None for k in (1, 2)]
    group["kodawari_signs"] = [axis[1] if axis else 1.0 for axis in axes]
    _new_socket(group, "Geometry", "INPUT")
    _new_socket(group, "Geometry", "OUTPUT")
    tree = _Tree(group)
    group_in, group_out = tree.node("NodeGroupInput"), tree.node("NodeGroupOutput")
    table = tree.object_geometry("frames", table_obj)
    position = tree.node("GeometryNodeInputPosition").outputs[0] if any(computed) else None
    separate = None
    if any(axes):
        separate = tree.node("ShaderNodeSeparateXYZ")
        tree.links.new(position, separate.inputs[0])

    def coordinate(k, name):
        if not computed[k]:
            return tree.named(name, "FLOAT")
        if k > 0 and axes[k - 1]:
            return separate.outputs[axes[k - 1][0]]
        return tree.affine(position, rows[k], constant=k == 0)

    s, u, v = (coordinate(k, name) for k, name in enumerate(COORDINATES))
    t, w = s, None
    if with_ends:
        clamp = tree.node("ShaderNodeClamp")
        tree.links.new(s, clamp.inputs["Value"])
        clamp.inputs["Min"].default_value, clamp.inputs["Max"].default_value = 0.0, float(SEGMENTS)
        t = clamp.outputs[0]
        # Beyond an end the packing keeps w outside [0, 1024]: w = (s - clamp(s)) / end_scale.
        w = tree.math("MULTIPLY", tree.math("SUBTRACT", s, t), 1.0 / end_scale)
    # t = 1024 (the tail) reads the last row, the tail's frame, at fraction 0.
    segment = tree.math("FLOOR", t, 0.0)
    fraction = tree.math("SUBTRACT", t, segment)
    fields = sampled_fields(with_ends)

    def bend(prefix):
        row = {name: tree.sample(table, prefix + name, segment) for name in fields}
        at = tree.multiply_add(row["e2"], u, row["o"])
        at = tree.multiply_add(row["e3"], v, at)
        change = tree.multiply_add(row["de2"], u, row["do"])
        change = tree.multiply_add(row["de3"], v, change)
        if w is not None:
            at = tree.multiply_add(row["e1"], w, at)
            change = tree.multiply_add(row["de1"], w, change)
        return tree.multiply_add(change, fraction, at)

    moved = bend("")
    if with_keys:
        # The user's shape keys move the mesh before the swim: their offset from the rest
        # shape (the bound rest table gives it back) rides on the bent body, as a relative
        # key on top of the swim did.
        position = tree.node("GeometryNodeInputPosition").outputs[0]
        offset = tree.node("ShaderNodeVectorMath", operation="SUBTRACT")
        tree.links.new(position, offset.inputs[0])
        tree.links.new(bend(REST), offset.inputs[1])
        add = tree.node("ShaderNodeVectorMath", operation="ADD")
        tree.links.new(moved, add.inputs[0])
        tree.links.new(offset.outputs[0], add.inputs[1])
        moved = add.outputs[0]
    if fins_obj is not None:
        # Off the fins the index is -1: Sample Index gives a zero offset out of range.
        offset = tree.sample(
            tree.object_geometry("fins", fins_obj), FIN_OFFSET, tree.named(FIN_INDEX, "INT")
        )
        add = tree.node("ShaderNodeVectorMath", operation="ADD")
        tree.links.new(moved, add.inputs[0])
        tree.links.new(offset, add.inputs[1])
        moved = add.outputs[0]
    set_position = tree.node("GeometryNodeSetPosition")
    tree.links.new(group_in.outputs[0], set_position.inputs["Geometry"])
    tree.links.new(moved, set_position.inputs["Position"])
    result = set_position.outputs[0]
    # The bound attributes stay on the user's mesh, not on what the swim hands on: Blender
    # 3.4 copies the mesh for Set Position (the attribute too, 12 bytes per vertex more
    # until the next frame), and exports and later modifiers have no use for them.
    stored = [name for name, c in zip(COORDINATES, computed) if not c]
    for name in (*stored, FIN_INDEX) if fins_obj is not None else stored:
        remove = tree.node("GeometryNodeRemoveAttribute")
        remove.inputs["Name"].default_value = name
        tree.links.new(result, remove.inputs["Geometry"])
        result = remove.outputs[0]
    tree.links.new(result, group_out.inputs[0])
    return group


# ----------------------------------------------------------------------------- set-up


def stored_letters(computed):
    """Which of s, u, v the route stores as attributes, as letters ("suv" before any was
    computed: the node groups of older files carry no mark and store all three)."""
    return "".join(letter for letter, c in zip("suv", computed) if not c)


def stored_names(group):
    letters = group.get("kodawari_stored", "suv")
    return [name for letter, name in zip("suv", COORDINATES) if letter in letters]


def _object_axis(row):
    """(index, sign) when row[:3] is exactly plus or minus one object axis, else None."""
    normal = [float(x) for x in row[:3]]
    for index, value in enumerate(normal):
        if abs(value) == 1.0 and all(x == 0.0 for i, x in enumerate(normal) if i != index):
            return index, value
    return None


def has_ends(packed):
    """Some vertex lies past an end of the axis (w != 0: s outside [0, 1024])."""
    return bool(np.any((packed[:, 0] < 0.0) | (packed[:, 0] > float(SEGMENTS))))


def _rows(table, out, offsets=(0.0, 0.0), signs=(1.0, 1.0)):
    """The core's frame table (8 * 1024, 3) as the helper's rows (8, 1025, 3): each field's
    1024 segments, then the tail's frame (value + change of the last segment, no change).
    offsets (c_u, c_v): the constants of u and v where the tree computes them from Position
    as n . P alone; O + u e2 + v e3 = (O + c_u e2 + c_v e3) + (n_u . P) e2 + (n_v . P) e3, so
    they are added to the origins (and their changes) here, once per row, not per vertex.
    signs: -1 where the tree reads u or v as an object axis's coordinate, the negative of
    n . P: e2 or e3 (and its change) turn over instead."""
    segments = table.reshape(len(FIELDS), SEGMENTS, 3)
    out[:, :SEGMENTS] = segments
    out[0::2, SEGMENTS] = segments[0::2, -1] + segments[1::2, -1]  # o, e1, e2, e3 at t = 1
    out[1::2, SEGMENTS] = 0.0
    c_u, c_v = offsets
    if c_u or c_v:
        out[0:2] += np.float32(c_u) * out[4:6] + np.float32(c_v) * out[6:8]  # o, do from e2, e3
    for sign, fields in zip(signs, (slice(4, 6), slice(6, 8))):
        if sign < 0:
            out[fields] *= np.float32(-1.0)
    return out


def _helper_object(name, count, attributes):
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(count)
    for attribute in attributes:
        mesh.attributes.new(attribute, "FLOAT_VECTOR", "POINT")
    return bpy.data.objects.new(name, mesh)  # in no collection: not in the scene's Outliner


def move_first(obj, mod):
    """Put a modifier first in the object's stack (3.4 has no ObjectModifiers.move)."""
    index = list(obj.modifiers).index(mod)
    if index == 0:
        return
    if hasattr(obj.modifiers, "move"):  # 4.0+
        obj.modifiers.move(index, 0)
        return
    with bpy.context.temp_override(object=obj, active_object=obj):
        bpy.ops.object.modifier_move_to_index(modifier=mod.name, index=0)


def _remove_helpers(mod):
    group = mod.node_group
    mod.node_group = None
    if group is None or group.users > 0:
        return  # shared with a duplicate (Shift-D): its helpers stay with it
    for label in ("frames", "fins"):
        helper = _helper(group, label)
        if helper is not None:
            mesh = helper.data
            bpy.data.objects.remove(helper)
            if mesh is not None and mesh.users == 0:
                bpy.data.meshes.remove(mesh)
    bpy.data.node_groups.remove(group)


def _write_attribute(mesh, name, kind, values):
    attribute = mesh.attributes.get(name)
    if attribute is not None and (attribute.data_type != kind or attribute.domain != "POINT"):
        mesh.attributes.remove(attribute)
        attribute = None
    if attribute is None:
        attribute = mesh.attributes.new(name, kind, "POINT")
    attribute.data.foreach_set("vector" if kind == "FLOAT_VECTOR" else "value", values.reshape(-1))


def install(obj, rig):
    """Bind the route to the object's mesh for `rig` (runtime.SwimRig): the coordinate
    attributes, the helpers and the modifier, first in the stack. Replaces an earlier
    installation (a rebind). Its eye and camera are visibility.sync's to set."""
    mesh = obj.data
    mod = modifier(obj) or obj.modifiers.get(MODIFIER)
    if mod is not None and mod.type == "NODES":
        _remove_helpers(mod)
    else:
        mod = obj.modifiers.new(MODIFIER, "NODES")
    with_keys = mesh.shape_keys is not None
    packed = rig.packed_coordinates()
    with_ends = has_ends(packed)
    # A coordinate the rest axis makes affine in the rest position (measured on every vertex
    # at bind time, docs/algorithms.md §1.6) is computed from Position: no attribute. With
    # the user's shape keys Position is not the rest position, so all three are stored.
    computed = tuple(bool(h) and not with_keys for h in rig.affine_holds)
    for k, name in enumerate(COORDINATES):
        if not computed[k]:
            _write_attribute(mesh, name, "FLOAT", np.ascontiguousarray(packed[:, k]))
        elif has_attribute(mesh, name):
            mesh.attributes.remove(mesh.attributes[name])
    del packed
    if mesh.attributes.get(PACKED) is not None:
        mesh.attributes.remove(mesh.attributes[PACKED])
    fields = sampled_fields(with_ends)
    rest_fields = tuple(REST + f for f in fields) if with_keys else ()
    table_obj = _helper_object(TABLE, ROWS, fields + rest_fields)
    if with_keys:
        rest_rows = _rows(rig.rest_table(), np.empty((len(FIELDS), ROWS, 3), np.float32))
        for k, name in enumerate(FIELDS):
            if REST + name in rest_fields:
                attribute = table_obj.data.attributes[REST + name]
                attribute.data.foreach_set("vector", rest_rows[k].reshape(-1))
    fins_obj = None
    if rig.fin_vertices is not None:
        index = np.full(len(mesh.vertices), -1, np.int32)
        index[rig.fin_vertices] = np.arange(len(rig.fin_vertices), dtype=np.int32)
        _write_attribute(mesh, FIN_INDEX, "INT", index)
        fins_obj = _helper_object(FINS, len(rig.fin_vertices), (FIN_OFFSET,))
    elif mesh.attributes.get(FIN_INDEX) is not None:
        mesh.attributes.remove(mesh.attributes[FIN_INDEX])
    mod.node_group = build_group(
        table_obj, fins_obj, rig.end_scale, with_keys, with_ends, rig.affine_rows, computed
    )
    mod.node_group["kodawari_with_keys"] = with_keys
    # In Edit Mode the user edits the rest shape: show it, as the shape key used to.
    mod.show_in_editmode = False
    move_first(obj, mod)
    rig.installed_on = mesh.as_pointer()
    # Blender reports the attributes written here as a change of the mesh: the rig was
    # just bound to this very rest shape, so that report needs no rest check (which would
    # read every position and make Blender copy them, 12 bytes per vertex).
    rig.own_update = True
    rig.release_coordinates()  # the attribute holds them now
    return mod


def has_attribute(mesh, name):
    """The mesh has an attribute of that name, asked without touching its values. Blender
    4+ shares a mesh's arrays with its evaluated copy; `attributes.get(name)` and `name in
    attributes` hand out a writable attribute, so Blender first gives the user's mesh a copy
    of its own (12 bytes per vertex for the bound coordinates, kept while the evaluated copy
    lives: every frame of playback). `find` only compares names."""
    return mesh.attributes.find(name) >= 0


def installed_for(obj, rig):
    """True when the object's route was installed for this very rig (same binding). Asked
    every frame: it reads nothing per vertex and copies nothing (has_attribute)."""
    mod = modifier(obj)
    if mod is None or getattr(rig, "installed_on", None) != obj.data.as_pointer():
        return False
    mesh = obj.data
    return (
        all(has_attribute(mesh, name) for name in stored_names(mod.node_group))
        and (rig.fin_vertices is None) != has_attribute(mesh, FIN_INDEX)
        # shape keys added or removed since: the tree reads their offset, or not
        and bool(mod.node_group.get("kodawari_with_keys")) == (mesh.shape_keys is not None)
    )


def uninstall(obj):
    """Remove the modifier, its node group, the helpers and the attributes: the mesh is as
    it was before the swim."""
    mod = modifier(obj) or obj.modifiers.get(MODIFIER)
    if mod is not None and mod.type == "NODES":
        _remove_helpers(mod)
        obj.modifiers.remove(mod)
    mesh = obj.data
    if mesh is not None and getattr(mesh, "library", None) is None:
        for name in (*COORDINATES, PACKED, FIN_INDEX):
            attribute = mesh.attributes.get(name)
            if attribute is not None:
                mesh.attributes.remove(attribute)


_row_buffer = np.empty((len(FIELDS), ROWS, 3), np.float32)


def write_frame(obj, table, fin_offsets):
    """The frame's table (float32 (8 * 1024, 3)) and fin offsets (float32 (M, 3) or None)
    into the helpers; tags them so Blender re-evaluates the modifier."""
    mod = modifier(obj)  # looked up once a frame: the helpers and the constants hang on it
    if mod is None:
        return False
    table_mesh, fins_mesh = helpers(mod)
    if table_mesh is None:
        return False
    group = mod.node_group
    offsets = group.get("kodawari_offsets", (0.0, 0.0))
    rows = _rows(table, _row_buffer, tuple(offsets), tuple(group.get("kodawari_signs", (1.0, 1.0))))
    attributes = table_mesh.attributes
    for k, name in enumerate(FIELDS):
        # Only the fields the tree samples are in the helper (sampled_fields; a file saved
        # before holds all eight, and gets all eight).
        attribute = attributes.get(name)
        if attribute is not None:
            attribute.data.foreach_set("vector", rows[k].reshape(-1))
    table_mesh.update_tag()
    if (
        fins_mesh is not None
        and fin_offsets is not None
        and len(fins_mesh.vertices) == len(fin_offsets)
    ):
        fins_mesh.attributes[FIN_OFFSET].data.foreach_set("vector", fin_offsets.reshape(-1))
        fins_mesh.update_tag()
    return True
