"""Render the gallery: every cloud type in a landscape, from the ground, under the add-on's
daylight (addon/sky_light.py), as a photograph would frame it.

Usage: .venv/bin/python scripts/gallery.py --out docs/gallery [--size 640x360] [--samples 16]
       [--types cumulus,stratus,...] [--shots side-low,below-high,...] [--resolution 192]
       [--names FILE.json]

Each type is baked first (`cloudgen bake`, uniform voxels: --resolution along the box's
longest side; layers, whose boxes are wide and thin, at --layer-resolution) and its VDB
rendered in Cycles on the CPU — much faster than the procedural OSL material and the same
field up to the voxel size. Shots:

  side   side-on toward the horizon, a 35 mm lens at eye height: a compact cloud fills about
         45 % of the frame width with its base a few degrees above the horizon; a layer is
         overhead and runs away toward the horizon
  below  from the ground looking up, a 24 mm lens, pitched 55° up (a compact cloud from
         beside its base; a layer straight overhead)
  sun    side-on, the sun low and right behind the cloud's upper edge (silver lining)

and suns: low (12°, 120° from the view: side-lit from behind the camera), high (60°, 150°).
The scene: the Nishita sky, the matched sun lamp, AgX, a dull ground plane to the horizon,
32 volume bounces, OpenImageDenoise where Blender has it. Files are numbered in a shuffled
order (NN.png, no type in the name) so a reviewer sees no hint; the key is written to
--names (default OUT/key.json). 1 scene unit is read as 250 m for the altitudes below.
"""
import argparse
import json
import math
import os
import pathlib
import random
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "osl"))

# cloud base above the ground, scene units (1 unit ~ 250 m: the cumulus preset is 1 km wide), by
# type: typical WMO base heights
BASE_ALTITUDE = {"stratus": 2.0, "nimbostratus": 4.0, "stratocumulus": 5.0, "altocumulus": 12.0,
                 "altostratus": 14.0, "cirrocumulus": 26.0, "cirrus": 30.0, "cirrostratus": 32.0}
SUNS = {"low": (12.0, 120.0), "high": (60.0, 150.0)}
LAYER_RATIO = 0.3
FAR_EDGE_DEG = 6.0  # a layer's box is widened until its far edge is this low above the horizon
EYE = 0.017  # eye height, scene units (1.7 m)


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--samples", type=int, default=16, help="samples per pixel (denoised; default 16)")
    ap.add_argument("--types", default="", help="comma-separated presets (default: all)")
    ap.add_argument("--shots", default="side-low,below-high",
                    help="comma-separated VIEW-SUN (default side-low,below-high)")
    ap.add_argument("--resolution", type=int, default=192, help="voxels along a compact cloud's longest side")
    ap.add_argument("--layer-resolution", type=int, default=2048, help="voxels along a layer's longest side")
    ap.add_argument("--names", default=None, help="where the key (file -> type, shot) goes")
    ap.add_argument("--seed", type=int, default=13, help="shuffle of the file numbers")
    return ap.parse_args(argv)


def is_layer(box):
    return box[2] < LAYER_RATIO * max(box[0], box[1])


def place(box, view, lens, width, height, name):
    """(cloud centre, camera location, camera rotation) for a box and a view; the camera looks
    along +Y turned up by its pitch."""
    from mathutils import Vector

    bx, by, bz = box
    tan_x = 18.0 / lens
    tan_y = tan_x * height / width
    if is_layer(box):
        base = BASE_ALTITUDE.get(name, 10.0)
        centre = Vector((0.0, 0.0, base + bz / 2))
        if view == "below":  # under the middle, looking at a point a quarter of the box ahead
            return centre, Vector((0.0, 0.0, EYE)), max(55.0, math.degrees(math.atan2(base, 0.25 * by)))
        # under the near part of the layer, looking along it toward the horizon
        pitch = math.degrees(math.atan(0.55 * tan_y))  # horizon at ~22 % from the bottom
        return centre, Vector((0.0, -0.4 * by, EYE)), pitch
    pitch = math.degrees(math.atan(0.55 * tan_y))
    top = math.radians(pitch) + math.atan(tan_y) - math.radians(2.0)  # elevation the top may reach
    d = max(bx / 2 / (0.45 * tan_x), bz / (math.tan(top) - math.tan(math.radians(4.0))))
    base = d * math.tan(math.radians(4.0))
    centre = Vector((0.0, d, base + bz / 2))
    if view == "below":  # near the base of a cloud a little higher up, looking up at its middle
        base = max(base, 0.8 * max(bx, by))
        centre = Vector((0.0, d, base + bz / 2))
        cam = Vector((0.0, d - 0.7 * max(bx, by), EYE))
        rise = math.degrees(math.atan2(centre.z - EYE, centre.y - cam.y))
        return centre, cam, rise
    return centre, Vector((0.0, 0.0, EYE)), pitch


