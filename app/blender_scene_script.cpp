#include "app/blender_scene_script.h"

namespace morphoflow {

const char* const kBlenderSceneBody = R"PY(
import argparse
import math
import os
import sys

import bpy
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))


def options():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender -b --python blender_scene.py --",
                                description="Set up (and render) the morphoflow run in " + HERE)
    p.add_argument("--render", action="store_true", help="render: the animation, or --frame")
    p.add_argument("--frame", help="one frame: N (1 shows the sequence's first file) or 'last'")
    p.add_argument("--resolution", type=int, default=RUN["resolution"], help="the picture's width in pixels")
    p.add_argument("--samples", type=int, default=64, help="Cycles samples per pixel")
    p.add_argument("--output", default=os.path.join(HERE, "render", "frame_"),
                   help="Blender's output path: '#' is the frame number, else it is appended")
    p.add_argument("--save", help="also save the set-up as this .blend file")
    a = p.parse_args(argv)
    if a.frame is not None and a.frame != "last":
        if not a.frame.isdigit() or not 1 <= int(a.frame) <= RUN["frames"]:
            p.error(f"--frame {a.frame}: give a frame from 1 to {RUN['frames']}, or 'last'")
    if a.resolution < 16 or a.samples < 1:
        p.error("--resolution is at least 16 pixels, --samples at least 1")
    return a


def to_blender(v):
    """A morphoflow vector (y up) in Blender's axes (z up): the object turned 90 degrees about x."""
    return Vector((v[0], -v[2], v[1]))


def volume_object(scene):
    volume = bpy.data.volumes.new(RUN["name"])
    volume.filepath = os.path.join(HERE, RUN["first"])
    volume.is_sequence = RUN["frames"] > 1
    volume.frame_start = 1
    volume.frame_offset = -1  # Blender's frame 1 shows the sequence's first file
    volume.frame_duration = RUN["frames"]
    volume.sequence_mode = "CLIP"
    obj = bpy.data.objects.new(RUN["name"], volume)
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)  # the scene's y (up) along Blender's z
    scene.collection.objects.link(obj)
    volume.materials.append(material())
    return obj, volume


def material():
    """A Principled Volume on the grids by name; the temperature glows as blackbody at RUN's emission."""
    m = bpy.data.materials.new(RUN["name"] + "_volume")
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    shader = nodes.new("ShaderNodeVolumePrincipled")
    shader.inputs["Density"].default_value = RUN["density"]
    shader.inputs["Density Attribute"].default_value = "density"
    if "color" in RUN["grids"]:
        shader.inputs["Color Attribute"].default_value = "color"
    else:
        shader.inputs["Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    if "temperature" in RUN["grids"]:  # wired always: raising Blackbody Intensity makes it glow
        attr = nodes.new("ShaderNodeAttribute")
        attr.attribute_name = "temperature"
        kelvin = nodes.new("ShaderNodeMapRange")
        kelvin.clamp = False
        t0, k0, per = RUN["ambient"], RUN["kelvin_at_ambient"], RUN["kelvin_per_unit"]
        kelvin.inputs["From Min"].default_value, kelvin.inputs["From Max"].default_value = t0, t0 + 1.0
        kelvin.inputs["To Min"].default_value, kelvin.inputs["To Max"].default_value = k0, k0 + per
        links.new(attr.outputs["Fac"], kelvin.inputs["Value"])
        links.new(kelvin.outputs["Result"], shader.inputs["Temperature"])
        shader.inputs["Blackbody Intensity"].default_value = RUN["emission"]
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(shader.outputs["Volume"], out.inputs["Volume"])
    return m


def lights(scene):
    sun = bpy.data.objects.new("key", bpy.data.lights.new("key", "SUN"))
    sun.data.energy = RUN["key_strength"]
    sun.data.color = RUN["key_colour"]
    sun.data.angle = math.radians(2.0)
    # A sun shines along its -z: from the key's direction toward the scene.
    sun.rotation_euler = (-to_blender(RUN["to_key"])).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(sun)
    # The sky lights the volume; the camera sees the preview's dark background.
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    sky = nodes["Background"]
    sky.inputs["Color"].default_value = (*RUN["sky_colour"], 1.0)
    sky.inputs["Strength"].default_value = RUN["sky_strength"]
    backdrop = nodes.new("ShaderNodeBackground")
    # (dimmed by the exposure, so that the picture's backdrop is the preview's)
    backdrop.inputs["Color"].default_value = (*[c / 2.0 ** RUN["exposure"] for c in RUN["backdrop"]], 1.0)
    path, mix = nodes.new("ShaderNodeLightPath"), nodes.new("ShaderNodeMixShader")
    links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(sky.outputs["Background"], mix.inputs[1])
    links.new(backdrop.outputs["Background"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["World Output"].inputs["Surface"])
    scene.world = world


def camera(scene):
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.angle = math.radians(RUN["field_of_view"])
    cam.location = to_blender(RUN["eye"])
    cam.rotation_euler = (to_blender(RUN["centre"]) - cam.location).to_track_quat("-Z", "Y").to_euler()
    cam.data.clip_end = 100.0 * max(RUN["domain"])
    scene.collection.objects.link(cam)
    scene.camera = cam


def set_up(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    obj, volume = volume_object(scene)
    lights(scene)
    camera(scene)
    scene.frame_start, scene.frame_end = 1, RUN["frames"]
    scene.render.fps = RUN["fps"]
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = a.samples
    scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    scene.cycles.volume_step_rate = 1.0
    scene.cycles.volume_max_steps = 4096
    scene.render.resolution_x = scene.render.resolution_y = a.resolution  # the preview's square view
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.view_settings.view_transform = "Filmic"
    scene.view_settings.exposure = RUN["exposure"]
    scene.render.filepath = a.output
    scene.frame_set(1)
    volume.grids.load()
    if not volume.grids.is_loaded or len(volume.grids) == 0:
        sys.exit(f"blender_scene: no grids in {volume.grids.frame_filepath}: {volume.grids.error_message}")
    if "vel" in RUN["grids"]:
        volume.velocity_grid = "vel"  # motion blur (Render Properties > Motion Blur) follows the fluid
    return scene


def main():
    a = options()
    scene = set_up(a)
    if a.save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(a.save))
    if not a.render:
        return
    if a.frame is None:
        bpy.ops.render.render(animation=True)
        return
    frame = RUN["frames"] if a.frame == "last" else int(a.frame)
    scene.frame_set(frame)
    scene.render.filepath = scene.render.frame_path(frame=frame)  # the name the animation would give it
    bpy.ops.render.render(write_still=True)
    print("blender_scene: frame", frame, "->", scene.render.filepath)


main()
)PY";

}  // namespace morphoflow
