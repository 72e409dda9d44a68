# Bar inputs (issue 34): two Blender-made meshes with one shape key each, exported as .glb.
import bpy, math, sys
out = sys.argv[sys.argv.index("--") + 1]

def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)

# 1. Suzanne, subdivided twice (quads), shape key "Smile": the mouth region lifts and widens.
reset()
bpy.ops.mesh.primitive_monkey_add()
ob = bpy.context.active_object
mod = ob.modifiers.new("s", 'SUBSURF'); mod.levels = 2
bpy.ops.object.modifier_apply(modifier="s")
ob.shape_key_add(name="Basis")
k = ob.shape_key_add(name="Smile")
for i, v in enumerate(ob.data.vertices):
    c = v.co
    # mouth: front (y < -0.6), lower face (z < -0.15); a smooth falloff
    w = max(0.0, 1.0 - ((c.z + 0.35) / 0.3) ** 2) * max(0.0, min(1.0, (-c.y - 0.55) / 0.2))
    k.data[i].co.z = c.z + 0.18 * w * (c.x * c.x * 4.0 + 0.2)
    k.data[i].co.x = c.x * (1.0 + 0.25 * w)
bpy.ops.export_scene.gltf(filepath=out + "/suzanne_smile.glb", export_format='GLB', export_morph=True)
print("suzanne", len(ob.data.vertices), len(ob.data.polygons))

# 2. A character-like arm: a tube of quads (64 rings of 48) whose radius swells and narrows and
#    whose axis bends, capped by two n-gons, with shape key "Flex": a muscle bulge on one side.
reset()
import bmesh
me = bpy.data.meshes.new("arm")
bm = bmesh.new()
rings, around = 64, 48
def ring_point(r, a):
    # a forearm-like profile: the radius swells and narrows along the arm (wrist, forearm, elbow)
    # and the axis bends a little, so that the base itself has something to lose
    z = -1.0 + 2.0 * r / (rings - 1)
    radius = 0.25 * (1.0 + 0.2 * math.sin(2.5 * z) + 0.08 * math.cos(7.0 * z))
    t = 2 * math.pi * a / around
    return (radius * math.cos(t) + 0.15 * z * z, radius * math.sin(t), z)
verts = [[bm.verts.new(ring_point(r, a)) for a in range(around)] for r in range(rings)]
for r in range(rings - 1):
    for a in range(around):
        b = (a + 1) % around
        bm.faces.new((verts[r][a], verts[r][b], verts[r + 1][b], verts[r + 1][a]))
bm.faces.new([verts[0][a] for a in reversed(range(around))])
bm.faces.new([verts[-1][a] for a in range(around)])
bm.to_mesh(me)
ob = bpy.data.objects.new("arm", me)
bpy.context.collection.objects.link(ob)
ob.shape_key_add(name="Basis")
k = ob.shape_key_add(name="Flex")
for i, v in enumerate(ob.data.vertices):
    c = v.co
    cx = 0.15 * c.z * c.z  # the bent axis at this height
    r = math.hypot(c.x - cx, c.y)
    if r < 1e-6:
        continue
    side = max(0.0, (c.x - cx) / r)  # the front half
    along = math.exp(-((c.z - 0.3) / 0.25) ** 2)
    s = 1.0 + 0.6 * along * side ** 2
    k.data[i].co.x = cx + (c.x - cx) * s
    k.data[i].co.y = c.y * s
bpy.ops.export_scene.gltf(filepath=out + "/arm_flex.glb", export_format='GLB', export_morph=True)
print("arm", len(ob.data.vertices), len(ob.data.polygons))
