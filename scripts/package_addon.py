"""Assemble the installable add-on: build/addon/cloudgen/, build/cloudgen-addon.zip and
build/cloudgen-extension.zip.

    python scripts/package_addon.py [--build build] [--out build] [--blender BLENDER]

Contents: addon/*.py, blender_manifest.toml, README.md; blender_nodes.py
(copied from osl/ — the Script-node wiring lives in one place);
shaders/*.osl (flattened by osl/flatten.py: self-contained);
lib/cloudgen_native.abi3.so (from <build>/python); presets/clouds.json
(native/presets/clouds.json); LICENSE. No executable: Bake to VDB bakes inside
Blender (addon/bake_local.py); the cloudgen CLI is the pipeline tool, not shipped.

build/cloudgen-addon.zip holds the folder `cloudgen/` (legacy "Install from
Disk", Blender 3.4+); build/cloudgen-extension.zip is the extension (4.2+)
built by Blender's own tool (`blender --command extension build`; here its
script blender_ext.py from the bpy wheel or a Blender given with --blender),
after `extension validate`. Writes into a temporary folder and renames.
"""
import argparse
import importlib.util
import pathlib
import shutil
import subprocess
import sys
import zipfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "osl"))
import flatten  # noqa: E402


def package(build: pathlib.Path, out: pathlib.Path) -> pathlib.Path:
    final = out / "addon" / "cloudgen"
    tmp = out / "addon" / ".cloudgen.tmp"
    if tmp.exists():
        shutil.rmtree(tmp)
    (tmp / "lib").mkdir(parents=True)
    (tmp / "shaders").mkdir()
    (tmp / "presets").mkdir()
    for f in sorted((ROOT / "addon").iterdir()):
        if f.suffix in (".py", ".toml", ".md") and f.is_file():
            shutil.copy2(f, tmp / f.name)
    shutil.copy2(ROOT / "osl" / "blender_nodes.py", tmp / "blender_nodes.py")
    for name in flatten.SHADERS:
        (tmp / "shaders" / f"{name}.osl").write_text(flatten.shader_source(name))
    shutil.copy2(ROOT / "native" / "presets" / "clouds.json", tmp / "presets" / "clouds.json")
    libs = sorted((build / "python").glob("cloudgen_native*.so"))
    if not libs:
        raise SystemExit(f"package_addon: no cloudgen_native*.so in {build / 'python'} (build first)")
    shutil.copy2(libs[0], tmp / "lib" / "cloudgen_native.abi3.so")
    shutil.copy2(ROOT / "LICENSE", tmp / "LICENSE")
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)

    zpath = out / "cloudgen-addon.zip"
    ztmp = zpath.with_suffix(".zip.tmp")
    with zipfile.ZipFile(ztmp, "w", zipfile.ZIP_DEFLATED) as z:
        for f in sorted(final.rglob("*")):
            if f.is_file() and "__pycache__" not in f.parts:
                info = zipfile.ZipInfo.from_file(f, f"cloudgen/{f.relative_to(final)}")
                info.compress_type = zipfile.ZIP_DEFLATED
                z.writestr(info, f.read_bytes())
    ztmp.replace(zpath)
    return final


def blender_ext_script():
    """Blender's extension tool (bl_pkg/cli/blender_ext.py) inside the bpy wheel, or None."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        return None
    for loc in spec.submodule_search_locations:
        found = sorted(pathlib.Path(loc).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1]
    return None


def extension_commands(final: pathlib.Path, outdir: pathlib.Path, blender=None):
    """[validate, build] argument lists of Blender's extension tool, or None without one."""
    if blender:
        base = [blender, "--factory-startup", "--command", "extension"]
    else:
        script = blender_ext_script()
        if script is None:
            return None
        base = [sys.executable, str(script)]
    return [base + ["validate", str(final)],
            base + ["build", "--source-dir", str(final), "--output-dir", str(outdir)]]


def build_extension(final: pathlib.Path, out: pathlib.Path, blender=None):
    """build/cloudgen-extension.zip by Blender's tool; None (with a warning) without one."""
    tmpdir = out / ".extension.tmp"
    if tmpdir.exists():
        shutil.rmtree(tmpdir)
    tmpdir.mkdir(parents=True)
    commands = extension_commands(final, tmpdir, blender)
    if commands is None:
        print("package_addon: warning: no Blender extension tool (bpy wheel or --blender): "
              "cloudgen-extension.zip not built", file=sys.stderr)
        shutil.rmtree(tmpdir)
        return None
    for cmd in commands:
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            shutil.rmtree(tmpdir)
            raise SystemExit(f"package_addon: {' '.join(cmd[-3:])} failed:\n{run.stdout}{run.stderr}")
    built = sorted(tmpdir.glob("*.zip"))
    target = out / "cloudgen-extension.zip"
    built[0].replace(target)
    shutil.rmtree(tmpdir)
    return target


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(ROOT / "build"), help="build directory (python/, bin/)")
    ap.add_argument("--out", default=str(ROOT / "build"), help="where addon/cloudgen and the zip go")
    ap.add_argument("--blender", default=None,
                    help="a Blender 4.2+ whose `--command extension` builds the extension zip "
                         "(default: the bpy wheel's blender_ext.py when bpy is installed)")
    a = ap.parse_args()
    final = package(pathlib.Path(a.build), pathlib.Path(a.out))
    ext = build_extension(final, pathlib.Path(a.out), a.blender)
    print(f"package_addon: {final} and {pathlib.Path(a.out) / 'cloudgen-addon.zip'}"
          + (f" and {ext}" if ext else ""))


if __name__ == "__main__":
    main()
