"""Running the cloudgen CLI: its plan, a stored bake key, a verified output.

The CLI speaks JSON lines (docs/cli_protocol.md); addon/cli_events.py of this
checkout is the one reader, loaded here by path (workers run from the same
checkout, on shared storage, as the client).
"""
from __future__ import annotations

import ctypes
import importlib.util
import json
import os
import pathlib
import signal
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEFAULT_CLI = ROOT / "build" / "bin" / "cloudgen"


def _load_cli_events():
    name = "cloudgen_cli_events"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, ROOT / "addon" / "cli_events.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


cli_events = _load_cli_events()


class CliError(RuntimeError):
    """The CLI failed: .code is its exit code, str() its one-line message."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def _die_with_parent():
    """In the child: SIGTERM when the parent (a worker) dies, so the CLI removes its temporary."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def run_events(cli, args, on_event=None):
    """Runs `cloudgen ARGS --json`; returns its BakeEvents; CliError on failure."""
    proc = subprocess.Popen([str(cli), *map(str, args), "--json"], stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_die_with_parent)
    events = cli_events.BakeEvents()
    try:
        for line in proc.stdout:
            event = events.feed(line)
            if event is not None and on_event is not None:
                on_event(event)
        stderr = proc.stderr.read()
        code = proc.wait()
    except BaseException:
        proc.terminate()
        proc.wait()
        raise
    if code != 0:
        message = events.error["message"] if events.error else (stderr.strip().splitlines() or ["?"])[-1]
        raise CliError(code, message)
    return events


def stored_key(cli, path) -> str | None:
    """The cloudgen_bake_key of the `density` grid of a VDB, or None (missing, unreadable)."""
    if not os.path.isfile(path):
        return None
    r = subprocess.run([str(cli), "info", str(path), "--json"], stdin=subprocess.DEVNULL, capture_output=True,
                       text=True)
    if r.returncode != 0:
        return None
    try:
        grids = json.loads(r.stdout)["grids"]
    except (ValueError, KeyError):
        return None
    for g in grids:
        if g.get("name") == "density":
            return g.get("metadata", {}).get("cloudgen_bake_key")
    return None


def verify_output(cli, path, key, grid_dims):
    """CliError unless `path` opens, has the `density` grid with bake key `key`, and its
    active voxels lie inside the grid's index bounds [0, dims)."""
    r = subprocess.run([str(cli), "info", str(path), "--json"], stdin=subprocess.DEVNULL, capture_output=True,
                       text=True)
    if r.returncode != 0:
        raise CliError(1, f"{path} does not read back: {(r.stderr.strip().splitlines() or ['?'])[-1]}")
    grids = [g for g in json.loads(r.stdout)["grids"] if g.get("name") == "density"]
    if len(grids) != 1:
        raise CliError(1, f"{path} has no single grid named 'density'")
    g = grids[0]
    if g["metadata"].get("cloudgen_bake_key") != key:
        raise CliError(1, f"{path} holds bake key {g['metadata'].get('cloudgen_bake_key')}, expected {key}")
    if not g["empty"]:
        lo, hi = g["bbox_min"], g["bbox_max"]
        if any(lo[a] < 0 or hi[a] >= grid_dims[a] for a in range(3)):
            raise CliError(1, f"{path} has voxels outside the grid {grid_dims}: {lo}..{hi}")
    return g
