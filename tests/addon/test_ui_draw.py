"""The panels' draw code runs (with a recording stand-in for UILayout: background
mode has no region to draw in) and shows the status lines, sliders and preview."""
import types


class FakeLayout:
    def __init__(self, log):
        self.log = log

    def _child(self, *a, **k):
        return FakeLayout(self.log)

    row = column = box = split = _child

    def label(self, text="", icon="NONE"):
        self.log.append(("label", text))

    def prop(self, data, prop, **k):
        getattr(data, prop)  # the property exists
        self.log.append(("prop", k.get("text", prop)))

    def operator(self, idname, **k):
        self.log.append(("operator", idname))
        return types.SimpleNamespace()

    def template_icon(self, icon_value=0, scale=1.0):
        self.log.append(("icon", icon_value))

    def template_curve_mapping(self, data, prop, **k):
        getattr(data, prop)
        self.log.append(("curve", prop))


def draw(cls, context):
    log = []
    panel = types.SimpleNamespace(layout=FakeLayout(log), group=getattr(cls, "group", ""))
    if hasattr(cls, "params"):
        panel.params = types.MethodType(cls.params, panel)
    if hasattr(cls, "poll") and not cls.poll(context):
        return None
    cls.draw(panel, context)
    return log


def test_panels_draw(addon, scene):
    import bpy

    ui = addon.ui
    log = draw(ui.CLOUDGEN_PT_main, bpy.context)
    assert ("operator", "cloudgen.add_cloud") in log and ("operator", "cloudgen.render_settings") in log
    assert draw(ui.CLOUDGEN_PT_preview, bpy.context) is None  # no cloud yet
    bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    main = draw(ui.CLOUDGEN_PT_cloud_main, bpy.context)
    assert ("prop", "Density") in main and ("curve", "mapping") in main
    noise = draw(ui.CLOUDGEN_PT_cloud_noise, bpy.context)
    assert ("prop", "Worley Influence") in noise
    # every slider has a "?" whose tooltip is the declared help (the slider's own tooltip is Blender's)
    helps = [e for e in main + noise if e == ("operator", "cloudgen.parameter_help")]
    sliders = [e for e in main + noise if e[0] == "prop" and e[1] not in ("mapping", "cloudgen_shape_source")]
    assert len(helps) >= len(sliders) > 0, (len(helps), sliders)
    help_op = bpy.types.CLOUDGEN_OT_parameter_help
    for p in addon.bridge.parameters():
        text = help_op.help_text(p["name"])
        assert text.startswith(p["label"] + ": ") and not text.endswith("."), (p["name"], text)
        assert help_op.description(bpy.context, types.SimpleNamespace(name=p["name"])) == text
    anim = draw(ui.CLOUDGEN_PT_animation, bpy.context)
    assert ("prop", "Time") in anim and ("operator", "cloudgen.time_from_frame") in anim
    prev = draw(ui.CLOUDGEN_PT_preview, bpy.context)
    assert ("prop", "preview_axis") in prev
    assert not [e for e in prev if e[0] == "label"]  # no error shown
    scene.cycles.shading_system = False
    log = draw(ui.CLOUDGEN_PT_main, bpy.context)
    assert any(kind == "label" and "baked VDB" in text for kind, text in log)


def test_panel_shows_import_error(addon, monkeypatch):
    import bpy

    monkeypatch.setattr(addon.bridge, "_error", "cloudgen native module unavailable — test")
    log = draw(addon.ui.CLOUDGEN_PT_main, bpy.context)
    first = []
    for kind, text in log:   # the line, wrapped to the sidebar's width
        if kind != "label":
            break
        first.append(text)
    assert " ".join(first).startswith("cloudgen native module unavailable — test"), log
