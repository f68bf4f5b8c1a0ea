"""Cloud objects: create one, find its nodes, read its parameters back.

A cloud is a mesh object (a cube of size 1 scaled to the box size) with
obj["cloudgen_type"] = the cloud type and a material built by
nodes.build_material (group nodes "Cloud Noise" and "Cloud Main").
"""
import bpy

from . import bridge, nodes

TYPE_KEY = "cloudgen_type"


def is_cloud(obj) -> bool:
    return obj is not None and TYPE_KEY in obj.keys()


def cloud_material(obj):
    """The first material of obj that holds the cloud group nodes, or None."""
    if obj is None or not hasattr(obj.data, "materials"):
        return None
    for mat in obj.data.materials:
        if mat and mat.node_tree and nodes.MAIN_GROUP in mat.node_tree.nodes \
                and nodes.NOISE_GROUP in mat.node_tree.nodes:
            return mat
    return None


def cloud_nodes(obj):
    """(Cloud Main group node, Cloud Noise group node) of a cloud's material; LookupError if none."""
    mat = cloud_material(obj)
    if mat is None:
        raise LookupError(f"{obj.name if obj else 'None'} has no cloudgen material "
                          f"(group nodes '{nodes.MAIN_GROUP}' and '{nodes.NOISE_GROUP}')")
    return mat.node_tree.nodes[nodes.MAIN_GROUP], mat.node_tree.nodes[nodes.NOISE_GROUP]


def _value(sock, kind):
    v = sock.default_value
    if kind == "int":
        return int(v)
    if kind == "vector":
        return [float(x) for x in v]
    return float(v)


def params_from_object(obj) -> dict:
    """Every declared parameter's current value for this cloud, keyed by declared name:
    socket values of the material's group nodes (what the render uses; a keyframed or
    driven value as of the current frame), box_size = obj.dimensions, object_location =
    the world location, shape_curve = the Shape Gradient curve at its 17 heights.
    Not validated: pass it to bridge.resolve_params (or the core) to check ranges."""
    main, noise = cloud_nodes(obj)
    values = {}
    for p in bridge.parameters():
        name = p["name"]
        if name == "shape_curve":
            values[name] = nodes.shape_curve_samples(main.node_tree)
        elif name == "box_size":
            values[name] = [float(x) for x in obj.dimensions]
        elif name == "object_location":
            values[name] = [float(x) for x in obj.matrix_world.translation]
        else:
            node = main if nodes.GROUP_OF.get(p["group"]) == nodes.MAIN_GROUP else noise
            if p["label"] in node.inputs:
                values[name] = _value(node.inputs[p["label"]], p["kind"])
    return values


def _unit_cube(name):
    h = 0.5
    verts = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    return mesh


def create_cloud(context, cloud_type: str, location=None):
    """A new cloud of the given type, linked to the active collection, selected and active.
    Raises RuntimeError (native module missing) or KeyError (unknown type)."""
    presets = bridge.presets()
    if cloud_type not in presets:
        raise KeyError(f"unknown cloud type {cloud_type!r}; known: {', '.join(sorted(presets))}")
    values = bridge.resolve_params({"preset": cloud_type})
    look = presets[cloud_type].get("material", {})
    label = cloud_type.replace("_", " ").title()
    obj = bpy.data.objects.new(label, _unit_cube(label))
    obj.scale = values["box_size"]
    obj.location = location if location is not None else context.scene.cursor.location
    obj.display_type = "BOUNDS" if bpy.app.version < (4, 0, 0) else "WIRE"
    obj[TYPE_KEY] = cloud_type
    collection = getattr(context, "collection", None) or context.scene.collection
    collection.objects.link(obj)
    context.view_layer.update()  # matrix_world and dimensions before the drivers read them
    mat = nodes.build_material(label, values, look, obj)
    obj.data.materials.append(mat)
    for o in context.view_layer.objects:
        o.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return obj
