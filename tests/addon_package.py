"""The packaged add-on the Blender tests load (build/addon/cloudgen, made by
scripts/package_addon.py): rebuilt when a source it copies is newer — the
add-on, the shaders, LICENSE, the native module from build/."""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
ADDON_PARENT = ROOT / "build" / "addon"
PACKAGE = ADDON_PARENT / "cloudgen"


def _sources():
    yield from (ROOT / "addon").iterdir()
    yield from (ROOT / "osl").glob("*")
    yield ROOT / "LICENSE"
    yield ROOT / "scripts" / "package_addon.py"
    yield from (ROOT / "build" / "python").glob("cloudgen_native*")


def is_stale():
    init = PACKAGE / "__init__.py"
    if not init.exists() or not (PACKAGE / "bake.py").exists():
        return True
    # the folder's own time is when it was assembled (the files keep their sources' times)
    built = PACKAGE.stat().st_mtime
    return any(f.stat().st_mtime > built for f in _sources() if f.is_file())


def ensure():
    """Repackage when stale; put the package's parent on sys.path."""
    if is_stale():
        subprocess.run([sys.executable, str(ROOT / "scripts" / "package_addon.py")], check=True)
    if str(ADDON_PARENT) not in sys.path:
        sys.path.insert(0, str(ADDON_PARENT))
