"""The client side of a distributed bake: plan, skip what is done, run the rest
on Dask, join bricks, copy repeated frames, report."""
from __future__ import annotations

import dataclasses
import os
import pathlib
import shutil
import sys
import time

from .cloudgen_cli import CliError, run_events, stored_key
from .planning import absolute_args, brick_units, frame_units
from .units import UnitError, is_done, run_unit

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_CANCELLED = 0, 1, 2, 130


@dataclasses.dataclass
class Settings:
    bake_args: list                # `cloudgen bake` options (files made absolute)
    cli: str                       # the cloudgen executable (the workers run the same path)
    bricks: int = 1                # > 1: split one grid into this many bricks
    scheduler: str | None = None   # tcp://HOST:PORT of a running scheduler
    scheduler_file: str | None = None
    workers: int = 2               # LocalCluster worker processes (no scheduler given)
    work_dir: str | None = None    # bricks and per-frame files; default: next to the output
    keep_bricks: bool = False
    progress: bool = True          # the progress line on stderr
    on_progress: object = None     # called with (units done, units) as units finish


@dataclasses.dataclass
class Summary:
    units: int = 0
    computed: int = 0
    skipped: int = 0
    copied: int = 0
    merged: bool = False
    seconds: float = 0.0
    voxels: int = 0
    output: list = dataclasses.field(default_factory=list)
    dashboard: str | None = None

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["voxels_per_s"] = self.voxels / self.seconds if self.seconds > 0 else 0.0
        return d


def make_client(settings, threads_env: dict):
    from dask.distributed import Client, LocalCluster  # imported here: `--help` needs no Dask

    if settings.scheduler or settings.scheduler_file:
        client = Client(settings.scheduler, scheduler_file=settings.scheduler_file)
        return client, None
    try:
        import bokeh  # noqa: F401  (the dashboard needs it)
        dashboard = "127.0.0.1:0"  # this machine only; a real cluster has its own dashboard
    except ImportError:
        dashboard = None
    cluster = LocalCluster(n_workers=settings.workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=dashboard, env=threads_env)
    return Client(cluster), cluster


def _with_threads(settings: Settings) -> list:
    """LocalCluster workers share this machine: each CLI gets its share of the cores."""
    args = list(settings.bake_args)
    if settings.scheduler or settings.scheduler_file or "--threads" in args:
        return args
    return args + ["--threads", str(max(1, (os.cpu_count() or 1) // settings.workers))]


def _copy_atomically(source: str, target: str):
    tmp = f"{target}.cloudgen-copy-{os.getpid()}.tmp"
    try:
        shutil.copyfile(source, tmp)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def run(settings: Settings, client=None, on_unit=None) -> Summary:
    """Runs a distributed bake; raises UnitError/CliError/ValueError on failure and
    KeyboardInterrupt through. on_unit(result) is called as each unit finishes."""
    t0 = time.perf_counter()
    args = absolute_args(_with_threads(settings))
    output = pathlib.Path(next(a for i, a in enumerate(args) if i and args[i - 1] == "--output"))
    work = pathlib.Path(settings.work_dir) if settings.work_dir else output.parent / ".cloudgen-dask"
    work.mkdir(parents=True, exist_ok=True)
    summary = Summary()
    merge = None
    if settings.bricks > 1:
        units, final, whole_key, folder = brick_units(settings.cli, args, settings.bricks, work)
        summary.output = [final]
        if stored_key(settings.cli, final) == whole_key:  # the joined file is there already
            summary.units = summary.skipped = len(units)
            summary.seconds = time.perf_counter() - t0
            return summary
        merge = (final, folder)
        copies = []
    else:
        units, copies = frame_units(settings.cli, args, work)
        summary.output = [u.output for u in units] + [c[0] for c in copies]
    summary.units = len(units)

    todo = [u for u in units if not is_done(settings.cli, u)]
    summary.skipped = len(units) - len(todo)
    own_client = client is None
    cluster = None
    if todo and own_client:
        env = {"PYTHONPATH": os.pathsep.join([str(pathlib.Path(__file__).resolve().parents[1]),
                                              os.environ.get("PYTHONPATH", "")])}
        client, cluster = make_client(settings, env)
    try:
        if todo:
            summary.dashboard = getattr(client, "dashboard_link", None) if cluster is not None else None
            _run_units(client, todo, settings, summary, t0, on_unit)
    finally:
        if own_client and client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    if merge is not None:
        final, folder = merge
        run_events(settings.cli, ["merge", "--output", final, *[u.output for u in units]])
        summary.merged = True
        if not settings.keep_bricks:
            shutil.rmtree(folder, ignore_errors=True)
    for path, source, key in copies:
        if stored_key(settings.cli, path) != key:
            _copy_atomically(source, path)
            summary.copied += 1
    if settings.work_dir is None:
        for leftover in work.glob("sequence_frame_*.json"):
            leftover.unlink()
        try:
            work.rmdir()  # only when empty: bricks kept on purpose stay
        except OSError:
            pass
    summary.seconds = time.perf_counter() - t0
    return summary


def _run_units(client, todo, settings, summary, t0, on_unit):
    from dask.distributed import as_completed

    futures = [client.submit(run_unit, u, settings.cli, key=f"cloudgen-{u.key}", pure=False) for u in todo]
    try:
        for done, future in enumerate(as_completed(futures), start=1):
            result = future.result()  # a unit's exception is raised here
            summary.computed += result["computed"]
            summary.voxels += result["voxels"]
            if on_unit is not None:
                on_unit(result)
            if settings.on_progress is not None:
                settings.on_progress(summary.skipped + done, summary.units)
            if settings.progress:
                elapsed = time.perf_counter() - t0
                rate = summary.voxels / elapsed if elapsed > 0 else 0.0
                print(f"\rcloudgen-dask: {summary.skipped + done}/{summary.units} units, "
                      f"{rate / 1e6:.2f} M voxels/s", end="", file=sys.stderr, flush=True)
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        if settings.progress:
            print(file=sys.stderr)


__all__ = ["Settings", "Summary", "run", "UnitError", "CliError", "EXIT_OK", "EXIT_FAILED", "EXIT_USAGE",
           "EXIT_CANCELLED"]
