"""The CLI's image plugin (native/io/image_plugin.h): OpenImageIO is loaded only by
`cloudgen preview`, from <dir of the executable>/../lib/cloudgen_image.so.

Checks the linkage (readelf), what a running process really loads (the dynamic
loader's own LD_DEBUG=files report), that the plugin is found next to the
executable wherever that is, and the errors for a missing or foreign plugin.
Runs build/bin/cloudgen of this checkout, or $CLOUDGEN_BIN.
"""
import os
import pathlib
import shutil
import subprocess

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
CLOUDGEN = pathlib.Path(os.environ.get("CLOUDGEN_BIN", str(REPO_ROOT / "build" / "bin" / "cloudgen")))
PLUGIN = CLOUDGEN.parent.parent / "lib" / "cloudgen_image.so"
TIMEOUT = 120  # guards against a hang only

if not os.access(CLOUDGEN, os.X_OK):
    pytest.skip(f"cloudgen binary not built: {CLOUDGEN}", allow_module_level=True)


def run(binary, *args, env=None, cwd=None):
    return subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, timeout=TIMEOUT,
                          env=env, cwd=cwd)


def needed(path):
    """The NEEDED entries of an ELF file's dynamic section."""
    out = subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True, check=True).stdout
    return [line.split("[", 1)[1].rstrip("]") for line in out.splitlines() if "(NEEDED)" in line]


def loaded_files(binary, *args, tmp_path):
    """(result, every file the dynamic loader opened) for one run, from LD_DEBUG=files."""
    log = tmp_path / "ld.log"
    env = dict(os.environ, LD_DEBUG="files", LD_DEBUG_OUTPUT=str(log))
    r = run(binary, *args, env=env)
    text = "".join(p.read_text(errors="replace") for p in tmp_path.glob("ld.log*"))
    for p in tmp_path.glob("ld.log*"):
        p.unlink()
    files = {line.split("file=", 1)[1].split()[0] for line in text.splitlines() if "file=" in line}
    assert files, f"LD_DEBUG=files reported nothing for {args}"
    return r, files


def oiio(files):
    return sorted(f for f in files if "OpenImageIO" in f)


@pytest.fixture
def copied_cli(tmp_path):
    """The CLI copied into TMP/bin/ (no TMP/lib/ yet)."""
    (tmp_path / "bin").mkdir()
    exe = tmp_path / "bin" / "cloudgen"
    shutil.copy2(CLOUDGEN, exe)
    return exe


def expect_one_error_line(r, code, *words):
    lines = r.stderr.strip().splitlines()
    assert r.returncode == code, (r.returncode, r.stdout, r.stderr)
    assert len(lines) == 1 and lines[0].startswith("cloudgen: error: "), r.stderr
    for w in words:
        assert w in lines[0], f"{w!r} not in: {lines[0]}"


@pytest.mark.skipif(shutil.which("readelf") is None, reason="readelf (binutils) missing")
def test_linkage_cli_without_openimageio_plugin_with_it():
    assert PLUGIN.is_file(), f"the image plugin is not built next to the CLI: {PLUGIN}"
    cli = needed(CLOUDGEN)
    assert not [n for n in cli if "OpenImageIO" in n], f"the CLI links OpenImageIO: {cli}"
    assert any("openvdb" in n for n in cli), cli
    assert any("OpenImageIO" in n for n in needed(PLUGIN)), needed(PLUGIN)
    syms = subprocess.run(["readelf", "--dyn-syms", "-W", str(PLUGIN)], capture_output=True, text=True,
                          check=True).stdout
    exported = sorted({line.split()[-1] for line in syms.splitlines()
                       if " FUNC " in line and " GLOBAL " in line and " UND " not in line})
    assert exported == ["cloudgen_image_plugin_id", "cloudgen_image_write_slice"], exported


@pytest.mark.parametrize("args", [("--version",), ("presets",),
                                  ("bake", "--preset", "cumulus", "--resolution", 16, "--quiet")],
                         ids=["version", "presets", "bake"])
def test_commands_without_images_load_no_openimageio(args, tmp_path):
    if args[0] == "bake":
        args = (*args, "--output", tmp_path / "c.vdb")
    r, files = loaded_files(CLOUDGEN, *args, tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert not oiio(files), f"{args[0]} loaded {oiio(files)}"
    assert not [f for f in files if "cloudgen_image" in f], f"{args[0]} loaded the image plugin"


@pytest.mark.parametrize("ext", ["png", "exr"])
def test_preview_loads_the_plugin(ext, tmp_path):
    out = tmp_path / f"s.{ext}"
    r, files = loaded_files(CLOUDGEN, "preview", "--preset", "cumulus", "--axis", "y", "--size", 16, "--output", out,
                            tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 0
    assert [f for f in files if f.endswith("cloudgen_image.so")], sorted(files)
    assert oiio(files), "preview wrote an image without loading OpenImageIO?"


def test_plugin_found_beside_the_executable_not_the_working_directory(copied_cli, tmp_path):
    (tmp_path / "lib").symlink_to(PLUGIN.parent, target_is_directory=True)
    out = tmp_path / "s.png"
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    r = run(copied_cli, "preview", "--preset", "cumulus", "--axis", "z", "--size", 8, "--output", out, cwd=elsewhere)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_missing_plugin_is_a_clear_error_and_bake_still_works(copied_cli, tmp_path):
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    for ext in ("png", "exr"):
        r = run(copied_cli, "preview", "--preset", "cumulus", "--axis", "y", "--size", 8,
                "--output", out_dir / f"s.{ext}")
        expect_one_error_line(r, 1, "image plugin", str(tmp_path / "bin" / ".." / "lib" / "cloudgen_image.so"),
                              "is missing", "cloudgen_image")
    assert list(out_dir.iterdir()) == [], "a failed preview left files"
    r = run(copied_cli, "preview", "--preset", "cumulus", "--axis", "y", "--output", out_dir / "s.png", "--json")
    assert r.returncode == 1 and '"event":"error"' in r.stdout.replace(" ", ""), (r.stdout, r.stderr)
    r = run(copied_cli, "bake", "--preset", "cumulus", "--resolution", 16, "--quiet", "--output", out_dir / "c.vdb")
    assert r.returncode == 0, r.stderr
    assert (out_dir / "c.vdb").stat().st_size > 0


def test_a_foreign_library_as_plugin_is_refused(copied_cli, tmp_path):
    # Any shared library without the plugin's entry points: zlib's.
    libz = next((p for p in (pathlib.Path("/lib/x86_64-linux-gnu/libz.so.1"), pathlib.Path("/usr/lib/libz.so.1"))
                 if p.exists()), None)
    if libz is None:
        pytest.skip("no libz.so.1 to stand in for a foreign plugin")
    (tmp_path / "lib").mkdir()
    shutil.copy2(libz, tmp_path / "lib" / "cloudgen_image.so")
    r = run(copied_cli, "preview", "--preset", "cumulus", "--axis", "y", "--size", 8, "--output", tmp_path / "s.png")
    expect_one_error_line(r, 1, "image plugin", "belongs to another build", "cloudgen_image_plugin_id")
    assert not (tmp_path / "s.png").exists()