def widened(name, values):
    """A layer's parameters with its box widened (never narrowed) so that, seen from under its
    near part, its far edge lies FAR_EDGE_DEG above the horizon: a sheet that runs toward the
    horizon, not a patch overhead. The noise is in scene units, so the texture keeps its scale
    (only more of it); the sheet's fade grows with the box."""
    box = list(values.get("box_size", [2, 2, 2]))
    if not is_layer(box):
        return values
    need = BASE_ALTITUDE.get(name, 10.0) / (0.9 * math.tan(math.radians(FAR_EDGE_DEG)))
    if max(box[0], box[1]) >= need:
        return values
    return dict(values, box_size=[max(box[0], need), max(box[1], need), box[2]])


def bake(name, values, out_vdb, args):
    res = args.layer_resolution if is_layer(values["box_size"]) else args.resolution
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(dict(values, preset=name), f)
    try:
        subprocess.run([str(ROOT / "build" / "bin" / "cloudgen"), "bake", "--params", f.name, "--resolution",
                        str(res), "--output", out_vdb, "--quiet", "--max-memory", "16"], check=True)
    finally:
        os.remove(f.name)


def shot(name, view, sun, vdb, out_png, args):
    import render_cloud

    ra = render_cloud.parse_args(["--preset", name, "--output", out_png, "--size", args.size,
                                  "--samples", str(args.samples), "--vdb", vdb])
    values = widened(name, render_cloud.resolve_params(ra))
    scene = render_cloud.build_scene(values, ra)  # the sky light, the material, the VDB object
    w, h = (int(v) for v in args.size.lower().split("x"))
    lens = 24.0 if view == "below" else 35.0
    box = values["box_size"]
    centre, cam_at, pitch = place(box, view, lens, w, h, name)
    cloud = scene.objects["Cloud"]
    cloud.location = centre
    cam = scene.camera
    cam.data.lens = lens
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.clip_end = 1.0e5
    cam.location = cam_at
    cam.rotation_euler = (math.radians(90.0 + pitch), 0.0, 0.0)
    sl = render_cloud._addon_file("sky_light")
    if sun == "behind":  # the sun right behind the cloud's upper part: silver lining
        from mathutils import Vector

        aim = centre + Vector((0.0, 0.0, 0.25 * box[2]))
        rel = aim - cam_at
        elevation = math.degrees(math.atan2(rel.z, math.hypot(rel.x, rel.y)))
        sl.daylight(scene, elevation, 0.0, ground_size=1.0e4)
    else:
        elevation, azimuth = SUNS[sun]
        sl.daylight(scene, elevation, azimuth, ground_size=1.0e4)
    scene.cycles.use_denoising = sl.denoiser_built_in()
    return render_cloud.render(scene, out_png)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    import cloudgen_native as cn

    presets = cn.presets()
    names = [t for t in args.types.split(",") if t] or sorted(presets)
    unknown = sorted(set(names) - set(presets))
    if unknown:
        raise SystemExit(f"gallery: error: unknown types {unknown}; known: {sorted(presets)}")
    shots = [s.split("-") for s in args.shots.split(",") if s]
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # numbers are drawn over every type, so re-rendering some types keeps the others' files
    everything = [(n, v, s) for n in sorted(presets) for v, s in shots]
    numbers = list(range(1, len(everything) + 1))
    random.Random(args.seed).shuffle(numbers)
    jobs, numbers = zip(*[(job, k) for job, k in zip(everything, numbers) if job[0] in names]) or ((), ())
    key_path = pathlib.Path(args.names) if args.names else out / "key.json"
    key = json.loads(key_path.read_text()) if key_path.exists() else {}
    with tempfile.TemporaryDirectory(prefix="cloudgen-gallery-") as work:
        baked = {}
        for (name, view, sun), number in zip(jobs, numbers):
            if name not in baked:
                baked[name] = os.path.join(work, f"{name}.vdb")
                params = widened(name, dict(cn.defaults(), **presets[name]["params"]))
                bake(name, params, baked[name], args)
            png = out / f"{number:02d}.png"
            seconds = shot(name, view, sun, baked[name], str(png), args)
            key[png.name] = {"type": name, "view": view, "sun": sun, "seconds": round(seconds, 1)}
            key_path.write_text(json.dumps(key, indent=1, sort_keys=True) + "\n")
            print(f"gallery: {png} {name} {view}-{sun} {seconds:.1f} s", flush=True)


if __name__ == "__main__":
    main()
