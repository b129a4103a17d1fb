# Run inside Blender (tests/blender/*): enables the osr-vk add-on from this checkout and builds
# the test scene by script: a 4 m box room open to the camera, an area light under the
# ceiling, a copper-coloured sphere and a red and a green wall (an asymmetric scene, so a flipped
# or mirrored image cannot pass), at a small size for lavapipe.
import math
import os
import sys

import addon_utils
import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def enable_addon(executable, from_checkout=True):
    """Enables osr_vk from this checkout (or, from_checkout False, the installed one)."""
    blender_dir = os.path.join(REPO, "blender")
    if from_checkout and blender_dir not in sys.path:
        sys.path.insert(0, blender_dir)
    addon_utils.enable("osr_vk", default_set=True, handle_error=None)
    if "osr_vk" not in bpy.context.preferences.addons:
        raise SystemExit("the osr_vk add-on did not enable")
    bpy.context.preferences.addons["osr_vk"].preferences.executable = executable


def _material(name, color, emission=None):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Specular"].default_value = 0.0
    return mat


def _plane(name, location, rotation, size, mat):
    bpy.ops.mesh.primitive_plane_add(size=1, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.scale = (size[0], size[1], 1)
    obj.name = name
    obj.data.materials.append(mat)
    return obj


def build_scene(executable, width=96, height=72, from_checkout=True, reset=True):
    """An empty file with the add-on enabled (osr-vk at `executable`) and the test scene.
    reset False: in the open file instead, after deleting its objects (Blender's UI, whose
    window a factory reset would replace)."""
    if reset:
        bpy.ops.wm.read_factory_settings(use_empty=True)  # also disables add-ons: enable after
    else:
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
    enable_addon(executable, from_checkout)
    scene = bpy.context.scene
    white = _material("white", (0.8, 0.8, 0.8))
    red = _material("red", (0.8, 0.1, 0.1))
    green = _material("green", (0.1, 0.7, 0.1))
    # A closed room, x in [-2, 2], y in [-3, 2], z in [0, 4]; the camera inside it looks +y.
    # Planes face +Z before rotation; each is turned to face the inside.
    _plane("floor", (0, -0.5, 0), (0, 0, 0), (4, 5), white)
    _plane("ceiling", (0, -0.5, 4), (math.pi, 0, 0), (4, 5), white)
    _plane("back", (0, 2, 2), (math.pi / 2, 0, 0), (4, 4), white)
    _plane("front", (0, -3, 2), (-math.pi / 2, 0, 0), (4, 4), white)
    _plane("left", (-2, -0.5, 2), (0, math.pi / 2, 0), (4, 5), red)
    _plane("right", (2, -0.5, 2), (0, -math.pi / 2, 0), (4, 5), green)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0.6, 0.6, 0.6), segments=48, ring_count=24)
    sphere = bpy.context.active_object
    sphere.name = "sphere"
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(_material("copper", (0.9, 0.5, 0.3)))
    bpy.ops.object.light_add(type="AREA", location=(0, 0, 3.95))
    light = bpy.context.active_object
    light.name = "ceiling light"
    light.data.shape = "RECTANGLE"
    light.data.size, light.data.size_y = 1.2, 0.8
    light.data.energy = 80.0
    bpy.ops.object.camera_add(location=(0, -2.9, 2.0), rotation=(math.pi / 2, 0, 0))
    cam = bpy.context.active_object
    cam.data.lens = 18
    scene.camera = cam
    scene.render.engine = "OSR_VK"
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.world = bpy.data.worlds.new("world")
    scene.world.color = (0.0, 0.0, 0.0)
    return scene
