"""Render a cloud procedurally with the cloudgen OSL shaders in Cycles (bpy wheel).

Usage: .venv/bin/python scripts/render_cloud.py --preset cumulus --output out/cumulus.png
       [--params FILE.json] [--size 320x240] [--samples 64] [--step-rate 0.05] [--seed 0]
       [--vdb FILE.vdb]

Builds a small scene — the cloud box with its volume material fed by Cloud
Main, a camera and light — and renders it on the CPU with OSL. Writes the image
atomically. Two lights: `--light sky` (default) is what the add-on's "Cloud Sky
& Sun" sets up — a Nishita sky, a sun lamp matched to it, AgX (Filmic on 3.4),
an exposure for the sun's elevation, 512 volume bounces, the Mie phase where
Cycles has it, denoising on where Blender has OpenImageDenoise;
`--light studio` is the benchmarks' reference scene — a flat blue world, a 6 W
sun, Standard view, 4 bounces, Henyey–Greenstein, denoising off (the output is
what the model computes, not a denoiser's guess).

The material comes from the add-on's one volume-material builder
(addon/volume_material.py, loaded by its path; in the studio with a Principled
Volume on every Blender version, phase "HG": the references are rendered with it);
it takes the preset's material settings ("material" in
native/presets/clouds.json: anisotropy, color, step_rate, halo, backscatter,
side_scatter); --step-rate
overrides the step rate. The OSL compiles run in a private temporary folder
(addon/osl_temp.py) that is removed afterwards. With --vdb the same scene renders a baked VDB
(`cloudgen bake` of the same parameters) instead of the procedural material: a
Volume object at the box's centre (the grid is in the cloud's local frame,
scene units) whose Principled Volume (same colour and anisotropy) takes the
grid `density` through its Density Attribute (Density 1) and steps at the
voxel size (material step rate 1, as the add-on's bake does; --step-rate
overrides it); OSL is off (the VDB needs no script nodes). The camera is
placed from the box and the lens
(`frame_camera`): a compact or tall cloud is seen from the side, slightly
below its middle, far enough back that the whole box fits; a layer cloud (Sheet
of 0.5 or more) is lifted overhead and seen from below at an angle,
its far edge just above the bottom of the frame.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "osl"))


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", help="cloud type (see `cloudgen presets`)")
    src.add_argument("--params", help="JSON parameter file (see docs/model.md)")
    ap.add_argument("--output", required=True, help="PNG (8-bit) or EXR (float) file to write")
    ap.add_argument("--size", default="320x240", help="WxH pixels (default 320x240)")
    ap.add_argument("--samples", type=int, default=64, help="samples per pixel (default 64)")
    ap.add_argument("--step-rate", type=float, default=None,
                    help="volume step rate of the material (Cycles; default: the preset's, else 0.2)")
    ap.add_argument("--seed", type=int, default=0, help="Cycles sampling seed")
    ap.add_argument("--threads", type=int, default=0, help="render threads (0 = all)")
    ap.add_argument("--no-early-exit", action="store_true",
                    help="compile Cloud Main without its early exit (benchmarking only)")
    ap.add_argument("--zoom", type=float, default=1.0,
                    help="multiply the framed camera's focal length (a close-up; default 1)")
    ap.add_argument("--aim", default=None,
                    help="with --zoom: aim at this point of the box, generated coordinates X,Y,Z in [0, 1]")
    ap.add_argument("--vdb", default=None,
                    help="render this baked VDB (grid `density`, cloud-local frame) instead of the procedural material")
    ap.add_argument("--light", choices=("sky", "studio"), default="sky",
                    help="sky (default): the add-on's daylight (addon/sky_light.py: Nishita sky, matched sun lamp, "
                         "AgX/Filmic, exposure), Mie phase where Cycles has it, denoised; studio: a flat blue "
                         "world, a 6 W sun, Standard view, Henyey-Greenstein, no denoiser (the benchmarks' "
                         "reference scene)")
    ap.add_argument("--sun-elevation", type=float, default=35.0, help="sky light: sun elevation, degrees")
    ap.add_argument("--sun-rotation", type=float, default=150.0,
                    help="sky light: sun azimuth, degrees (0: ahead of the camera, 180: behind it)")
    ap.add_argument("--bounces", type=int, default=None,
                    help="volume bounces (default: the add-on's 512 with the sky light, 4 in the studio)")
    return ap.parse_args(argv)


DEFAULT_MATERIAL = {"anisotropy": 0.3, "color": [1.0, 1.0, 1.0], "step_rate": 0.2}
LENS_MM = 50.0


def resolve_material(args):
    """The preset's material settings over the defaults (a parameter file's
    "preset" counts too); --step-rate wins."""
    import cloudgen_native as cn

    preset = args.preset
    if preset is None:
        preset = json.loads(pathlib.Path(args.params).read_text()).get("preset")
    material = dict(DEFAULT_MATERIAL)
    if preset in cn.presets():
        material.update(cn.presets()[preset].get("material", {}))
    if getattr(args, "step_rate", None) is not None:
        material["step_rate"] = args.step_rate
    return material


def resolve_params(args):
    import cloudgen_native as cn

    given = {"preset": args.preset} if args.preset else json.loads(pathlib.Path(args.params).read_text())
    preset = given.pop("preset", None)
    if preset is not None and preset not in cn.presets():
        raise SystemExit(f"render_cloud: error: unknown preset {preset!r}; known: {sorted(cn.presets())}")
    values = dict(cn.presets()[preset]["params"] if preset else cn.defaults())
    values.update(given)
    cn.density(values, [[0.0, 0.0, 0.0]])  # validates every value (ValueError names the key)
    return values


def _addon_file(name):
    """addon/<name>.py loaded by its path (a module of the add-on that imports none of
    the add-on's others), once."""
    import importlib.util

    key = f"cloudgen_addon_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, ROOT / "addon" / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[key] = module
    return sys.modules[key]


def build_scene(values, args):
    import blender_nodes
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    vdb = getattr(args, "vdb", None)
    scene.cycles.shading_system = not vdb  # OSL only for the procedural material
    sky = getattr(args, "light", "studio") == "sky"
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = sky and _addon_file("sky_light").denoiser_built_in()
    scene.cycles.seed = args.seed
    bounces = getattr(args, "bounces", None)
    bounces = (_addon_file("sky_light").CLOUD_BOUNCES if sky else 4) if bounces is None else bounces
    scene.cycles.volume_bounces = bounces
    scene.cycles.max_bounces = max(bounces, 4)
    scene.render.threads_mode = "FIXED" if args.threads else "AUTO"
    if args.threads:
        scene.render.threads = args.threads
    w, h = (int(v) for v in args.size.lower().split("x"))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"

    box = values["box_size"]
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, box[2] / 2))  # frame_camera may lift it
    cloud = bpy.context.active_object
    cloud.name = "Cloud"
    cloud.scale = box
    mat = bpy.data.materials.new("Cloud")
    material = resolve_material(args)
    # the add-on's one volume-material builder, always with a Principled Volume (HG,
    # the preset's anisotropy): the benchmarks' references are rendered with it
    step = getattr(args, "step_rate", None)
    phase = "AUTO" if sky else "HG"  # the sky: Mie where Cycles has it; the studio: as the references
    if vdb:
        step = 1.0 if step is None else step  # a VDB steps at its voxel size (as the add-on's bake)
        _addon_file("volume_material").volume_material(mat, material, grid="density", phase=phase,
                                                       step_rate=step)
        cloud = vdb_object(vdb, cloud, mat)
    else:
        _addon_file("volume_material").volume_material(mat, material, phase=phase, step_rate=material["step_rate"])
        nt = mat.node_tree
        coords = nt.nodes.new("ShaderNodeTexCoord")
        defines = {"CG_NO_EARLY_EXIT": 1} if getattr(args, "no_early_exit", False) else None
        with _addon_file("osl_temp").private_tempdir():  # Cycles' compiles leave .oso files otherwise
            main, _ = blender_nodes.cloud_density_nodes(nt, values, coords.outputs["Generated"],
                                                        defines=defines)
        _addon_file("volume_material").link_density(mat, main.outputs["Density"])
        cloud.data.materials.append(mat)

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = LENS_MM
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    location, rotation, cloud_z = frame_camera(box, w, h, cam_data.sensor_width,
                                               layer=is_layer(values))
    cam.location, cam.rotation_euler = location, rotation
    cloud.location.z = cloud_z
    scene.camera = cam
    zoom = getattr(args, "zoom", 1.0) or 1.0
    if zoom != 1.0 or getattr(args, "aim", None):
        aim_camera(cam, box, cloud_z, zoom, args.aim)

    if sky:
        _addon_file("sky_light").daylight(scene, args.sun_elevation, args.sun_rotation)
        _addon_file("volume_material").point_halos(scene)
        return scene
    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy = 6.0
    sun_data.angle = math.radians(1.0)
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (math.radians(40), math.radians(0), math.radians(-35))
    scene.collection.objects.link(sun)

    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.25, 0.45, 0.85, 1.0)
    bg.inputs["Strength"].default_value = 0.8
    scene.world = world
    return scene


