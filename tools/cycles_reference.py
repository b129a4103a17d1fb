"""Renders a glTF with Cycles as the scenes/ references are rendered (scenes/README.md): Blender's
importer, CPU, Blackman-Harris 1 px, 64 bounces, no clamping, denoising or adaptive sampling,
non-metal Principled BSDFs as Lambertian Diffuse + Emission, with the Principled's Alpha kept
as a mix with a Transparent BSDF (how Cycles renders alpha: stochastic transparency too).

    blender -b --factory-startup --python tools/cycles_reference.py -- SCENE.gltf OUT.exr \\
        [--spp N] [--size N]
"""
import argparse
import sys

import bpy
import numpy

if "bool" not in numpy.__dict__:  # Blender 3.4's importer uses numpy.bool (removed in 1.24)
    numpy.bool = bool


def lambertian(nt) -> None:
    for p in [n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"]:
        if any(p.inputs[k].is_linked or p.inputs[k].default_value != 0.0
               for k in ("Metallic", "Transmission")):
            continue
        outs = [link.to_socket for link in p.outputs["BSDF"].links]
        diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
        emit = nt.nodes.new("ShaderNodeEmission")
        add = nt.nodes.new("ShaderNodeAddShader")
        clear = nt.nodes.new("ShaderNodeBsdfTransparent")
        mix = nt.nodes.new("ShaderNodeMixShader")
        for dst, src in ((diff.inputs["Color"], "Base Color"), (diff.inputs["Normal"], "Normal"),
                         (emit.inputs["Color"], "Emission"), (emit.inputs["Strength"], "Emission Strength"),
                         (mix.inputs["Fac"], "Alpha")):
            if p.inputs[src].is_linked:
                nt.links.new(p.inputs[src].links[0].from_socket, dst)
            elif src != "Normal":
                dst.default_value = p.inputs[src].default_value
        nt.links.new(diff.outputs[0], add.inputs[0])
        nt.links.new(emit.outputs[0], add.inputs[1])
        nt.links.new(clear.outputs[0], mix.inputs[1])
        nt.links.new(add.outputs[0], mix.inputs[2])
        for o in outs:
            nt.links.new(mix.outputs[0], o)
        nt.nodes.remove(p)


def main() -> None:
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("out")
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--size", type=int, default=128)
    args = parser.parse_args(argv)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=args.scene)
    for m in bpy.data.materials:
        if m.use_nodes:
            lambertian(m.node_tree)
    s = bpy.context.scene
    s.camera = next(o for o in s.objects if o.type == "CAMERA")
    s.render.engine = "CYCLES"
    c = s.cycles
    c.device, c.samples, c.use_adaptive_sampling, c.use_denoising = "CPU", args.spp, False, False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = 64
    c.volume_bounces = c.transparent_max_bounces = 64
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.pixel_filter_type, c.filter_width = "BLACKMAN_HARRIS", 1.0
    s.render.resolution_x = s.render.resolution_y = args.size
    s.render.resolution_percentage = 100
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "16"
    s.render.filepath = args.out
    bpy.ops.render.render(write_still=True)


main()
