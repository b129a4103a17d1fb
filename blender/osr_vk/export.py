# Blender scene -> what osr-vk reads: a glTF written by Blender's own exporter (io_scene_gltf2),
# completed where that exporter stops short of a render:
# - only the active camera is kept (osr-vk renders the file's first camera);
# - area lights, which KHR_lights_punctual cannot hold (the exporter drops them), become
#   one-sided emissive polygons of the same shape and brightness as in Cycles, whose area
#   light of power P and area A has radiance P / (4 A) (not P / (pi A): measured, docs/blender.md);
# - the world's colour or equirectangular image becomes an --env file.
# What neither can express is listed for one warning in Blender's report, never a failure.
import contextlib
import json
import math
import os
import struct

import bpy
import numpy as np
from mathutils import Vector

from . import exr

# glTF is +Y up: Blender (x, y, z) is glTF (x, z, -y) (the exporter's export_yup).
def _to_gltf(v):
    return (v[0], v[2], -v[1])


class ExportError(Exception):
    pass


class Export:
    def __init__(self, gltf_path, env_path, warnings):
        self.gltf_path, self.env_path, self.warnings = gltf_path, env_path, warnings


def _renderable_objects(depsgraph):
    for inst in depsgraph.object_instances:
        obj = inst.object
        yield obj.original if obj.original is not None else obj


def _material_problem(mat):
    """Why glTF cannot express `mat`'s node setup, or None."""
    if mat is None or not mat.use_nodes or mat.node_tree is None:
        return None
    outputs = [n for n in mat.node_tree.nodes if n.type == "OUTPUT_MATERIAL"]
    out = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
    if out is None:
        return None
    if out.inputs["Volume"].is_linked:
        return "volume"
    surface = out.inputs["Surface"]
    if not surface.is_linked:
        return None
    root = surface.links[0].from_node
    if root.type in {"BSDF_PRINCIPLED", "EMISSION"}:
        return None
    if root.type == "GROUP" and root.node_tree and "glTF" in root.node_tree.name:
        return None
    return "node setup (%s)" % root.bl_label


def survey(depsgraph):
    """Warnings for what the glTF cannot carry: node materials, volumes, hair, camera effects."""
    scene = depsgraph.scene
    materials, volumes, hair, others = set(), set(), set(), []
    seen = set()
    for obj in _renderable_objects(depsgraph):
        if obj.name in seen:
            continue
        seen.add(obj.name)
        if obj.type == "VOLUME":
            volumes.add(obj.name)
        if obj.type in {"CURVES", "HAIR"} or any(
                p.settings.type == "HAIR" for p in getattr(obj, "particle_systems", [])):
            hair.add(obj.name)
        if obj.type == "LIGHT" and obj.data.type == "AREA" and obj.data.spread < math.pi - 1e-3:
            others.append("area light %s: spread below 180 degrees (rendered as 180)" % obj.name)
        for slot in getattr(obj, "material_slots", []):
            problem = _material_problem(slot.material)
            if problem == "volume":
                volumes.add(slot.material.name)
            elif problem:
                materials.add("%s (%s)" % (slot.material.name, problem.split("(")[-1].rstrip(")")))
    cam = scene.camera.data if scene.camera else None
    if cam is not None and cam.type == "PERSP":
        if abs(cam.shift_x) > 1e-6 or abs(cam.shift_y) > 1e-6:
            others.append("camera shift")
        if cam.dof.use_dof:
            others.append("depth of field")
    if scene.render.use_motion_blur:
        others.append("motion blur")
    if scene.render.pixel_aspect_x != scene.render.pixel_aspect_y:
        others.append("non-square pixels")
    world = scene.world
    if world is not None and world.use_nodes and world.node_tree:
        out = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        if out is not None and out.inputs["Volume"].is_linked:
            volumes.add("world " + world.name)
    parts = []
    if materials:
        parts.append("materials glTF cannot express, exported as plain glTF materials: "
                     + ", ".join(sorted(materials)))
    if volumes:
        parts.append("volumes (skipped): " + ", ".join(sorted(volumes)))
    if hair:
        parts.append("hair (skipped): " + ", ".join(sorted(hair)))
    parts += others
    return parts


