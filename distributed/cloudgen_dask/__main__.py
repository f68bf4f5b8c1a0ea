"""python -m cloudgen_dask bake|render ... (see --help)."""
from __future__ import annotations

import argparse
import json
import os
import sys

from . import render, runner
from .cloudgen_cli import DEFAULT_CLI, CliError
from .units import UnitError

BAKE_HELP = """Runs `cloudgen bake` split into units on Dask: the frames of a sequence, or
--bricks N bricks of one grid. Every option not listed here goes to `cloudgen bake`
unchanged (--preset/--params/--sequence, --resolution, --quality, --camera, --frames,
--fps, --output, ...). A rerun skips every unit whose file already holds its bake key.
Exit codes: 0 ok, 1 a unit failed (one line names it), 2 bad options, 130 interrupted."""


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cloudgen_dask")
    sub = parser.add_subparsers(dest="command", required=True)
    bake = sub.add_parser("bake", description=BAKE_HELP)
    bake.add_argument("--bricks", type=int, default=1, help="split one grid into N bricks (default 1: split frames)")
    bake.add_argument("--scheduler", help="tcp://HOST:PORT of a Dask scheduler (default: a LocalCluster)")
    bake.add_argument("--scheduler-file", help="a Dask scheduler file")
    bake.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    bake.add_argument("--work-dir", help="bricks and per-frame files (default: OUTPUT_DIR/.cloudgen-dask)")
    bake.add_argument("--keep-bricks", action="store_true", help="keep the bricks after merging")
    bake.add_argument("--cloudgen", default=os.environ.get("CLOUDGEN_BIN", str(DEFAULT_CLI)),
                      help="the cloudgen executable, the same path on every worker")
    bake.add_argument("--summary-json", action="store_true", help="print the summary as one JSON line")
    bake.add_argument("--json", action="store_true",
                      help="machine-readable: JSON lines on stdout (progress, summary, error; docs/cli_protocol.md)")
    bake.add_argument("--no-progress", action="store_true")
    render.add_parser(sub)
    args, rest = parser.parse_known_args(argv)
    if args.command == "render":
        if rest:
            parser.error(f"unknown options: {' '.join(rest)}")
        return render.main(args)
    if not 1 <= args.bricks <= 100000:
        parser.error(f"--bricks must be an integer in [1, 100000]; got {args.bricks}")
    if not 1 <= args.workers <= 1024:
        parser.error(f"--workers must be an integer in [1, 1024]; got {args.workers}")
    if "--output" not in rest and not any(a.startswith("--output=") for a in rest):
        parser.error("give --output FILE.vdb (as for cloudgen bake)")
    def event(name, **fields):  # the CLI's JSON-lines protocol (docs/cli_protocol.md)
        if args.json:
            print(json.dumps({"event": name, **fields}), flush=True)

    settings = runner.Settings(bake_args=rest, cli=args.cloudgen, bricks=args.bricks, scheduler=args.scheduler,
                               scheduler_file=args.scheduler_file, workers=args.workers, work_dir=args.work_dir,
                               keep_bricks=args.keep_bricks, progress=not (args.no_progress or args.json),
                               on_progress=lambda done, total: event("progress", fraction=done / max(total, 1),
                                                                     units_done=done, units=total))

    def fail(code, message):
        print(f"cloudgen-dask: error: {message}", file=sys.stderr)
        event("error", code=code, message=str(message))
        return code

    try:
        summary = runner.run(settings)
    except KeyboardInterrupt:
        print("cloudgen-dask: interrupted; finished units are kept, rerun to resume", file=sys.stderr)
        event("error", code=runner.EXIT_CANCELLED, message="interrupted; finished units are kept")
        return runner.EXIT_CANCELLED
    except CliError as exc:
        return fail(runner.EXIT_USAGE if exc.code == 2 else runner.EXIT_FAILED, exc)
    except UnitError as exc:
        return fail(runner.EXIT_FAILED, exc)
    except ValueError as exc:
        return fail(runner.EXIT_USAGE, exc)
    d = summary.as_dict()
    if args.json:
        event("summary", **d)
    elif args.summary_json:
        print(json.dumps(d))
    else:
        print(f"cloudgen-dask: {d['units']} units: {d['computed']} baked, {d['skipped']} already done, "
              f"{d['copied']} frames copied{', bricks merged' if d['merged'] else ''}; {d['seconds']:.1f} s, "
              f"{d['voxels_per_s'] / 1e6:.2f} M voxels/s")
    return runner.EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
