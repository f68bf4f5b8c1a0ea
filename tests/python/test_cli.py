"""The cloudgen command-line tool: usage, bad input, atomic output, cancel,
sequences, and reading a bake back through `cloudgen info`.

Runs build/bin/cloudgen of this checkout, or $CLOUDGEN_BIN. Every bad input
must exit with 2, print ONE line `cloudgen: error: ...` naming the argument,
and leave the output directory exactly as it was (no file, no temporary).
"""
import importlib.util
import json
import os
import pathlib
import signal
import struct
import subprocess
import sys

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(REPO_ROOT / "build" / "bin" / "cloudgen"))

# Guards against a hang only; no test asserts how long anything takes.
TIMEOUT = 120

if not os.access(CLOUDGEN, os.X_OK):
    pytest.skip(f"cloudgen binary not built: {CLOUDGEN}", allow_module_level=True)


def run(*args, cwd=None):
    return subprocess.run([CLOUDGEN, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=TIMEOUT)


def _load_cli_events():
    """addon/cli_events.py, the one reader of the CLI's JSON lines (no bpy needed)."""
    spec = importlib.util.spec_from_file_location("cli_events", REPO_ROOT / "addon" / "cli_events.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


cli_events = _load_cli_events()


def events(result):
    """The BakeEvents of a `--json` run's stdout (every line must be a protocol event)."""
    ev = cli_events.BakeEvents()
    for line in result.stdout.splitlines():
        ev.feed(line)
    return ev


def listing(directory):
    return sorted(p.name for p in pathlib.Path(directory).iterdir())


def expect_usage_error(result, *words):
    """Exit 2 and one stderr line `cloudgen: error: ...` containing every word."""
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    assert len(lines) == 1, f"expected one line, got: {result.stderr!r}"
    assert lines[0].startswith("cloudgen: error: "), lines[0]
    for w in words:
        assert w in lines[0], f"{w!r} not named in: {lines[0]}"


def info_json(path):
    r = run("info", path, "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def png_size(path):
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


# ------------------------------------------------------------------ usage ---

def test_help_texts():
    r = run("--help")
    assert r.returncode == 0 and "usage: cloudgen" in r.stdout
    for verb in ("bake", "preview", "presets", "params", "info"):
        assert verb in r.stdout
        v = run(verb, "--help")
        assert v.returncode == 0, (verb, v.stderr)
        assert v.stdout.startswith(f"usage: cloudgen {verb}"), v.stdout[:80]
    # The PNG display mapping is documented where users look for it.
    assert "1 − exp(−density/S)" in run("preview", "--help").stdout
    assert "max(peak/3, 0.001)" in run("preview", "--help").stdout
    assert "--max-memory" in run("bake", "--help").stdout


def test_no_command_and_unknown_command():
    expect_usage_error(run(), "command")
    expect_usage_error(run("bakee"), "bakee")
    expect_usage_error(run("bake", "--preset", "cumulus", "--bogus"), "--bogus")


def test_presets_lists_cumulus():
    r = run("presets")
    assert r.returncode == 0
    assert any(line.split()[0] == "cumulus" for line in r.stdout.splitlines() if line.strip())
    assert "cumulus" in json.loads(run("presets", "--json").stdout)


def test_params_json_has_every_declared_key():
    r = run("params", "--json")
    assert r.returncode == 0, r.stderr
    decls = json.loads(r.stdout)
    expected = {"name", "label", "group", "kind", "count", "default", "min", "max", "soft_min", "soft_max",
                "map", "unit", "help"}
    names = [d["name"] for d in decls]
    assert len(names) == len(set(names))
    for d in decls:
        assert expected <= set(d), f"{d.get('name')}: missing {expected - set(d)}"
    for key in ("density", "cloud_scale", "time", "box_size", "wind_direction", "shape_curve"):
        assert key in names
    # The module and the CLI describe the same parameters with the same keys
    # (checked when the module is built; its own tests require it).
    try:
        import cloudgen_native
    except ImportError:
        cloudgen_native = None
    if hasattr(cloudgen_native, "parameters"):
        module_decls = cloudgen_native.parameters()
        assert [p["name"] for p in module_decls] == names
        for p, d in zip(module_decls, decls):
            assert set(p) <= set(d), f"{p['name']}: the CLI lacks {set(p) - set(d)}"
    table = run("params")
    assert table.returncode == 0 and all(n in table.stdout for n in names)


# -------------------------------------------------------------- bad input ---

BAD_PARAM_FILES = [
    ("malformed", '{"density": 0.5,, }', ["--params", "JSON"]),
    ("truncated", '{"density": 0.', ["--params", "JSON"]),
    ("empty", "", ["--params"]),
    ("not an object", "[1, 2]", ["--params"]),
    ("unknown key", '{"densty": 0.5}', ["--params", "densty"]),
    ("out of range", '{"density": 50}', ["--params", "density", "[0, 10]"]),
    ("int not integer", '{"shape_mode": 0.5}', ["--params", "shape_mode"]),
    ("negative", '{"cloud_scale": -1}', ["--params", "cloud_scale"]),
    ("NaN", '{"density": NaN}', ["--params"]),
    ("Infinity", '{"density": Infinity}', ["--params"]),
    ("huge", '{"density": 1e999}', ["--params", "JSON"]),
    ("wrong type", '{"density": "high"}', ["--params", "density"]),
    ("vector length", '{"box_size": [1, 2]}', ["--params", "box_size"]),
    ("unknown preset in file", '{"preset": "nimbus"}', ["--params", "nimbus"]),
]


# Every case through bake; preview shares load_params, so a few cases suffice there.
PARAM_FILE_RUNS = [("bake", *c) for c in BAD_PARAM_FILES] + \
    [("preview", *c) for c in BAD_PARAM_FILES if c[0] in ("truncated", "unknown key", "out of range")]


@pytest.mark.parametrize("verb,case,text,words", PARAM_FILE_RUNS, ids=[f"{r[0]}-{r[1]}" for r in PARAM_FILE_RUNS])
def test_bad_parameter_files(verb, case, text, words, params_file, out_dir):
    p = params_file(text)
    before = listing(out_dir)
    if verb == "bake":
        r = run("bake", "--params", p, "--resolution", 16, "--output", out_dir / "x.vdb")
    else:
        r = run("preview", "--params", p, "--axis", "y", "--size", 16, "--output", out_dir / "x.png")
    expect_usage_error(r, *words)
    assert listing(out_dir) == before


BAD_BAKE_ARGS = [
    ("unknown preset", ["--preset", "nimbus"], ["--preset", "nimbus", "cumulus"]),
    ("missing params file", ["--params", "/nonexistent/p.json"], ["--params"]),
    ("both sources", ["--preset", "cumulus", "--params", "x.json"], ["--preset", "--params"]),
    ("no source", [], ["--preset", "--params"]),
    ("resolution text", ["--preset", "cumulus", "--resolution", "abc"], ["--resolution", "abc"]),
    ("resolution zero", ["--preset", "cumulus", "--resolution", "0"], ["--resolution", "[1,"]),
    ("resolution negative", ["--preset", "cumulus", "--resolution", "-4"], ["--resolution"]),
    ("resolution float", ["--preset", "cumulus", "--resolution", "12.5"], ["--resolution"]),
    ("resolution missing", ["--preset", "cumulus", "--resolution"], ["--resolution"]),
    ("time NaN", ["--preset", "cumulus", "--time", "nan"], ["--time"]),
    ("time Inf", ["--preset", "cumulus", "--time", "inf"], ["--time"]),
    ("time out of range", ["--preset", "cumulus", "--time", "1e9"], ["--time"]),
    ("tolerance negative", ["--preset", "cumulus", "--tolerance", "-1"], ["--tolerance"]),
    ("threads text", ["--preset", "cumulus", "--threads", "many"], ["--threads"]),
    ("max-memory zero", ["--preset", "cumulus", "--max-memory", "0"], ["--max-memory"]),
    ("frames reversed", ["--preset", "cumulus", "--frames", "5-2"], ["--frames"]),
    ("frames text", ["--preset", "cumulus", "--frames", "a-b"], ["--frames"]),
    ("fps zero", ["--preset", "cumulus", "--frames", "1-2", "--fps", "0"], ["--fps"]),
    ("fps NaN", ["--preset", "cumulus", "--frames", "1-2", "--fps", "nan"], ["--fps"]),
]


@pytest.mark.parametrize("case,args,words", BAD_BAKE_ARGS, ids=[c[0] for c in BAD_BAKE_ARGS])
def test_bad_bake_arguments(case, args, words, out_dir):
    if "--resolution" not in args:
        args = args + ["--resolution", "16"]
    before = listing(out_dir)
    expect_usage_error(run("bake", *args, "--output", out_dir / "x.vdb"), *words)
    assert listing(out_dir) == before


BAD_PREVIEW_ARGS = [
    ("axis", ["--axis", "w"], ["--axis", "x, y or z"]),
    ("axis missing", [], ["--axis"]),
    ("offset above", ["--axis", "z", "--offset", "1.5"], ["--offset", "[0, 1]"]),
    ("offset NaN", ["--axis", "z", "--offset", "nan"], ["--offset"]),
    ("size zero", ["--axis", "z", "--size", "0"], ["--size"]),
    ("size text", ["--axis", "z", "--size", "big"], ["--size"]),
    ("size height", ["--axis", "z", "--size", "64x0"], ["--size"]),
    ("png scale zero", ["--axis", "z", "--png-scale", "0"], ["--png-scale", "auto", "(0, 1e6]"]),
    ("png scale text", ["--axis", "z", "--png-scale", "bright"], ["--png-scale", "auto"]),
    ("png scale NaN", ["--axis", "z", "--png-scale", "nan"], ["--png-scale"]),
]


@pytest.mark.parametrize("case,args,words", BAD_PREVIEW_ARGS, ids=[c[0] for c in BAD_PREVIEW_ARGS])
def test_bad_preview_arguments(case, args, words, out_dir):
    before = listing(out_dir)
    expect_usage_error(run("preview", "--preset", "cumulus", *args, "--output", out_dir / "x.png"), *words)
    assert listing(out_dir) == before


@pytest.mark.parametrize("name", ["x.jpg", "x", "x.vdb"])
def test_preview_refuses_other_formats(name, out_dir):
    expect_usage_error(run("preview", "--preset", "cumulus", "--axis", "z", "--output", out_dir / name),
                       "--output", ".png", ".exr")
    assert listing(out_dir) == []


def test_bake_refuses_non_vdb_output(out_dir):
    expect_usage_error(run("bake", "--preset", "cumulus", "--resolution", 8, "--output", out_dir / "x.png"),
                       "--output", ".vdb")
    assert listing(out_dir) == []


@pytest.mark.parametrize("verb", ["bake", "preview"])
def test_unwritable_output_path(verb, tmp_path):
    # Tests run as root, so permissions cannot make a directory unwritable:
    # use a parent that does not exist and a parent that is a regular file.
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    for target in (tmp_path / "missing" / "x", blocker / "x", tmp_path):
        ext = ".vdb" if verb == "bake" else ".png"
        out = target if target == tmp_path else target.with_suffix(ext)
        before = listing(tmp_path)
        if verb == "bake":
            r = run("bake", "--preset", "cumulus", "--resolution", 8, "--output", out)
        else:
            r = run("preview", "--preset", "cumulus", "--axis", "z", "--size", 8, "--output", out)
        expect_usage_error(r, "--output")
        assert listing(tmp_path) == before


def test_absurd_resolution_refused_with_estimate(out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 100000, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--resolution", "GiB", "--max-memory")
    assert listing(out_dir) == []
    # The budget is the one given: a tiny budget refuses even a small bake.
    r = run("bake", "--preset", "cumulus", "--resolution", 64, "--max-memory", "1e-6", "--output", out_dir / "x.vdb")
    expect_usage_error(r, "--resolution", "GiB")
    assert listing(out_dir) == []


def test_info_on_missing_or_bad_file(tmp_path):
    r = run("info", tmp_path / "missing.vdb")
    assert r.returncode == 1 and r.stderr.startswith("cloudgen: error:") and "missing.vdb" in r.stderr
    junk = tmp_path / "junk.vdb"
    junk.write_text("junk")
    r = run("info", junk)
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1, r.stderr


# ---------------------------------------------------------- bake & preview ---

def test_bake_then_info(out_dir):
    out = out_dir / "cumulus.vdb"
    r = run("bake", "--preset", "cumulus", "--resolution", 32, "--output", out)
    assert r.returncode == 0, r.stderr
    # human output: results on stdout, progress on stderr (a pipe: whole tens of percent)
    assert f"wrote {out}" in r.stdout
    assert "bake: 100%" in r.stderr.splitlines(), r.stderr
    assert "%" not in r.stdout, r.stdout
    assert listing(out_dir) == ["cumulus.vdb"]

    text = run("info", out)
    assert text.returncode == 0, text.stderr
    assert "grid: density" in text.stdout
    active = int(next(l for l in text.stdout.splitlines() if "active voxels:" in l).split(":")[1])
    assert active > 0

    doc = info_json(out)
    (g,) = doc["grids"]
    assert g["name"] == "density" and g["class"] == "fog volume" and g["value_type"] == "float"
    assert g["active_voxels"] == active and g["min"] >= 0 and g["max"] > 0
    box = json.loads((REPO_ROOT / "native" / "presets" / "clouds.json").read_text())["cumulus"]["params"]["box_size"]
    assert abs(g["voxel_size"][0] - max(box) / 32) < 1e-6  # 32 voxels along the cumulus box's longest side
    meta = g["metadata"]
    assert meta["cloudgen_preset"] == "cumulus" and meta["cloudgen_resolution"] == "32"
    params = json.loads(meta["cloudgen_params"])
    assert params["box_size"] == pytest.approx(box, rel=1e-6)  # stored as float32
    assert "blosc" in doc["compression"]


def test_bake_options(out_dir, params_file):
    p = params_file('{"preset": "cumulus", "density": 0.25}')
    out = out_dir / "c.vdb"
    r = run("bake", "--params", p, "--resolution", 24, "--time", 2.5, "--half", "--no-lod", "--threads", 1,
            "--quiet", "--output", out)
    assert r.returncode == 0, r.stderr
    assert "%" not in r.stdout + r.stderr, ("--quiet prints no progress", r.stdout, r.stderr)
    (g,) = info_json(out)["grids"]
    assert g["half"] is True
    assert float(g["metadata"]["cloudgen_time"]) == 2.5
    assert json.loads(g["metadata"]["cloudgen_params"])["density"] == 0.25
    assert "cloudgen_preset" not in g["metadata"]


def test_empty_cloud_bakes_valid_empty_file(out_dir, params_file):
    p = params_file('{"preset": "cumulus", "density": 0}')
    out = out_dir / "empty.vdb"
    r = run("bake", "--params", p, "--resolution", 16, "--output", out)
    assert r.returncode == 0, r.stderr
    (g,) = info_json(out)["grids"]
    assert g["name"] == "density" and g["active_voxels"] == 0


@pytest.mark.parametrize("pattern,expected", [
    ("seq.vdb", ["seq_0001.vdb", "seq_0002.vdb", "seq_0003.vdb"]),
    ("f_###.vdb", ["f_001.vdb", "f_002.vdb", "f_003.vdb"]),
])
def test_sequence_writes_one_file_per_frame(pattern, expected, out_dir):
    r = run("bake", "--preset", "cumulus", "--resolution", 16, "--frames", "1-3", "--fps", 24,
            "--output", out_dir / pattern)
    assert r.returncode == 0, r.stderr
    assert listing(out_dir) == expected
    assert r.stdout.count("wrote ") == 3
    for frame, name in enumerate(expected, start=1):
        (g,) = info_json(out_dir / name)["grids"]
        assert abs(float(g["metadata"]["cloudgen_time"]) - frame / 24) < 1e-6, (name, g["metadata"])


def test_preview_png_and_exr(out_dir):
    png = out_dir / "slice.png"
    r = run("preview", "--preset", "cumulus", "--axis", "y", "--offset", 0.5, "--size", 64, "--output", png)
    assert r.returncode == 0, r.stderr
    box = json.loads((REPO_ROOT / "native" / "presets" / "clouds.json").read_text())["cumulus"]["params"]["box_size"]
    assert png_size(png) == (64, round(64 * box[2] / box[0])), f"height from the box face aspect (cumulus: {box})"
    exr = out_dir / "slice.exr"
    r = run("preview", "--preset", "cumulus", "--axis", "z", "--offset", 0.3, "--size", "40x20", "--lod",
            "--output", exr)
    assert r.returncode == 0, r.stderr
    assert exr.read_bytes()[:4] == b"\x76\x2f\x31\x01"  # OpenEXR magic
    assert listing(out_dir) == ["slice.exr", "slice.png"]


# ----------------------------------------------------------------- cancel ---

@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_cancel_leaves_nothing(sig, out_dir):
    out = out_dir / "big.vdb"
    proc = subprocess.Popen([CLOUDGEN, "bake", "--preset", "cumulus", "--resolution", "384", "--threads", "1",
                             "--output", str(out), "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        seen = []
        for line in proc.stdout:
            seen.append(line)
            if cli_events.parse(line)["event"] == "progress":
                break
        assert proc.poll() is None, f"the bake ended before it could be cancelled: {seen}"
        proc.send_signal(sig)
        proc.wait(timeout=TIMEOUT)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    stderr = proc.stderr.read()
    assert proc.returncode == 130, (proc.returncode, stderr)
    assert stderr.strip().startswith("cloudgen: error: cancelled")
    assert listing(out_dir) == [], "a cancelled bake must leave no file and no temporary"


def test_full_disk_fails_and_leaves_nothing(tmp_path):
    # A full disk, simulated by a 4 KiB file-size limit with SIGXFSZ ignored (writes then
    # fail with EFBIG as they fail with ENOSPC on a full disk). Exact: exit 1, no file at all.
    import resource

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))

    out = tmp_path / "big.vdb"
    r = subprocess.run([CLOUDGEN, "bake", "--preset", "cumulus", "--resolution", "64", "--output", str(out),
                        "--quiet"], capture_output=True, text=True, preexec_fn=limit)
    assert r.returncode == 1, (r.returncode, r.stdout, r.stderr)
    assert "disk full" in r.stderr, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [], list(tmp_path.iterdir())
