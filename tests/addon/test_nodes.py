"""Node groups: sockets equal the declarations; the Shape Gradient curve and the
core's piecewise-linear profile are the same curve; animation parameters are
keyframable and Time can follow the frame."""
import numpy as np
import pytest


@pytest.fixture
def cloud(scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    return bpy.context.view_layer.objects.active


def test_group_sockets_equal_declarations(addon, cloud):
    """Names (labels), types, defaults and ranges: the socket's min/max are the declared
    soft range (Blender treats group-socket limits as soft ones); floats whose soft
    range is [0, 1] are FACTOR sliders. Defaults compared at float32 precision."""
    import bpy
    import cloudgen_native as cn

    nodes = addon.nodes
    main, noise = addon.cloud_object.cloud_nodes(cloud)
    for group, node in ((nodes.MAIN_GROUP, main), (nodes.NOISE_GROUP, noise)):
        decl = nodes.group_parameters(group)
        socks = {s.name: s for s in nodes.group_sockets(node.node_tree)}
        extra = {nodes.DISTORTION_NOISE} if group == nodes.MAIN_GROUP else set()
        assert set(socks) == {p["label"] for p in decl} | extra, group
        for p in decl:
            s = socks[p["label"]]
            want_type, want_sub = nodes.socket_kind(p)
            if bpy.app.version >= (4, 0, 0):
                assert (s.socket_type, getattr(s, "subtype", "NONE")) == (want_type, want_sub), p["name"]
            else:
                assert s.bl_socket_idname == want_type + ("Factor" if want_sub == "FACTOR" else ""), p["name"]
            assert s.min_value == pytest.approx(p["soft_min"], rel=1e-6), p["name"]
            assert s.max_value == pytest.approx(p["soft_max"], rel=1e-6), p["name"]
            d = s.default_value
            got = list(d) if p["kind"] == "vector" else [d]
            want = p["default"] if p["kind"] == "vector" else [p["default"]]
            assert np.allclose(got, want, rtol=1e-6, atol=0), p["name"]
    # every declared parameter is reachable: a socket, the curve, or the box (driven by the object)
    covered = {p["name"] for g in (nodes.MAIN_GROUP, nodes.NOISE_GROUP) for p in nodes.group_parameters(g)}
    assert covered | {"shape_curve"} == {p["name"] for p in cn.parameters()}
    if bpy.app.version >= (4, 0, 0):  # grouped in interface panels
        panels = [it.name for it in noise.node_tree.interface.items_tree if it.item_type == "PANEL"]
        assert panels == ["Noise", "Animation", "Box"]


def test_instance_values_are_the_preset(addon, cloud):
    import cloudgen_native as cn

    values = addon.cloud_object.params_from_object(cloud)
    want = cn.resolve_params({"preset": "cumulus"})
    for k, v in want.items():
        assert np.allclose(values[k], v, rtol=1e-6, atol=1e-7), k


def test_shape_curve_is_the_native_piecewise_linear_curve(addon, cloud):
    """curve_mapping.evaluate at the 17 heights and the 16 midpoints equals linear
    interpolation of the preset's samples (what the core does, docs/model.md) to 1e-6;
    an edited curve reaches params_from_object and changes the preview."""
    import cloudgen_native as cn

    main, _ = addon.cloud_object.cloud_nodes(cloud)
    samples = cn.resolve_params({"preset": "cumulus"})["shape_curve"]
    got = addon.nodes.shape_curve_samples(main.node_tree)
    assert np.allclose(got, samples, atol=1e-6)
    node = main.node_tree.nodes[addon.nodes.CURVE_NODE]
    mapping = node.mapping
    mapping.initialize()
    xs = np.linspace(0, 1, 33)
    evaluated = [mapping.evaluate(mapping.curves[0], float(x)) for x in xs]
    assert np.allclose(evaluated, np.interp(xs, np.linspace(0, 1, 17), samples), atol=1e-6)

    import bpy

    assert bpy.ops.cloudgen.refresh_preview() == {"FINISHED"}
    before = addon.preview.state.values.copy()
    mapping.curves[0].points[8].location = (0.5, 0.2)  # pinch the waist
    mapping.update()
    after_samples = addon.nodes.shape_curve_samples(main.node_tree)
    assert after_samples[8] == pytest.approx(0.2, abs=1e-6)
    assert addon.cloud_object.params_from_object(cloud)["shape_curve"][8] == pytest.approx(0.2, abs=1e-6)
    bpy.ops.cloudgen.refresh_preview()
    assert not np.array_equal(before, addon.preview.state.values)


def test_animation_keyframes_and_time_from_frame(addon, cloud, scene):
    import bpy

    mat = cloud.active_material
    _, noise = addon.cloud_object.cloud_nodes(cloud)
    for label in ("Wind Strength", "Wind Direction", "Stationary", "Time", "Evolution"):
        assert noise.inputs[label].keyframe_insert("default_value", frame=1), label
    noise.inputs["Wind Strength"].default_value = 0.8
    noise.inputs["Wind Strength"].keyframe_insert("default_value", frame=10)
    scene.frame_set(10)
    assert noise.inputs["Wind Strength"].default_value == pytest.approx(0.8)
    scene.frame_set(1)
    assert noise.inputs["Wind Strength"].default_value == pytest.approx(0.0)

    noise.inputs["Time"].driver_remove("default_value")  # the keyframes of Time give way
    mat.node_tree.animation_data.action = None
    assert bpy.ops.cloudgen.time_from_frame(enable=True) == {"FINISHED"}
    assert addon.nodes.time_follows_frame(mat)
    scene.render.fps, scene.render.fps_base = 24, 1.0
    scene.frame_set(48)
    assert noise.inputs["Time"].default_value == pytest.approx(2.0)
    assert addon.cloud_object.params_from_object(cloud)["time"] == pytest.approx(2.0)
    bpy.ops.cloudgen.time_from_frame(enable=False)
    assert not addon.nodes.time_follows_frame(mat)


def test_box_follows_the_object(addon, cloud, scene):
    """Box Size and Object Location sockets are driven by the object (what the shader sees)
    and params_from_object reads the object itself."""
    _, noise = addon.cloud_object.cloud_nodes(cloud)
    cloud.scale = (3.0, 2.0, 1.0)
    cloud.location = (10.0, -4.0, 2.5)
    scene.frame_set(scene.frame_current)
    assert tuple(noise.inputs["Box Size"].default_value) == pytest.approx((3.0, 2.0, 1.0))
    assert tuple(noise.inputs["Object Location"].default_value) == pytest.approx((10.0, -4.0, 2.5))
    values = addon.cloud_object.params_from_object(cloud)
    assert values["box_size"] == pytest.approx([3.0, 2.0, 1.0])
    assert values["object_location"] == pytest.approx([10.0, -4.0, 2.5])
