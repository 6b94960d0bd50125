# A Blender-made skinned character as exporters write it: an armature object with its own
# transform, bones in a hierarchy, a body mesh parented to the armature with an armature
# modifier and vertex groups, a static pedestal, one action; exported with Blender's glTF I/O.
# Usage: blender -b --python tools/scripts/blender_rig.py -- OUT.glb FRAME... (needs python3-numpy;
# tests/skins/README.md).
import bpy, math, sys
from mathutils import Vector, Euler

out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 24

# Armature object, moved, turned and scaled (as rigs imported from other tools often are).
arm_data = bpy.data.armatures.new("Armature")
arm = bpy.data.objects.new("Armature", arm_data)
scene.collection.objects.link(arm)
arm.location = (0.3, 0.2, 0.5)
arm.rotation_euler = Euler((0.0, 0.0, math.radians(30)))
arm.scale = (1.2, 1.2, 1.2)
bpy.context.view_layer.objects.active = arm
bpy.ops.object.mode_set(mode="EDIT")
eb = arm_data.edit_bones
def bone(name, head, tail, parent=None):
    b = eb.new(name)
    b.head, b.tail = Vector(head), Vector(tail)
    if parent:
        b.parent = eb[parent]
    return b
bone("root", (0, 0, 0.6), (0, 0.3, 0.6))
bone("spine", (0, 0.3, 0.6), (0, 0.8, 0.7), "root")
bone("head", (0, 0.8, 0.7), (0, 1.1, 0.9), "spine")
for side, x in (("L", 0.15), ("R", -0.15)):
    bone("leg_f." + side, (x, 0.7, 0.6), (x, 0.7, 0.0), "spine")
    bone("leg_b." + side, (x, 0.1, 0.6), (x, 0.1, 0.0), "root")
bone("tail", (0, 0.0, 0.65), (0, -0.4, 0.8), "root")
bpy.ops.object.mode_set(mode="OBJECT")

# The body: boxes joined into one mesh, each part's vertices in its bone's group.
parts = [
    ("root", (0, 0.2, 0.6), (0.18, 0.25, 0.12)),
    ("spine", (0, 0.55, 0.65), (0.18, 0.25, 0.12)),
    ("head", (0, 0.95, 0.8), (0.12, 0.15, 0.12)),
    ("leg_f.L", (0.15, 0.7, 0.3), (0.05, 0.05, 0.3)),
    ("leg_f.R", (-0.15, 0.7, 0.3), (0.05, 0.05, 0.3)),
    ("leg_b.L", (0.15, 0.1, 0.3), (0.05, 0.05, 0.3)),
    ("leg_b.R", (-0.15, 0.1, 0.3), (0.05, 0.05, 0.3)),
    ("tail", (0, -0.2, 0.72), (0.04, 0.2, 0.04)),
]
objs = []
for name, c, s in parts:
    bpy.ops.mesh.primitive_cube_add(size=2, location=c)
    o = bpy.context.active_object
    o.scale = s
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    # Subdivide so that a joint blends across many vertices.
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.subdivide(number_cuts=3)
    bpy.ops.object.mode_set(mode="OBJECT")
    vg = o.vertex_groups.new(name=name)
    vg.add([v.index for v in o.data.vertices], 1.0, "REPLACE")
    objs.append(o)
bpy.ops.object.select_all(action="DESELECT")
for o in objs:
    o.select_set(True)
bpy.context.view_layer.objects.active = objs[0]
bpy.ops.object.join()
body = bpy.context.active_object
body.name = "Body"
# Blend the spine's rear vertices into the root group, and the neck into the head.
vgs = {g.name: g for g in body.vertex_groups}
for v in body.data.vertices:
    co = body.matrix_world @ v.co
    if 0.3 < co.y < 0.45 and co.z > 0.45:
        vgs["root"].add([v.index], 0.5, "REPLACE")
        vgs["spine"].add([v.index], 0.5, "REPLACE")
