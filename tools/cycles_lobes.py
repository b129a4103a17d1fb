"""Cycles reference of a scenes/lobes glTF, imported by Blender's own glTF importer.

blender -b --factory-startup --python tools/cycles_lobes.py -- SCENE.gltf OUT.exr SPP [MODE]
128 x 128, Blackman-Harris filter of width 1 px (as scenes/README.md), 64 bounces, black world.
Blender 3.4's importer does not know KHR_materials_diffuse_transmission or _anisotropy; for
those the Principled BSDF is set up here from the glTF (Translucent BSDF mixed in by the factor;
Principled anisotropy with alpha_x, alpha_y equal to the extension's alpha_t, alpha_b).
MODE "matched" also rewrites what the importer maps differently from the glTF definition
(Volume Absorption: Cycles absorbs density * (1 - colour), glTF -log(colour) / distance).
"""
import json
import math
import sys

import bpy
import numpy

# Blender 3.4's glTF importer still uses numpy.bool, which numpy 1.24 removed.
numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
scene_path, out_path, spp = argv[0], argv[1], int(argv[2])
mode = argv[3] if len(argv) > 3 else "import"
gltf = json.load(open(scene_path))

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_path)
sc = bpy.context.scene
sc.render.engine = "CYCLES"
sc.cycles.device = "CPU"
sc.cycles.samples = spp
sc.cycles.use_adaptive_sampling = False
sc.cycles.use_denoising = False
sc.cycles.max_bounces = sc.cycles.diffuse_bounces = sc.cycles.glossy_bounces = 64
sc.cycles.transmission_bounces = sc.cycles.volume_bounces = sc.cycles.transparent_max_bounces = 64
sc.cycles.sample_clamp_direct = sc.cycles.sample_clamp_indirect = 0.0
sc.cycles.filter_type = "BLACKMAN_HARRIS"
sc.cycles.filter_width = 1.0
sc.cycles.caustics_reflective = sc.cycles.caustics_refractive = True
sc.cycles.blur_glossy = 0.0
sc.render.resolution_x = sc.render.resolution_y = 128
sc.render.resolution_percentage = 100
sc.render.threads_mode = "FIXED"
sc.render.threads = 2
world = bpy.data.worlds.new("black")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0, 0, 0, 1)
sc.world = world
sc.camera = [o for o in sc.objects if o.type == "CAMERA"][0]
sc.render.image_settings.file_format = "OPEN_EXR"
sc.render.image_settings.color_depth = "16"
sc.render.image_settings.exr_codec = "ZIP"

for gm in gltf["materials"]:
    ext = gm.get("extensions", {})
    mat = bpy.data.materials.get(gm["name"])
    if mat is None:
        continue
    nt = mat.node_tree
    pbr = [n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"]
    if "KHR_materials_anisotropy" in ext and pbr:
        a = ext["KHR_materials_anisotropy"]
        r = gm["pbrMetallicRoughness"].get("roughnessFactor", 1.0)
        s = a.get("anisotropyStrength", 0.0)
        ab = r * r
        at = ab + (1 - ab) * s * s
        # Cycles 3.4: alpha_x = r^2 / aspect, alpha_y = r^2 * aspect, aspect = sqrt(1 - 0.9 A).
        pbr[0].inputs["Roughness"].default_value = math.sqrt(math.sqrt(at * ab))
        pbr[0].inputs["Anisotropic"].default_value = (1 - ab / at) / 0.9
        pbr[0].inputs["Anisotropic Rotation"].default_value = a.get("anisotropyRotation", 0.0) / (2 * math.pi)
        tangent = nt.nodes.new("ShaderNodeTangent")
        tangent.direction_type = "UV_MAP"
        nt.links.new(tangent.outputs[0], pbr[0].inputs["Tangent"])
    if "KHR_materials_diffuse_transmission" in ext and pbr:
        d = ext["KHR_materials_diffuse_transmission"]
        out = [n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"][0]
        translucent = nt.nodes.new("ShaderNodeBsdfTranslucent")
        translucent.inputs[0].default_value = list(d.get("diffuseTransmissionColorFactor", [1, 1, 1])) + [1]
        mix = nt.nodes.new("ShaderNodeMixShader")
        mix.inputs[0].default_value = d.get("diffuseTransmissionFactor", 0.0)
        surface = out.inputs["Surface"].links[0].from_socket
        nt.links.new(surface, mix.inputs[1])
        nt.links.new(translucent.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
    if "KHR_materials_volume" in ext and mode == "matched":
        v = ext["KHR_materials_volume"]
        absorb = [n for n in nt.nodes if n.type == "VOLUME_ABSORPTION"]
        if absorb:
            sigma = [-math.log(c) / v["attenuationDistance"] for c in v["attenuationColor"]]
            absorb[0].inputs["Density"].default_value = 1.0
            absorb[0].inputs["Color"].default_value = [1 - x for x in sigma] + [1]

sc.render.filepath = out_path
bpy.ops.render.render(write_still=True)
