"""A private temporary folder for Cycles' OSL compiles.

Blender's Cycles add-on (cycles/osl.py, osl_compile) compiles a Script node's
shader into a `tempfile.NamedTemporaryFile(suffix=".oso", delete=False)` and
removes it only for external scripts: every internal Script node compiled
leaves one .oso in the system temp folder (three per cloud). Inside
`private_tempdir()` the tempfile module's folder is a fresh private one, and
it is removed with everything in it afterwards.

No bpy and no imports of the add-on's own modules: scripts/render_cloud.py
loads this file by its path.
"""
import contextlib
import shutil
import tempfile


@contextlib.contextmanager
def private_tempdir(prefix="cloudgen-osl-"):
    """tempfile.gettempdir() is a new private folder inside the block; the folder and
    what was written into it are removed on the way out (also on error)."""
    previous = tempfile.tempdir
    folder = tempfile.mkdtemp(prefix=prefix)
    tempfile.tempdir = folder
    try:
        yield folder
    finally:
        tempfile.tempdir = previous
        shutil.rmtree(folder, ignore_errors=True)
