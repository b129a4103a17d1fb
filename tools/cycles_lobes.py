"""Cycles reference of a scenes/lobes glTF, imported by Blender's own glTF importer.

blender -b --factory-startup --python tools/cycles_lobes.py -- SCENE.gltf OUT.exr SPP [MODE...]
128 x 128, Blackman-Harris filter of width 1 px (as scenes/README.md), 64 bounces, black world,
half-float EXR. Blender 3.4's importer does not know KHR_materials_diffuse_transmission or
_anisotropy; for those the Principled BSDF is set up here from the glTF (Translucent BSDF mixed
in by the factor; Principled anisotropy with alpha_x, alpha_y equal to the extension's alpha_t,
alpha_b).
MODE "matched" also rewrites what the importer maps differently from the glTF definition
(Volume Absorption: Cycles absorbs density * (1 - colour), glTF -log(colour) / distance).
MODE "lambert" replaces the Principled BSDF of every plain diffuse material (metallic 0, no
specular: specularFactor 0 or specularColorFactor 0) by a Diffuse BSDF of roughness 0, the
Lambertian lobe the glTF asks for; the importer's Principled BSDF is Disney's diffuse there.
MODE "onesided" makes an emissive material that is not doubleSided emit from its front only
(Cycles emits from both sides of a mesh).
MODE "coat" builds KHR_materials_clearcoat as the extension defines it, in place of Principled
v1's clearcoat: a Mix Shader of the base and a GGX Glossy BSDF (roughness as the extension's,
so the same alpha) by clearcoatFactor x Fresnel (IOR 1.5, about glTF's Schlick with F0 0.04).
"""
import argparse
import json
import math
import sys

import bpy
import numpy

# Blender 3.4's glTF importer still uses numpy.bool, which numpy 1.24 removed.
numpy.bool = bool


def is_plain_diffuse(gm: dict) -> bool:
    """True when the glTF material is a Lambertian lobe only: metallic 0 and no specular."""
    pbr = gm.get("pbrMetallicRoughness", {})
    spec = gm.get("extensions", {}).get("KHR_materials_specular")
    if pbr.get("metallicFactor", 1.0) != 0 or spec is None:
        return False
    return spec.get("specularFactor", 1.0) == 0 or max(spec.get("specularColorFactor", [1])) == 0


def set_up_render(spp: int, out_path: str) -> None:
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = spp
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    sc.cycles.max_bounces = sc.cycles.diffuse_bounces = sc.cycles.glossy_bounces = 64
    sc.cycles.transmission_bounces = sc.cycles.volume_bounces = 64
    sc.cycles.transparent_max_bounces = 64
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
    sc.render.filepath = out_path


