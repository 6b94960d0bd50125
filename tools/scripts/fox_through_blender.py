# The Khronos Fox through Blender: imported with Blender's glTF I/O, put on a pedestal, exported
# again with its three actions, and Blender's own pose of the fox at given frames baked into
# static files beside it.
# Usage: blender -b --python tools/scripts/fox_through_blender.py -- Fox.glb OUT.glb FRAME...
# (needs python3-numpy; tests/skins/README.md).
import bpy, sys
import numpy
if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Blender 3.4's importer still names it; numpy 1.24 dropped it
argv = sys.argv[sys.argv.index("--") + 1:]
src, out, frames = argv[0], argv[1], [int(x) for x in argv[2:]]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 24
bpy.ops.import_scene.gltf(filepath=src)
arm = next(o for o in scene.objects if o.type == "ARMATURE")
fox = next(o for o in scene.objects if o.type == "MESH")
print("armature", arm.name, arm.matrix_world, "fox", fox.name, fox.parent and fox.parent.name)
print("actions", [a.name for a in bpy.data.actions], arm.animation_data.action and arm.animation_data.action.name)
bpy.ops.mesh.primitive_cylinder_add(radius=60.0, depth=10.0, location=(0, 0, -5))
bpy.context.active_object.name = "Pedestal"
# A camera of the file's own, so that the skinned and the baked file are seen from one place.
from mathutils import Euler
import math
cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(cam)
cam.location = (180.0, -260.0, 150.0)
cam.rotation_euler = Euler((math.radians(68), 0, math.radians(34)))
scene.camera = cam
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_animations=True, export_skins=True,
                          export_cameras=True)
ped = bpy.data.objects["Pedestal"]
for f in frames:
    scene.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    mesh = bpy.data.meshes.new_from_object(fox.evaluated_get(dg), depsgraph=dg)
    baked = bpy.data.objects.new(f"Baked{f}", mesh)
    baked.matrix_world = fox.matrix_world.copy()
    scene.collection.objects.link(baked)
    bpy.ops.object.select_all(action="DESELECT")
    for o in (baked, ped, cam):
        o.select_set(True)
    bpy.ops.export_scene.gltf(filepath=out.replace(".glb", f"_baked_{f}.glb"), export_format="GLB",
                              use_selection=True, export_animations=False, export_skins=False,
                              export_cameras=True)
    scene.collection.objects.unlink(baked)
