"""What a bake is made from: the cloud's parameters, its output path, the scene's
frame range, and the field keys recorded with the bake (volume_object.store_record)."""
import hashlib
import json
import os

import bpy

from . import bridge, cloud_object

DEFAULT_DIR = "//cloudgen/"


def cloud_params(obj) -> dict:
    """Every parameter of the cloud as the render uses it (cloud_object.params_from_object);
    for a cloud without the node groups, its type's preset with the object's box and location."""
    try:
        return cloud_object.params_from_object(obj)
    except (LookupError, AttributeError):
        pass
    presets = bridge.presets()
    kind = obj.get(cloud_object.TYPE_KEY, "cumulus")
    if kind not in presets:
        raise LookupError(f"{obj.name}: unknown cloud type {kind!r}")
    values = dict(presets[kind]["params"])
    values["box_size"] = [float(x) for x in obj.dimensions]
    values["object_location"] = [float(x) for x in obj.matrix_world.translation]
    return values


def default_path(obj) -> str:
    return DEFAULT_DIR + bpy.path.clean_name(obj.name) + ".vdb"


def resolve_output(path: str) -> str:
    """Absolute output path; ValueError for a blend-relative path in an unsaved file."""
    if path.startswith("//") and not bpy.data.filepath:
        raise ValueError(f"the output path {path!r} is relative to the .blend file, which is "
                         "not saved yet: save the file or give an absolute path")
    out = os.path.normpath(bpy.path.abspath(path))
    if not out.lower().endswith(".vdb"):
        raise ValueError(f"the output path {out!r} must end in .vdb")
    return out


def make_output_folder(output: str):
    """Create the output's folder; ValueError naming the path when that cannot be done."""
    parent = os.path.dirname(output)
    if os.path.exists(parent) and not os.path.isdir(parent):
        raise ValueError(f"cannot write {output!r}: {parent!r} is a file, not a folder")
    try:
        os.makedirs(parent, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"cannot create the folder {parent!r}: {exc.strerror}") from exc


def scene_frames(scene):
    """(first, last, fps) of the scene's frame range."""
    return scene.frame_start, scene.frame_end, scene.render.fps / scene.render.fps_base


def field_keys(params_list) -> list:
    """cloudgen_native.field_key of each parameter set ("" where the core has none): equal
    keys, equal density fields — what a later edit is compared with to call a bake stale."""
    return [bridge.field_key(p) or "" for p in params_list]


def params_digests(params_list) -> list:
    """A digest of each parameter set itself, recorded beside its field key: the field key also
    changes with the cloud model (a cloudgen whose model computes another field from the same
    parameters), so a stale bake whose parameters still give this digest was made with another
    model (checks.stale_reason). The parameters are JSON by construction (the CLI reads them as a
    parameter file), so nothing here guesses at other types."""
    return [hashlib.sha256(json.dumps(p, sort_keys=True, separators=(",", ":")).encode())
            .hexdigest()[:16] for p in params_list]
