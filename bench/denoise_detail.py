"""Does the denoiser erase a dense cloud's lobes? OpenImageDenoise at 16 and 64 spp, fed the
colour alone, colour + albedo, or colour + albedo + normal (Blender's default), against a
many-sample render without it, on the default cumulus seen close (its 256³ bake, the add-on's
daylight: scripts/render_cloud.py --light sky --vdb, zoomed onto the cloud so it fills the frame).

Usage: .venv/bin/python bench/denoise_detail.py [--work DIR] [--size 160x120] [--ref-samples 512]
       [--out bench/results/denoise_detail.json] [--reuse]

Measured on the display PNGs' luminance (what a viewer sees), with the reference's own grain
taken out by a Gaussian blur of 1.5 px:
- `rmse_vs_ref`: RMSE of the variant against the reference, both blurred by 1.5 px;
- `lobe_energy`: the deviation of the 1.5-6 px band (the blur at 1.5 px minus the blur at 6 px:
  lobes a few pixels across) as a fraction of the reference's; below 1 the lobes are flattened,
  above 1 grain adds to them;
- `lobe_corr`: the correlation of that band with the reference's (1: the same lobes).
docs/render_trade.md quotes the results. One render at a time; the reference at 512 spp takes
about 20 minutes on 2 cores.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "bench"), str(ROOT / "scripts")]
from common import machine_info, write_json  # noqa: E402

# name, samples, denoiser guide passes (None: no denoiser)
VARIANTS = (("rgb_16", 16, "RGB"), ("rgb_albedo_16", 16, "RGB_ALBEDO"),
            ("rgb_albedo_normal_16", 16, "RGB_ALBEDO_NORMAL"), ("plain_16", 16, None),
            ("rgb_64", 64, "RGB"), ("rgb_albedo_normal_64", 64, "RGB_ALBEDO_NORMAL"), ("plain_64", 64, None))
GRAIN_PX, LOBE_PX = 1.5, 6.0


def render_variant(work, name, samples, passes, size, vdb, seed):
    import render_cloud as rc

    args = rc.parse_args(["--preset", "cumulus", "--output", str(work / f"{name}.png"), "--size", size,
                          "--samples", str(samples), "--vdb", str(vdb), "--zoom", "2.2", "--aim", "0.5,0.5,0.55",
                          "--seed", str(seed)])
    scene = rc.build_scene(rc.resolve_params(args), args)
    scene.cycles.use_denoising = passes is not None
    if passes is not None:
        scene.cycles.denoising_input_passes = passes
    return rc.render(scene, args.output)


def lobe_measures(img, ref):
    """(rmse_vs_ref, lobe_energy, lobe_corr) of a luminance image against the reference's."""
    from camera_finish import _blur

    def band(a):
        return _blur(a, GRAIN_PX) - _blur(a, LOBE_PX)

    rmse = float(np.sqrt(((_blur(img, GRAIN_PX) - _blur(ref, GRAIN_PX)) ** 2).mean()))
    b, rb = band(img), band(ref)
    return rmse, float(b.std() / rb.std()), float(np.corrcoef(b.ravel(), rb.ravel())[0, 1])


def luminance(path):
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("L"), dtype=np.float64)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", default=None, help="folder for the bake and the renders (default: a temporary one)")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--ref-samples", type=int, default=512)
    ap.add_argument("--out", default=str(ROOT / "bench" / "results" / "denoise_detail.json"))
    ap.add_argument("--reuse", action="store_true",
                    help="measure the renders already in --work (their times from its times.json)")
    args = ap.parse_args(argv)
    work = pathlib.Path(args.work or tempfile.mkdtemp(prefix="denoise-detail-"))
    work.mkdir(parents=True, exist_ok=True)
    vdb = work / "cumulus_256.vdb"
    plan = (("reference", args.ref_samples, None),) + VARIANTS
    seconds = {}
    if not args.reuse:
        cli = os.environ.get("CLOUDGEN_BIN", str(ROOT / "build" / "bin" / "cloudgen"))
        subprocess.run([cli, "bake", "--preset", "cumulus", "--resolution",
                        "256", "--output", str(vdb), "--quiet"], check=True)
        for name, samples, passes in plan:
            seconds[name] = round(render_variant(work, name, samples, passes, args.size, vdb,
                                                 1 if name == "reference" else 0), 1)
            print(f"denoise_detail: {name}: {samples} spp, passes {passes}: {seconds[name]} s", flush=True)
            write_json(work / "times.json", seconds)
    elif (work / "times.json").exists():
        seconds = json.loads((work / "times.json").read_text())
    ref = luminance(work / "reference.png")
    rows = []
    for name, samples, passes in VARIANTS:
        rmse, energy, corr = lobe_measures(luminance(work / f"{name}.png"), ref)
        rows.append({"name": name, "samples": samples, "passes": passes, "render_s": seconds.get(name),
                     "rmse_vs_ref": round(rmse, 2), "lobe_energy": round(energy, 3), "lobe_corr": round(corr, 3)})
        print(f"{name:22s} rmse {rmse:5.2f}  lobe energy {energy:5.3f}  lobe corr {corr:5.3f}")
    write_json(args.out, {"size": args.size, "reference_samples": args.ref_samples,
                          "reference_render_s": seconds.get("reference"), "grain_px": GRAIN_PX,
                          "lobe_px": LOBE_PX, "machine": machine_info(), "variants": rows})
    print(f"denoise_detail: wrote {args.out}")


if __name__ == "__main__":
    main()
