"""Screenshot of Blender's real interface with the cloudgen add-on: the Shading
workspace with a cumulus, its material's node tree (Cloud Noise → Cloud Main)
in the shader editor and the Cloud tab of the 3D view's sidebar with the live
preview. Run by scripts/screenshot_ui.sh under Xvfb (Debian's Blender 3.4,
software OpenGL). Args after `--`: OUTPUT.png [TAB_X TAB_Y]: where to click
to open the Cloud tab (found once by looking; see the .sh)."""
import subprocess
import sys

import addon_utils
import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
OUTPUT = argv[0]
BAKE_PATH = OUTPUT + ".cumulus.vdb"
CLICK = (int(argv[1]), int(argv[2])) if len(argv) >= 3 else None
SCROLL = int(argv[3]) if len(argv) >= 4 else 0

addon_utils.enable("cloudgen", default_set=True)
for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob)
window = bpy.context.window_manager.windows[0]
window.workspace = bpy.data.workspaces["Shading"]


def areas(kind):
    return [a for a in window.screen.areas if a.type == kind]


def setup():
    with bpy.context.temp_override(window=window, area=areas("VIEW_3D")[0]):
        bpy.ops.cloudgen.add_cloud(cloud_type="cumulus")
    cloud = bpy.context.view_layer.objects.active
    # bake it (small) so the 3D view shows the cloud: Debian's 3.4 has no OSL
    # for the procedural material, and a Volume object draws in solid mode
    with bpy.context.temp_override(window=window, area=areas("VIEW_3D")[0]):
        bpy.ops.cloudgen.bake_vdb("EXEC_DEFAULT", filepath=BAKE_PATH, resolution=64)
    bpy.context.view_layer.objects.active = cloud
    cloud.select_set(True)
    for area in areas("VIEW_3D"):
        space = area.spaces.active
        space.show_region_ui = True
        space.shading.type = "SOLID"
        with bpy.context.temp_override(window=window, area=area,
                                       region=[r for r in area.regions if r.type == "WINDOW"][0]):
            bpy.ops.view3d.view_selected()
    print("cloud", cloud.name)
    for area in areas("VIEW_3D"):
        for r in area.regions:
            if r.type == "UI":
                print(f"sidebar region x={r.x} y={r.y} w={r.width} h={r.height} window_h={window.height}")
    return None


def frame_nodes():
    # after a redraw the shader editor shows the cloud's material
    for area in areas("NODE_EDITOR"):
        region = [r for r in area.regions if r.type == "WINDOW"][0]
        with bpy.context.temp_override(window=window, screen=window.screen, area=area, region=region,
                                       space_data=area.spaces.active):
            print("node editor tree:", area.spaces.active.edit_tree, bpy.ops.node.view_all.poll())
            if bpy.ops.node.view_all.poll():
                bpy.ops.node.view_all()
    return None


def click():
    if CLICK:
        x, y = CLICK
        # move first, let Blender see the hover, then click
        subprocess.run(["xdotool", "mousemove", str(x), str(y), "sleep", "0.5", "click", "1"], check=False)
    return None


def scroll_sidebar():
    # the preview sits below the sliders and the curve: scroll the sidebar to it
    area = areas("VIEW_3D")[0]
    region = [r for r in area.regions if r.type == "UI"][0]
    with bpy.context.temp_override(window=window, screen=window.screen, area=area, region=region):
        for _ in range(SCROLL // 40):
            if bpy.ops.view2d.scroll_down.poll():
                bpy.ops.view2d.scroll_down(deltax=0, deltay=40, page=False)
    # and the preview image in the workspace's image editor too
    preview = bpy.data.images.get("Cloud Preview")
    for area in areas("IMAGE_EDITOR"):
        area.spaces.active.image = preview
        region = [r for r in area.regions if r.type == "WINDOW"][0]
        with bpy.context.temp_override(window=window, screen=window.screen, area=area, region=region):
            if bpy.ops.image.view_all.poll():
                bpy.ops.image.view_all(fit_view=True)
    return None


def shoot():
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=OUTPUT)
    print("screenshot", OUTPUT)
    import os

    os.remove(BAKE_PATH) if os.path.exists(BAKE_PATH) else None
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(setup, first_interval=3.0)
bpy.app.timers.register(frame_nodes, first_interval=5.0)
bpy.app.timers.register(click, first_interval=7.0)
bpy.app.timers.register(scroll_sidebar, first_interval=9.0)
bpy.app.timers.register(shoot, first_interval=12.0)