# Two materials: two primitives sharing one skin.
m1 = bpy.data.materials.new("Fur"); m1.diffuse_color = (0.8, 0.35, 0.1, 1)
m2 = bpy.data.materials.new("Legs"); m2.diffuse_color = (0.1, 0.1, 0.1, 1)
body.data.materials.append(m1); body.data.materials.append(m2)
for p in body.data.polygons:
    c = body.matrix_world @ p.center
    p.material_index = 1 if c.z < 0.35 else 0
# Parent to the armature keeping the world placement (the mesh object gets a parent inverse).
body.parent = arm
body.matrix_parent_inverse = arm.matrix_world.inverted()
mod = body.modifiers.new("Armature", "ARMATURE")
mod.object = arm

# A static pedestal.
bpy.ops.mesh.primitive_cylinder_add(radius=1.0, depth=0.2, location=(0.3, 0.6, -0.1))
bpy.context.active_object.name = "Pedestal"

# One action: the root bobs and turns, the legs swing, the head nods, the tail wags.
action = bpy.data.actions.new("Trot")
arm.animation_data_create()
arm.animation_data.action = action
pb = arm.pose.bones
for f in range(0, 49, 4):
    t = f / 24.0
    ph = 2 * math.pi * t
    pb["root"].location = (0.0, 0.05 * math.sin(2 * ph), 0.1 * math.sin(ph))
    pb["root"].rotation_mode = "QUATERNION"
    pb["root"].rotation_quaternion = Euler((0, 0, 0.4 * math.sin(ph))).to_quaternion()
    pb["head"].rotation_quaternion = Euler((0.5 * math.sin(ph), 0, 0)).to_quaternion()
    for name, s in (("leg_f.L", 1), ("leg_f.R", -1), ("leg_b.L", -1), ("leg_b.R", 1)):
        pb[name].rotation_quaternion = Euler((0.7 * s * math.sin(ph), 0, 0)).to_quaternion()
    pb["tail"].rotation_quaternion = Euler((0, 0, 0.8 * math.sin(3 * ph))).to_quaternion()
    for b in pb:
        b.keyframe_insert("rotation_quaternion", frame=f)
        b.keyframe_insert("location", frame=f)
scene.frame_start, scene.frame_end = 0, 48

# A camera (no lights: Hush and Mitsuba's conventions light the scene with a sun and sky).
cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
scene.collection.objects.link(cam)
cam.location = (3.2, -2.4, 1.8)
cam.rotation_euler = Euler((math.radians(70), 0, math.radians(52)))
scene.camera = cam
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_animations=True,
                          export_skins=True, export_apply=False, export_lights=False,
                          export_cameras=True)

# Blender's own pose at given frames, baked into static files: the evaluated body (armature
# modifier applied) as a new object at the body's world placement, beside the pedestal.
frames = [int(x) for x in sys.argv[sys.argv.index("--") + 2:]]
for f in frames:
    scene.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    ev = body.evaluated_get(dg)
    mesh = bpy.data.meshes.new_from_object(ev, depsgraph=dg)
    baked = bpy.data.objects.new(f"Baked{f}", mesh)
    baked.matrix_world = body.matrix_world.copy()
    scene.collection.objects.link(baked)
    print("frame", f, "root rotation", arm.pose.bones["root"].rotation_quaternion[:], "first vertex", (baked.matrix_world @ mesh.vertices[0].co)[:], "rest", (body.matrix_world @ body.data.vertices[0].co)[:])
    bpy.ops.object.select_all(action="DESELECT")
    for o in (baked, bpy.data.objects["Pedestal"], cam):
        o.select_set(True)
    bpy.ops.export_scene.gltf(filepath=out.replace(".glb", f"_baked_{f}.glb"), export_format="GLB",
                              use_selection=True, export_animations=False, export_skins=False,
                              export_lights=False, export_cameras=True)
    scene.collection.objects.unlink(baked)
