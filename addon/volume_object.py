"""A bake's result on the cloud: the Volume object `<cloud>_VDB` with its material,
the procedural/baked switch, and the bake record.

- The VDB grid lives in the cloud's local frame (centred, the object's scale
  folded into the box size, docs/model.md §8), so the Volume object is parented
  to the cloud with the cloud's scale cancelled: it sits at the cloud's location
  and rotation and moves with it.
- cloud["cloudgen_source"] is 'PROCEDURAL' or 'BAKED'; BAKED hides the
  procedural box from render and shows the Volume object.
- cloud["cloudgen_bake"] (RECORD_KEY) describes the last successful bake: the
  files, the frame range, the field key of each file's parameters and what the
  CLI did (see store_record).
"""
import bpy
from mathutils import Matrix

from . import bridge, volume_material

SOURCE_KEY = "cloudgen_source"
BAKED_FROM_KEY = "cloudgen_baked_from"
RECORD_KEY = "cloudgen_bake"


def baked_object(cloud):
    """The cloud's Volume object, or None."""
    for child in cloud.children:
        if child.get(BAKED_FROM_KEY) == cloud.name and child.type == "VOLUME":
            return child
    obj = bpy.data.objects.get(cloud.name + "_VDB")
    return obj if obj is not None and obj.type == "VOLUME" else None


def baked_material(cloud):
    """`<cloud>_VDB`, a volume material reading the grid `density`: like the cloud's own
    "Cloud Volume" node (same shader, phase and colour as the procedural render), else
    a Principled Volume with the cloud type's colour and anisotropy (volume_material.py)."""
    name = cloud.name + "_VDB"
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    look = bridge.presets().get(cloud.get("cloudgen_type", ""), {}).get("material", {})
    source = None
    for m in getattr(cloud.data, "materials", []):
        if m and m.node_tree and volume_material.VOLUME_NODE in m.node_tree.nodes:
            source = m.node_tree.nodes[volume_material.VOLUME_NODE]
            break
    volume_material.volume_material(mat, look, grid="density", like=source, phase="HG")
    volume_material.point_halos(bpy.context.scene)
    return mat


def apply_bake(context, cloud, stored_path: str, frames=None):
    """Create or update `<cloud>_VDB` reading stored_path (the first file of a sequence)
    and switch the cloud to BAKED. Returns the Volume object."""
    obj = baked_object(cloud)
    if obj is None:
        vol = bpy.data.volumes.new(cloud.name + "_VDB")
        obj = bpy.data.objects.new(cloud.name + "_VDB", vol)
        for coll in cloud.users_collection or (context.scene.collection,):
            coll.objects.link(obj)
    vol = obj.data
    vol.filepath = stored_path
    vol.is_sequence = frames is not None
    if frames is not None:
        first, last = frames
        vol.frame_start = first
        vol.frame_duration = last - first + 1
        vol.frame_offset = first - 1  # files are numbered by scene frame
        vol.sequence_mode = "CLIP"
    vol.grids.load()
    obj[BAKED_FROM_KEY] = cloud.name
    # the grid is in the cloud's local frame with the scale folded in: cancel the scale
    obj.parent = cloud
    scale = [s if abs(s) > 1e-12 else 1.0 for s in cloud.scale]
    obj.matrix_parent_inverse = Matrix.Diagonal((1.0 / scale[0], 1.0 / scale[1], 1.0 / scale[2], 1.0))
    obj.matrix_basis = Matrix.Identity(4)
    mat = baked_material(cloud)
    if obj.data.materials:
        obj.data.materials[0] = mat
    else:
        obj.data.materials.append(mat)
    set_source(cloud, "BAKED")
    return obj


def set_source(cloud, source: str):
    """'BAKED': render the Volume object, not the procedural box; 'PROCEDURAL': the reverse."""
    if source not in ("PROCEDURAL", "BAKED"):
        raise ValueError(f"source must be PROCEDURAL or BAKED, not {source!r}")
    baked = baked_object(cloud)
    if source == "BAKED" and baked is None:
        raise LookupError(f"{cloud.name} has no baked VDB yet: bake it first")
    cloud[SOURCE_KEY] = source
    cloud.hide_render = source == "BAKED"
    if baked is not None:
        baked.hide_render = source != "BAKED"
        baked.hide_viewport = source != "BAKED"


def store_record(cloud, result, files, frames, keys, digests=()):
    """cloud[RECORD_KEY] for a successful bake: "files" (as the Volume object reads them),
    "frames" ([first, last], [] for one frame), "field_keys" (bake_params.field_keys of
    each file's parameters, in file order), "params_digests" (bake_params.params_digests of
    the same: did the parameters change, or the model?), the counts "baked", "copied", "kept", and for
    a sequence "baked_frames", "copied_frames" ([frame, source frame] pairs), "kept_frames"."""
    frame_of = dict(zip(result.files, result.frames))
    record = {
        "files": list(files),
        "frames": list(frames) if frames else [],
        "field_keys": list(keys),
        "params_digests": list(digests),
        "baked": len(result.paths), "copied": len(result.copied), "kept": len(result.kept),
    }
    record.update(getattr(result, "counts_override", None) or {})  # a Dask bake: the runner's counts
    if frames:
        record["baked_frames"] = [frame_of[p] for p in result.paths if frame_of.get(p) is not None]
        record["copied_frames"] = [[frame_of[p], src] for p, src in result.copied
                                   if frame_of.get(p) is not None and src is not None]
        record["kept_frames"] = [frame_of[p] for p in result.kept if frame_of.get(p) is not None]
    cloud[RECORD_KEY] = record
    return record


def bake_record(cloud) -> dict:
    """The cloud's bake record as plain Python ({} when it was never baked)."""
    record = cloud.get(RECORD_KEY)
    return record.to_dict() if hasattr(record, "to_dict") else dict(record or {})
