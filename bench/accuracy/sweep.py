#!/usr/bin/env python3
"""The accuracy sweep: error against time for each speed/accuracy knob.

  .venv/bin/python bench/accuracy/sweep.py [--quick] [--scenes a,b] [--knobs x,y] [--force]
                                           [--runs N] [--out DIR] [--results-only]

For each scene (scenes.py) a reference image (measure.reference: procedural OSL,
fine volume step, many samples, two seeds averaged), then for every knob
(knobs.py), each setting alone with the others at the base settings: bake (the
`cloudgen bake --json` CLI, best of 3, peak RSS through os.wait4, VDB size),
render in a subprocess (render_job.py, best of --runs, peak RSS), image error
against the reference (metrics.image_rmse / image_flip) and field error
(field.py) — measure.measure_point, cached per point in
<out>/accuracy_cache/<scene>/ so a re-run measures only what changed (--force: all).
<out>/accuracy.json (schema: results.py) is rewritten from the whole cache after
every point, so an interrupted run leaves valid results. Renders go to
<out>/images/<scene>/ (EXR, not committed; ref.png thumbnails are).

--quick: 32x24 pixels, few samples, one run, two settings per knob, into a
temporary directory (a smoke test of a few minutes).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tempfile
import time

BENCH = pathlib.Path(__file__).resolve().parents[1]
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

from common import machine_info

from accuracy import scenes
from accuracy.config import ROOT, SweepConfig
from accuracy.knobs import BY_NAME, KNOBS
from accuracy.measure import measure_point, reference
from accuracy.results import write_results
from accuracy.runner import log


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--scenes", default=",".join(s for s, d in scenes.SCENES.items() if not d.get("extra")))
    ap.add_argument("--knobs", default=",".join(k.name for k in KNOBS))
    ap.add_argument("--force", action="store_true", help="re-measure cached points and references")
    ap.add_argument("--runs", type=int, default=None, help="renders per point (default 2, --quick 1)")
    ap.add_argument("--out", default=None, help="results directory (default bench/results; --quick: a temp dir)")
    ap.add_argument("--results-only", action="store_true",
                    help="only rewrite accuracy.json from the cache (e.g. after matched.py)")
    a = ap.parse_args(argv)
    a.scenes = [s for s in a.scenes.split(",") if s]
    a.knobs = [k for k in a.knobs.split(",") if k]
    for s in a.scenes:
        if s not in scenes.SCENES:
            raise SystemExit(f"sweep: unknown scene {s!r}; known: {list(scenes.SCENES)}")
    for k in a.knobs:
        if k not in BY_NAME:
            raise SystemExit(f"sweep: unknown knob {k!r}; known: {list(BY_NAME)}")
    return a


def config_of(a):
    if a.out:
        out = pathlib.Path(a.out)
    else:
        out = pathlib.Path(tempfile.mkdtemp(prefix="cloudgen-accuracy-")) if a.quick else ROOT / "bench/results"
    cfg = SweepConfig(out=out, quick=a.quick, runs=a.runs or (1 if a.quick else 2))
    cfg.machine = measuring_machine(cfg) if a.results_only else machine_info()
    return cfg


def measuring_machine(cfg):
    """The machine that measured the cache: the one accuracy.json names (--results-only
    rewrites it after the sweep, when the load is the sweep's own), else this one now."""
    try:
        return json.loads(cfg.results.read_text())["machine"]
    except (OSError, ValueError, KeyError, TypeError):
        return machine_info()


def sweep(cfg, want_scenes, want_knobs, force=False):
    """Measure every wanted knob on every wanted scene; returns the failures (text)."""
    import cloudgen_native as cn

    for s in want_scenes:  # the references first: every image error needs them
        reference(cfg, s, "4.5", force=force)
        write_results(cfg)
    failures = []
    for knob in KNOBS:
        if knob.name not in want_knobs:
            continue
        if not knob.available(cfg):
            log(f"skip {knob.name}: not available yet")
            continue
        for s in want_scenes:
            if not knob.runs_on(s):
                continue
            values = dict(cn.defaults(), **cn.presets()[scenes.SCENES[s]["preset"]]["params"])
            for setting in knob.settings_for(s, cfg, values):
                for pt in knob.points(setting, cfg):
                    try:
                        measure_point(cfg, s, pt, force)
                    except Exception as exc:  # keep going: one failed point must not stop the sweep
                        failures.append(f"{s} {pt['knob']} {setting}: {exc}")
                        log(f"[{s}] FAILED {pt['knob']} {setting}: {exc}")
                    write_results(cfg)
    write_results(cfg)
    return failures


def main(argv=None):
    a = parse_args(argv)
    cfg = config_of(a)
    log(f"accuracy sweep into {cfg.out} (quick={cfg.quick}, scenes {a.scenes}, knobs {a.knobs})")
    if a.results_only:
        write_results(cfg)
        return 0
    t_start = time.time()
    failures = sweep(cfg, a.scenes, a.knobs, a.force)
    log(f"done in {time.time() - t_start:.0f} s; results {cfg.results}")
    for f in failures:
        log("FAILED " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
