"""Assemble the installable add-on: build/addon/cloudgen/ and build/cloudgen-addon.zip.

    python scripts/package_addon.py [--build build] [--out build]

Contents: addon/*.py, blender_manifest.toml, README.md; blender_nodes.py
(copied from osl/ — the Script-node wiring lives in one place);
shaders/*.osl (flattened by osl/flatten.py: self-contained);
lib/cloudgen_native.abi3.so (from <build>/python); bin/cloudgen (the CLI);
presets/clouds.json (native/presets/clouds.json). The zip holds the folder
`cloudgen/` (legacy "Install from file"; for an extension, `blender --command
extension build` on the folder). Writes into a temporary folder and renames.
"""
import argparse
import pathlib
import shutil
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
    (tmp / "bin").mkdir()
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
    cli = build / "bin" / "cloudgen"
    if cli.is_file():
        shutil.copy2(cli, tmp / "bin" / "cloudgen")
    else:
        print(f"package_addon: warning: {cli} missing; the add-on cannot bake without it", file=sys.stderr)
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(ROOT / "build"), help="build directory (python/, bin/)")
    ap.add_argument("--out", default=str(ROOT / "build"), help="where addon/cloudgen and the zip go")
    a = ap.parse_args()
    final = package(pathlib.Path(a.build), pathlib.Path(a.out))
    print(f"package_addon: {final} and {pathlib.Path(a.out) / 'cloudgen-addon.zip'}")


if __name__ == "__main__":
    main()
