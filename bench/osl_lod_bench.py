"""The procedural render's level of detail, measured: our default cumulus (Cloud
Main's early exit, and octaves finer than the pixel footprint at the shading
point's distance not evaluated) against a cloud shader of the thesis's kind
(bench/osl_thesis_style.osl: the whole eight-octave noise stack at every shading
point in the box, no early exit, no level of detail), at equal image error.

The scene is the thesis's: an 85 mm camera framing the cumulus box, an 18 W/m²
sun lamp, a sky texture world, 1 volume bounce, 256x256, 64 samples, Cycles on
the CPU with OSL, denoising off. Images are linear EXR.

Error: relative RMSE against a converged render of the full-detail cloud (the
cumulus with eight octaves everywhere, no LOD; rendered with the early exit,
which never changes a value, at --truth-samples): sqrt(mean((I - T)^2)) /
mean(T), over the pixels the cloud covers (where T differs from a sky-only
render by more than 1 %) and over the whole image. Sampling noise is part of
the error. Each variant renders at --samples; if ours is noisier than the
thesis's, the noise model E^2 = bias^2 + v / spp gives the sample count that
reaches the thesis's error: up to 10 % more, ours's time is scaled by it
(an overestimate), beyond that ours is rendered again at that count. Times:
wall and the process's CPU seconds (all render threads), best of --runs.
Variants: thesis, ours, ours_nolod (pixel angle 0), shape_only (no noise: the
time of everything else, another image).

Usage: .venv/bin/python bench/osl_lod_bench.py [--runs 1] [--size 256] [--samples 64]
       [--truth-samples 1024] [--work DIR] [--json bench/results/osl_lod_blender45.json]
The truth render (the slow part) is cached in --work by its settings.
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

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "osl"))
sys.path.insert(0, str(ROOT / "bench"))

LENS_MM = 85.0
SUN_W_M2 = 18.0
THESIS_OCTAVES = 8.0
PRESET = "cumulus"
MASK_REL = 0.01  # a pixel is the cloud's where the truth differs from the sky by more than this


def loadavg():
    return [float(v) for v in pathlib.Path("/proc/loadavg").read_text().split()[:3]]


def pixel_angle(cam_data, width, height):
    """Radians per pixel at the image centre (Blender's sensor fit)."""
    import render_cloud

    tx, _ = render_cloud._addon_file("camera_fit").tan_half_fov(cam_data, width, height)
    return 2.0 * tx / width


def thesis_node(nt, values):
    """The thesis-style shader as an internal-text Script node, its inputs set from values."""
    import blender_nodes
    import bpy
    import flatten
    from cycles import osl as cycles_osl

    text = bpy.data.texts.new("osl_thesis_style.osl")
    text.write(flatten.flatten(ROOT / "bench" / "osl_thesis_style.osl"))
    node = nt.nodes.new("ShaderNodeScript")
    node.mode = "INTERNAL"
    node.script = text
    messages = []
    if not cycles_osl.update_script_node(node, lambda kind, msg: messages.append(f"{kind}: {msg}")):
        raise RuntimeError(f"compiling osl_thesis_style.osl failed: {messages}")
    blender_nodes.set_inputs(node, values)
    return node


def build(values, variant, size, samples, seed):
    """The thesis's scene with the cloud as `variant`: "thesis" (osl_thesis_style), "ours"
    (Cloud Noise + Cloud Main, LOD from the camera), "ours_nolod", "full" (ours without LOD,
    every octave: the truth's cloud), "shape_only" (Cloud Main without noise: the time of
    everything but the noise, another image) or "sky" (no cloud)."""
    import blender_nodes
    import bpy
    import render_cloud

    blender_nodes.ensure_oslquery_importable()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.shading_system = True
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.seed = seed
    scene.cycles.volume_bounces = 1
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"

    box = values["box_size"]
    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = LENS_MM
    cam = bpy.data.objects.new("Camera", cam_data)
    scene.collection.objects.link(cam)
    location, rotation, cloud_z = render_cloud.frame_camera(box, size, size, cam_data.sensor_width, LENS_MM)
    cam.location, cam.rotation_euler = location, rotation
    scene.camera = cam

    sun_data = bpy.data.lights.new("Sun", "SUN")
    sun_data.energy = SUN_W_M2
    sun_data.angle = math.radians(0.545)
    sun = bpy.data.objects.new("Sun", sun_data)
    sun.rotation_euler = (math.radians(40), 0.0, math.radians(-35))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    sky = world.node_tree.nodes.new("ShaderNodeTexSky")
    if hasattr(sky, "sun_disc"):
        sky.sun_disc = False  # the sun is the lamp
    world.node_tree.links.new(sky.outputs["Color"], world.node_tree.nodes["Background"].inputs["Color"])
    scene.world = world
    if variant == "sky":
        return scene, {}

    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, cloud_z))
    cloud = bpy.context.active_object
    cloud.scale = box
    mat = bpy.data.materials.new("Cloud")
    material = render_cloud.resolve_material(argparse.Namespace(preset=PRESET, step_rate=None))
    volume = render_cloud._addon_file("volume_material").volume_material(
        mat, material, phase="HG", step_rate=material["step_rate"])
    nt = mat.node_tree
    coords = nt.nodes.new("ShaderNodeTexCoord")
    info = {"step_rate": material["step_rate"]}
    with render_cloud._addon_file("osl_temp").private_tempdir():
        if variant == "thesis":
            node = thesis_node(nt, dict(values, noise_detail=THESIS_OCTAVES))
            height = blender_nodes.script_node(nt, "cloud_height")
            blender_nodes.set_inputs(height, values)
            curve = blender_nodes.shape_curve_node(nt, values["shape_curve"])
            nt.links.new(coords.outputs["Generated"], height.inputs["Generated"])
            nt.links.new(height.outputs["Height"], curve.inputs["Value"])
            nt.links.new(curve.outputs["Value"], node.inputs["shape_gradient"])
            nt.links.new(coords.outputs["Generated"], node.inputs["Generated"])
            density = node.outputs["Density"]
            info["noise_detail"] = THESIS_OCTAVES
        else:
            v = dict(values, noise_detail=THESIS_OCTAVES) if variant == "full" else values
            main, noise = blender_nodes.cloud_density_nodes(nt, v, coords.outputs["Generated"])
            if variant == "ours":
                angle = pixel_angle(cam_data, size, size)
                noise.inputs["lod_pixel_angle"].default_value = angle
                info["lod_pixel_angle"] = angle
            if variant == "shape_only":  # timing floor: no noise at all (Distortion Noise 1/2)
                for link in list(nt.links):
                    if link.from_node == noise:
                        nt.links.remove(link)
            density = main.outputs["Density"]
            info["noise_detail"] = v["noise_detail"]
    nt.links.new(density, volume.inputs["Density"])
    cloud.data.materials.append(mat)
    info["camera_distance"] = math.dist(location, (0.0, 0.0, cloud_z))
    return scene, info


