"""Hostile parameter, camera and sequence files (issue 15, findings 3, 7, 8):
limits on size, nesting depth, string length, values and frames, duplicate keys,
`fps`, unknown keys in frame entries; every refusal is one `cloudgen: error:`
line, exit 2, that shows at most ~100 characters of the bad value.

Tolerance: none; the one-line message must stay under 400 characters.
Timeouts catch hangs only."""
import json
import os
import pathlib
import subprocess

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
CLOUDGEN = os.environ.get("CLOUDGEN_BIN", str(REPO_ROOT / "build" / "bin" / "cloudgen"))
TIMEOUT = 120
DEEP = 100000  # the depth that overflowed the stack in nlohmann's dump()

if not os.access(CLOUDGEN, os.X_OK):
    pytest.skip(f"cloudgen binary not built: {CLOUDGEN}", allow_module_level=True)

CAMERA = {"camera_to_cloud": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 10], [0, 0, 0, 1]],
          "tan_half_fov": [0.4, 0.3], "resolution": [64, 48]}


def deep(n=DEEP):
    return "[" * n + "]" * n


def refused(r, *words, label=""):
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2, f"{label}: exit {r.returncode}, stderr {r.stderr[-500:]!r}"
    assert len(lines) == 1 and lines[0].startswith("cloudgen: error:"), f"{label}: {r.stderr[-500:]!r}"
    assert len(lines[0]) < 400, f"{label}: a {len(lines[0])}-character message: {lines[0][:200]}..."
    for w in words:
        assert w in lines[0], f"{label}: {w!r} not in {lines[0]!r}"


def bake(tmp_path, option, text, name="in.json", *extra):
    f = tmp_path / name
    f.write_text(text)
    args = [CLOUDGEN, "bake", option, f, "--resolution", "8", "--output", tmp_path / "o.vdb", *extra]
    if option == "--camera":
        args += ["--preset", "cumulus"]
    return subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT)


PARAMS = {
    "deep value": ('{"density": ' + deep() + "}", "nested deeper than 16"),
    "deep shape": ('{"shape": ' + deep() + "}", "nested deeper than 16"),
    "deep object": ('{"a": ' + '{"a": ' * 1000 + "1" + "}" * 1000 + "}", "nested deeper than 16"),
    "duplicate key": ('{"density": 0.5, "density": 0.6}', "appears twice"),
    "long string": ('{"preset": "' + "x" * 100000 + '"}', "at most 4096"),
    "long key": ('{"' + "k" * 100000 + '": 1}', "at most 4096"),
    "many values": ('{"box_size": [' + ",".join(["1"] * 200000) + "]}", "more than 100000 values"),
    "big file": ('{"density": 0.5}' + " " * (2 << 20), "larger than"),
    "long bad number list": ('{"box_size": [' + ",".join(["1e30"] * 5000) + "]}", "box_size"),
    "long unknown key": ('{"' + "u" * 4000 + '": 1}', "unknown parameter"),
    "huge number": ('{"density": 1e999}', "not valid JSON"),
}


@pytest.mark.parametrize("case", PARAMS)
def test_params_file_limits(tmp_path, case):
    text, word = PARAMS[case]
    refused(bake(tmp_path, "--params", text), "--params", word, label=case)


CAMERAS = {
    "deep near": {**CAMERA, "near": "DEEP"},
    "deep type": {**CAMERA, "type": "DEEP"},
    "deep fov": {**CAMERA, "tan_half_fov": "DEEP"},
    "deep matrix": {**CAMERA, "camera_to_cloud": "DEEP"},
    "deep lights": {**CAMERA, "light_directions": "DEEP"},
    "deep resolution": {**CAMERA, "resolution": "DEEP"},
}


@pytest.mark.parametrize("case", CAMERAS)
def test_camera_file_nesting(tmp_path, case):
    text = json.dumps(CAMERAS[case]).replace('"DEEP"', deep())
    refused(bake(tmp_path, "--camera", text), "--camera", "nested deeper", label=case)


def test_camera_duplicate_key_and_long_value(tmp_path):
    text = json.dumps(CAMERA)[:-1] + ', "near": 0.1, "near": 0.2}'
    refused(bake(tmp_path, "--camera", text), "appears twice", label="duplicate near")
    text = json.dumps({**CAMERA, "type": "P" * 4000})
    refused(bake(tmp_path, "--camera", text), "perspective", label="long type")


SEQUENCES = {
    "deep params": ('{"frames": [{"frame": 1, "params": {"density": ' + deep() + "}}]}", "nested deeper"),
    "deep frames": ('{"frames": ' + deep() + "}", "nested deeper"),
    "unknown entry key": ('{"frames": [{"frame": 1, "params": {}, "time": 3}]}', "unknown key 'time'"),
    "negative fps": ('{"fps": -3, "frames": [{"frame": 1, "params": {}}]}', "'fps'"),
    "text fps": ('{"fps": "24", "frames": [{"frame": 1, "params": {}}]}', "'fps'"),
    "zero fps": ('{"fps": 0, "frames": [{"frame": 1, "params": {}}]}', "'fps'"),
    "duplicate frames key": ('{"frames": [{"frame": 1, "params": {}}], "frames": []}', "appears twice"),
    "duplicate key in entry": ('{"frames": [{"frame": 1, "frame": 2, "params": {}}]}', "appears twice"),
    "huge frame": ('{"frames": [{"frame": 18446744073709551615, "params": {}}]}', "frame numbers"),
    "too many frames": (json.dumps({"frames": [{"frame": i, "params": {}} for i in range(100001)]}),
                        "at most 100000"),
}


@pytest.mark.parametrize("case", SEQUENCES)
def test_sequence_file_limits(tmp_path, case):
    text, word = SEQUENCES[case]
    refused(bake(tmp_path, "--sequence", text, "seq.json"), "--sequence", word, label=case)
    assert not list(tmp_path.glob("o*.vdb")), case


def test_valid_sequence_with_fps_still_bakes(tmp_path):
    text = json.dumps({"fps": 24, "frames": [{"frame": 1, "params": {"preset": "cumulus"}}]})
    r = bake(tmp_path, "--sequence", text, "seq.json")
    assert r.returncode == 0, r.stderr
