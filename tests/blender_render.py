"""Renders one frame of a morphoflow VDB sequence with Blender (background
mode, Cycles on the CPU), as docs/vfx.md shows: a Volume object on the
sequence, a Principled Volume shading the "density" grid, "vel" as the motion
blur grid, the scene's y axis up.

blender -b --factory-startup -P blender_render.py -- FIRST.vdb FRAMES FRAME OUT.png [WIDTH SAMPLES DENSITY EMISSION]
With DENSITY "element": a smoke element as a compositor gets it, a
Principled Volume left at Blender's defaults (it reads `density` and
`temperature` by name) but for its Color Attribute, which Blender leaves
empty and its own smoke sets to `color`; EMISSION is then the camera's zoom
(1: the whole domain in view)."""
import math
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
first, frames, frame, out = argv[0], int(argv[1]), int(argv[2]), argv[3]
width = int(argv[4]) if len(argv) > 4 else 320
samples = int(argv[5]) if len(argv) > 5 else 16

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# The sequence: NAME.000000.vdb, NAME.000001.vdb, ... as Blender frames 1, 2, ...
volume = bpy.data.volumes.new("morphoflow")
volume.filepath = first
volume.is_sequence = True
volume.frame_start = 1
volume.frame_offset = -1  # Blender frame 1 shows NAME.000000.vdb
volume.frame_duration = frames
volume.sequence_mode = "CLIP"
obj = bpy.data.objects.new("morphoflow", volume)
obj.rotation_euler = (math.pi / 2, 0.0, 0.0)  # the scene's y (up) along Blender's Z
scene.collection.objects.link(obj)

material = bpy.data.materials.new("morphoflow_volume")
material.use_nodes = True
nodes, links = material.node_tree.nodes, material.node_tree.links
nodes.clear()
shader = nodes.new("ShaderNodeVolumePrincipled")
element = len(argv) > 6 and argv[6] == "element"
if element:
    shader.inputs["Color Attribute"].default_value = "color"
else:
    shader.inputs["Density"].default_value = float(argv[6]) if len(argv) > 6 else 20.0
    shader.inputs["Color"].default_value = (1.0, 0.45, 0.15, 1.0)
    shader.inputs["Emission Strength"].default_value = float(argv[7]) if len(argv) > 7 else 2.0
    shader.inputs["Emission Color"].default_value = (1.0, 0.35, 0.1, 1.0)
output = nodes.new("ShaderNodeOutputMaterial")
links.new(shader.outputs["Volume"], output.inputs["Volume"])
volume.materials.append(material)

scene.frame_set(frame)
volume.grids.load()
if not volume.grids.is_loaded or len(volume.grids) == 0:
    sys.exit(f"blender_render: no grids in {volume.grids.frame_filepath}: {volume.grids.error_message}")
volume.velocity_grid = "vel"  # motion blur (render.use_motion_blur) follows the fluid
corner_lo, corner_hi = [float("inf")] * 3, [-float("inf")] * 3
for c in obj.bound_box:
    for a in range(3):
        corner_lo[a] = min(corner_lo[a], c[a])
        corner_hi[a] = max(corner_hi[a], c[a])
centre_local = [(corner_lo[a] + corner_hi[a]) / 2 for a in range(3)]
size = max(corner_hi[a] - corner_lo[a] for a in range(3))
bpy.context.view_layer.update()
from mathutils import Vector
centre = obj.matrix_world @ Vector(centre_local)

target = bpy.data.objects.new("target", None)
target.location = centre
scene.collection.objects.link(target)
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
zoom = float(argv[7]) if element and len(argv) > 7 else 1.0
camera.location = centre + Vector((1.9, -2.4, 1.5)) * (size / zoom)
track = camera.constraints.new("TRACK_TO")
track.target = target
scene.collection.objects.link(camera)
scene.camera = camera
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 5.0
sun.rotation_euler = (0.6, 0.2, 0.8)
scene.collection.objects.link(sun)
world = bpy.data.worlds.new("world")
world.color = (0.02, 0.02, 0.025)
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
scene.render.resolution_x = width
scene.render.resolution_y = width * 3 // 4
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print("blender_render: grids", [g.name for g in volume.grids], "->", out)
