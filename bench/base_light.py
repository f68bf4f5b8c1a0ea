"""Where a heap cloud's light comes from, side-on: the gallery's side-low shot of one type
(scripts/gallery.py, 320x180, 16 spp, no denoiser, scene-linear EXR) rendered once as it is
and once with each source removed (the sky's strength 0, the sun lamp, the companion cumulus,
the haze, the ground) and once without the main cloud, to find its pixels. Prints a markdown
table of the mean luminance (Rec.709) of two regions of the main cloud's middle fifth of
columns: the flank a third of the way up each column's longest run of cloud pixels (5 rows)
and the base (its lowest 5 rows). Cloud pixels: where the render differs from the one without
the main cloud by more than 15 % of the render's luminance in RGB distance, after a 5x5 box
blur (a grey base in front of a pale sky differs in colour more than in luminance).
docs/lighting.md quotes the result.

Usage: PYTHONPATH=build/python .venv/bin/python bench/base_light.py [--type cumulus_congestus]
       [--out /tmp/base_light] [--bake-dir DIR]
"""
import argparse
import os
import pathlib
import subprocess
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
VARIANTS = ("all", "no_sky", "no_sun", "no_companions", "no_haze", "no_ground", "no_main")
# what each variant hides (the sky is switched off instead: its world has no object)
HIDDEN = {"no_sun": lambda o: o.type == "LIGHT",
          "no_companions": lambda o: o.name.startswith("Companion"),
          "no_haze": lambda o: o.name.startswith("Cloud Haze"),
          "no_ground": lambda o: o.name.startswith(("Cloud Ground", "Cloud Woods")),  # the woods stand on it
          "no_main": lambda o: o.name == "Cloud"}


def render_variant(variant, name, out, bake_dir):
    """Run in a child process: the gallery's shot with one source removed just before rendering."""
    sys.path.insert(0, str(ROOT / "scripts"))
    os.environ["GALLERY_NO_DENOISE"] = "1"
    import gallery
    import render_cloud

    plain = render_cloud.render

    def render(scene, out_png):
        if variant == "no_sky":
            for node in scene.world.node_tree.nodes:
                if node.type == "BACKGROUND":
                    node.inputs["Strength"].default_value = 0.0
        for o in scene.objects:
            if variant in HIDDEN and HIDDEN[variant](o):
                o.hide_render = True
        return plain(scene, out_png)

    gallery.shot.__globals__["render_cloud"].render = render
    gallery.main(["--out", str(pathlib.Path(out) / variant), "--samples", "16", "--bake-dir", bake_dir, "--types",
                  name, "--shots", "side-low", "--size", "320x180", "--format", "exr", "--no-finish"])


def load(folder):
    import OpenImageIO as oiio

    exr = next(pathlib.Path(folder).glob("*.exr"))
    return oiio.ImageBuf(str(exr)).get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


def luminance(rgb):
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def box_blur(a, k=2):
    p = np.pad(a, k, mode="edge")
    h, w = a.shape
    return sum(p[k + dy:k + dy + h, k + dx:k + dx + w] for dy in range(-k, k + 1) for dx in range(-k, k + 1)) / (
        2 * k + 1) ** 2


def regions(everything, without_main):
    """(flank pixels, base pixels) of the main cloud: see the module's docstring."""
    diff = np.sqrt(sum(box_blur(everything[..., c] - without_main[..., c]) ** 2 for c in range(3)))
    mask = diff > 0.15 * box_blur(luminance(everything))
    cols = [c for c in range(mask.shape[1]) if mask[:, c].sum() > 20]
    lo, hi = min(cols), max(cols)
    flank, base = [], []
    for c in range(lo + int(0.4 * (hi - lo)), lo + int(0.6 * (hi - lo)) + 1):
        on = np.concatenate([[0], mask[:, c].astype(np.int8), [0]])
        starts, ends = np.where(np.diff(on) == 1)[0], np.where(np.diff(on) == -1)[0] - 1
        k = int(np.argmax(ends - starts))
        top, bottom = starts[k], ends[k]
        row = bottom - (bottom - top) // 3
        flank += [(r, c) for r in range(row - 2, row + 3)]
        base += [(r, c) for r in range(bottom - 4, bottom + 1)]
    return flank, base


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--type", default="cumulus_congestus")
    ap.add_argument("--out", default="/tmp/base_light")
    ap.add_argument("--bake-dir", default="/tmp/base_light/bakes")
    ap.add_argument("--variant", help=argparse.SUPPRESS)  # the child process's one render
    args = ap.parse_args()
    if args.variant:
        return render_variant(args.variant, args.type, args.out, args.bake_dir)
    for v in VARIANTS:
        subprocess.run([sys.executable, __file__, "--type", args.type, "--out", args.out, "--bake-dir",
                        args.bake_dir, "--variant", v], check=True, stdout=subprocess.DEVNULL)
    images = {v: load(pathlib.Path(args.out) / v) for v in VARIANTS}
    flank, base = regions(images["all"], images["no_main"])
    shown = VARIANTS[:-1]
    print("| region | " + " | ".join(v.replace("_", " ") for v in shown) + " |")
    print("|---" * (len(shown) + 1) + "|")
    for label, px in (("flank (a third up)", flank), ("base band (the lowest 5 rows)", base)):
        rows, cols = zip(*px)
        print(f"| {label} | " + " | ".join(f"{luminance(images[v])[rows, cols].mean():.2f}" for v in shown) + " |")


if __name__ == "__main__":
    main()
