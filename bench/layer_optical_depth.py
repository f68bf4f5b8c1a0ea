"""Each preset's optical depth straight up: the model's density (extinction per scene unit,
cloudgen_native.density) summed along vertical columns through its box. Columns at random over
the box's middle (a fifth of each side either way of the centre for a layer, three tenths for a
compact cloud), COLUMNS of them, STEPS midpoint steps each; a column counts as covered where its
optical depth exceeds 1. Prints a markdown table (docs/model.md quotes it) beside ISCCP's
optical-depth classes for the genus (Rossow and Schiffer 1999: satellite classes by cloud-top
pressure and optical depth, thin < 3.6 <= medium < 23 <= thick; a guide, not the WMO's
definition).

Usage: PYTHONPATH=build/python .venv/bin/python bench/layer_optical_depth.py [--columns 4000]
"""
import argparse
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "scripts"))
from render_cloud import is_layer  # noqa: E402  the one layer rule (a Sheet), as the gallery's

STEPS = 200
# the layer genus's ISCCP class (its cell in the cloud-top pressure x optical depth table; the
# classes average satellite pixels, so a compact cloud's own column has none here, and a veil
# thin enough for a halo is thinner than ISCCP's "cirrostratus")
ISCCP = {"stratocumulus": "3.6–23", "stratus": "> 23", "altocumulus": "< 3.6",
         "altostratus": "3.6–23", "nimbostratus": "> 23", "cirrus": "< 3.6", "cirrostratus": "3.6–23"}


def column_depths(values, columns, rng):
    """Optical depths of `columns` vertical columns through the middle of the preset's box."""
    import cloudgen_native as cn

    bx, by, bz = values["box_size"]
    frac = 0.2 if is_layer(values) else 0.3
    xs = rng.uniform(-frac * bx, frac * bx, columns)
    ys = rng.uniform(-frac * by, frac * by, columns)
    zs = (np.arange(STEPS) + 0.5) / STEPS * bz - bz / 2
    pts = np.stack([np.repeat(xs, STEPS), np.repeat(ys, STEPS), np.tile(zs, columns)], 1)
    return cn.density(values, pts).reshape(columns, STEPS).sum(1) * (bz / STEPS)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--columns", type=int, default=4000)
    args = ap.parse_args()
    import cloudgen_native as cn

    presets = cn.presets()
    print("| type | box height (units) | optical depth p10 / p50 / p90 | max | covered | ISCCP class |")
    print("|---|---|---|---|---|---|")
    for name in sorted(presets):
        values = dict(cn.defaults(), **presets[name]["params"])
        od = column_depths(values, args.columns, np.random.default_rng(1))
        p10, p50, p90 = np.percentile(od, (10, 50, 90))
        print(f"| {name} | {values['box_size'][2]:g} | {p10:.2f} / {p50:.2f} / {p90:.2f} | {od.max():.2f} "
              f"| {np.mean(od > 1.0):.0%} | {ISCCP.get(name, '–')} |")


if __name__ == "__main__":
    main()
