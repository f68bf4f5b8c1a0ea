"""Adding clouds leaves nothing in the temp folder. Blender's Cycles add-on
(cycles/osl.py) compiles an internal Script node into a temporary .oso that it
never removes; the add-on compiles (three Script nodes for the first cloud, two
for each further one) inside osl_temp.private_tempdir(). The process's temp folder is pointed at
an empty folder of the test's own (tempfile.tempdir), so other processes' files
cannot interfere. Exact: no file or folder may remain (tolerance 0)."""
import os
import tempfile

import pytest


def test_three_clouds_leave_no_oso(addon, scene, tmp_path, monkeypatch):
    import bpy
    from cloudgen import blender_nodes, cloud_object

    if not blender_nodes.osl_available():
        pytest.skip("this Blender has no OSL: nothing is compiled")
    systemp = tmp_path / "systemp"
    systemp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(systemp))
    clouds = [cloud_object.create_cloud(bpy.context, kind) for kind in ("cumulus", "stratus", "cirrus")]
    for cloud in clouds:
        main = cloud.active_material.node_tree.nodes["Cloud Main"].node_tree
        assert main.nodes["Group Output"].inputs["Density"].is_linked, f"{cloud.name}: not compiled"
    left = sorted(os.path.relpath(os.path.join(d, f), systemp)
                  for d, dirs, files in os.walk(systemp) for f in files + dirs)
    assert left == [], f"left in the temp folder: {left}"
    assert tempfile.tempdir == str(systemp), "the private folder was not given back"
