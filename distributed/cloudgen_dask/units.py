"""Units of a distributed bake and what a worker does with one.

A unit is one CLI run that writes one file: a frame of a sequence (or the
only frame of a single bake), or a brick of one grid. Its key is the bake key
the CLI will store in the file, so "done" means: the file is there and holds
that key. Workers import this module by name (the client and the workers run
from the same checkout).
"""
from __future__ import annotations

import dataclasses
import time

from .cloudgen_cli import CliError, run_events, stored_key, verify_output


class UnitError(RuntimeError):
    """A unit failed for a reason a retry cannot fix (bad input, unwritable output)."""


@dataclasses.dataclass(frozen=True)
class Unit:
    name: str          # "frame 12", "brick 3/8", "bake": what a person reads in messages
    key: str           # the bake key the output will hold
    output: str        # absolute path of the file the unit writes
    args: tuple        # `cloudgen` arguments (bake ... --output OUTPUT), without --json
    grid: tuple        # voxels per axis of the whole grid (bounds check of the output)
    voxels: int        # voxels this unit evaluates at most (throughput figures)


def is_done(cli, unit: Unit) -> bool:
    return stored_key(cli, unit.output) == unit.key


def run_unit(unit: Unit, cli: str) -> dict:
    """Runs on a worker: bakes the unit unless its output already holds its key,
    then reads the output back. Returns figures; raises UnitError naming the unit."""
    t0 = time.perf_counter()
    if is_done(cli, unit):
        return {"name": unit.name, "computed": False, "seconds": 0.0, "voxels": 0}
    try:
        events = run_events(cli, [*unit.args, "--update", "--quiet"])
        verify_output(cli, unit.output, unit.key, unit.grid)
    except CliError as exc:
        raise UnitError(f"unit {unit.name} ({unit.output}): {exc}") from None
    wrote = events.written[0] if events.written else {}
    return {"name": unit.name, "computed": bool(events.written), "seconds": time.perf_counter() - t0,
            "voxels": unit.voxels if events.written else 0, "bytes": wrote.get("bytes", 0)}
