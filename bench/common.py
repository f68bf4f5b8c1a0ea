"""bench/common.py — what bench/report.py and bench/accuracy/* share (standard library only):

- atomic_write / write_json: a file is replaced whole or not at all (temporary
  file in the same folder + os.replace; the temporary file is removed on error);
- splice: the generated block between two marker lines of a Markdown document,
  hand-written text outside the markers kept;
- machine_info: what machine measured the numbers, one schema for every results file.

bench/ must be on sys.path (the scripts in bench/ have it as their folder; those
in bench/accuracy/ add it).
"""
from __future__ import annotations

import json
import os
import platform
import re
import tempfile
from pathlib import Path

# ------------------------------------------------------------------- files --


def atomic_write(path, data):
    """Write `data` (str: UTF-8, or bytes) to `path`, creating its folder. Readers see
    the old file or the new one, never a part; on any error the old file is untouched
    and no temporary file is left. A new file gets mode 0644, a replaced one keeps its mode."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        mode = path.stat().st_mode & 0o7777
    except OSError:
        mode = 0o644
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def write_json(path, data, indent=1):
    """`data` as indented JSON plus a final newline, atomically."""
    atomic_write(path, json.dumps(data, indent=indent) + "\n")


# ------------------------------------------------------------------ splice --


def splice(text, begin, end, body, new_doc=""):
    """`text` with everything from the line `begin` to the line `end` replaced by
    `begin`, `body`, `end` (one per line; `body` as given). Without both markers
    (in that order) the block is appended after the text, or, when the text is
    empty, written after `new_doc` (e.g. a title)."""
    block = f"{begin}\n{body}\n{end}"
    if begin in text and end in text and text.index(begin) < text.index(end):
        head, rest = text.split(begin, 1)
        return head + block + rest.split(end, 1)[1]
    if not text.strip():
        return new_doc + block + "\n"
    return text.rstrip() + "\n\n" + block + "\n"


# ----------------------------------------------------------------- machine --


def read_text(path):
    """The file's text, or "" when it cannot be read."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            return f.read()
    except OSError:
        return ""


SIMD = ("sse4_2", "avx", "avx2", "fma", "avx512f")


def machine_info(read=None):
    """What machine measured the numbers (Linux /proc; empty / None where unknown):

    cpu_model, cpu_vendor, cpu_family_model_stepping ("6/85/7"), cpu_mhz_nominal (float or None),
    simd (the flags of SIMD that the CPU has), hypervisor (bool: a virtual machine; None: unknown),
    nproc (cores this process may use), mem_total_gib (None when /proc/meminfo is
    unreadable), kernel, load_average (1, 5, 15 minutes, or None).

    `read(path) -> str` reads a file ("" when it cannot; default read_text)."""
    read = read or read_text
    cpuinfo = read("/proc/cpuinfo") or ""

    def field(name):
        m = re.search(r"^%s\s*:\s*(.*)$" % re.escape(name), cpuinfo, re.M)
        return m.group(1).strip() if m else ""

    flags = field("flags").split()
    mem = re.search(r"^MemTotal:\s+(\d+)", read("/proc/meminfo") or "", re.M)
    try:
        mhz = float(field("cpu MHz"))
    except ValueError:
        mhz = None
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    try:
        nproc = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        nproc = os.cpu_count() or 0
    fms = [field("cpu family"), field("model"), field("stepping")]
    return {
        "cpu_model": field("model name") or platform.processor(),
        "cpu_vendor": field("vendor_id"),
        "cpu_family_model_stepping": "/".join(fms) if any(fms) else "",
        "cpu_mhz_nominal": mhz,
        "simd": [f for f in SIMD if f in flags],
        "hypervisor": "hypervisor" in flags,
        "nproc": nproc,
        "mem_total_gib": round(int(mem.group(1)) / 2 ** 20, 1) if mem else None,
        "kernel": platform.release(),
        "load_average": load,
    }
