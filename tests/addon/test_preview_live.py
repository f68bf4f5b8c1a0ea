"""The live preview follows slider changes through the depsgraph handler (in
background mode without a throttle timer: see addon/preview.py)."""
import cloudgen_native as cn
import numpy as np


def test_preview_follows_a_slider(addon, scene):
    import bpy

    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    obj = bpy.context.view_layer.objects.active
    first = addon.preview.state.values.copy()
    main, noise = addon.cloud_object.cloud_nodes(obj)
    noise.inputs["Seed"].default_value = 7
    bpy.context.view_layer.update()  # fires depsgraph_update_post, as a slider drag does
    got = addon.preview.state.values
    assert not np.array_equal(first, got)
    s = scene.cloudgen
    params = addon.cloud_object.params_from_object(obj)
    w, h = addon.preview.preview_size(params, s.preview_axis.lower(), s.preview_width)
    assert np.array_equal(got, cn.slice(params, s.preview_axis.lower(), s.preview_offset, w, h))
    # the axis and offset settings refresh it too
    s.preview_axis = "Z"
    assert addon.preview.state.values.shape == (s.preview_width, s.preview_width)  # 4 x 4 top view
    s.preview_live = False
    noise.inputs["Seed"].default_value = 8
    bpy.context.view_layer.update()
    assert np.array_equal(addon.preview.state.values,
                          cn.slice(dict(params, seed=7), "z", s.preview_offset, s.preview_width, s.preview_width))
    assert not bpy.app.timers.is_registered(addon.preview._timer)
