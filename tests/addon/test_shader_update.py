"""A .blend made with another cloudgen carries that version's shaders: their text and compiled
bytecode travel in the file, and a Script node renders from its bytecode. Opened with this
add-on, the groups are brought to its model on load (checks.on_load_post ->
nodes.update_shaders), so that a procedural render matches what a bake of the same cloud gives
now. Exact: the text equals this add-on's flattened source and the bytecode equals a fresh
compile of it (but for the compile's temporary file name, which the .oso records); a current
file is left as it is."""
import re

SOFT = "cg_anvil_edge_width(cg_edge_width(edge_sharpness), hl, anvil, anvil_height, top_height)"
CRISP = "cg_edge_width(edge_sharpness)"  # Cloud Main before 2026-11-29: the anvil kept the crisp edge


def _cloud_main_group():
    import bpy

    return next(ng for ng in bpy.data.node_groups
                if ng.get("cloudgen_version") is not None and "cloud_main" in ng.nodes)


def _code(bytecode):
    """The .oso without what names the compile's temporary file: its comment lines (the
    compiler's command line) and the %filename{...} hints."""
    return [re.sub(r'%filename\{"[^"]*"\}', "", line) for line in bytecode.splitlines() if not line.startswith("#")]


def _reopen_as_older(nodes, tmp_path, file_name):
    """Drop every group's shader key (as a cloudgen before the key wrote none), save a copy and open
    it: the add-on's load_post handler runs on it."""
    import bpy

    for ng in bpy.data.node_groups:
        if nodes.SHADERS_KEY in ng:
            del ng[nodes.SHADERS_KEY]
    blend = tmp_path / file_name
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    bpy.ops.wm.open_mainfile(filepath=str(blend))


def test_an_older_models_shaders_are_updated_on_load(addon, scene, tmp_path):
    import bpy
    from cycles import osl as cycles_osl

    nodes = addon.nodes
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulonimbus")
    group = _cloud_main_group()
    node = group.nodes["cloud_main"]
    current, fresh = node.script.as_string(), _code(node.bytecode)
    assert SOFT in current, "the test's older model no longer differs from this one"
    # make the file an older cloudgen's: its Cloud Main compiled from the crisp anvil, no key recorded
    node.script.clear()
    node.script.write(current.replace(SOFT, CRISP))
    assert cycles_osl.update_script_node(node, lambda *_: None)
    assert _code(node.bytecode) != fresh
    name = group.name
    _reopen_as_older(nodes, tmp_path, "older.blend")
    node = bpy.data.node_groups[name].nodes["cloud_main"]
    assert node.script.as_string() == current, "the shader text was not brought to this model"
    assert _code(node.bytecode) == fresh, "the Script node still renders an older model's bytecode"
    assert "Density" in node.outputs and node.outputs["Density"].is_linked, "recompiled but not linked"
    assert nodes.outdated_groups() == [], [ng.name for ng in nodes.outdated_groups()]


def test_a_current_file_is_left_as_it_is(addon, scene, tmp_path):
    import bpy

    nodes = addon.nodes
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    before = {ng.name: ng.get(nodes.SHADERS_KEY) for ng in bpy.data.node_groups}
    assert set(before.values()) == {nodes.shader_sources_key()}, before
    assert nodes.update_shaders() == []
    blend = tmp_path / "current.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    bytecode = _cloud_main_group().nodes["cloud_main"].bytecode  # not recompiled: the same to the byte
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    assert nodes.update_shaders() == []
    assert _cloud_main_group().nodes["cloud_main"].bytecode == bytecode


def test_a_group_from_before_a_new_parameter_gains_its_socket_on_load(addon, scene, tmp_path):
    """A Cloud Main made before Anvil Fibres existed (no socket, a shader without the input): on
    load the group gains the socket at its default 0 (the older file's smooth anvil), in the
    Cloud Main panel where Blender has panels, linked to the recompiled shader's input."""
    import bpy
    from cycles import osl as cycles_osl

    nodes = addon.nodes
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulonimbus")
    group = _cloud_main_group()
    node = group.nodes["cloud_main"]
    current = node.script.as_string()
    older = re.sub(r"\n    float anvil_fibres = 0\.0\n        \[\[[^\n]*\]\],", "", current)
    assert older != current, "the test no longer finds Cloud Main's Anvil Fibres input"
    older = re.sub(r"\banvil_fibres\);", "0.0);", older)  # the shader's one use (the header's are kept)
    node.script.clear()
    node.script.write(older)
    assert cycles_osl.update_script_node(node, lambda *_: None)
    assert "anvil_fibres" not in node.inputs
    item = next(i for i in group.interface.items_tree if i.item_type == "SOCKET" and i.name == "Anvil Fibres")
    group.interface.remove(item)
    name = group.name
    _reopen_as_older(nodes, tmp_path, "before_anvil_fibres.blend")
    group = bpy.data.node_groups[name]
    node = group.nodes["cloud_main"]
    assert node.script.as_string() == current
    sockets = [i for i in group.interface.items_tree if i.item_type == "SOCKET" and i.name == "Anvil Fibres"]
    assert len(sockets) == 1, [i.name for i in group.interface.items_tree]
    assert sockets[0].parent.name == "Cloud Main", sockets[0].parent.name
    assert node.inputs["anvil_fibres"].is_linked, "the new input is not wired to the group's socket"
    users = [n for m in bpy.data.materials if m.node_tree for n in m.node_tree.nodes
             if n.bl_idname == "ShaderNodeGroup" and n.node_tree == group]
    assert users and all(n.inputs["Anvil Fibres"].default_value == 0.0 for n in users)
    assert nodes.outdated_groups() == [], [ng.name for ng in nodes.outdated_groups()]
