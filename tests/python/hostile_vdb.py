"""Hostile VDB files made from a small bake: truncations, header fields, length
fields, bool bytes, bit flips (issue 15). Deterministic: the same file gives the
same cases in the same order. Used by test_hostile_vdb.py and, with every case,
by `python tests/python/hostile_vdb.py cloudgen` (the probe that counts)."""
import random
import struct
import subprocess
import sys


def walk_fields(data):
    """(offset, size, label) of the length/count fields of the header, the file
    metadata, the first grid descriptor and its metadata (a streamed file, as
    cloudgen writes it)."""
    fields = [(8, 4, "version"), (20, 1, "offsets flag")]
    pos = 57

    def text(label):
        nonlocal pos
        n = struct.unpack_from("<I", data, pos)[0]
        fields.append((pos, 4, label))
        pos += 4 + n
        return data[pos - n:pos]

    def meta_map(label):
        nonlocal pos
        count = struct.unpack_from("<i", data, pos)[0]
        fields.append((pos, 4, label + " count"))
        pos += 4
        for _ in range(count):
            name = text(label + " name")
            type_name = text(label + " type")
            size = struct.unpack_from("<I", data, pos)[0]
            fields.append((pos, 4, f"{label} size of {name.decode()}"))
            pos += 4
            if type_name == b"bool":
                fields.append((pos, 1, f"bool {name.decode()}"))
            pos += size

    meta_map("file metadata")
    fields.append((pos, 4, "grid count"))
    pos += 4
    text("grid name")
    text("grid type")
    text("grid parent")
    for k in range(3):
        fields.append((pos, 8, f"grid offset {k}"))
        pos += 8
    fields.append((pos, 4, "grid compression"))
    pos += 4
    meta_map("grid metadata")
    fields.append((pos, 4, "after the grid metadata (transform)"))
    return fields, pos


def cases(data, seed=15, flips=200):
    """Yields (label, bytes) for each hostile variant of `data`."""
    data = bytes(data)
    fields, tree_at = walk_fields(data)
    bounds = sorted({o for o, _, _ in fields} | {o + s for o, s, _ in fields} | {tree_at})
    cuts = sorted(set(bounds) | set(range(0, len(data), max(1, len(data) // 40))) | {len(data) - 1})
    for cut in cuts:
        yield f"truncated at {cut}", data[:cut]
    for offset, size, label in fields:
        if size == 1:
            values = [2, 127, 255] if label.startswith("bool") else [2, 255]
            for v in values:
                yield f"{label} = {v}", data[:offset] + bytes([v]) + data[offset + 1:]
            continue
        fmt = "<I" if size == 4 else "<Q"
        old = struct.unpack_from(fmt, data, offset)[0]
        top = (1 << (8 * size)) - 1
        for v in sorted({0, 1, old + 1, max(old - 1, 0), top, top >> 1, 1 << (8 * size - 1), 0x10000000}):
            if v != old:
                yield f"{label} = {v}", data[:offset] + struct.pack(fmt, v & top) + data[offset + size:]
    rng = random.Random(seed)
    for i in range(flips):
        b = bytearray(data)
        at = rng.randrange(len(b)) if i % 2 else rng.randrange(min(len(b), tree_at + 512))
        b[at] ^= 1 << rng.randrange(8)
        yield f"bit flip {i} at {at}", bytes(b)


def run_info(cloudgen, path, timeout=120, env=None, preexec=None):
    """(returncode, stderr, hung) of `cloudgen info PATH`."""
    try:
        r = subprocess.run([cloudgen, "info", str(path)], capture_output=True, text=True, timeout=timeout,
                           env=env, preexec_fn=preexec, errors="replace")
    except subprocess.TimeoutExpired:
        return None, "", True
    return r.returncode, r.stderr, False


def verdict(rc, stderr, hung):
    """'clean' (read, or refused with one line) or what went wrong."""
    if hung:
        return "hang"
    if rc is not None and rc < 0:
        return f"crash (signal {-rc})"
    if "Sanitizer" in stderr or "runtime error" in stderr:
        return "sanitizer report"
    lines = stderr.strip().splitlines()
    if rc == 0:
        return "clean"
    if rc == 1 and len(lines) == 1 and lines[0].startswith("cloudgen: error:") and len(lines[0]) <= 600:
        return "clean"
    return f"unclean (exit {rc}, {len(lines)} stderr lines)"


if __name__ == "__main__":  # the probe: every case, counted
    import collections
    import pathlib
    import tempfile
    cloudgen = sys.argv[1]
    with tempfile.TemporaryDirectory() as d:
        src = pathlib.Path(d) / "src.vdb"
        subprocess.run([cloudgen, "bake", "--preset", "cumulus", "--resolution", "8", "--quiet", "--output",
                        str(src)], check=True)
        counts = collections.Counter()
        for label, blob in cases(src.read_bytes()):
            p = pathlib.Path(d) / "case.vdb"
            p.write_bytes(blob)
            rc, err, hung = run_info(cloudgen, p, timeout=60)
            v = verdict(rc, err, hung)
            counts[v] += 1
            counts["read" if rc == 0 else "refused" if v == "clean" else "bad"] += 1
            if v != "clean":
                print(f"{label}: {v}: {err.strip()[:300]}", flush=True)
        print(dict(counts))
