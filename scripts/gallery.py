"""Render the gallery: every cloud type in a landscape, from the ground, under the add-on's
daylight (addon/sky_light.py), as a photograph would frame it.

Usage: .venv/bin/python scripts/gallery.py --out docs/gallery [--size 640x360] [--samples 16]
       [--types cumulus,stratus,...] [--shots side-low,below-high,...] [--resolution 256]
       [--names FILE.json] [--bake-dir DIR] [--format png|exr]

Each type is baked first (`cloudgen bake`; a compact cloud at --resolution voxels along its
longest side, with a field of companion cumulus; a layer as nested square rings, each with a
voxel sized from a pixel's footprint: scripts/gallery_scene.py) and rendered in Cycles on the
CPU. Shots:

  side   side-on toward the horizon, a 35 mm lens at eye height, the horizon 12 % up the frame
  below  from the ground looking up, a 24 mm lens pitched 50° up (altostratus and
         cirrostratus: toward the sun, how veils are told apart; stratus and
         nimbostratus: 20° up, the hills and the rain in view)
  behind side-on, the sun low and right behind the cloud's upper edge (silver lining)

and suns: low (25°, 120° from the view: side-lit from behind the camera), high (60°, 150°);
side-on under the low sun, compact clouds have it behind the shoulder (SIDE_LIT_AZIMUTH) and
thin ice layers have the sun ahead, and the veils (altostratus, cirrostratus) have their sun
in the frame (sun_direction).
The scene: the Nishita sky, the matched sun lamp, AgX and white balance, the add-on's
Landscape (hilly ground, haze; clean air for the towers: CLEAN_AIR_KM), rain under the rain
clouds (addon/precipitation.py), 512 volume bounces, OpenImageDenoise where Blender has it
(GALLERY_NO_DENOISE=1: off). Under the
grey overcasts the camera is balanced for the overcast's own light; every frame is exposed by
the add-on's meter (addon/exposure_meter.py): a sunlit frame with the sun's glare in it down to
GLARE_LIGHT, a frame whose deck hides the sun for its metered light (sunlit_share).
Each PNG render also gets its camera finish, NN.jpg (vignetting, sensor grain, in-camera
sharpening, JPEG: scripts/camera_finish.py; --no-finish: none); measure on the PNG.
Files are numbered in a shuffled order (NN.png, no type in the name) so a reviewer sees no
hint; the key is written to --names (default OUT/key.json).
1 scene unit is 250 m.
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
import camera_finish  # noqa: E402
import gallery_scene as gs  # noqa: E402
import render_cloud  # noqa: E402

SUNS = {"low": (25.0, 120.0), "high": (60.0, 150.0)}
# veils are told apart by the sun seen through them ("as through ground glass", altostratus; a
# milky veil the sun shines through, cirrostratus): their view from below looks toward the sun
# (off-centre: dead centre the glow read as "a vignette or spotlight gradient", round 5)
SUN_IN_VIEW = {"altostratus": (44.0, 22.0), "cirrostratus": (44.0, 22.0)}
# side-on under the low sun, the altostratus has its sun in the frame too (upper right; the
# frame spans -4 to 27 degrees up, +-27 across): a watery disc low in a grey sheet names it;
# with the sun behind the camera it was a plain grey field, named stratus (round 8). Balanced
# to that sun (its 4,000 K, sky_light), not to the overcast: at 5,700 K it came out sepia
SUN_IN_VIEW_SIDE = {"altostratus": (18.0, 16.0), "cirrostratus": (18.0, 16.0)}
# the cirrostratus too: its halo then stands as an arc around the sun, left of it, across the
# frame. With the sun ahead but out of frame (SUN_AHEAD, 45°) only a piece of the arc crossed
# the top right corner, and two reviewers read it as "a straight diagonal band of light, like a
# rendering artefact" and "a light leak" (round 16)
# the hills' height scale (km) where it is a cue: the far hill tops vanish into a low stratus
# base (0.35 km), which tells it from altostratus ("hills disappearing into it", round 5)
HILLS_KM = {"stratus": 2.5, "nimbostratus": 1.0}
# the air of a convective day, km of visibility (the Landscape's haze) for every compact type
# (gs.is_layer false): towers grow in clean, unstable air (behind a cold front 150-250 km is
# common); at the add-on's 80 km the haze took a third to a half of their shading (measured by
# visibility in docs/lighting.md; round 9: "evenly pale grey-green, no sunlit side"). The layers
# keep landscape.VISIBILITY_KM: their far edge is hidden in it.
CLEAN_AIR_KM = 200.0
# under a sheet that hides the sun (gs.OVERCAST) a camera is balanced to the overcast's own
# light, exposure_meter.OVERCAST_BALANCE_K, not to the sun (by name, not by the measured share as
# Meter Exposure does: the altostratus side-on, its sun in the frame, keeps the sun's balance)
# ... and exposed for the overcast's own light, as the add-on's Meter Exposure exposes it: moved
# from the sun's exposure to the frame's metered light at exposure_meter.OVERCAST_KEY as the deck
# hides the sun from the ground around the camera (exposure_meter.blended_exposure; the three
# overcasts let through at most 1 % of it, so they take the overcast's exposure whole)
# The camera's meter (addon/exposure_meter.py, shared with the add-on's Meter Exposure):
# SUNNY_LIGHT, the median frame luminance of the round-15 gallery's sunlit frames without the
# sun's glow (2.15-4.71); a sunlit frame metered above GLARE_LIGHT (twice that) is exposed down
# to it: the veils toward the sun read 44-58 (round 17), and exposed like a sunny frame the
# cirrostratus's whole 22° halo sat in AgX's shoulder (round 16: "a hard-edged disc")
meter = render_cloud._addon_file("exposure_meter")
SUNNY_LIGHT, GLARE_LIGHT = meter.SUNNY_LIGHT, meter.GLARE_LIGHT
glare_compensation = meter.glare_compensation
# a compact cloud side-on under the low sun: the sun behind the photographer's shoulder, 140°
# from the view (round 22; 90° until round 21). Lit from the side, the face the camera sees
# takes the sun at grazing angles while the sky lights all of it: with the light converged
# (512 bounces) the shaded flank came out 0.53 of the sunlit one (the sky alone gave 38 % of
# it, docs/lighting.md), 17 display levels apart, and both round-21 reviewers read the heap
# clouds as "lit from no direction". At 140° the lit face is brighter and the flat base shows
# as a grey band under it (320x180 trials at 90, 120 and 140°). Tried in round 27 and taken
# back: 60°, the sun ahead and to the side, out of frame (the cumulus's lit pixels p10 / p50 /
# p90 153 / 186 / 226 against 168 / 208 / 221 at 140°, the sky brightening toward the sun);
# both reviewers still saw "evenly white, no shaded side" and the three side views scored
# 2, 2, 2 and 1, 2, 2 against round 26's 2, 2, 2 and 2, 2, 2
SIDE_LIT_AZIMUTH = 140.0
# the cirrus side-on under the low sun: the sun ahead, 45° right of the view and out of frame,
# where forward scattering shows thin ice (at 120° a Cs veil's phase, g 0.75, is a tenth of that
# and the reviewer saw no cloud)
SUN_AHEAD = {"cirrus": 45.0}


def sunlit_share(values, centre, cam_at, scene):
    """The share of the sun's direct light reaching the ground around the camera through the
    main cloud (a layer: its widened deck; the add-on's rule, exposure_meter.sunlit_share, with
    the sun lamp sky_light.daylight placed)."""
    import cloudgen_native as cn

    vm = render_cloud._addon_file("volume_material")
    toward, _ = vm.sun_light(vm.scene_sun(scene))
    to_model = [[1.0, 0.0, 0.0, -centre[0]], [0.0, 1.0, 0.0, -centre[1]], [0.0, 0.0, 1.0, -centre[2]],
                [0.0, 0.0, 0.0, 1.0]]
    points = meter.ground_disc(cam_at, gs.km(meter.SHARE_RADIUS_KM))
    return meter.sunlit_share([(values, to_model)], points, tuple(toward), cn.density)


def sun_direction(name, view, sun, compact):
    """(elevation, azimuth from the view) of the sun for a shot: SUNS, except the veils from
    below (SUN_IN_VIEW) and side-on under the low sun (SUN_IN_VIEW_SIDE), compact clouds
    side-lit and the cirrus with the sun ahead (SUN_AHEAD)."""
    if view == "below" and name in SUN_IN_VIEW:
        return SUN_IN_VIEW[name]
    if view == "side" and sun == "low" and name in SUN_IN_VIEW_SIDE:
        return SUN_IN_VIEW_SIDE[name]
    elevation, azimuth = SUNS[sun]
    if view == "side" and sun == "low":
        azimuth = SIDE_LIT_AZIMUTH if compact else SUN_AHEAD.get(name, azimuth)
    return elevation, azimuth


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--samples", type=int, default=32, help="samples per pixel (denoised; default 32)")
    ap.add_argument("--types", default="", help="comma-separated presets (default: all)")
    ap.add_argument("--shots", default="side-low,below-high",
                    help="comma-separated VIEW-SUN (default side-low,below-high)")
    ap.add_argument("--resolution", type=int, default=256, help="voxels along a compact cloud's longest side")
    ap.add_argument("--names", default=None, help="where the key (file -> type, shot) goes")
    ap.add_argument("--seed", type=int, default=13, help="shuffle of the file numbers")
    ap.add_argument("--format", default="png", choices=("png", "exr"), help="png (default) or exr (scene-linear)")
    ap.add_argument("--bake-dir", default=None, help="keep the baked VDBs here (default: a temporary folder)")
    ap.add_argument("--no-finish", action="store_true",
                    help="write only the render, not also its camera finish NN.jpg (scripts/camera_finish.py)")
    return ap.parse_args(argv)


def bake(name, values, out_vdb, resolution, supersample=1):
    """`cloudgen bake` of these values to out_vdb, unless a file with the same bake key is
    there (--update); supersample: samples per voxel axis (--supersample)."""
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(dict(values, preset=name), f)
    extra = ["--supersample", str(supersample)] if supersample > 1 else []
    try:
        subprocess.run([str(ROOT / "build" / "bin" / "cloudgen"), "bake", "--params", f.name, "--resolution",
                        str(resolution), "--output", out_vdb, "--quiet", "--max-memory", "16", "--update"] + extra,
                       check=True)
    finally:
        os.remove(f.name)
    return out_vdb


def bake_all(name, values, work, args):
    """Bake what a type's shots need: {'main': path} for a compact type (plus 'companions':
    [paths]), {'levels': [(path, inner, outer)]} for a layer."""
    w = int(args.size.lower().split("x")[0])
    if gs.is_layer(values):
        levels = []
        for k, (lv, res, inner, outer) in enumerate(gs.layer_levels(name, values, w)):
            # baked as the level's whole square, twice as wide as the ring its material keeps
            # (gs.ring_mask), so that no volume's boundary stands where its density is not zero.
            # A Cycles volume's bounds follow the VDB's active voxels, and behind such a wall
            # Cycles mishandles the rays: with the ring's hole left out of the VDB it dropped the
            # density in a wedge behind the hole's wall (rounds 7 and 8, stratocumulus side-on:
            # "a bright triangle with a hard vertical edge, like a stitching seam"); baked out to
            # the ring's outer edge only (until 2026-12-02), the sun shone through behind level
            # 1's outer wall, 14.3 km out: a lit patch of haze and deck with a hard vertical edge
            # and a flat top ("a faint circular arc", rounds 41 and 42; 80x72 border renders of
            # it, docs/gallery/ring_seam.png: gone with the sun lamp hidden, with level 0 alone,
            # and with every level baked whole; not changed by a finer step, 128 transparent
            # bounces, or levels cross-faded over a quarter of the ring). The bakes themselves
            # match the model (max |VDB - density| 1.5e-4 at 2.9 mean density)
            path = bake(name, lv, os.path.join(work, f"{name}_L{k}.vdb"), res,
                        supersample=gs.level_supersample(lv, res))
            levels.append((path, inner, outer))
        return {"levels": levels}
    main_res = args.resolution * gs.MAIN_RESOLUTION_SCALE.get(name, 1)
    out = {"main": bake(name, values, os.path.join(work, f"{name}.vdb"), main_res), "companions": []}
    if name in gs.COMPANIONS:
        comp = gs.COMPANIONS[name][0]
        for i in range(len(gs.COMPANION_VARIANTS)):
            path = os.path.join(work, f"{comp}_companion{i}.vdb")
            out["companions"].append(bake(comp, gs.companion_values(name, i), path, args.resolution // 2))
    return out


def shot(name, view, sun, values, baked, out_png, args):
    import bpy
    from mathutils import Vector

    main_vdb = baked["main"] if "main" in baked else baked["levels"][0][0]
    ra = render_cloud.parse_args(["--preset", name, "--output", out_png, "--size", args.size,
                                  "--samples", str(args.samples), "--vdb", main_vdb])
    scene = render_cloud.build_scene(values, ra)  # the material, the main VDB object
    w, h = (int(v) for v in args.size.lower().split("x"))
    cloud = scene.objects["Cloud"]
    mat = cloud.data.materials[0]
    rng = random.Random(f"{name}-{view}")
    if "levels" in baked:
        centre, cam_at, pitch, lens = gs.layer_view(name, values, view, w, h)
        cloud.location = centre
        gs.ring_mask(mat, baked["levels"][0][1], baked["levels"][0][2])
        for k, (path, inner, outer) in enumerate(baked["levels"][1:], start=1):
            m = mat.copy()
            m.name = f"Cloud L{k}"
            m.node_tree.nodes.clear()
            render_cloud._addon_file("volume_material").volume_material(
                m, render_cloud.resolve_material(ra), grid="density", phase="AUTO", step_rate=1.0)
            gs.ring_mask(m, inner, outer)
            gs.add_vdb(scene, path, m, centre, name=f"Cloud L{k}")
    else:
        centre, cam_at, pitch, lens = gs.compact_view(name, values, view, w, h)
        cloud.location = centre
        if baked["companions"]:
            import cloudgen_native as cn

            comp = gs.COMPANIONS[name][0]
            cmat = bpy.data.materials.new("Companion")
            render_cloud._addon_file("volume_material").volume_material(
                cmat, dict(cn.presets()[comp].get("material", {})), grid="density", phase="AUTO", step_rate=1.0)
            for i, (x, y, z, s, rot) in enumerate(gs.companions(name, values, centre, view, w, h, rng)):
                gs.add_vdb(scene, baked["companions"][i % len(baked["companions"])], cmat, (x, y, z), s, rot,
                           name=f"Companion {i}")
    cam = scene.camera
    cam.data.lens = lens
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.clip_end = 1.0e5
    cam.location = cam_at
    cam.rotation_euler = (math.radians(90.0 + pitch), 0.0, 0.0)
    sl = render_cloud._addon_file("sky_light")
    if sun == "behind":  # the sun right behind the cloud's upper part: silver lining
        aim = Vector(centre) + Vector((0.0, 0.0, 0.25 * values["box_size"][2]))
        rel = aim - Vector(cam_at)
        elevation = math.degrees(math.atan2(rel.z, math.hypot(rel.x, rel.y)))
        sl.daylight(scene, elevation, 0.0)
    else:
        sl.daylight(scene, *sun_direction(name, view, sun, compact="main" in baked))
    render_cloud._addon_file("volume_material").point_halos(scene)  # the ice veils' 22° halo
    sun_seen = view == "side" and sun == "low" and name in SUN_IN_VIEW_SIDE  # its light, its balance
    if name in gs.OVERCAST and not sun_seen and hasattr(scene.view_settings, "use_white_balance"):
        scene.view_settings.white_balance_temperature = meter.OVERCAST_BALANCE_K
    ls = render_cloud._addon_file("landscape")
    ls.landscape(scene, centre=cam_at[:2], haze_top=gs.haze_top(name), hill_km=HILLS_KM.get(name, ls.HILL_KM),
                 visibility_km=ls.VISIBILITY_KM if gs.is_layer(values) else CLEAN_AIR_KM)
    rain = render_cloud._addon_file("precipitation")
    if name in rain.LOOKS:  # what falls from a rain cloud: under a layer, over the whole landscape
        import cloudgen_native as cn

        box = rain.rain_box(values, centre, cn.density,
                            half=ls.units(ls.TERRAIN_HALF_KM) if gs.is_layer(values) else None)
        rain.add_rain(scene, box[:2], box[2], box[3], box[4], **rain.LOOKS[name])
    light = meter.frame_luminance(scene)  # what a camera's meter reads: auto-ISO, exposure
    share = sunlit_share(gs.widened(name, values), centre, cam_at, scene)
    sunny = scene.view_settings.exposure + glare_compensation(light)
    scene.view_settings.exposure = meter.blended_exposure(sunny, light, share)
    print(f"gallery: {name} {view}: sunlit share {share:.3f}, sunny exposure {sunny:+.2f}, "
          f"metered exposure {scene.view_settings.exposure:+.2f}", flush=True)
    iso = camera_finish.iso_for_light(light, SUNNY_LIGHT)
    print(f"gallery: {name} {view}: frame luminance {light:.4g}, ISO {iso:.0f}", flush=True)
    scene.cycles.use_denoising = sl.denoiser_built_in() and not os.environ.get("GALLERY_NO_DENOISE")
    return render_cloud.render(scene, out_png), iso


# Every shot a run may ask for, in a fixed order: a file's number depends only on its type,
# view and sun (and --seed), never on which --types and --shots this run renders, so runs
# into one folder never overwrite each other's files (a --shots below-high run once took the
# number of another run's side-on stratus).
STANDARD_SHOTS = [("side", "low"), ("below", "high"), ("side", "behind")]


def file_numbers(all_types, names, shots, seed):
    """[((type, view, sun), number)] for the jobs of this run, numbered over every type and
    every standard shot (plus any other shot asked for) in one shuffle."""
    universe = STANDARD_SHOTS + [s for s in shots if s not in STANDARD_SHOTS]
    everything = [(n, v, s) for n in all_types for v, s in universe]
    numbers = list(range(1, len(everything) + 1))
    random.Random(seed).shuffle(numbers)
    return [(job, k) for job, k in zip(everything, numbers) if job[0] in names and (job[1], job[2]) in shots]


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    import cloudgen_native as cn

    presets = cn.presets()
    names = [t for t in args.types.split(",") if t] or sorted(presets)
    unknown = sorted(set(names) - set(presets))
    if unknown:
        raise SystemExit(f"gallery: error: unknown types {unknown}; known: {sorted(presets)}")
    shots = [tuple(s.split("-")) for s in args.shots.split(",") if s]
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    jobs, numbers = zip(*file_numbers(sorted(presets), names, shots, args.seed)) or ((), ())
    key_path = pathlib.Path(args.names) if args.names else out / "key.json"
    key = json.loads(key_path.read_text()) if key_path.exists() else {}
    with tempfile.TemporaryDirectory(prefix="cloudgen-gallery-") as tmp:
        work = args.bake_dir or tmp
        os.makedirs(work, exist_ok=True)
        baked = {}
        for (name, view, sun), number in zip(jobs, numbers):
            values = gs.widened(name, dict(cn.defaults(), **presets[name]["params"]))
            if name not in baked:
                baked[name] = bake_all(name, values, work, args)
            png = out / f"{number:02d}.{args.format}"
            seconds, iso = shot(name, view, sun, values, baked[name], str(png), args)
            key[png.name] = {"type": name, "view": view, "sun": sun, "seconds": round(seconds, 1)}
            if args.format == "png" and not args.no_finish:  # the render as a camera records it
                jpg = png.with_suffix(".jpg")
                camera_finish.finish_file(str(png), str(jpg), iso=iso)
                key[png.name].update(finished=jpg.name, iso=round(iso))
            key_path.write_text(json.dumps(key, indent=1, sort_keys=True) + "\n")
            print(f"gallery: {png} {name} {view}-{sun} {seconds:.1f} s", flush=True)


if __name__ == "__main__":
    main()
