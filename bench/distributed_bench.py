"""Distributed bake figures (docs/distributed.md): 1 against 2 LocalCluster workers
for a brick bake and a frame sequence, the overhead per unit, the merge's time
and peak memory. A measurement, not a test: nothing asserts a time.

    .venv/bin/python bench/distributed_bench.py [--quick] [--out bench/results/distributed.json]

Every CLI runs with --threads 1, so 1 worker uses one core and 2 workers two:
the ratio is the scaling of the runner, not of the CLI's own threads. Each
configuration runs `--runs` times (best kept) in a fresh output folder.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "distributed"))
from common import machine_info, write_json  # noqa: E402

CLI = ROOT / "build" / "bin" / "cloudgen"


def runner(workers, args, work):
    """Wall seconds and the summary of one `python -m cloudgen_dask bake` run."""
    cmd = [sys.executable, "-m", "cloudgen_dask", "bake", "--no-progress", "--summary-json", "--workers",
           str(workers), *map(str, args), "--threads", "1"]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "distributed")}
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=work)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return wall, json.loads(r.stdout.splitlines()[-1])


def single(args, work):
    """Wall seconds of the same bake by one `cloudgen bake --threads 1`."""
    t0 = time.perf_counter()
    subprocess.run([str(CLI), "bake", *map(str, args), "--threads", "1", "--quiet"], check=True, cwd=work)
    return time.perf_counter() - t0


def best(n, make):
    results = []
    for _ in range(n):
        with tempfile.TemporaryDirectory(prefix="cloudgen-dbench-") as work:
            results.append(make(work))
    return min(results, key=lambda r: r[0] if isinstance(r, tuple) else r)


def merge_figures(args, bricks):
    """Time and peak RSS of `cloudgen merge` alone, on bricks kept from a run."""
    with tempfile.TemporaryDirectory(prefix="cloudgen-dbench-") as work:
        runner(2, ["--bricks", bricks, "--keep-bricks", "--work-dir", "w", *args], work)
        brick_files = sorted(pathlib.Path(work, "w").glob("bricks_*/*.vdb"))
        brick_bytes = sum(p.stat().st_size for p in brick_files)
        t0 = time.perf_counter()
        proc = subprocess.Popen([str(CLI), "merge", "--output", str(pathlib.Path(work, "m.vdb")),
                                 *map(str, brick_files)], stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        if status != 0:
            sys.exit("merge failed")
        merged = pathlib.Path(work, "m.vdb").stat().st_size
        return {"seconds": seconds, "peak_rss_mib": usage.ru_maxrss / 1024, "bricks": len(brick_files),
                "brick_bytes": brick_bytes, "merged_bytes": merged}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="256^3 and 8 frames instead of 512^3 and 24")
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--out", default=str(ROOT / "bench" / "results" / "distributed.json"))
    a = ap.parse_args(argv)
    res, frames, bricks = (256, 8, 8) if a.quick else (512, 24, 16)
    brick_args = ["--preset", "cumulus", "--resolution", res, "--output", "c.vdb"]
    seq_args = ["--preset", "cumulus", "--resolution", 128, "--frames", f"1-{frames}", "--output", "f_####.vdb"]
    load0 = os.getloadavg()
    out = {"machine": machine_info(), "load_average_start": load0, "runs": a.runs, "resolution": res,
           "bricks": bricks, "frames": frames}
    out["brick_single_cli_s"] = best(a.runs, lambda w: single(brick_args, w))
    for workers in (1, 2):
        wall, summary = best(a.runs, lambda w, n=workers: runner(n, ["--bricks", bricks, *brick_args], w))
        out[f"brick_{workers}w"] = {"wall_s": wall, "summary": summary}
        wall, summary = best(a.runs, lambda w, n=workers: runner(n, seq_args, w))
        out[f"frames_{workers}w"] = {"wall_s": wall, "summary": summary}
    out["frames_single_cli_s"] = best(a.runs, lambda w: single(seq_args, w))
    out["brick_speedup"] = out["brick_1w"]["wall_s"] / out["brick_2w"]["wall_s"]
    out["frames_speedup"] = out["frames_1w"]["wall_s"] / out["frames_2w"]["wall_s"]
    # overhead per unit: the 1-worker run against the single CLI doing the same voxels on one core
    out["brick_overhead_per_unit_s"] = (out["brick_1w"]["wall_s"] - out["brick_single_cli_s"]) / bricks
    out["frames_overhead_per_unit_s"] = (out["frames_1w"]["wall_s"] - out["frames_single_cli_s"]) / frames
    out["merge"] = merge_figures(brick_args, bricks)
    out["load_average_end"] = os.getloadavg()
    with tempfile.TemporaryDirectory() as work:
        subprocess.run([str(CLI), "bake", *map(str, brick_args), "--quiet"], check=True, cwd=work)
        out["whole_file_bytes"] = pathlib.Path(work, "c.vdb").stat().st_size
    write_json(a.out, out)
    print(json.dumps({k: v for k, v in out.items() if k != "machine"}, indent=1))


if __name__ == "__main__":
    main()
