"""The add-on's only door to the native core (cloudgen_native) and to the
files shipped inside the package (shaders, presets), and to Blender's OpenVDB
Python module (openvdb()).

The module is loaded from the package's own `lib/cloudgen_native.abi3.so`
first, else by a plain `import cloudgen_native`. When neither works the
add-on still registers: `error()` is one line naming what failed, which every
panel shows and every operator that needs the core reports.

Set CLOUDGEN_ADDON_NO_NATIVE=1 to behave as if the module were missing (tests).
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import os
import pathlib

from . import cli_events

PACKAGE_DIR = pathlib.Path(__file__).resolve().parent
LIB_DIR = PACKAGE_DIR / "lib"
SHADER_DIR = PACKAGE_DIR / "shaders"
PRESETS_JSON = PACKAGE_DIR / "presets" / "clouds.json"

_module = None
_error = None
_loaded = False


def _load():
    global _module, _error, _loaded
    _module, _error, _loaded = None, None, True
    if os.environ.get("CLOUDGEN_ADDON_NO_NATIVE") == "1":
        _error = "cloudgen_native disabled (CLOUDGEN_ADDON_NO_NATIVE=1)"
        return
    problems = []
    for path in sorted(LIB_DIR.glob("cloudgen_native*.so")) + sorted(LIB_DIR.glob("cloudgen_native*.pyd")):
        try:
            loader = importlib.machinery.ExtensionFileLoader("cloudgen_native", str(path))
            spec = importlib.util.spec_from_file_location("cloudgen_native", str(path), loader=loader)
            mod = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(mod)
            _module = mod
            return
        except Exception as exc:  # noqa: BLE001 - any failure becomes the one-line report
            problems.append(f"{path.name}: {exc}")
    try:
        import cloudgen_native as mod  # noqa: PLC0415
        _module = mod
    except Exception as exc:  # noqa: BLE001
        problems.append(f"import cloudgen_native: {exc}")
        _error = "cloudgen native module unavailable — " + "; ".join(problems)


def reload():
    """Forget the loaded module and try again (after installing it, or in tests)."""
    global _loaded
    _loaded = False
    _load()


def native():
    """The cloudgen_native module, or None (see error())."""
    if not _loaded:
        _load()
    return _module


def error() -> str | None:
    """One line saying why the native module is unavailable, or None."""
    if not _loaded:
        _load()
    return _error


def require():
    """The module, or RuntimeError with the one-line reason."""
    mod = native()
    if mod is None:
        raise RuntimeError(_error)
    return mod


def parameters() -> list:
    return list(require().parameters())


def presets() -> dict:
    """{name: {"description", "params", "material"}}: the core's presets, or the
    shipped JSON's (so the cloud-type menu still lists the types) when the
    module is missing."""
    mod = native()
    if mod is not None:
        return dict(mod.presets())
    try:
        return json.loads(PRESETS_JSON.read_text())
    except (OSError, ValueError):
        return {}


def resolve_params(values: dict) -> dict:
    """Validated full parameter set; ValueError/TypeError name the bad key and its range."""
    return dict(require().resolve_params(values))


def slice(values: dict, axis: str, offset: float, width: int, height: int):  # noqa: A001
    return require().slice(values, axis, offset, width, height)


def slice_display_scale(peak: float) -> float:
    """S of the slice display grey = 1 - exp(-density / S) (the CLI's PNG mapping)."""
    return require().slice_display_scale(peak)


def shader_source(name: str) -> str:
    """The flattened (self-contained) OSL source shipped in shaders/<name>.osl."""
    path = SHADER_DIR / f"{name}.osl"
    if not path.is_file():
        raise FileNotFoundError(f"shader {name!r} is not in the add-on package ({path})")
    return path.read_text()


def cloudgen_executable() -> str | None:
    """The `cloudgen` CLI the user chose in the add-on's preferences (an explicit path, for
    Fit to Camera bakes and pipelines), or None: the add-on ships no executable and does
    not look on PATH. Bake to VDB bakes inside Blender without it (bake_local.py)."""
    from . import prefs  # noqa: PLC0415 - bpy-dependent; bridge itself has no bpy at import

    path = prefs.cli_path()
    if path and os.path.isfile(path) and os.access(path, os.X_OK):
        return path
    return None


_vdb = None


def openvdb():
    """Blender's OpenVDB Python module: `openvdb` (official builds and the bpy wheel 4.4+,
    after bpy.utils.expose_bundled_modules where it exists), `pyopenvdb` (official 3.5-4.3,
    and Debian's Blender with python3-openvdb); RuntimeError saying so when there is none."""
    global _vdb
    if _vdb is not None:
        return _vdb
    try:
        import bpy  # noqa: PLC0415

        expose = getattr(bpy.utils, "expose_bundled_modules", None)
        if expose is not None:
            expose()
    except Exception:  # noqa: BLE001 - only a hint for the import below
        pass
    problems = []
    for name in ("openvdb", "pyopenvdb"):
        try:
            mod = importlib.import_module(name)
        except Exception as exc:  # noqa: BLE001
            problems.append(f"{name}: {exc}")
            continue
        if hasattr(mod, "FloatGrid") and hasattr(mod, "write"):
            _vdb = mod
            return mod
        problems.append(f"{name}: not OpenVDB's Python module")
    raise RuntimeError("this Blender has no OpenVDB Python module (official Blender builds have it "
                       "since 3.5; on Linux distributions install python3-openvdb), so Bake to VDB "
                       "cannot write files here; bake with the cloudgen command-line tool instead "
                       "(docs/farm.md) — " + "; ".join(problems))


# ---------------------------------------------------------------- tiers, field key, the CLI
# tiers() and field_key() degrade to a one-line reason / None when the loaded
# module predates them (the add-on still registers and bakes).
def tiers() -> dict:
    """{name: {"label", "description", "render", "bake", "preview", "measured"}} in the
    core's order (Draft, Preview, Final); RuntimeError naming what is missing."""
    mod = require()
    if not hasattr(mod, "tiers"):
        raise RuntimeError("this cloudgen_native has no quality tiers (tiers()): update the add-on")
    return dict(mod.tiers())


def field_key(values: dict):
    """16 hex digits, equal for equal density fields; None when the core has no field_key()."""
    mod = native()
    if mod is None or not hasattr(mod, "field_key"):
        return None
    return str(mod.field_key(values))


_cli_checked = {}  # (executable, its modification time) -> None (it matches) or the problem


def cli_problem(executable):
    """None when this cloudgen CLI speaks the add-on's protocol (cli_events.PROTOCOL) and is
    the same release as the loaded cloudgen_native, else one line saying what differs.
    Asked once per session (`cloudgen --version --json`), again only when the file changes."""
    try:
        key = (str(executable), os.stat(executable).st_mtime_ns)
    except OSError as exc:
        return f"cannot run the cloudgen command-line tool {executable}: {exc.strerror}"
    if key not in _cli_checked:
        try:
            mod = require()
            if not hasattr(mod, "version"):
                raise RuntimeError("this cloudgen_native has no version(): reinstall the add-on")
            info = cli_events.cli_version(executable)
            cli_events.check_protocol(info, dict(mod.version()))
            _cli_checked[key] = None
        except (cli_events.ProtocolError, RuntimeError) as exc:
            _cli_checked[key] = str(exc)
    return _cli_checked[key]
