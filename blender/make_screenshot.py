# Screenshot of Blender's UI after an osr-vk render, for docs/blender.md (there scaled to
# 1280 x 720 and saved as JPEG). Needs a display
# (Blender cannot draw its UI headless); on a machine without one, under Xvfb (a .blend file
# on the command line keeps the splash screen away):
#   blender -b --factory-startup --python-expr \
#       "import bpy; bpy.ops.wm.save_as_mainfile(filepath='/tmp/empty.blend')"
#   xvfb-run -s "-screen 0 1600x900x24" blender --factory-startup /tmp/empty.blend \
#       --python blender/make_screenshot.py -- build/osr-vk shot.png
# Builds the test scene of tests/blender, renders it with the osr-vk engine (One Shot
# Radiance), shows the result in an image editor beside the osr-vk render panel, saves the
# screenshot and quits.
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests", "blender"))
import blender_scene  # noqa: E402

executable, output = [os.path.abspath(a) for a in sys.argv[sys.argv.index("--") + 1:][:2]]


def largest_area(screen, kind):
    areas = [a for a in screen.areas if a.type == kind]
    return max(areas, key=lambda a: a.width * a.height) if areas else None


def render_and_show():
    window = bpy.context.window_manager.windows[0]
    scene = bpy.context.scene
    with bpy.context.temp_override(window=window):
        bpy.ops.render.render()
    screen = window.screen
    view3d = largest_area(screen, "VIEW_3D")
    view3d.type = "IMAGE_EDITOR"
    view3d.spaces.active.image = bpy.data.images["Render Result"]
    props = largest_area(screen, "PROPERTIES")
    props.spaces.active.context = "RENDER"
    print("osr-vk screenshot: rendered", scene.render.resolution_x, scene.render.resolution_y)
    bpy.app.timers.register(fit, first_interval=1.0)


def fit():  # once the new image editor has been drawn at its size
    window = bpy.context.window_manager.windows[0]
    editor = largest_area(window.screen, "IMAGE_EDITOR")
    region = next(r for r in editor.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=window, area=editor, region=region):
        bpy.ops.image.view_all(fit_view=True)
    bpy.app.timers.register(shoot, first_interval=1.0)


def shoot():
    window = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=window, area=window.screen.areas[0]):
        bpy.ops.screen.screenshot(filepath=output)
    print("osr-vk screenshot: wrote", output)
    bpy.ops.wm.quit_blender()


def start():
    window = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=window, area=largest_area(window.screen, "VIEW_3D")):
        scene = blender_scene.build_scene(executable, 400, 300, reset=False)
    scene.osr_vk.mode, scene.osr_vk.passes, scene.osr_vk.time_limit = "osr", 32, 120.0
    bpy.app.timers.register(render_and_show, first_interval=1.0)


bpy.app.timers.register(start, first_interval=1.0)