def render_exr(scene, path):
    import render_cloud

    return render_cloud.render(scene, path)


def read_exr(path):
    import bpy

    img = bpy.data.images.load(str(path))
    w, h = img.size
    px = np.array(img.pixels[:], dtype=np.float64).reshape(h, w, 4)[..., :3]
    bpy.data.images.remove(img)
    return px


def rel_rmse(img, truth, mask):
    d2 = ((img - truth) ** 2).mean(axis=-1)
    t = truth.mean(axis=-1)
    return {"cloud": float(math.sqrt(d2[mask].mean()) / t[mask].mean()),
            "image": float(math.sqrt(d2.mean()) / t.mean())}


def save_png(px, path):
    """A look at a linear image: x / (1 + x) per channel (viewing only)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.imsave(str(path), np.clip(px / (1.0 + px), 0, 1)[::-1])


def timed(values, variant, size, samples, seed, runs, out):
    """Render `runs` times: wall seconds and the process's CPU seconds (every render thread;
    less sensitive than wall time to other work on a shared machine)."""
    times, cpu, loads = [], [], []
    info = {}
    for _ in range(runs):
        scene, info = build(values, variant, size, samples, seed)
        loads.append(loadavg()[0])
        c0 = time.process_time()
        times.append(render_exr(scene, out))
        cpu.append(time.process_time() - c0)
    return {"variant": variant, "samples": samples, "best_s": min(times), "all_s": times,
            "best_cpu_s": min(cpu), "all_cpu_s": cpu, "load1_before": loads, **info}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--truth-samples", type=int, default=1024)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--variants", default="thesis,ours,ours_nolod,shape_only")
    ap.add_argument("--work", default=os.path.join(tempfile.gettempdir(), "cloudgen-osl-lod"))
    ap.add_argument("--json", default=None, help="write the result here (atomically)")
    opts = ap.parse_args()
    import bpy
    import cloudgen_native as cn
    import common

    work = pathlib.Path(opts.work)
    work.mkdir(parents=True, exist_ok=True)
    values = dict(cn.presets()[PRESET]["params"])
    full = dict(cn.defaults())
    full.update(values)
    values = full
    s, n = opts.size, opts.samples
    result = {"blender": bpy.app.version_string, "preset": PRESET, "size": [s, s], "samples": n,
              "truth_samples": opts.truth_samples, "seed": opts.seed, "runs": opts.runs,
              "lens_mm": LENS_MM, "sun_w_m2": SUN_W_M2, "volume_bounces": 1,
              "machine": common.machine_info(), "load_start": loadavg(), "renders": {}}

    # keyed by the cloud's field key too: a preset change must not reuse an old truth
    key = cn.field_key(dict(values, noise_detail=THESIS_OCTAVES))
    truth_path = work / f"truth_{s}_{opts.truth_samples}_{key}.exr"
    if not truth_path.exists():
        scene, _ = build(values, "full", s, opts.truth_samples, opts.seed + 1000)
        result["truth_render_s"] = render_exr(scene, truth_path)
    sky_path = work / f"sky_{s}.exr"
    if not sky_path.exists():
        scene, _ = build(values, "sky", s, 16, opts.seed)
        render_exr(scene, sky_path)
    truth, sky = read_exr(truth_path), read_exr(sky_path)
    mask = np.abs(truth - sky).max(axis=-1) > MASK_REL * sky.max(axis=-1)
    result["cloud_pixels"] = int(mask.sum())
    save_png(truth, work / "truth.png")

    for variant in [v for v in opts.variants.split(",") if v]:
        out = work / f"{variant}_{n}.exr"
        r = timed(values, variant, s, n, opts.seed, opts.runs, out)
        img = read_exr(out)
        r["rel_rmse"] = rel_rmse(img, truth, mask)
        save_png(img, work / f"{variant}_{n}.png")
        result["renders"][f"{variant}_{n}"] = r
        print(json.dumps({variant: r}), flush=True)

    renders = result["renders"]
    if f"thesis_{n}" in renders and f"ours_{n}" in renders:
        th, ours = renders[f"thesis_{n}"], renders[f"ours_{n}"]
        e_t, e_o = th["rel_rmse"]["cloud"], ours["rel_rmse"]["cloud"]
        equal = {"ours_samples": n, "ours_s": ours["best_s"], "ours_cpu_s": ours["best_cpu_s"], "ours_error": e_o,
                 "method": "same spp"}
        if e_o > e_t:
            # E^2 = b^2 + v/spp with b >= 0, so v <= n E_o^2 and ours reaches E_t by at most
            # need = n (E_o/E_t)^2 samples. Up to 10 % more samples: the time scaled by
            # need/n (an overestimate: the scene sync does not grow with spp); beyond: rendered.
            need = n * e_o ** 2 / e_t ** 2
            if need <= 1.1 * n:
                equal.update({"ours_samples": need, "ours_s": ours["best_s"] * need / n,
                              "ours_cpu_s": ours["best_cpu_s"] * need / n, "ours_error": e_t,
                              "method": "time scaled by the samples that reach the thesis's error"})
            else:
                need = int(math.ceil(need))
                out = work / f"ours_{need}.exr"
                r = timed(values, "ours", s, need, opts.seed, opts.runs, out)
                r["rel_rmse"] = rel_rmse(read_exr(out), truth, mask)
                renders[f"ours_{need}"] = r
                equal = {"ours_samples": need, "ours_s": r["best_s"], "ours_cpu_s": r["best_cpu_s"],
                         "ours_error": r["rel_rmse"]["cloud"],
                         "method": "rendered at the samples that reach the thesis's error"}
        equal.update({"thesis_samples": n, "thesis_s": th["best_s"], "thesis_cpu_s": th["best_cpu_s"],
                      "thesis_error": e_t, "speedup": th["best_s"] / equal["ours_s"],
                      "speedup_cpu": th["best_cpu_s"] / equal["ours_cpu_s"],
                      "speedup_same_spp": th["best_s"] / ours["best_s"]})
        result["equal_error"] = equal
    result["load_end"] = loadavg()
    text = json.dumps(result, indent=1)
    print(text)
    if opts.json:
        common.write_json(opts.json, result)


if __name__ == "__main__":
    main()
