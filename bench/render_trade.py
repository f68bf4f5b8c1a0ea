"""The render settings users reach for first, measured: volume bounces, the denoiser
against samples, adaptive sampling and the phase function, on the default cumulus
(a baked VDB) under the add-on's daylight (scripts/render_cloud.py --light sky).

Usage: .venv/bin/python bench/render_trade.py [--size 192x108] [--ref-samples 512]
       [--out bench/results/render_trade.json] [--sheet docs/images/render_trade_phase.png]
       [--work DIR] [--vdb FILE.vdb] [--quick]

One bpy process renders every variant in turn (one render at a time, Cycles CPU,
all threads), writing a linear EXR (the error measures) and the AgX display PNG
(FLIP, the contact sheet) of each. docs/render_trade.md explains the method and
the results. --quick is the smoke test's configuration: 32x18 px, 1 spp, two
variants of each study.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "scripts"))

from common import atomic_write, machine_info, splice, write_json  # noqa: E402

PRESET = "cumulus"
BASE_SAMPLES = 64
VIEWS = {                  # sun elevation, sun rotation (0: ahead of the camera, 180: behind it)
    "sun_behind": (35.0, 150.0),   # render_cloud.py's default: behind the camera, to one side
    "toward_sun": (10.0, 0.0),     # low sun straight ahead, behind the cloud: the silver lining
}
PHASES = {  # name: list of (weight, phase, parameter) lobes of Volume Scatter nodes
    "hg_0.3": [(1.0, "HENYEY_GREENSTEIN", 0.3)],
    "hg_0.6": [(1.0, "HENYEY_GREENSTEIN", 0.6)],
    "hg_0.85": [(1.0, "HENYEY_GREENSTEIN", 0.85)],
    "mie_20um": [(1.0, "MIE", 20.0)],
    "dual_hg_0.8_-0.2": [(0.7, "HENYEY_GREENSTEIN", 0.8), (0.3, "HENYEY_GREENSTEIN", -0.2)],
}
CLOUD_ALPHA = 0.1          # a pixel is cloud where the cloud's coverage (alpha) is at least this
BODY_ALPHA = 0.9           # the cloud's optically thick body; rim: CLOUD_ALPHA <= alpha < BODY_ALPHA


def base_bounces():
    """The add-on's volume bounces for clouds (sky_light.CLOUD_BOUNCES, 512 since 2026-11-28;
    the study's first run, 2026-11-24, used the 16 of then)."""
    import render_cloud

    return render_cloud._addon_file("sky_light").CLOUD_BOUNCES


def study_plan(quick, ref_samples):
    """The variants of every study: dicts with name, study, view, samples, bounces,
    denoise, adaptive (threshold or None), phase (None = the add-on's AUTO), seed."""
    base = base_bounces()

    def v(name, study, samples=BASE_SAMPLES, bounces=base, denoise=False, adaptive=None,
          phase=None, view="sun_behind", seed=0):
        return dict(name=name, study=study, view=view, samples=samples, bounces=bounces,
                    denoise=denoise, adaptive=adaptive, phase=phase, seed=seed)

    if quick:
        return [v("reference", "reference", samples=2, seed=1),
                v("bounces_1", "bounces", samples=1, bounces=1), v("bounces_64", "bounces", samples=1, bounces=64),
                v("spp_1", "denoise", samples=1), v("spp_1_oidn", "denoise", samples=1, denoise=True),
                v("adaptive_0.1", "adaptive", samples=2, adaptive=0.1),
                v("phase_hg_0.3_toward_sun", "phase", samples=1, phase="hg_0.3", view="toward_sun"),
                v("phase_dual_hg_0.8_-0.2_toward_sun", "phase", samples=1, phase="dual_hg_0.8_-0.2",
                  view="toward_sun")]
    plan = [v("reference", "reference", samples=ref_samples, seed=1)]
    plan += [v(f"bounces_{b}", "bounces", bounces=b) for b in (1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024)]
    for spp in (4, 8, 16, 32, 64):
        plan += [v(f"spp_{spp}", "denoise", samples=spp), v(f"spp_{spp}_oidn", "denoise", samples=spp, denoise=True)]
    plan += [v("spp_128", "denoise", samples=128)]
    plan += [v(f"adaptive_{t}", "adaptive", samples=128, adaptive=t) for t in (0.01, 0.05, 0.1)]
    for view in VIEWS:
        plan += [v(f"phase_{p}_{view}", "phase", phase=p, view=view) for p in PHASES]
    return plan


