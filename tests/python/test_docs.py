"""The parameter table in docs/model.md is generated from the declarations; it must not drift."""
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_model_doc_parameter_table_matches_declarations():
    # exact text comparison: any drift of a name, default, range, unit or help fails
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_param_docs.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