def aim_camera(cam, box, cloud_z, zoom, aim):
    """A close-up from the framed position: the focal length times `zoom`, turned
    to look at `aim` ("X,Y,Z" generated box coordinates; default the centre)."""
    from mathutils import Vector

    g = [0.5, 0.5, 0.5] if not aim else [float(v) for v in aim.split(",")]
    if len(g) != 3 or not all(0.0 <= v <= 1.0 for v in g) or zoom <= 0:
        raise SystemExit(f"render_cloud: --aim needs X,Y,Z in [0, 1] and --zoom > 0; got {aim!r}, {zoom}")
    target = Vector(((g[0] - 0.5) * box[0], (g[1] - 0.5) * box[1], cloud_z + (g[2] - 0.5) * box[2]))
    cam.data.lens *= zoom
    cam.rotation_euler = (target - cam.location).to_track_quat("-Z", "Y").to_euler()


def vdb_object(path, box_obj, mat):
    """Replace the procedural box `box_obj` by a Volume object reading `path`, at the
    box's location with unit scale (the grid is in scene units, centred on the box)."""
    import bpy

    vol = bpy.data.volumes.new("CloudVDB")
    vol.filepath = str(pathlib.Path(path).resolve())
    vol.grids.load()
    obj = bpy.data.objects.new("Cloud", vol)
    obj.location = box_obj.location
    bpy.data.objects.remove(box_obj)
    obj.name = "Cloud"
    vol.materials.append(mat)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def is_layer(values) -> bool:
    """A layer is a Sheet (no round outline): framed from below here, baked in nested rings by the
    gallery. A flat box alone is not one (the cumulonimbus's is wide for its anvil)."""
    return values.get("sheet", 0.0) >= 0.5