# ---------------------------------------------------------------- scenes --

def scene_args(vdb, size, variant):
    elevation, rotation = VIEWS[variant["view"]]
    return argparse.Namespace(preset=PRESET, params=None, size=size, samples=variant["samples"], step_rate=None,
                              seed=variant["seed"], threads=0, no_early_exit=False, zoom=1.0, aim=None,
                              vdb=str(vdb), light="sky", sun_elevation=elevation, sun_rotation=rotation,
                              bounces=variant["bounces"])


def set_phase(mat, lobes):
    """Replace the material's "Cloud Volume" by Volume Scatter lobes (white, density
    from the grid), mixed by their weights (the weights sum to 1, so the extinction is
    unchanged: a Mix Shader scales each closure's density by its weight)."""
    nt = mat.node_tree
    old = nt.nodes["Cloud Volume"]
    out = nt.nodes["Material Output"]
    grid = nt.nodes.get("Density Grid")
    if grid is None:
        grid = nt.nodes.new("ShaderNodeAttribute")
        grid.attribute_name = old.inputs["Density Attribute"].default_value
    color = tuple(old.inputs["Color"].default_value)
    nt.nodes.remove(old)
    shaders = []
    for _, phase, param in lobes:
        node = nt.nodes.new("ShaderNodeVolumeScatter")
        node.phase = phase
        node.inputs["Color"].default_value = color
        if phase == "MIE":
            node.inputs["Diameter"].default_value = param
        else:
            node.inputs["Anisotropy"].default_value = param
        nt.links.new(grid.outputs["Fac"], node.inputs["Density"])
        shaders.append(node)
    if len(shaders) == 1:
        nt.links.new(shaders[0].outputs["Volume"], out.inputs["Volume"])
        return
    if len(shaders) != 2:
        raise ValueError(f"a phase has one or two lobes, not {len(shaders)}")
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = lobes[1][0]  # Fac = the second shader's weight
    nt.links.new(shaders[0].outputs["Volume"], mix.inputs[1])
    nt.links.new(shaders[1].outputs["Volume"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Volume"])


def build(render_cloud, values, vdb, size, variant, mask=False):
    import bpy

    scene = render_cloud.build_scene(values, scene_args(vdb, size, variant))
    cyc = scene.cycles
    cyc.use_denoising = bool(variant["denoise"])
    if variant["denoise"]:
        cyc.denoiser = "OPENIMAGEDENOISE"
    cyc.use_adaptive_sampling = variant["adaptive"] is not None
    if variant["adaptive"] is not None:
        cyc.adaptive_threshold = float(variant["adaptive"])
        cyc.adaptive_min_samples = 0  # automatic
    if variant["phase"]:
        set_phase(bpy.data.materials["Cloud"], PHASES[variant["phase"]])
    if mask:  # the cloud's coverage: transparent film, few samples, no bounces needed
        scene.render.film_transparent = True
        cyc.samples, cyc.volume_bounces, cyc.use_denoising = 16, 1, False
    return scene


def render(scene, exr, png):
    """Render; write the linear EXR and the display PNG. Returns the render's wall seconds."""
    import bpy

    t0 = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - t0
    result = bpy.data.images["Render Result"]
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth, settings.exr_codec = "OPEN_EXR", "32", "ZIP"
    result.save_render(str(exr), scene=scene)
    if png:
        settings.file_format, settings.color_depth, settings.color_mode = "PNG", "8", "RGB"
        result.save_render(str(png), scene=scene)
    return seconds


def load_rgba(path, linear):
    """An image file as float HxWx4, row 0 at the top (linear EXR values untouched; a
    PNG's stored display values in [0, 1])."""
    import bpy

    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        if linear:
            img.colorspace_settings.name = "Non-Color"
        w, h = img.size
        buf = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(buf)
    finally:
        bpy.data.images.remove(img)
    return buf.reshape(h, w, 4)[::-1].copy()


# --------------------------------------------------------------- measures --

def luminance(rgb):
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def masked_mean(values, mask):
    return float(values[mask].mean()) if mask.any() else 0.0


def errors(test, ref, cloud, test_png=None, ref_png=None):
    """RMSE and mean absolute difference (linear, R G B) over the image and over the
    cloud's pixels; the cloud RMSE relative to the reference's mean there; FLIP of the
    display images."""
    d = test[..., :3].astype(np.float64) - ref[..., :3]
    out = {"rmse": float(np.sqrt(np.mean(d * d))), "mae": float(np.mean(np.abs(d)))}
    dc = d[cloud] if cloud.any() else d.reshape(-1, 3)
    out["rmse_cloud"] = float(np.sqrt(np.mean(dc * dc)))
    out["mae_cloud"] = float(np.mean(np.abs(dc)))
    ref_mean = masked_mean(ref[..., :3].mean(axis=2), cloud) if cloud.any() else float(ref[..., :3].mean())
    out["rel_rmse_cloud"] = out["rmse_cloud"] / ref_mean if ref_mean > 0 else float("nan")
    if test_png is not None and ref_png is not None:
        import flip_evaluator

        r8 = np.ascontiguousarray(ref_png[..., :3], dtype=np.float32)
        t8 = np.ascontiguousarray(test_png[..., :3], dtype=np.float32)
        _, mean, _ = flip_evaluator.evaluate(r8, t8, "LDR", inputsRGB=True, applyMagma=False,
                                             computeMeanError=True, parameters={})
        out["flip"] = float(mean)
    return out


def brightness(img, png, alpha):
    """Mean linear luminance and mean display value (0-255, the PNG's luminance) of the
    cloud's body (alpha >= BODY_ALPHA) and rim (CLOUD_ALPHA <= alpha < BODY_ALPHA)."""
    body = alpha >= BODY_ALPHA
    rim = (alpha >= CLOUD_ALPHA) & ~body
    lum, disp = luminance(img), luminance(png) * 255.0
    out = {"body_linear": masked_mean(lum, body), "rim_linear": masked_mean(lum, rim),
           "body_display": masked_mean(disp, body), "rim_display": masked_mean(disp, rim)}
    out["rim_median_linear"] = float(np.median(lum[rim])) if rim.any() else 0.0
    out["rim_over_body"] = out["rim_linear"] / out["body_linear"] if out["body_linear"] > 0 else float("nan")
    return out


# ------------------------------------------------------------------- run --

def bake(vdb):
    cli = os.environ.get("CLOUDGEN_BIN", str(ROOT / "build" / "bin" / "cloudgen"))
    subprocess.run([str(cli), "bake", "--preset", PRESET, "--resolution", "128", "--output", str(vdb), "--quiet"],
                   check=True)


def run(args):
    import render_cloud

    work = pathlib.Path(args.work or tempfile.mkdtemp(prefix="render-trade-"))
    work.mkdir(parents=True, exist_ok=True)
    vdb = pathlib.Path(args.vdb) if args.vdb else work / "cumulus_128.vdb"
    if not args.vdb and not (args.reuse and vdb.exists()):
        bake(vdb)
    values = render_cloud.resolve_params(argparse.Namespace(preset=PRESET, params=None))
    plan = study_plan(args.quick, args.ref_samples)
    load_before, load_after = list(os.getloadavg()), None
    if args.reuse:
        old = json.loads(pathlib.Path(args.out).read_text())
        load_before, load_after = old["load_before"], old["load_after"]
    masks = {}
    for view in sorted({v["view"] for v in plan}):
        probe = dict(plan[0], view=view, phase=None, denoise=False, adaptive=None)
        if not (args.reuse and (work / f"mask_{view}.exr").exists()):
            render(build(render_cloud, values, vdb, args.size, probe, mask=True), work / f"mask_{view}.exr", None)
        masks[view] = load_rgba(work / f"mask_{view}.exr", linear=True)[..., 3]
    images, rows = {}, []
    earlier = {}  # --reuse: the renders of an earlier run in --work, its times from --out
    if args.reuse:
        earlier = {r["name"]: r for r in json.loads(pathlib.Path(args.out).read_text())["variants"]}
    for i, variant in enumerate(plan):
        exr, png = work / f"{variant['name']}.exr", work / f"{variant['name']}.png"
        if variant["name"] in earlier and exr.exists() and png.exists():
            seconds, load = earlier[variant["name"]]["render_s"], earlier[variant["name"]]["load_1min"]
        else:
            scene = build(render_cloud, values, vdb, args.size, variant)
            load = os.getloadavg()[0]
            seconds = render(scene, exr, png)
        img, disp = load_rgba(exr, linear=True), load_rgba(png, linear=False)
        if not np.isfinite(img).all():
            raise SystemExit(f"render_trade: {variant['name']}: non-finite pixels in {exr}")
        images[variant["name"]] = (img, disp)
        row = dict(variant, render_s=round(seconds, 3), load_1min=round(load, 2),
                   **brightness(img, disp, masks[variant["view"]]))
        rows.append(row)
        print(f"[{i + 1}/{len(plan)}] {variant['name']}: {seconds:.1f} s (load {load:.1f})", flush=True)
    measure(rows, images, masks)
    result = {
        "preset": PRESET, "size": args.size, "vdb_resolution": 128, "quick": bool(args.quick),
        "base": {"samples": 1 if args.quick else BASE_SAMPLES, "bounces": base_bounces(), "denoise": False,
                 "light": "sky", "phase": "AUTO (Mie 20 um where Cycles has it)"},
        "views": {k: {"sun_elevation": e, "sun_rotation": r} for k, (e, r) in VIEWS.items()},
        "phases": {k: [list(lobe) for lobe in lobes] for k, lobes in PHASES.items()},
        "masks": {"cloud_alpha": CLOUD_ALPHA, "body_alpha": BODY_ALPHA,
                  "cloud_pixels": {k: int((m >= CLOUD_ALPHA).sum()) for k, m in masks.items()}},
        "blender": blender_version(),
        "machine": machine_info(),
        "load_before": [round(x, 2) for x in load_before],
        "load_after": load_after or [round(x, 2) for x in os.getloadavg()],
        "total_render_s": round(sum(r["render_s"] for r in rows), 1),
        "variants": rows,
    }
    write_json(args.out, derive(result))
    print(f"render_trade: wrote {args.out} ({len(rows)} renders, {result['total_render_s']} s of rendering)")
    if args.sheet:
        contact_sheet(rows, images, args.sheet)
        print(f"render_trade: wrote {args.sheet}")
    return result


def measure(rows, images, masks):
    """Each row's errors against its study's reference: bounces against the most bounces (same
    seed), phases against none (brightness only), the rest against the reference."""
    by_name = {r["name"]: r for r in rows}
    top_bounces = max((r for r in rows if r["study"] == "bounces"), key=lambda r: r["bounces"], default=None)
    for r in rows:
        if r["study"] in ("denoise", "adaptive"):
            ref = "reference"
        elif r["study"] == "bounces":
            ref = top_bounces["name"]
        else:
            continue
        cloud = masks[r["view"]] >= CLOUD_ALPHA
        (t, tp), (f, fp) = images[r["name"]], images[ref]
        r["reference"] = ref
        r.update(errors(t, f, cloud, tp, fp))
        r["body_vs_reference"] = r["body_linear"] / by_name[ref]["body_linear"] - 1.0 \
            if by_name[ref]["body_linear"] > 0 else float("nan")


def contact_sheet(rows, images, path):
    """The phases in two rows (toward the sun; sun behind the camera), display images."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phase_rows = [r for r in rows if r["study"] == "phase"]
    views = [v for v in VIEWS if any(r["view"] == v for r in phase_rows)][::-1]  # toward_sun first
    names = [p for p in PHASES if any(r["phase"] == p for r in phase_rows)]
    if not views or not names:
        return
    h, w = images[phase_rows[0]["name"]][1].shape[:2]
    fig, axes = plt.subplots(len(views), len(names), squeeze=False,
                             figsize=(2.6 * len(names), 2.6 * len(views) * h / w + 0.9 * len(views)))
    for i, view in enumerate(views):
        for j, phase in enumerate(names):
            ax = axes[i][j]
            row = next((r for r in phase_rows if r["view"] == view and r["phase"] == phase), None)
            ax.axis("off")
            if row is None:
                continue
            ax.imshow(np.clip(images[row["name"]][1][..., :3], 0, 1), interpolation="nearest")
            ax.set_title(f"{phase} · {view.replace('_', ' ')}\nbody {row['body_linear']:.3g}, "
                         f"rim median {row['rim_median_linear']:.3g}", fontsize=8)
    r0 = phase_rows[0]
    fig.suptitle(f"Default cumulus (VDB 128³, {r0['samples']} spp, {r0['bounces']} bounces, no denoiser): "
                 "the phase function", fontsize=9)
    fig.tight_layout(h_pad=1.2)
    with tempfile.TemporaryDirectory() as tmp:
        out = pathlib.Path(tmp) / "sheet.png"
        fig.savefig(out, dpi=110)
        plt.close(fig)
        atomic_write(path, out.read_bytes())


def derive(data):
    """Add the noise model to `data` (in place) and return it. A render without the
    denoiser at n samples has per-pixel noise variance c / n (independent samples), and
    so does the reference at N: RMSE(n vs reference)^2 = c (1/n + 1/N). c is the least-
    squares fit over the fixed-sample renders without the denoiser; the reference's own
    RMSE is sqrt(c / N). Every denoiser / adaptive row gets its cloud error against the
    truth, sqrt(RMSE^2 - c / N), and the samples a plain render needs for that error, c / e^2."""
    rows = data["variants"]
    ref = next((r for r in rows if r["name"] == "reference"), None)
    plain = [r for r in rows if r["study"] == "denoise" and not r["denoise"]]
    if ref is None or not plain:
        return data
    big_n = ref["samples"]
    model = {"reference_samples": big_n, "fit_samples": sorted(r["samples"] for r in plain)}
    for key in ("rmse", "rmse_cloud"):
        xs = np.array([1.0 / r["samples"] + 1.0 / big_n for r in plain])
        ys = np.array([r[key] ** 2 for r in plain])
        c = float((xs * ys).sum() / (xs * xs).sum())
        model[f"c_{key}"] = c
        model[f"reference_{key}"] = math.sqrt(c / big_n)
        model[f"fit_max_rel_dev_{key}"] = float(np.max(np.abs(c * xs - ys) / ys)) if (ys > 0).all() else None
    data["noise_model"] = model
    c, floor2 = model["c_rmse_cloud"], model["c_rmse_cloud"] / big_n
    for r in rows:
        if r["study"] in ("denoise", "adaptive"):
            e = math.sqrt(max(r["rmse_cloud"] ** 2 - floor2, 0.0))
            r["rmse_cloud_vs_truth"] = e
            r["equivalent_spp"] = c / (e * e) if e > 0 else float("inf")
    return data


# ----------------------------------------------------------------- report --

BEGIN, END = "<!-- generated:start -->", "<!-- generated:end -->"


def _f(x, fmt=".3g"):
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def report_tables(data):
    """The generated part of docs/render_trade.md: method facts and one table per study."""
    rows = {r["name"]: r for r in data["variants"]}
    m, ref = data["machine"], rows.get("reference", {})
    lines = [
        "## Measured",
        "",
        f"- **Machine:** {m.get('cpu_model')} ({m.get('nproc')} cores, {m.get('mem_total_gib')} GiB); "
        f"load average {', '.join(str(x) for x in data['load_before'])} before, "
        f"{', '.join(str(x) for x in data['load_after'])} after; Blender {data['blender']}",
        f"- **Image:** {data['size']} px; VDB {data['vdb_resolution']}³ of the {data['preset']}; "
        f"{data['total_render_s']} s of rendering in all, one render at a time, one run each",
        f"- **Reference** (denoiser, adaptive): {ref.get('samples')} spp, {ref.get('bounces')} bounces, "
        f"seed {ref.get('seed')}, no denoiser, {_f(ref.get('render_s'))} s. Other renders: seed 0.",
        f"- **Cloud pixels:** coverage ≥ {data['masks']['cloud_alpha']} ("
        + ", ".join(f"{k}: {v} px" for k, v in data["masks"]["cloud_pixels"].items())
        + f"); *body*: coverage ≥ {data['masks']['body_alpha']}; "
        "*rim*: the cloud pixels outside the body.",
        "",
        f"### Volume bounces (sun behind the camera; {data['base']['samples']} spp; error against the most "
        "bounces, same seed)",
        "",
        "| Bounces | Render s | Body (linear) | Body (display 0–255) | Body vs most | RMSE cloud | Rel. RMSE cloud "
        "| MAE cloud | FLIP |",
        "|--:|--:|--:|--:|--:|--:|--:|--:|--:|",
    ]
    for r in sorted((r for r in data["variants"] if r["study"] == "bounces"), key=lambda r: r["bounces"]):
        lines.append(f"| {r['bounces']} | {_f(r['render_s'])} | {_f(r['body_linear'])} | {_f(r['body_display'])} "
                     f"| {_f(100 * r['body_vs_reference'], '+.1f')} % | {_f(r['rmse_cloud'])} "
                     f"| {_f(r['rel_rmse_cloud'])} | {_f(r['mae_cloud'])} | {_f(r['flip'])} |")
    nm = data.get("noise_model") or {}
    bounces = data["base"]["bounces"]
    lines += ["", f"### Samples with and without OpenImageDenoise ({bounces} bounces; error against the reference)", "",
              "*Vs truth* removes the reference's own noise (see Method: "
              f"reference RMSE ≈ {_f(nm.get('reference_rmse'))} over the image, "
              f"{_f(nm.get('reference_rmse_cloud'))} over the cloud); *as noisy spp*: the samples a render "
              "without the denoiser needs for the same cloud error vs truth.", "",
              "| spp | OIDN | Render s | RMSE | RMSE cloud | Rel. RMSE cloud | Cloud vs truth | As noisy spp "
              "| MAE cloud | FLIP |",
              "|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for r in sorted((r for r in data["variants"] if r["study"] == "denoise"),
                    key=lambda r: (r["samples"], r["denoise"])):
        lines.append(f"| {r['samples']} | {'on' if r['denoise'] else 'off'} | {_f(r['render_s'])} | {_f(r['rmse'])} "
                     f"| {_f(r['rmse_cloud'])} | {_f(r['rel_rmse_cloud'])} | {_f(r.get('rmse_cloud_vs_truth'))} "
                     f"| {_f(r.get('equivalent_spp'), '.0f')} | {_f(r['mae_cloud'])} | {_f(r['flip'])} |")
    lines += ["", f"### Adaptive sampling ({bounces} bounces; at most the given samples; error against the reference)",
              "",
              "| Noise threshold | Max spp | Render s | RMSE | RMSE cloud | Rel. RMSE cloud | Cloud vs truth "
              "| As noisy spp | MAE cloud | FLIP |",
              "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    fixed = sorted((r for r in data["variants"] if r["study"] == "denoise" and not r["denoise"]),
                   key=lambda r: r["samples"])
    adaptive = sorted((r for r in data["variants"] if r["study"] == "adaptive"), key=lambda r: -r["adaptive"])
    for r in adaptive + [f for f in fixed if f["samples"] >= 32]:
        label = "off (fixed)" if r["adaptive"] is None else str(r["adaptive"])
        lines.append(f"| {label} | {r['samples']} | {_f(r['render_s'])} | {_f(r['rmse'])} | {_f(r['rmse_cloud'])} "
                     f"| {_f(r['rel_rmse_cloud'])} | {_f(r.get('rmse_cloud_vs_truth'))} "
                     f"| {_f(r.get('equivalent_spp'), '.0f')} | {_f(r['mae_cloud'])} | {_f(r['flip'])} |")
    lines += ["", f"### Phase function ({data['base']['samples']} spp, {data['base']['bounces']} bounces, "
              "no denoiser; no reference: each is a different model)", "",
              "| Phase | Sun behind: render s | body (linear) | body (display) | Toward the sun: render s "
              "| body (linear) | rim mean (linear) | rim median (linear) | rim mean / body | body (display) "
              "| rim (display) |",
              "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"]
    for phase in data["phases"]:
        b = next((r for r in data["variants"] if r["phase"] == phase and r["view"] == "sun_behind"), {})
        t = next((r for r in data["variants"] if r["phase"] == phase and r["view"] == "toward_sun"), {})
        if not b and not t:
            continue
        lines.append(f"| {phase} | {_f(b.get('render_s'))} | {_f(b.get('body_linear'))} | {_f(b.get('body_display'))} "
                     f"| {_f(t.get('render_s'))} | {_f(t.get('body_linear'))} | {_f(t.get('rim_linear'))} "
                     f"| {_f(t.get('rim_median_linear'))} "
                     f"| {_f(t.get('rim_over_body'))} | {_f(t.get('body_display'))} | {_f(t.get('rim_display'))} |")
    return "\n".join(lines)


def write_report(data, doc):
    doc = pathlib.Path(doc)
    text = doc.read_text() if doc.exists() else ""
    atomic_write(doc, splice(text, BEGIN, END, report_tables(data), "# Render settings: the trade, extended\n\n"))


def blender_version():
    import bpy

    return bpy.app.version_string


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="192x108", help="WxH pixels (default 192x108)")
    ap.add_argument("--ref-samples", type=int, default=512, help="samples of the reference render (default 512)")
    ap.add_argument("--out", default=str(ROOT / "bench" / "results" / "render_trade.json"), help="results JSON")
    ap.add_argument("--sheet", default=str(ROOT / "docs" / "images" / "render_trade_phase.png"),
                    help="phase contact sheet PNG ('' for none)")
    ap.add_argument("--work", default=None, help="folder for the renders (default: a new temporary folder)")
    ap.add_argument("--vdb", default=None, help="a baked cumulus VDB (default: bake one at 128)")
    ap.add_argument("--quick", action="store_true", help="smoke test: 2 variants per study, 1-2 spp")
    ap.add_argument("--doc", default=str(ROOT / "docs" / "render_trade.md"),
                    help="Markdown report whose generated block is rewritten ('' for none)")
    ap.add_argument("--reuse", action="store_true",
                    help="measure the renders an earlier run left in --work again (times from --out); "
                         "render only what is missing")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite --doc's generated block from --out without rendering")
    args = ap.parse_args(argv)
    if args.ref_samples < 1:
        ap.error(f"--ref-samples must be >= 1, not {args.ref_samples}")
    try:
        w, h = (int(x) for x in args.size.lower().split("x"))
        if w < 8 or h < 8:
            raise ValueError
    except ValueError:
        ap.error(f"--size must be WxH with both at least 8, not {args.size!r}")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.report_only:
        data = derive(json.loads(pathlib.Path(args.out).read_text()))
        write_json(args.out, data)
    else:
        data = run(args)
    if args.doc:
        write_report(data, args.doc)
        print(f"render_trade: wrote {args.doc}")


if __name__ == "__main__":
    main()