# What osr-vk --frames replays from the glTF: object transforms keyed in each object's action
# (docs/blender.md, "Render Animation"). Keyed delta_scale and delta_rotation_quaternion are
# not among them: the 3.4 exporter writes no animation for them (measured).
_TRANSFORMS = {"location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "scale",
               "delta_location", "delta_rotation_euler"}
# Modifiers whose result changes with the frame by themselves (simulations, caches, effects).
_TIME_MODIFIERS = {"CLOTH", "SOFT_BODY", "FLUID", "DYNAMIC_PAINT", "PARTICLE_SYSTEM", "OCEAN",
                   "EXPLODE", "WAVE", "BUILD", "MESH_CACHE", "MESH_SEQUENCE_CACHE", "NODES"}


def _node_trees(tree, seen):
    """`tree` and the node groups inside it."""
    # By address: a material's own node tree is called "Shader Nodetree" in every material.
    if tree is None or tree.as_pointer() in seen:
        return
    seen.add(tree.as_pointer())
    yield tree
    for node in tree.nodes:
        if node.type == "GROUP":
            yield from _node_trees(node.node_tree, seen)


def _moves(obj):
    """Whether `obj` or a parent of it is keyed (its action has F-curves)."""
    while obj is not None:
        ad = obj.animation_data
        if ad is not None and ad.action is not None and ad.action.fcurves:
            return True
        obj = obj.parent
    return False


def animation_problems(depsgraph, frames):
    """Why the scene's animation over Blender frames `frames` cannot come through one glTF
    export to osr-vk --frames (a list of reasons; empty: it can). Only object transforms keyed
    in actions can: anything else that Blender evaluates per frame (materials, lights' and
    cameras' data, shape keys, armatures, drivers, constraints, NLA strips, simulations,
    geometry nodes, image sequences, camera switches) needs a fresh export per frame."""
    scene = depsgraph.scene.original
    reasons, ids, seen = [], [], set()

    def add(id_, label):
        if id_ is not None and id_.as_pointer() not in seen:
            seen.add(id_.as_pointer())
            ids.append((id_, label))

    add(scene, "scene %s" % scene.name)
    if scene.world is not None:
        add(scene.world, "world %s" % scene.world.name)
        for tree in _node_trees(scene.world.node_tree, set()):
            add(tree, "world %s" % scene.world.name)
    objects = []
    for obj in list(_renderable_objects(depsgraph)) + [scene.camera]:
        while obj is not None and obj.name not in {o.name for o in objects}:
            objects.append(obj)
            obj = obj.parent  # a parent moves its children
    trees = set()
    for obj in objects:
        add(obj, "object %s" % obj.name)
        data = obj.data
        if data is not None:
            add(data, "%s data of %s" % (obj.type.lower(), obj.name))
            add(getattr(data, "shape_keys", None), "shape keys of %s" % obj.name)
        for slot in getattr(obj, "material_slots", []):
            if slot.material is not None:
                add(slot.material, "material %s" % slot.material.name)
                for tree in _node_trees(slot.material.node_tree, trees):
                    add(tree, "material %s" % slot.material.name)
        if any(not c.mute for c in obj.constraints):
            reasons.append("constraints on %s" % obj.name)
        if obj.rigid_body is not None:
            reasons.append("rigid body %s" % obj.name)
        for mod in getattr(obj, "modifiers", []):
            if not mod.show_render:
                continue
            if mod.type in _TIME_MODIFIERS:
                reasons.append("%s on %s" % (mod.bl_rna.name, obj.name))
                continue
            # A modifier that reads another object (Armature, Boolean, Hook, Curve, ...)
            # changes the mesh as that object moves, and the glTF has the mesh once.
            for prop in mod.bl_rna.properties:
                if prop.type == "POINTER" and getattr(prop.fixed_type, "identifier", "") == "Object":
                    other = getattr(mod, prop.identifier)
                    if other is not None and _moves(other):
                        reasons.append("%s on %s follows %s" % (mod.bl_rna.name, obj.name, other.name))
        if obj.type == "LIGHT" and obj.data.type == "AREA" and _moves(obj):
            # Written as an emissive polygon in world space at the first frame.
            reasons.append("area light %s moves" % obj.name)
    for id_, label in ids:
        ad = getattr(id_, "animation_data", None)
        if ad is None:
            continue
        if len(ad.drivers):
            reasons.append("drivers on %s" % label)
        if any(not t.mute and len(t.strips) for t in ad.nla_tracks):
            reasons.append("NLA strips on %s" % label)
        if ad.action is None:
            continue
        for fc in ad.action.fcurves:
            if fc.mute:
                continue
            if not isinstance(id_, bpy.types.Object) or fc.data_path not in _TRANSFORMS:
                reasons.append("animated %s (%s)" % (label, fc.data_path))
                break
            if fc.extrapolation != "CONSTANT" or len(fc.modifiers):
                # The exporter samples the keyed range; the glTF holds the end keys outside it.
                reasons.append("F-curve extrapolation or modifiers on %s (%s)" % (label, fc.data_path))
                break
            if fc.range()[0] % 1.0:
                # Sampled from the first key at whole-frame steps: keys between frames would
                # put every sample between frames.
                reasons.append("keys between frames on %s (%s)" % (label, fc.data_path))
                break
    images = set()
    for id_, label in ids:
        if isinstance(id_, bpy.types.NodeTree):
            for node in id_.nodes:
                image = getattr(node, "image", None)
                if image is not None and image.source in {"SEQUENCE", "MOVIE"} and image.name not in images:
                    images.add(image.name)
                    reasons.append("image %s is a %s" % (image.name, image.source.lower()))
    if scene.rigidbody_world is not None and scene.rigidbody_world.enabled and scene.rigidbody_world.collection:
        reasons.append("the rigid body world")
    first, last = min(frames), max(frames)
    # A marker at or before the first frame chose the camera already; one after it switches.
    if any(m.camera is not None and first < m.frame <= last for m in scene.timeline_markers):
        reasons.append("markers that switch the camera")
    return reasons


