"""`python -m cloudgen_dask render`: a frame range rendered by `blender -b` in
chunks on Dask workers — the farm side of a distributed bake.

Each chunk runs `blender -b SCENE -E ENGINE -o OUTPUT -s A -e B -a` on a worker
and counts only when Blender exits 0 and every frame of the chunk is on disk.
"""
from __future__ import annotations

import glob
import os
import pathlib
import re
import subprocess
import sys
import time


class ChunkError(RuntimeError):
    pass


def add_parser(sub):
    p = sub.add_parser("render", description=__doc__)
    p.add_argument("scene", help="the .blend file (on storage every worker sees)")
    p.add_argument("--frames", required=True, help="A-B, the frames to render")
    p.add_argument("--chunks", type=int, default=2, help="how many `blender -b` runs (default 2)")
    p.add_argument("--output", required=True, help="Blender's -o pattern, e.g. //render/f_#### or /abs/f_####")
    p.add_argument("--engine", default="CYCLES")
    p.add_argument("--blender", default=os.environ.get("BLENDER", "blender"), help="the Blender executable")
    p.add_argument("--scheduler", help="tcp://HOST:PORT of a Dask scheduler (default: a LocalCluster)")
    p.add_argument("--scheduler-file")
    p.add_argument("--workers", type=int, default=2)
    return p


def chunks(first: int, last: int, count: int) -> list:
    """`count` contiguous near-equal (A, B) ranges covering first..last (fewer when there are fewer frames)."""
    n = last - first + 1
    count = max(1, min(count, n))
    return [(first + n * i // count, first + n * (i + 1) // count - 1) for i in range(count)]


def frame_files(output: str, scene: str, frame: int) -> list:
    """Files Blender wrote for `frame` with -o `output` (# runs padded; `//` is the scene's folder)."""
    base = output
    if base.startswith("//"):
        base = str(pathlib.Path(scene).resolve().parent / base[2:])
    if "#" not in base:
        base += "####"
    m = list(re.finditer(r"#+", base))[-1]
    stem = base[:m.start()] + str(frame).zfill(m.end() - m.start()) + base[m.end():]
    return glob.glob(glob.escape(stem) + ".*")


def render_chunk(blender, scene, engine, output, first, last) -> dict:
    t0 = time.perf_counter()
    cmd = [blender, "-b", scene, "-E", engine, "-o", output, "-s", str(first), "-e", str(last), "-a"]
    r = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True)
    if r.returncode != 0:
        tail = (r.stderr.strip() or r.stdout.strip()).splitlines()[-1:] or ["?"]
        raise ChunkError(f"chunk {first}-{last}: blender exited {r.returncode}: {tail[0]}")
    missing = [f for f in range(first, last + 1) if not frame_files(output, scene, f)]
    if missing:
        raise ChunkError(f"chunk {first}-{last}: blender exited 0 but frames {missing} are not on disk")
    return {"chunk": [first, last], "seconds": time.perf_counter() - t0}


def main(args) -> int:
    from . import runner

    m = re.fullmatch(r"(\d+)-(\d+)", args.frames)
    if not m or int(m.group(1)) > int(m.group(2)):
        print(f"cloudgen-dask: error: --frames must be A-B with A <= B; got {args.frames!r}", file=sys.stderr)
        return runner.EXIT_USAGE
    if not os.path.isfile(args.scene):
        print(f"cloudgen-dask: error: scene {args.scene!r} does not exist", file=sys.stderr)
        return runner.EXIT_USAGE
    scene = os.path.abspath(args.scene)
    output = args.output if args.output.startswith("//") else os.path.abspath(args.output)
    parts = chunks(int(m.group(1)), int(m.group(2)), args.chunks)
    client, cluster = runner.make_client(args, {})
    try:
        futures = [client.submit(render_chunk, args.blender, scene, args.engine, output, a, b, pure=False)
                   for a, b in parts]
        for a, b in parts:
            print(f"cloudgen-dask: render chunk {a}-{b}", file=sys.stderr)
        results = client.gather(futures)
    except ChunkError as exc:
        print(f"cloudgen-dask: error: {exc}", file=sys.stderr)
        return runner.EXIT_FAILED
    except KeyboardInterrupt:
        print("cloudgen-dask: interrupted", file=sys.stderr)
        return runner.EXIT_CANCELLED
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    print(f"cloudgen-dask: rendered {len(results)} chunks: " +
          ", ".join(f"{r['chunk'][0]}-{r['chunk'][1]} in {r['seconds']:.1f} s" for r in results))
    return runner.EXIT_OK
