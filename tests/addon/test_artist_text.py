"""Artist-facing text (issue 12, finding 7), in the 4.5 wheel: descriptions carry the
declared help without a trailing period (Blender adds one; "..") — group sockets,
operator and property descriptions; Shape Source is a named choice in the sidebar
(Exponent / Gradient Curve, writing the socket); Wind Direction's fields are labelled
(XYZ subtype); the driven Box Size / Object Location inputs are hidden on the group
node; every sidebar label fits the default sidebar width (panel.DEFAULT_CHARS
characters); tier tooltips speak time and look, not FLIP/RMSE."""
import re

from test_ui_draw import draw


def _registered(addon):
    return list(addon._registered)


def test_descriptions_have_no_trailing_period(addon):
    """Our operators' descriptions (docstrings) and every property we declare."""
    import bpy

    bad = []
    for cls in _registered(addon):
        rna = getattr(cls, "bl_rna", None)
        if rna is None:
            continue
        if issubclass(cls, bpy.types.Operator) and rna.description.rstrip().endswith("."):
            bad.append(f"{cls.__name__}: {rna.description[-40:]!r}")
        for name in getattr(cls, "__annotations__", {}):
            prop = rna.properties.get(name)
            if prop is not None and prop.description.rstrip().endswith("."):
                bad.append(f"{cls.__name__}.{name}: {prop.description[-40:]!r}")
    assert not bad, "descriptions ending in '.' (Blender adds one):\n" + "\n".join(bad)


def test_group_sockets_carry_the_declared_help(addon, scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    cloud = bpy.context.view_layer.objects.active
    main, noise = addon.cloud_object.cloud_nodes(cloud)
    declared = {p["label"]: p for p in addon.bridge.parameters()}
    problems = []
    for node in (main, noise):
        for item in addon.nodes.group_sockets(node.node_tree):
            p = declared.get(item.name)
            if p is None:
                continue
            want = p["help"].rstrip().rstrip(".")
            if item.description != want[:255]:
                problems.append(f"{item.name}: {item.description[:50]!r} != {want[:50]!r}")
    assert not problems, "\n".join(problems)


def test_shape_source_is_a_named_choice(addon, scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    cloud = bpy.context.view_layer.objects.active
    main, _ = addon.cloud_object.cloud_nodes(cloud)
    cloud.cloudgen_shape_source = "EXPONENT"
    assert main.inputs["Shape Source"].default_value == 0
    cloud.cloudgen_shape_source = "CURVE"
    assert main.inputs["Shape Source"].default_value == 1
    log = draw(addon.ui.CLOUDGEN_PT_cloud_main, bpy.context)
    assert ("prop", "cloudgen_shape_source") in log and ("label", "Shape Source:") in log
    items = [i.identifier for i in cloud.bl_rna.properties["cloudgen_shape_source"].enum_items]
    assert items == ["EXPONENT", "CURVE"], items


def test_wind_axes_labelled_and_driven_sockets_hidden(addon, scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    cloud = bpy.context.view_layer.objects.active
    _, noise = addon.cloud_object.cloud_nodes(cloud)
    assert noise.inputs["Wind Direction"].bl_idname == "NodeSocketVectorXYZ", noise.inputs["Wind Direction"].bl_idname
    for label in ("Box Size", "Object Location"):
        assert noise.inputs[label].hide, f"{label} is driven and must be hidden"
    assert not noise.inputs["Wind Strength"].hide


def test_sidebar_lines_fit_the_default_width(addon, scene, tmp_path):
    import bpy

    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "w.blend"))
    bpy.ops.cloudgen.add_cloud(cloud_type="stratocumulus")
    scene.render.engine = "BLENDER_WORKBENCH"      # the long "no procedural render" status line
    tiers = list(addon.quality.tiers())
    scene.cloudgen.quality = tiers[0]
    scene.cycles.samples = 3                        # "Changed by hand: ..."
    assert bpy.ops.cloudgen.bake_vdb(resolution=8) == {"FINISHED"}
    limit = addon.panel.DEFAULT_CHARS
    too_long = []
    for cls in [c for c in _registered(addon) if getattr(c, "bl_space_type", "") == "VIEW_3D"]:
        for kind, text in draw(cls, bpy.context) or []:
            if kind == "label" and len(text) > limit:
                too_long.append(f"{cls.__name__}: {len(text)} > {limit}: {text!r}")
    assert not too_long, "\n".join(too_long)


def test_tier_tooltips_speak_time_and_look(addon):
    for name, tier in addon.quality.tiers().items():
        tip = addon.quality.tier_tooltip(tier)
        assert "FLIP" not in tip and "RMSE" not in tip, f"{name}: {tip}"
        if tier.get("measured"):
            assert " s" in tip and any(words in tip for _, words in addon.quality.LOOKS), f"{name}: {tip}"
            # a render time means little without the image size, and a figure measured on an
            # earlier preset is told by its date (bench/accuracy/tiers_update.py writes both)
            assert " px, " in tip and re.search(r"\b20\d\d-\d\d-\d\d\b", tip), f"{name}: {tip}"
