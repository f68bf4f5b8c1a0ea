"""Lint: our OSL sources use no builtin noise (OptiX has no "simplex", "cell" or
"gabor" noise, and C++ cannot reproduce OSL's builtins bit for bit), and every
shader source is self-contained once flattened. Plain Python, no Blender."""
import pathlib
import re

import flatten

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = sorted((ROOT / "osl").glob("*.osl")) + sorted((ROOT / "native/include/cloudgen/shared").glob("*.h"))
# any call of a builtin noise function, whatever its name argument
BUILTIN_NOISE = re.compile(r'\b(noise|snoise|pnoise|psnoise|cellnoise|hashnoise)\s*\(')
FORBIDDEN_NAMES = re.compile(r'"(simplex|usimplex|cell|gabor|perlin|uperlin|hash)"')


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def test_sources_exist():
    names = {p.name for p in SOURCES}
    assert {"cloud_noise.osl", "cloud_main.osl", "cloud_height.osl", "noise.h", "cloud_model.h"} <= names


def test_no_builtin_noise_in_osl_or_shared_model():
    offenders = []
    for path in SOURCES:
        code = strip_comments(path.read_text())
        for rx in (BUILTIN_NOISE, FORBIDDEN_NAMES):
            for m in rx.finditer(code):
                line = code[: m.start()].count("\n") + 1
                offenders.append(f"{path.relative_to(ROOT)}:{line}: {m.group(0)}")
    assert not offenders, "builtin noise used:\n" + "\n".join(offenders)


def test_flattened_shaders_have_no_includes_left():
    for name in flatten.SHADERS:
        text = flatten.shader_source(name)
        assert "#include \"" not in strip_comments(text), name  # the C++ branch keeps <cmath>
        assert f"shader {name}(" in text, name