def rewrite_material(gm: dict, modes: list) -> None:
    ext = gm.get("extensions", {})
    mat = bpy.data.materials.get(gm["name"])
    if mat is None:
        return
    nt = mat.node_tree
    pbr = [n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"]
    if "lambert" in modes and pbr and is_plain_diffuse(gm):
        diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
        colour = pbr[0].inputs["Base Color"]
        if colour.is_linked:
            nt.links.new(colour.links[0].from_socket, diffuse.inputs["Color"])
        else:
            diffuse.inputs["Color"].default_value = colour.default_value
        diffuse.inputs["Roughness"].default_value = 0.0
        for link in list(pbr[0].outputs[0].links):
            nt.links.new(diffuse.outputs[0], link.to_socket)
        nt.nodes.remove(pbr[0])
        pbr = []
    if "onesided" in modes and pbr and max(gm.get("emissiveFactor", [0])) > 0 and not gm.get(
            "doubleSided", False):
        strength = pbr[0].inputs["Emission Strength"]
        front = nt.nodes.new("ShaderNodeMath")
        front.operation = "SUBTRACT"
        front.inputs[0].default_value = 1.0
        nt.links.new(nt.nodes.new("ShaderNodeNewGeometry").outputs["Backfacing"], front.inputs[1])
        scaled = nt.nodes.new("ShaderNodeMath")
        scaled.operation = "MULTIPLY"
        scaled.inputs[1].default_value = strength.default_value
        nt.links.new(front.outputs[0], scaled.inputs[0])
        nt.links.new(scaled.outputs[0], strength)
    if "coat" in modes and "KHR_materials_clearcoat" in ext and pbr:
        c = ext["KHR_materials_clearcoat"]
        pbr[0].inputs["Clearcoat"].default_value = 0.0
        glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "GGX"
        glossy.inputs["Color"].default_value = (1, 1, 1, 1)
        glossy.inputs["Roughness"].default_value = c.get("clearcoatRoughnessFactor", 0.0)
        fresnel = nt.nodes.new("ShaderNodeFresnel")
        fresnel.inputs["IOR"].default_value = 1.5
        weight = nt.nodes.new("ShaderNodeMath")
        weight.operation = "MULTIPLY"
        weight.inputs[1].default_value = c.get("clearcoatFactor", 0.0)
        nt.links.new(fresnel.outputs[0], weight.inputs[0])
        out = [n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"][0]
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(weight.outputs[0], mix.inputs[0])
        nt.links.new(out.inputs["Surface"].links[0].from_socket, mix.inputs[1])
        nt.links.new(glossy.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
    if "KHR_materials_anisotropy" in ext and pbr:
        a = ext["KHR_materials_anisotropy"]
        r = gm["pbrMetallicRoughness"].get("roughnessFactor", 1.0)
        s = a.get("anisotropyStrength", 0.0)
        ab = r * r
        at = ab + (1 - ab) * s * s
        # Cycles 3.4: alpha_x = r^2 / aspect, alpha_y = r^2 * aspect, aspect = sqrt(1 - 0.9 A).
        pbr[0].inputs["Roughness"].default_value = math.sqrt(math.sqrt(at * ab))
        pbr[0].inputs["Anisotropic"].default_value = (1 - ab / at) / 0.9
        pbr[0].inputs["Anisotropic Rotation"].default_value = (
            a.get("anisotropyRotation", 0.0) / (2 * math.pi))
        tangent = nt.nodes.new("ShaderNodeTangent")
        tangent.direction_type = "UV_MAP"
        nt.links.new(tangent.outputs[0], pbr[0].inputs["Tangent"])
    if "KHR_materials_diffuse_transmission" in ext:
        d = ext["KHR_materials_diffuse_transmission"]
        out = [n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"][0]
        translucent = nt.nodes.new("ShaderNodeBsdfTranslucent")
        translucent.inputs[0].default_value = (
            list(d.get("diffuseTransmissionColorFactor", [1, 1, 1])) + [1])
        mix = nt.nodes.new("ShaderNodeMixShader")
        mix.inputs[0].default_value = d.get("diffuseTransmissionFactor", 0.0)
        surface = out.inputs["Surface"].links[0].from_socket
        nt.links.new(surface, mix.inputs[1])
        nt.links.new(translucent.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
    if "KHR_materials_volume" in ext and "matched" in modes:
        v = ext["KHR_materials_volume"]
        absorb = [n for n in nt.nodes if n.type == "VOLUME_ABSORPTION"]
        if absorb:
            sigma = [-math.log(c) / v["attenuationDistance"] for c in v["attenuationColor"]]
            absorb[0].inputs["Density"].default_value = 1.0
            absorb[0].inputs["Color"].default_value = [1 - x for x in sigma] + [1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="scenes/lobes/NAME.gltf")
    parser.add_argument("out", help="the EXR to write")
    parser.add_argument("spp", type=int)
    # No choices= here: Python 3.10's argparse checks an empty "*" list against them and fails.
    parser.add_argument("modes", nargs="*", help="matched, lambert, onesided, coat (see above)")
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:])
    if args.spp < 1:
        parser.error("spp must be at least 1")
    for mode in args.modes:
        if mode not in ("matched", "lambert", "onesided", "coat"):
            parser.error("unknown mode " + mode)
    with open(args.scene) as f:
        gltf = json.load(f)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=args.scene)
    set_up_render(args.spp, args.out)
    for gm in gltf["materials"]:
        rewrite_material(gm, args.modes)
    bpy.ops.render.render(write_still=True)


if __name__ == "__main__":
    main()
