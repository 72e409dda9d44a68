# Imports a .glb and writes its basis and its first shape key at full weight as OBJ (world space).
import sys, numpy
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_
import bpy
args = sys.argv[sys.argv.index("--") + 1:]
path, base_obj, key_obj = args
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=path)
ob = [o for o in bpy.data.objects if o.type == "MESH"][0]
keys = ob.data.shape_keys.key_blocks if ob.data.shape_keys else []
print("SHAPEKEYS", path, [k.name for k in keys])
def export(fn, value):
    for k in keys[1:]:
        k.value = 0.0
    if len(keys) > 1:
        keys[1].value = value
    bpy.ops.object.select_all(action='DESELECT')
    ob.select_set(True)
    bpy.ops.export_scene.obj(filepath=fn, use_selection=True, use_materials=False, use_uvs=False,
                             use_normals=False, use_mesh_modifiers=True, axis_forward='-Z', axis_up='Y')
export(base_obj, 0.0)
export(key_obj, 1.0)
