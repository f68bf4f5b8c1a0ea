"""The module loads in the Blender an artist downloads: it asks the dynamic linker
for nothing newer than glibc 2.28 (Blender's Linux baseline), needs no libstdc++
(linked in), and exports only its init function. Read from the module's ELF
dynamic section with objdump (binutils); exact checks."""
import pathlib
import re
import shutil
import subprocess

import cloudgen_native
import pytest

MODULE = pathlib.Path(cloudgen_native.__file__)
BASELINE = (2, 28)

pytestmark = pytest.mark.skipif(shutil.which("objdump") is None, reason="objdump (binutils) not installed")


def objdump(flag):
    return subprocess.run(["objdump", flag, str(MODULE)], capture_output=True, text=True, check=True).stdout


def test_no_glibc_symbol_newer_than_the_baseline():
    versions = set(re.findall(r"\(GLIBC_(\d+)\.(\d+)(?:\.\d+)?\)", objdump("-T")))
    assert versions, "no GLIBC symbol versions found: is this an ELF module?"
    newer = sorted((int(a), int(b)) for a, b in versions if (int(a), int(b)) > BASELINE)
    assert not newer, f"{MODULE.name} needs glibc {newer[-1]} > {BASELINE}: symbols " + ", ".join(
        ln.split()[-1] for ln in objdump("-T").splitlines() if any(f"GLIBC_{a}.{b}" in ln for a, b in newer))


def test_no_cxx_runtime_needed():
    needed = re.findall(r"NEEDED\s+(\S+)", objdump("-p"))
    assert not any(n.startswith("libstdc++") for n in needed), needed
    assert not re.search(r"\((GLIBCXX|CXXABI)_", objdump("-T")), "C++ runtime symbols are imported"
    assert set(needed) <= {"libc.so.6", "libm.so.6", "libgcc_s.so.1", "libpthread.so.0", "ld-linux-x86-64.so.2"}, needed


def test_only_the_init_function_is_exported():
    exported = [ln.split()[-1] for ln in objdump("-T").splitlines()
                if re.search(r"\s(g|w)\s", ln) and "*UND*" not in ln and ".text" in ln]
    assert exported == ["PyInit_cloudgen_native"], exported
