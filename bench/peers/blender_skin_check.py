# Blender (3.4, Debian) re-import check of a skinned glb (issue 24): prints one line
#   RESULT armatures=A bones=B modifiers=M actions=N first=F last=L moved=D
# D = largest vertex displacement between the action's first and last frames (world units).
# blender -b --factory-startup --python-exit-code 1 --python blender_skin_check.py -- FILE.glb
import sys
import numpy
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_  # Blender 3.4's glTF importer with numpy >= 1.24 (corpus README)
import bpy

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=path)
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
meshes = [o for o in bpy.data.objects if o.type == "MESH"]
mods = [m for o in meshes for m in o.modifiers if m.type == "ARMATURE" and m.object in arms]
acts = list(bpy.data.actions)
scene = bpy.context.scene


def verts(frame):
    scene.frame_set(frame)
    dg = bpy.context.evaluated_depsgraph_get()
    o = meshes[0].evaluated_get(dg)
    return [o.matrix_world @ v.co for v in o.data.vertices]


r = acts[0].frame_range if acts else (0, 0)
moved = 0.0
if meshes and acts:
    a = verts(int(r[0]))
    moved = max(max((p - q).length for p, q in zip(a, verts(int(f)))) for f in range(int(r[0]), int(r[1]) + 1))
print("RESULT armatures=%d bones=%d modifiers=%d actions=%d first=%g last=%g moved=%g" % (
    len(arms), len(arms[0].data.bones) if arms else 0, len(mods), len(acts), r[0], r[1], moved))