def frame_camera(box, width, height, sensor_mm=36.0, lens_mm=LENS_MM, layer=False):
    """Camera (location, euler rotation) and the cloud box's centre height for a
    box of `box` scene units seen in a width x height image; `layer`: a sheet,
    seen from below (a flat box alone is not one: the cumulonimbus's is wide for
    its anvil). The camera looks along +y (the box's x side faces it)."""
    # half the field of view, as tangents (Blender's AUTO sensor fit: the sensor spans the longer side)
    t = (sensor_mm / 2) / lens_mm
    tan_x, tan_z = (t, t * height / width) if width >= height else (t * width / height, t)
    bx, by, bz = box
    wide = max(bx, by)
    if layer:
        # a layer: overhead, seen from below, the camera under the near part of the layer
        altitude = 0.35 * wide              # of the layer's base above the camera
        back = 0.1 * wide                   # camera this far inside the near edge
        far = by - back                     # horizontal distance to the far edge
        far_elevation = math.atan2(altitude, far)
        pitch = far_elevation + 0.7 * math.atan(tan_z)  # far edge in the lower part of the frame
        location = (0.0, -by / 2 + back, 0.0)
        return location, (math.radians(90.0) + pitch, 0.0, 0.0), altitude + bz / 2
    # a compact or tall cloud from the side: 1.9 x its largest side away (the
    # reference framing of the cumulus), further when the box would not fit
    fit = max(bx / 2 / tan_x, bz / 2 / tan_z) + by / 2
    distance = max(1.9 * max(box), fit)
    location = (0.0, -distance, bz * 0.3)
    pitch_up = math.atan2(bz * 0.5 - location[2], distance)
    return location, (math.radians(90.0) + pitch_up, 0.0, 0.0), bz / 2


def render(scene, output):
    """Render to `output` atomically. Blender writes into a private directory in
    the system temp dir (a render killed mid-way leaves nothing next to the
    output); the finished image is copied beside the output and renamed into
    place."""
    import shutil

    import bpy

    output = pathlib.Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    fmt = "OPEN_EXR" if output.suffix.lower() == ".exr" else "PNG"
    scene.render.image_settings.file_format = fmt
    if fmt == "OPEN_EXR":
        scene.render.image_settings.color_depth = "32"
    work = tempfile.mkdtemp(prefix="cloudgen-render-")
    staged = None
    try:
        scene.render.filepath = os.path.join(work, "render" + output.suffix)
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t0
        fd, staged = tempfile.mkstemp(prefix="." + output.name + ".", suffix=".tmp", dir=output.parent)
        os.close(fd)
        shutil.copyfile(scene.render.filepath, staged)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(staged, 0o666 & ~umask)  # mkstemp made it private; give it the usual mode
        os.replace(staged, output)
        staged = None
    finally:
        shutil.rmtree(work, ignore_errors=True)
        if staged and os.path.exists(staged):
            os.remove(staged)
    return seconds


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    values = resolve_params(args)
    scene = build_scene(values, args)
    seconds = render(scene, args.output)
    print(f"render: wrote {args.output} ({args.size}, {args.samples} spp) in {seconds:.1f} s")


if __name__ == "__main__":
    main()
