"""Reproduce the thesis's two model figures with cloudgen: the generation steps and the
parameter effects (its Fig. 36), for comparison with what the thesis shows.

Usage: .venv/bin/python scripts/thesis_figures.py [--out docs/gallery/thesis]
       [--work DIR] [--samples 32] [--size 240x180] [--resolution 128] [--no-denoise]
       [--only steps|effects]

Every variant starts from the model's defaults (`cloudgen_native.defaults()`: any
parameter the thesis does not name keeps its default) and sets only the thesis's
parameters (table in docs/gallery/thesis/README.md). Each is baked with the CLI
(`cloudgen bake --resolution N`) and its VDB rendered with scripts/render_cloud.py's
studio scene (a flat blue world, a sun, Standard view, 4 volume bounces); the steps figure
replaces the world by black for the camera (a dim grey ambient still lights the cloud, as
in the thesis's renders) and raises the sun to light the cloud from above-front. Renders
go to --work (default: a fresh temporary folder); a render whose parameter file there is
unchanged is reused, so re-running after a tweak only renders what changed. The two
figures are composed with matplotlib and written atomically as
OUT/generation_steps.png and OUT/parameter_effects.png. 25 renders in all.
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
from types import SimpleNamespace

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "osl"))

STEPS_BOX = [4.0, 4.0, 2.0]    # a wide, flat box: the thesis's ellipsoid is about twice as wide as tall
SHAPES_BOX = [3.0, 3.0, 3.0]   # cube: the height profile shows undistorted
NOISE_BOX = [4.0, 4.0, 2.5]

# (file stem, caption, the thesis's parameters for this step)
STEPS = [
    ("step1_ellipsoid", "distance from origin\n(Shape Exponent 1, Distortion 0)",
     {"shape_mode": 0, "shape_exponent": 1.0, "distortion": 0.0}),
    ("step2_shape", "shape function\n(Shape Exponent 0.6, Distortion 0)",
     {"shape_mode": 0, "shape_exponent": 0.6, "distortion": 0.0}),
    ("step3_worley", "+ Worley distortion\n(Distortion 1, Worley 1, Overall Sc. 0.7)",
     {"shape_mode": 0, "shape_exponent": 0.6, "distortion": 1.0, "overall_scale": 0.7,
      "worley_influence": 1.0, "noise_influence": 0.0}),
    ("step4_perlin", "+ Perlin distortion\n(Noise Influence 0.6)",
     {"shape_mode": 0, "shape_exponent": 0.6, "distortion": 1.0, "overall_scale": 0.7,
      "worley_influence": 1.0, "noise_influence": 0.6}),
    ("step5_dissolve", "~ dissolve (no such term): Noise\nInfl. 1, Distortion 2, Cloud Sc. 0.7",
     {"shape_mode": 0, "shape_exponent": 0.6, "distortion": 2.0, "overall_scale": 0.7,
      "worley_influence": 1.0, "noise_influence": 1.0, "cloud_scale": 0.7}),
]


def _curve(fn):
    """17 samples of a profile fn(h) at h = 0, 1/16, ..., 1, clamped to [0, 1], 3 decimals."""
    return [round(min(max(fn(k / 16.0), 0.0), 1.0), 3) for k in range(17)]


def _base(h, width=1.0 / 16.0):
    """0 at h = 0 rising to 1 at h = width: the flat base every profile shares."""
    return min(h / width, 1.0)


# (file stem, caption, 17-sample Shape Gradient): approximations of the thesis's four curves
SHAPE_CURVES = [
    ("shape_dome", "dome", _curve(lambda h: _base(h) * (1.0 - h * h))),
    ("shape_tower", "bell / tower",
     _curve(lambda h: _base(h) * 0.8 * (1.0 - (max(h - 0.35, 0.0) / 0.65) ** 2) ** 0.5)),
    ("shape_double", "double hump",
     _curve(lambda h: _base(h) * (0.22 + 0.6 * math.exp(-((h - 0.18) / 0.14) ** 2)
                                  + 0.55 * math.exp(-((h - 0.72) / 0.14) ** 2)) * (1.0 - h ** 8))),
    ("shape_skewed", "skewed", _curve(lambda h: _base(h) * (0.35 + 0.65 * min(h / 0.3, 1.0))
                                      * max(1.0 - max(h - 0.3, 0.0) / 0.7, 0.0) ** 1.3)),
]

# (key, label, the thesis's two values), in the thesis's order: its middle column, then its right
NOISE_PARAMS = [
    ("overall_scale", "Overall Scale", (0.5, 2.0)),
    ("worley_influence", "Worley Influence", (0.0, 1.0)),
    ("worley_clump", "Worley Clump", (0.0, 1.0)),
    ("wave", "Wave", (0.0, 0.5)),
    ("noise_influence", "Noise Influence", (0.0, 1.0)),
    ("noise_scale", "Noise Scale", (0.5, 2.0)),
    ("noise_detail", "Noise Detail", (2, 10)),
    ("noise_whisp", "Noise Whisp", (0.5, 0.7)),
]


def parse_args(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "gallery" / "thesis"), help="folder for the two PNGs")
    ap.add_argument("--work", default=None, help="folder for parameter files, VDBs and renders (kept; reused)")
    ap.add_argument("--samples", type=int, default=32, help="samples per pixel per panel (default 32)")
    ap.add_argument("--size", default="240x180", help="WxH of one panel (default 240x180)")
    ap.add_argument("--resolution", type=int, default=128, help="bake voxels along the box's longest side")
    ap.add_argument("--no-denoise", action="store_true", help="no OpenImageDenoise (raw path-traced grain)")
    ap.add_argument("--only", choices=("steps", "effects"), default=None, help="one figure only")
    return ap.parse_args(argv)


def variant_params(box, overrides):
    """The model's defaults, the box, then the thesis's parameters for this variant."""
    import cloudgen_native as cn

    values = dict(cn.defaults())
    values["box_size"] = list(box)
    values.update(overrides)
    cn.density(values, [[0.0, 0.0, 0.0]])  # validates (ValueError names the key)
    return values


def variants(which):
    """[(figure, stem, box, overrides)] of every panel to render."""
    out = []
    if which in (None, "steps"):
        out += [("steps", stem, STEPS_BOX, p) for stem, _, p in STEPS]
    if which in (None, "effects"):
        out += [("effects", stem, SHAPES_BOX, {"shape_mode": 1, "shape_curve": curve})
                for stem, _, curve in SHAPE_CURVES]
        out += [("effects", f"{key}_{value}", NOISE_BOX, {key: value})
                for key, _, values in NOISE_PARAMS for value in values]
    return out


def bake(params_file, vdb, resolution):
    cli = ROOT / "build" / "bin" / "cloudgen"
    subprocess.run([str(cli), "bake", "--params", str(params_file), "--resolution", str(resolution),
                    "--output", str(vdb), "--quiet"], check=True)


def black_world(scene):
    """A world black to the camera but a dim grey to the cloud (ambient fill, as the
    thesis's renders have: their shadow sides are grey, not black)."""
    import bpy

    world = bpy.data.worlds.new("Black")
    world.use_nodes = True
    nt = world.node_tree
    bg = nt.nodes["Background"]
    bg.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    bg.inputs["Strength"].default_value = 0.35
    black = nt.nodes.new("ShaderNodeBackground")
    black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    path = nt.nodes.new("ShaderNodeLightPath")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    nt.links.new(bg.outputs["Background"], mix.inputs[1])
    nt.links.new(black.outputs["Background"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], nt.nodes["World Output"].inputs["Surface"])
    scene.world = world
    sun = scene.objects["Sun"]
    sun.rotation_euler = (math.radians(28), 0.0, math.radians(-20))  # from above, in front of the cloud


def render_panel(figure, params_file, vdb, png, args):
    import render_cloud

    values = render_cloud.resolve_params(SimpleNamespace(preset=None, params=str(params_file)))
    ns = SimpleNamespace(preset=None, params=str(params_file), vdb=str(vdb), light="studio",
                         samples=args.samples, seed=0, bounces=None, threads=0, size=args.size,
                         step_rate=None, no_early_exit=False, zoom=1.0, aim=None)
    scene = render_cloud.build_scene(values, ns)
    if figure == "steps":
        black_world(scene)
    if not args.no_denoise:
        scene.cycles.use_denoising = render_cloud._addon_file("sky_light").denoiser_built_in()
    return render_cloud.render(scene, png)


def render_all(args, work):
    """Bake and render every panel (reusing unchanged ones); {stem: png path}."""
    pngs = {}
    todo = variants(args.only)
    for i, (figure, stem, box, overrides) in enumerate(todo, 1):
        values = variant_params(box, overrides)
        setup = {"params": values, "samples": args.samples, "size": args.size,
                 "resolution": args.resolution, "denoise": not args.no_denoise, "figure": figure}
        params_file, vdb, png = (work / f"{stem}{ext}" for ext in (".json", ".vdb", ".png"))
        setup_file = work / f"{stem}.setup.json"
        text = json.dumps(setup, sort_keys=True)
        pngs[stem] = png
        if png.exists() and setup_file.exists() and setup_file.read_text() == text:
            print(f"[{i}/{len(todo)}] {stem}: unchanged, reused")
            continue
        params_file.write_text(json.dumps(values))
        bake(params_file, vdb, args.resolution)
        seconds = render_panel(figure, params_file, vdb, png, args)
        setup_file.write_text(text)
        print(f"[{i}/{len(todo)}] {stem}: rendered in {seconds:.1f} s")
    return pngs


def save_atomically(fig, path):
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, staged = tempfile.mkstemp(prefix="." + path.name + ".", suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(staged, dpi=100, facecolor=fig.get_facecolor())
        os.chmod(staged, 0o644)
        os.replace(staged, path)
    finally:
        if os.path.exists(staged):
            os.remove(staged)


def steps_figure(pngs, out):
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(STEPS), figsize=(2.6 * len(STEPS), 2.65), facecolor="white")
    for ax, (stem, caption, _) in zip(axes, STEPS):
        ax.imshow(mpimg.imread(pngs[stem]))
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_xlabel(caption, fontsize=9)
    fig.suptitle("cloudgen: the density built up step by step (baked, Cycles, black world)", fontsize=10)
    fig.subplots_adjust(left=0.01, right=0.99, top=0.88, bottom=0.2, wspace=0.04)
    save_atomically(fig, out)
    plt.close(fig)


def _panel(ax, png, value=None):
    import matplotlib.image as mpimg

    ax.imshow(mpimg.imread(png))
    ax.set_xticks([])
    ax.set_yticks([])
    if value is not None:
        ax.text(0.04, 0.06, f"{value}", transform=ax.transAxes, color="white", fontsize=11,
                fontstyle="italic", fontweight="bold")


def _curve_inset(fig, rect, curve):
    """The Shape Gradient as Blender's curve widget draws it: height left to right,
    squared radius up, filled under the curve, on a grid."""
    ax = fig.add_axes(rect)
    h = [k / 16.0 for k in range(17)]
    ax.fill_between(h, curve, color="#9c9488")
    ax.plot(h, curve, color="#3d3a35", lw=1.0)
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.05)
    ax.set_xticks([0.25, 0.5, 0.75])
    ax.set_yticks([0.25, 0.5, 0.75])
    ax.grid(True, color="#b8b8b8", lw=0.5)
    ax.tick_params(labelbottom=False, labelleft=False, length=0)
    ax.set_facecolor("#f4f4f4")
    return ax