def _run_gltf_exporter(depsgraph, path, animation):
    scene = depsgraph.scene.original
    view_layer = scene.view_layers.get(depsgraph.view_layer.name)
    settings = dict(filepath=path, export_format="GLTF_SEPARATE", export_cameras=True,
                    export_lights=True, use_renderable=True, use_active_scene=True,
                    export_apply=True, export_yup=True, export_animations=animation,
                    # Animations sampled at every frame, so that each frame Blender renders
                    # is a key (exact, whatever the F-curves' interpolation), and the assigned
                    # actions as one glTF animation (osr-vk plays all at once anyway).
                    export_force_sampling=True, export_frame_step=1, export_nla_strips=False,
                    export_optimize_animation_size=False,
                    # The frame being rendered: by default the exporter poses the scene at
                    # frame 0, so F12 at another frame and every frame of Render Animation
                    # rendered frame 0's pose (measured: tests/blender, case animation_fallback).
                    export_current_frame=True,
                    # Materials with their KHR_materials_* extensions and emission strength,
                    # every UV map (a texture on the second one reads TEXCOORD_1) and the
                    # render colour attribute as COLOR_0 (kept only where the material uses
                    # it: _drop_unused_vertex_colors).
                    export_materials="EXPORT", export_colors=True, export_texcoords=True,
                    export_normals=True, export_extras=False,
                    convert_lighting_mode="SPEC")
    props = bpy.ops.export_scene.gltf.get_rna_type().properties
    settings = {k: v for k, v in settings.items() if k in props}  # older/newer exporters
    # The exporter exports the context's scene and view layer, and sets the window's scene
    # (then back to context.scene). With a window in the context, the scene and view layer to
    # export are set on it and restored after, not overridden: under an override Blender looks
    # context members up in a Python dict from C without taking the GIL whenever another
    # Python thread holds it, such as the render job's thread waiting for this export, and
    # crashed (Blender 3.4; tests/blender animation_f12 about 1 run in 10).
    window = bpy.context.window
    shown = (window.scene, window.view_layer) if window is not None else None
    try:
        if window is not None:
            window.scene = scene
            if view_layer is not None:
                window.view_layer = view_layer
            context = contextlib.nullcontext()
        else:
            context = bpy.context.temp_override(scene=scene, view_layer=view_layer)
        with context:
            # Render Animation moves the scene's frame but leaves the view layer's evaluated
            # state, which the exporter reads, at the last one evaluated: evaluate the frame
            # being rendered.
            frame, subframe = depsgraph.scene.frame_current, depsgraph.scene.frame_subframe
            scene.frame_set(frame, subframe=subframe)
            result = bpy.ops.export_scene.gltf(**settings)
            if animation:  # sampling moved the frame, and "current frame" does not restore it
                scene.frame_set(frame, subframe=subframe)
    except (RuntimeError, AttributeError) as e:
        raise ExportError("glTF export failed: %s" % str(e).strip().splitlines()[-1])
    finally:
        if window is not None:
            if window.scene != shown[0]:
                window.scene = shown[0]
            if window.view_layer != shown[1]:
                window.view_layer = shown[1]
    if "FINISHED" not in result or not os.path.isfile(path):
        raise ExportError("glTF export failed (is the glTF 2.0 add-on enabled?)")


