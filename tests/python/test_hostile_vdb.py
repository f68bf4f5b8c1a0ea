"""Hostile VDB files (issue 15, findings 1, 2, 8): `cloudgen info` and
`bake --update` on mutated copies of a small bake never crash, hang or take
gigabytes; each bad file costs one `cloudgen: error:` line (exit 1).

Tolerance: none — every case must be clean (read, or refused with one line).
Hangs are caught with a generous timeout only; no test asserts a time.
The whole run is `python tests/python/hostile_vdb.py build/bin/cloudgen`
(852 cases); here a deterministic subset."""
import os
import pathlib
import resource
import stat
import subprocess

import pytest
from hostile_vdb import cases, run_info, verdict

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(REPO_ROOT / "build" / "bin" / "cloudgen"))
TIMEOUT = 120  # a hang guard only
SANITIZED = os.environ.get("CLOUDGEN_SANITIZED") == "1"

if not os.access(CLOUDGEN, os.X_OK):
    pytest.skip(f"cloudgen binary not built: {CLOUDGEN}", allow_module_level=True)


def limit_memory():
    # The CLI itself (and its reader child, which lowers this further) stays
    # under 3 GiB of address space; before the fix, hostile files took > 8 GiB.
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


@pytest.fixture(scope="module")
def small_bake(tmp_path_factory):
    out = tmp_path_factory.mktemp("hostile") / "src.vdb"
    r = subprocess.run([CLOUDGEN, "bake", "--preset", "cumulus", "--resolution", "8", "--quiet", "--output", out],
                       capture_output=True, text=True, timeout=TIMEOUT)
    assert r.returncode == 0, r.stderr
    return out.read_bytes()


def subset(data):
    every = int(os.environ.get("CLOUDGEN_HOSTILE_EVERY", "8"))
    for i, (label, blob) in enumerate(cases(data)):
        if label.startswith(("bool", "version", "grid count", "file metadata count")) or i % every == 0:
            yield label, blob


def test_hostile_vdbs_cost_one_error_line(small_bake, tmp_path):
    bad, n = [], 0
    for label, blob in subset(small_bake):
        path = tmp_path / "case.vdb"
        path.write_bytes(blob)
        rc, err, hung = run_info(CLOUDGEN, path, TIMEOUT, preexec=None if SANITIZED else limit_memory)
        n += 1
        v = verdict(rc, err, hung)
        if v != "clean":
            bad.append(f"{label}: {v}: {err.strip()[:400]}")
    print(f"{n} hostile VDB cases, {len(bad)} not clean")
    assert n > 50 and not bad, "\n".join(bad)


@pytest.mark.parametrize("value", [2, 127, 255])
def test_half_float_bool_byte_refused_before_openvdb(small_bake, tmp_path, value):
    data = bytearray(small_bake)
    at = data.find(b"is_saved_as_half_float")
    at = data.find(b"bool", at) + 4 + 4  # type name, then the uint32 size (1), then the byte
    assert data[at - 4:at] == b"\x01\x00\x00\x00", "layout changed: the bool's size field"
    data[at] = value
    path = tmp_path / f"half{value}.vdb"
    path.write_bytes(data)
    rc, err, hung = run_info(CLOUDGEN, path, TIMEOUT)
    assert (rc, hung) == (1, False), f"byte {value}: exit {rc}, stderr {err!r}"
    assert "is_saved_as_half_float" in err and "0 or 1" in err, err


def test_format_version_zero_refused(small_bake, tmp_path):
    path = tmp_path / "v0.vdb"
    path.write_bytes(small_bake[:8] + b"\0\0\0\0" + small_bake[12:])
    rc, err, hung = run_info(CLOUDGEN, path, TIMEOUT)
    assert rc == 1 and "version 0" in err and len(err.strip().splitlines()) == 1, err


def test_info_on_fifo_and_directory_does_not_block(tmp_path):
    fifo = tmp_path / "pipe.vdb"
    os.mkfifo(fifo)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    rc, err, hung = run_info(CLOUDGEN, fifo, 60)
    assert not hung and rc == 1 and "not a regular file" in err, (rc, err)
    rc, err, hung = run_info(CLOUDGEN, tmp_path, 60)
    assert rc == 1 and "directory" in err, (rc, err)


@pytest.mark.parametrize("mutation", ["half255", "version0", "truncated", "bitflips"])
def test_bake_update_rebakes_a_hostile_existing_output(small_bake, tmp_path, mutation):
    out = tmp_path / "out.vdb"
    args = [CLOUDGEN, "bake", "--preset", "cumulus", "--resolution", "8", "--update", "--output", out]
    r = subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT)
    assert r.returncode == 0, r.stderr
    good = out.read_bytes()
    data = bytearray(good)
    if mutation == "half255":
        at = data.find(b"bool", data.find(b"is_saved_as_half_float")) + 8
        data[at] = 255
    elif mutation == "version0":
        data[8:12] = b"\0\0\0\0"
    elif mutation == "truncated":
        data = data[: len(data) // 2]
    else:
        for at in range(200, len(data), 97):
            data[at] ^= 0x5A
    out.write_bytes(bytes(data))
    r = subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT,
                       preexec_fn=None if SANITIZED else limit_memory)
    assert r.returncode == 0, f"{mutation}: exit {r.returncode}: {r.stderr[-2000:]}"
    assert f"wrote {out}" in r.stdout and "kept" not in r.stdout, r.stdout
    new = out.read_bytes()  # equal but for the file's UUID (bytes 21..57)
    assert new[:21] + new[57:] == good[:21] + good[57:], f"{mutation}: the rebaked file differs from the first bake"
