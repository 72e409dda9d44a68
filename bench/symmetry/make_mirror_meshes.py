# Two exactly mirror-symmetric meshes outside the corpus for issue 34's bar (docs/symmetry.md),
# made the way artists make them: one half, then Blender's Mirror modifier (merge on the plane).
#
#   blender -b --factory-startup --python bench/symmetry/make_mirror_meshes.py -- OUTDIR
#
# OUTDIR/suzanne_subdiv_mirror.obj: Suzanne, Catmull–Clark once, its x < 0 half deleted and
#   mirrored back (so the halves are exact reflections, not equal up to the subdivision's rounding).
# OUTDIR/creature_mirror.obj: a UV sphere whose right half is dented at random (seeded) and grows
#   two extruded horns, smart-UV-projected, mirrored (the modifier mirrors the UVs as well).
# OUTDIR/creature_mirror_smartuv.obj: the same mesh unwrapped again after the mirror, so its UV
#   islands are not mirror images (what "Attributes" in docs/symmetry.md is about).
# Both exported as quads and triangles (no triangulation), with UVs; Blender's -Z forward / Y up
# keeps x, the mirror axis.
import bmesh
import bpy
import mathutils
import random
import sys

out = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "."


def clear():
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()


def smart_uv(obj):
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.uv.smart_project(island_margin=0.01)
    bpy.ops.object.mode_set(mode="OBJECT")


def mirror_half(obj, unwrap_half=False):
    """Deletes the x < 0 half and applies a Mirror modifier across x (clipping, merge); with
    unwrap_half, the half is smart-UV-projected first, so the modifier mirrors its UVs too."""
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bm = bmesh.from_edit_mesh(obj.data)
    bmesh.ops.delete(bm, geom=[v for v in bm.verts if v.co.x < -1e-5], context="VERTS")
    for v in bm.verts:
        if abs(v.co.x) <= 1e-5:
            v.co.x = 0.0  # exactly on the plane
    bmesh.update_edit_mesh(obj.data)
    bpy.ops.object.mode_set(mode="OBJECT")
    if unwrap_half:
        smart_uv(obj)
    m = obj.modifiers.new("Mirror", "MIRROR")
    m.use_axis[0] = True
    m.use_clip = True
    m.use_mirror_merge = True
    m.merge_threshold = 1e-4
    bpy.ops.object.modifier_apply(modifier=m.name)


def export(obj, name):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.export_scene.obj(filepath=f"{out}/{name}", use_selection=True, use_triangles=False, use_uvs=True,
                             use_normals=False, use_materials=False)


clear()
bpy.ops.mesh.primitive_monkey_add()
suz = bpy.context.active_object
sub = suz.modifiers.new("Subsurf", "SUBSURF")
sub.levels = 1
bpy.ops.object.modifier_apply(modifier=sub.name)
mirror_half(suz)
export(suz, "suzanne_subdiv_mirror.obj")

clear()
bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
cr = bpy.context.active_object
bpy.ops.object.mode_set(mode="EDIT")
bm = bmesh.from_edit_mesh(cr.data)
rng = random.Random(34)
for v in bm.verts:
    if v.co.x > 1e-5:
        v.co += v.normal * (0.08 * rng.random())
bm.faces.ensure_lookup_table()
for centre in ((0.55, 0.0, 0.8), (0.9, -0.3, -0.2)):
    best = min(bm.faces, key=lambda f: (f.calc_center_median() - mathutils.Vector(centre)).length)
    faces = [best]
    n = best.normal.copy()
    for step in range(3):
        r = bmesh.ops.extrude_face_region(bm, geom=faces)
        bmesh.ops.delete(bm, geom=faces, context="FACES_ONLY")  # the region's old faces stay inside
        verts = [g for g in r["geom"] if isinstance(g, bmesh.types.BMVert)]
        faces = [g for g in r["geom"] if isinstance(g, bmesh.types.BMFace)]
        bmesh.ops.translate(bm, vec=n * 0.25, verts=verts)
        bmesh.ops.scale(bm, vec=(0.8, 0.8, 0.8), space=mathutils.Matrix.Translation(
            -sum((v.co for v in verts), mathutils.Vector()) / len(verts)), verts=verts)
bmesh.update_edit_mesh(cr.data)
bpy.ops.object.mode_set(mode="OBJECT")
mirror_half(cr, unwrap_half=True)
export(cr, "creature_mirror.obj")
smart_uv(cr)  # unwrapped again as a whole: islands that are not mirror images
export(cr, "creature_mirror_smartuv.obj")