def _uses_color_attribute(mat):
    """Whether a Color Attribute (or Attribute) node feeds the Principled BSDF's Base Color."""
    if mat is None or not mat.use_nodes or mat.node_tree is None:
        return False
    bsdf = next((n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is None:
        return False
    todo, seen = [bsdf.inputs["Base Color"]], set()
    while todo:
        socket = todo.pop()
        for link in socket.links:
            node = link.from_node
            if node.type in {"VERTEX_COLOR", "ATTRIBUTE"}:
                return True
            if node.name not in seen:
                seen.add(node.name)
                todo.extend(node.inputs)
    return False


def _drop_unused_vertex_colors(gltf):
    # glTF multiplies the base colour by COLOR_0 wherever a primitive has it, but Blender 3.4's
    # exporter writes the mesh's render colour attribute whatever the material does with it:
    # keep it only where the material's Base Color reads it, as Blender renders.
    materials = gltf.get("materials", [])
    for mesh in gltf.get("meshes", []):
        for prim in mesh.get("primitives", []):
            if "COLOR_0" not in prim.get("attributes", {}):
                continue
            index = prim.get("material")
            name = materials[index].get("name") if index is not None and index < len(materials) else None
            if not _uses_color_attribute(bpy.data.materials.get(name) if name else None):
                del prim["attributes"]["COLOR_0"]


def _keep_active_camera(gltf, camera_name):
    parents = {c: i for i, n in enumerate(gltf.get("nodes", [])) for c in n.get("children", [])}

    def owned(i):  # the camera node, or a correction node the exporter hung under it
        while i is not None:
            if gltf["nodes"][i].get("name") == camera_name:
                return True
            i = parents.get(i)
        return False

    kept = 0
    for i, node in enumerate(gltf.get("nodes", [])):
        if "camera" in node:
            if owned(i) and kept == 0:
                kept += 1
            else:
                del node["camera"]
    if kept == 0:
        raise ExportError("the active camera %s was not exported (is it hidden from rendering?)"
                          % camera_name)


def _polygon(light):
    """Corners of an area light's shape in its local XY plane, counter-clockwise seen from -Z."""
    sx = light.size
    sy = light.size_y if light.shape in {"RECTANGLE", "ELLIPSE"} else light.size
    if light.shape in {"SQUARE", "RECTANGLE"}:
        corners = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    else:
        n = 32
        corners = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    return [Vector((0.5 * sx * x, 0.5 * sy * y, 0.0)) for x, y in reversed(corners)]


def _add_area_lights(gltf, lights, bin_path):
    blob, meshes = bytearray(), []
    for obj in lights:
        light = obj.data
        world = obj.matrix_world
        pts = [world @ p for p in _polygon(light)]
        normal = (world.to_3x3() @ Vector((0.0, 0.0, -1.0))).normalized()
        area_vec = Vector((0.0, 0.0, 0.0))
        for k in range(1, len(pts) - 1):
            area_vec += (pts[k] - pts[0]).cross(pts[k + 1] - pts[0])
        area = area_vec.length / 2
        if area <= 0 or light.energy <= 0:
            continue
        if area_vec.dot(normal) < 0:  # mirrored transform: keep the winding facing the emission
            pts.reverse()
        radiance = [c * light.energy / (4.0 * area) for c in light.color]
        peak = max(radiance)
        if peak <= 0:
            continue
        tris = [i for k in range(1, len(pts) - 1) for i in (0, k, k + 1)]
        positions = [_to_gltf(p) for p in pts]
        n = _to_gltf(normal)
        base = len(blob)
        for p in positions:
            blob += struct.pack("<3f", *p)
        normals_at = len(blob)
        for _ in positions:
            blob += struct.pack("<3f", *n)
        index_at = len(blob)
        blob += struct.pack("<%dI" % len(tris), *tris)
        meshes.append((obj.name, base, normals_at, index_at, len(positions), len(tris),
                       [c / peak for c in radiance], peak, positions))
    if not meshes:
        return 0
    with open(bin_path, "wb") as f:
        f.write(blob)
    buffer = len(gltf.setdefault("buffers", []))
    gltf["buffers"].append({"uri": os.path.basename(bin_path), "byteLength": len(blob)})
    views, accessors = gltf.setdefault("bufferViews", []), gltf.setdefault("accessors", [])
    materials, gmeshes = gltf.setdefault("materials", []), gltf.setdefault("meshes", [])
    nodes = gltf.setdefault("nodes", [])
    scene = gltf["scenes"][gltf.get("scene", 0)]
    for name, base, normals_at, index_at, count, ntris, color, strength, positions in meshes:
        def accessor(offset, length, comp, kind, cnt, **extra):
            views.append({"buffer": buffer, "byteOffset": offset, "byteLength": length})
            accessors.append(dict(bufferView=len(views) - 1, componentType=comp, count=cnt,
                                  type=kind, **extra))
            return len(accessors) - 1

        lo = [min(p[i] for p in positions) for i in range(3)]
        hi = [max(p[i] for p in positions) for i in range(3)]
        pos = accessor(base, 12 * count, 5126, "VEC3", count, min=lo, max=hi)
        nrm = accessor(normals_at, 12 * count, 5126, "VEC3", count)
        idx = accessor(index_at, 4 * ntris, 5125, "SCALAR", ntris)
        materials.append({
            "name": name + " (area light)", "doubleSided": False,
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0,
                                     "roughnessFactor": 1.0},
            "emissiveFactor": color,
            # A light reflects nothing in Cycles: no specular layer either (its 4 % would also
            # be the denoisers' albedo guide, docs/denoise.md).
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength},
                           "KHR_materials_specular": {"specularFactor": 0.0}}})
        gmeshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
            "material": len(materials) - 1}]})
        nodes.append({"name": name, "mesh": len(gmeshes) - 1})
        scene.setdefault("nodes", []).append(len(nodes) - 1)
    used = gltf.setdefault("extensionsUsed", [])
    for extension in ("KHR_materials_emissive_strength", "KHR_materials_specular"):
        if extension not in used:
            used.append(extension)
    return len(meshes)


