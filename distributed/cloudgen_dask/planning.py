"""From `cloudgen bake` options to units: the CLI's own plan (`--dry-run`) names
the files and their bake keys; frames with equal keys are baked once and copied."""
from __future__ import annotations

import json
import os
import pathlib

from .cloudgen_cli import CliError, run_events
from .units import Unit

FILE_OPTIONS = ("--params", "--sequence", "--camera", "--output")


def absolute_args(args) -> list:
    """The bake options with every file path absolute (workers may start elsewhere)."""
    out = list(map(str, args))
    for i, a in enumerate(out):
        for opt in FILE_OPTIONS:
            if a == opt and i + 1 < len(out):
                out[i + 1] = os.path.abspath(out[i + 1])
            elif a.startswith(opt + "="):
                out[i] = opt + "=" + os.path.abspath(a[len(opt) + 1:])
    return out


def option(args, name):
    """The value of `name` in the options, or None."""
    for i, a in enumerate(args):
        if a == name and i + 1 < len(args):
            return args[i + 1]
        if a.startswith(name + "="):
            return a[len(name) + 1:]
    return None


def replace_option(args, name, value) -> list:
    """The options with `name` set to `value` (added when absent)."""
    out, i, found = [], 0, False
    while i < len(args):
        a = args[i]
        if a == name:
            out += [name, str(value)]
            i += 2
            found = True
            continue
        if a.startswith(name + "="):
            out += [name, str(value)]
            found = True
        else:
            out.append(a)
        i += 1
    return out if found else out + [name, str(value)]


def plan(cli, bake_args) -> dict:
    """The CLI's plan event of `cloudgen bake ARGS --dry-run` (CliError when the options are bad)."""
    events = run_events(cli, ["bake", *bake_args, "--dry-run"])
    return events.plan | ({"brick": events.brick} if events.brick else {})


def voxel_count(grid) -> int:
    return int(grid[0]) * int(grid[1]) * int(grid[2])


def frame_units(cli, bake_args, work_dir: pathlib.Path):
    """(units, copies): one unit per distinct bake key; copies = [(path, source path, key)]."""
    p = plan(cli, bake_args)
    grid, files = tuple(p["grid"]), p["files"]
    units, copies, first = [], [], {}
    sequence = option(bake_args, "--sequence")
    for f in files:
        if f["key"] in first:
            copies.append((f["path"], first[f["key"]], f["key"]))
            continue
        first[f["key"]] = f["path"]
        args = ["bake", *bake_args]
        if f["frame"] is not None and option(bake_args, "--frames") is not None:
            args = replace_option(args, "--frames", f"{f['frame']}-{f['frame']}")
        elif f["frame"] is not None and sequence is not None:
            args = replace_option(args, "--sequence", one_frame_sequence(sequence, f["frame"], work_dir))
        name = "bake" if f["frame"] is None else f"frame {f['frame']}"
        units.append(Unit(name, f["key"], f["path"], tuple(args), grid, voxel_count(grid)))
    return units, copies


def one_frame_sequence(sequence_file, frame, work_dir: pathlib.Path) -> str:
    """A sequence file holding only `frame` of `sequence_file` (the CLI validated the whole file)."""
    doc = json.loads(pathlib.Path(sequence_file).read_text())
    entry = next(e for e in doc["frames"] if e["frame"] == frame)
    path = work_dir / f"sequence_frame_{frame}.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps({"frames": [entry]}))
    os.replace(tmp, path)
    return str(path)


def brick_units(cli, bake_args, bricks: int, work_dir: pathlib.Path):
    """(units, output, whole key): `bricks` units of one grid, in a folder named by the whole bake's key."""
    whole = plan(cli, bake_args)
    if len(whole["files"]) != 1:
        raise ValueError(f"--bricks splits one grid; these options bake {len(whole['files'])} frames "
                         "(drop --bricks to split the frames instead)")
    output, grid = whole["files"][0]["path"], tuple(whole["grid"])
    folder = work_dir / f"bricks_{whole['files'][0]['key']}"
    folder.mkdir(parents=True, exist_ok=True)
    units = []
    for i in range(bricks):
        path = folder / f"brick_{i:05d}_of_{bricks:05d}.vdb"
        args = replace_option(["bake", *bake_args], "--output", str(path)) + ["--brick", f"{i}/{bricks}"]
        try:
            p = plan(cli, args[1:])
        except CliError as exc:
            raise CliError(exc.code, f"unit brick {i}/{bricks}: {exc}") from None
        tiles = p["brick"]["tiles"]
        units.append(Unit(f"brick {i}/{bricks}", p["files"][0]["key"], str(path), tuple(args), grid,
                          (tiles[1] - tiles[0]) * 512))
    return units, output, whole["files"][0]["key"], folder
