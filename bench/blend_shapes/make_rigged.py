# A rigged mesh with a shape key (issue 34's skinned path): a subdivided cylinder on a two-bone
# armature (automatic weights) with shape key "Bulge" at 0.4, exported as .glb.
#   blender -b --python bench/blend_shapes/make_rigged.py -- OUTDIR
import bpy, math, sys
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=0.3, depth=2.0)
ob = bpy.context.active_object
bpy.ops.object.mode_set(mode='EDIT')
bpy.ops.mesh.subdivide(number_cuts=15)
bpy.ops.object.mode_set(mode='OBJECT')
bpy.ops.object.armature_add(location=(0, 0, -1))
arm = bpy.context.active_object
bpy.ops.object.mode_set(mode='EDIT')
b = arm.data.edit_bones[0]; b.head = (0, 0, -1); b.tail = (0, 0, 0)
b2 = arm.data.edit_bones.new("upper"); b2.head = (0, 0, 0); b2.tail = (0, 0, 1); b2.parent = b
bpy.ops.object.mode_set(mode='OBJECT')
ob.select_set(True); arm.select_set(True); bpy.context.view_layer.objects.active = arm
bpy.ops.object.parent_set(type='ARMATURE_AUTO')
ob.shape_key_add(name="Basis")
k = ob.shape_key_add(name="Bulge")
for i, v in enumerate(ob.data.vertices):
    s = 1 + 0.5 * math.exp(-((v.co.z - 0.4) / 0.3) ** 2) * max(0, v.co.x / 0.3)
    k.data[i].co.x = v.co.x * s
k.value = 0.4
bpy.ops.export_scene.gltf(filepath=out + "/rigged_bulge.glb", export_format='GLB', export_morph=True, export_skins=True)
print("verts", len(ob.data.vertices))