def effects_figure(pngs, out):
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12.0, 7.6), facecolor="white")
    rows = len(SHAPE_CURVES)
    cell_h = 0.93 / rows       # one row: a pair of panels and its label
    img_h = cell_h * 0.78
    top = 0.965
    for r, (stem, caption, curve) in enumerate(SHAPE_CURVES):
        y = top - (r + 1) * cell_h + cell_h * 0.16
        ax = fig.add_axes([0.045, y, 0.2, img_h])
        _panel(ax, pngs[stem])
        ax.set_title(caption, fontsize=8, loc="right", pad=2)
        _curve_inset(fig, [0.005, y + img_h * 0.55, 0.075, img_h * 0.45], curve)
    for c, group in enumerate((NOISE_PARAMS[:4], NOISE_PARAMS[4:])):
        x0 = 0.29 + c * 0.36
        for r, (key, label, values) in enumerate(group):
            y = top - (r + 1) * cell_h + cell_h * 0.16
            for k, value in enumerate(values):
                _panel(fig.add_axes([x0 + k * 0.172, y, 0.168, img_h]), pngs[f"{key}_{value}"], value)
            fig.text(x0 + 0.17, y - cell_h * 0.02, label, ha="center", va="top", fontsize=10,
                     fontstyle="italic")
    fig.text(0.005, 0.99, "Shape Gradient (height →)", fontsize=8, va="top")
    fig.text(0.29, 0.99, "cloudgen: each Cloud Noise parameter at the thesis's two values "
             "(the others at the model's defaults)", fontsize=9, va="top")
    save_atomically(fig, out)
    plt.close(fig)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    import matplotlib

    matplotlib.use("Agg")
    work = pathlib.Path(args.work) if args.work else pathlib.Path(tempfile.mkdtemp(prefix="cloudgen-thesis-"))
    work.mkdir(parents=True, exist_ok=True)
    pngs = render_all(args, work)
    out = pathlib.Path(args.out)
    if args.only in (None, "steps"):
        steps_figure(pngs, out / "generation_steps.png")
        print(f"wrote {out / 'generation_steps.png'}")
    if args.only in (None, "effects"):
        effects_figure(pngs, out / "parameter_effects.png")
        print(f"wrote {out / 'parameter_effects.png'}")
    print(f"renders, parameter files and VDBs in {work}")


if __name__ == "__main__":
    main()
