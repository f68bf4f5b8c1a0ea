"""Names a person types (issue: artists see "Cumulus" in Blender): presets and tiers ignore
case, a mistyped preset, tier, parameter, option or command gets a "did you mean", and no
message carries the JSON library's exception tag. Exact substrings; one stderr line each."""
import cloudgen_native as cn
import pytest
from test_cli import expect_usage_error, run


def test_preset_and_tier_names_ignore_case(out_dir):
    r = run("bake", "--preset", "Cumulus", "--quality", "Draft", "--resolution", 8, "--output", out_dir / "c.vdb",
            "--quiet")
    assert r.returncode == 0, r.stderr
    assert cn.field_key({"preset": "CUMULUS"}) == cn.field_key({"preset": "cumulus"})


@pytest.mark.parametrize("args,words", [
    (("bake", "--preset", "cumulos"), ["--preset 'cumulos'", "did you mean 'cumulus'?"]),
    (("bake", "--preset", "cumulus", "--quality", "drafts"), ["--quality 'drafts'", "did you mean 'draft'?"]),
    (("bake", "--preset", "cumulus", "--resolutoin", "8"), ["--resolutoin", "did you mean '--resolution'?"]),
    (("bak",), ["unknown command 'bak'", "did you mean 'bake'?"]),
])
def test_did_you_mean(args, words, out_dir):
    expect_usage_error(run(*args, "--output", out_dir / "x.vdb"), *words)


def test_parameter_file_typos_and_json_errors(params_file, out_dir):
    r = run("bake", "--params", params_file('{"densty": 1}'), "--resolution", 8, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "unknown parameter 'densty'", "did you mean 'density'?")
    r = run("bake", "--params", params_file('{"density": 1,}'), "--resolution", 8, "--output", out_dir / "x.vdb")
    expect_usage_error(r, "not valid JSON", "line 1")
    assert "json.exception" not in r.stderr, r.stderr
    with pytest.raises(ValueError, match="did you mean 'noise_detail'"):
        cn.field_key({"noise_detial": 3})
    with pytest.raises(ValueError, match="did you mean 'stratus'"):
        cn.field_key({"preset": "stratos"})