def _srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _world_env(world, directory, warnings):
    """The --env file for `world`, or None for a black world."""
    if world is None:
        return None
    color, strength, image = tuple(world.color), 1.0, None
    if world.use_nodes and world.node_tree:
        nodes = world.node_tree.nodes
        out = next((n for n in nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        link = out.inputs["Surface"].links[0] if out and out.inputs["Surface"].is_linked else None
        if link is None:
            return None
        bg = link.from_node
        if bg.type != "BACKGROUND":
            warnings.append("world shader %s (rendered without environment)" % bg.bl_label)
            return None
        strength = bg.inputs["Strength"].default_value
        if bg.inputs["Strength"].is_linked:
            warnings.append("world strength input (its value used)")
        col = bg.inputs["Color"]
        if col.is_linked:
            src = col.links[0].from_node
            if src.type == "TEX_ENVIRONMENT" and src.image is not None and src.projection == "EQUIRECTANGULAR":
                image = src.image
                if src.inputs["Vector"].is_linked:
                    warnings.append("world texture mapping (ignored)")
            else:
                warnings.append("world colour from %s (rendered without environment)" % src.bl_label)
                return None
        else:
            color = tuple(col.default_value)[:3]
    if strength <= 0:
        return None
    path = os.path.join(directory, "world.exr")
    if image is None:
        rgb = np.array(color[:3], np.float32) * strength
        if not rgb.any():
            return None
        exr.write_rgb(path, np.broadcast_to(rgb, (4, 8, 3)))
        return path
    source = bpy.path.abspath(image.filepath, library=image.library)
    if (strength == 1.0 and not image.packed_file and os.path.isfile(source)
            and os.path.splitext(source)[1].lower() in {".exr", ".hdr"}):
        return source  # osr-vk reads the file itself, at full resolution
    w, h = image.size
    if w == 0 or h == 0:
        warnings.append("world image %s could not be loaded (rendered without environment)" % image.name)
        return None
    px = np.empty(w * h * image.channels, np.float32)
    image.pixels.foreach_get(px)
    px = px.reshape(h, w, image.channels)[::-1, :, :3]  # Blender's rows run bottom-up
    if not image.is_float and image.colorspace_settings.name == "sRGB":
        px = _srgb_to_linear(px)
    exr.write_rgb(path, px * strength)
    return path


def _hold_still(gltf, bin_path):
    """Gives a glTF without animations one: the camera's translation, one key. osr-vk --frames
    refuses a file without animation, and Render Animation of a still scene is one still."""
    if gltf.get("animations"):
        return
    node = next(i for i, n in enumerate(gltf["nodes"]) if "camera" in n)
    translation = gltf["nodes"][node].get("translation", [0.0, 0.0, 0.0])
    with open(bin_path, "wb") as f:
        f.write(struct.pack("<4f", 0.0, *translation))
    buffer = len(gltf.setdefault("buffers", []))
    gltf["buffers"].append({"uri": os.path.basename(bin_path), "byteLength": 16})
    views, accessors = gltf.setdefault("bufferViews", []), gltf.setdefault("accessors", [])
    views += [{"buffer": buffer, "byteOffset": 0, "byteLength": 4},
              {"buffer": buffer, "byteOffset": 4, "byteLength": 12}]
    accessors += [{"bufferView": len(views) - 2, "componentType": 5126, "count": 1,
                   "type": "SCALAR", "min": [0.0], "max": [0.0]},
                  {"bufferView": len(views) - 1, "componentType": 5126, "count": 1, "type": "VEC3"}]
    gltf["animations"] = [{"name": "still", "samplers": [{
        "input": len(accessors) - 2, "output": len(accessors) - 1, "interpolation": "STEP"}],
        "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]}]


def export(depsgraph, directory, animation=False):
    """Writes scene.gltf (+ world.exr) into `directory`; returns an Export. animation: with the
    scene's animation (animation_problems must have found none), for osr-vk --frames."""
    scene = depsgraph.scene
    if scene.camera is None:
        raise ExportError("the scene has no active camera")
    if scene.camera.type != "CAMERA" or scene.camera.data.type != "PERSP":
        raise ExportError("camera %s: osr-vk renders perspective cameras only" % scene.camera.name)
    geometry = ("MESH", "CURVE", "SURFACE", "META", "FONT")
    if not any(obj.type in geometry or (obj.type == "LIGHT" and obj.data.type == "AREA")
               for obj in _renderable_objects(depsgraph)):
        raise ExportError("nothing to render: the scene has no visible mesh objects or area lights")
    warnings = survey(depsgraph)
    gltf_path = os.path.join(directory, "scene.gltf")
    _run_gltf_exporter(depsgraph, gltf_path, animation)
    with open(gltf_path, encoding="utf-8") as f:
        gltf = json.load(f)
    _keep_active_camera(gltf, scene.camera.original.name if scene.camera.original else scene.camera.name)
    _drop_unused_vertex_colors(gltf)
    seen, area_lights = set(), []
    for obj in _renderable_objects(depsgraph):
        if obj.type == "LIGHT" and obj.data.type == "AREA" and obj.name not in seen:
            seen.add(obj.name)
            area_lights.append(obj)
    _add_area_lights(gltf, area_lights, os.path.join(directory, "area_lights.bin"))
    if animation:
        _hold_still(gltf, os.path.join(directory, "still.bin"))
    with open(gltf_path, "w", encoding="utf-8") as f:
        json.dump(gltf, f)
    env = _world_env(scene.world, directory, warnings)
    return Export(gltf_path, env, warnings)
