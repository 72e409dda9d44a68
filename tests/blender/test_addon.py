"""The Blender add-on, inside Blender (issue 22):

  blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- ZIP

installs the add-on zip, enables it, builds a torus with UVs and two materials (and a vertex
group), runs "Quad-dominant LOD" with two levels and checks the LODs: collection, counts, quad
fraction, UV layer, material slots and indices, vertex group, the original untouched; a "Protect"
vertex group whose vertices keep their exact positions (issue 34); then that
a bad mesh gives an error report, not a crash; and that `import quadlod` is the module. Run it
with BLENDER_USER_SCRIPTS / BLENDER_USER_CONFIG pointing at a fresh directory
(tests/blender/run_blender_tests.py does) so the user's Blender setup is not touched.
"""

import sys
import traceback

import bpy

failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


def counts(mesh):
    sizes = [p.loop_total for p in mesh.polygons]
    return dict(faces=len(sizes), quads=sum(k == 4 for k in sizes), tri_equivalent=sum(k - 2 for k in sizes))


def mesh_dict(mesh):
    from quadlod.blender_addon import _mesh_arrays

    a = _mesh_arrays(mesh)
    return dict(vertices=a["vertices"], faces=a["faces"][0], face_sizes=a["faces"][1], uvs=a["uvs"],
                materials=a["materials"])


def make_test_object():
    bpy.ops.mesh.primitive_torus_add(major_segments=48, minor_segments=16, generate_uvs=True)
    obj = bpy.context.active_object
    obj.name = "Ring"
    red = bpy.data.materials.new("Red")
    blue = bpy.data.materials.new("Blue")
    obj.data.materials.append(red)
    obj.data.materials.append(blue)
    for p in obj.data.polygons:  # two materials: one half of the ring each
        p.material_index = 1 if p.center.x > 0 else 0
    group = obj.vertex_groups.new(name="Upper")
    group.add([v.index for v in obj.data.vertices if v.co.z > 0], 1.0, "REPLACE")
    return obj


def main(zip_path):
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    bpy.ops.preferences.addon_enable(module="quadlod")
    import quadlod

    check(callable(quadlod.simplify) and callable(quadlod.lod_chain) and callable(quadlod.evaluate),
          "import quadlod gives the module API inside Blender")
    check(hasattr(bpy.ops.object, "quadlod_lod"), "operator registered")
    check(any(getattr(f, "__module__", "").startswith("quadlod") for f in bpy.types.VIEW3D_MT_object._dyn_ui_initialize()),
          "operator in the Object menu")

    obj = make_test_object()
    before = counts(obj.data)
    before_vertices = [tuple(v.co) for v in obj.data.vertices]
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    result = bpy.ops.object.quadlod_lod(levels=2, ratio=0.5, protect_uv_seams=True)
    check(result == {"FINISHED"}, f"operator finished ({result})")

    coll = bpy.data.collections.get("Ring_LODs")
    check(coll is not None, "collection Ring_LODs exists")
    lods = sorted(coll.objects, key=lambda o: o.name) if coll else []
    check([o.name for o in lods] == ["Ring_LOD1", "Ring_LOD2"], f"two LOD objects ({[o.name for o in lods]})")
    check(counts(obj.data) == before and [tuple(v.co) for v in obj.data.vertices] == before_vertices,
          "original mesh untouched")
    for k, lod in enumerate(lods, start=1):
        c = counts(lod.data)
        target = round(before["tri_equivalent"] * 0.5 ** k)
        check(abs(c["tri_equivalent"] - target) <= 0.03 * target + 2,
              f"LOD{k}: {c['tri_equivalent']} triangle-equivalents for a target of {target}")
        check(lod["quadlod_report"]["achieved"] == c["tri_equivalent"], f"LOD{k}: report matches the mesh")
        check(c["quads"] / c["faces"] >= 0.9, f"LOD{k}: quad fraction {c['quads'] / c['faces']:.3f} >= 0.9")
        check([layer.name for layer in lod.data.uv_layers] == [layer.name for layer in obj.data.uv_layers],
              f"LOD{k}: UV layers {[layer.name for layer in lod.data.uv_layers]}")
        uv = lod.data.uv_layers[0].data if lod.data.uv_layers else []
        eps = 1e-6  # UVs are re-projected within their chart: they stay in the input's [0, 1] square
        check(len(uv) == len(lod.data.loops) and all(-eps <= d.uv.x <= 1 + eps and -eps <= d.uv.y <= 1 + eps for d in uv),
              f"LOD{k}: one UV per loop, inside the input's [0, 1] range")
        check([m.name for m in lod.data.materials] == ["Red", "Blue"], f"LOD{k}: material slots Red, Blue")
        used = {p.material_index for p in lod.data.polygons}
        check(used == {0, 1}, f"LOD{k}: both material slots used ({used})")
        # The material border (x = 0 plane) survives: every face keeps the side of its material.
        wrong = sum(1 for p in lod.data.polygons if (p.center.x > 0) != (p.material_index == 1))
        check(wrong == 0, f"LOD{k}: {wrong} faces on the wrong side of the material border")
        check("Upper" in lod.vertex_groups, f"LOD{k}: vertex group carried")
        check(lod.matrix_world == obj.matrix_world, f"LOD{k}: same transform as the source")
        # The module's own metrics on the Blender meshes: no seam torn, no two UV islands merged.
        metrics = quadlod.evaluate(mesh_dict(obj.data), mesh_dict(lod.data), samples=20000)
        check(metrics["seams_torn"] == 0 and metrics["uv_islands_merged"] == 0,
              f"LOD{k}: {metrics['seams_torn']} seams torn, {metrics['uv_islands_merged']} UV islands merged")

    # Issue 34: the "Protect" vertex group reaches the reduction. A ring whose group holds the
    # vertices with x > 0.6 at weight 1: both LODs keep each of them at its exact position (and
    # the first LOD's weights carry them into the second); without the group they move.
    bpy.ops.mesh.primitive_torus_add(major_segments=48, minor_segments=16, location=(0, 0, -5))
    ring = bpy.context.active_object
    ring.name = "Guarded"
    keep = ring.vertex_groups.new(name="Keep")
    keep_ids = [v.index for v in ring.data.vertices if v.co.x > 0.6]
    keep.add(keep_ids, 1.0, "REPLACE")
    kept = {tuple(ring.data.vertices[i].co) for i in keep_ids}
    check(0.1 * len(ring.data.vertices) < len(kept) < 0.3 * len(ring.data.vertices), f"{len(kept)} vertices in group Keep")
    bpy.ops.object.select_all(action="DESELECT")
    ring.select_set(True)
    bpy.context.view_layer.objects.active = ring
    check(bpy.ops.object.quadlod_lod(levels=2, ratio=0.5, protect_group="Keep") == {"FINISHED"},
          "operator with a Protect vertex group")
    for k in (1, 2):
        lod = bpy.data.objects.get(f"Guarded_LOD{k}")
        out = {tuple(v.co) for v in lod.data.vertices} if lod else set()
        missing = len(kept - out)
        check(lod is not None and missing == 0, f"Guarded LOD{k}: {missing} of {len(kept)} protected vertices moved")
        check(lod is not None and lod["quadlod_report"].get("protected_vertices") == len(kept),
              f"Guarded LOD{k}: the report counts {lod['quadlod_report'].get('protected_vertices') if lod else None} protected")
    ring.name = "Unguarded"
    check(bpy.ops.object.quadlod_lod(levels=1, ratio=0.5) == {"FINISHED"}, "operator without a Protect group")
    plain = bpy.data.objects.get("Unguarded_LOD1")
    moved = len(kept - {tuple(v.co) for v in plain.data.vertices}) if plain else 0
    check(moved > len(kept) // 4, f"without the group {moved} of {len(kept)} of those vertices move")

    # Custom split normals travel: a cylinder with custom normals (all pointing up, so they are
    # recognisably not the ones Blender would compute) gets LODs with custom normals pointing up.
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, depth=1.0, location=(0, 0, 5))
    tube = bpy.context.active_object
    tube.data.use_auto_smooth = True
    tube.data.normals_split_custom_set([(0.0, 0.0, 1.0)] * len(tube.data.loops))
    check(tube.data.has_custom_normals, "test cylinder has custom normals")
    bpy.ops.object.select_all(action="DESELECT")
    tube.select_set(True)
    bpy.context.view_layer.objects.active = tube
    check(bpy.ops.object.quadlod_lod(levels=1, ratio=0.6) == {"FINISHED"}, "operator on the custom-normal mesh")
    lod = bpy.data.objects.get(tube.name + "_LOD1")
    check(lod is not None and lod.data.has_custom_normals, "LOD keeps custom split normals")
    if lod is not None:
        lod.data.calc_normals_split()
        up = sum(1 for loop in lod.data.loops if loop.normal.z > 0.99)
        check(up == len(lod.data.loops), f"LOD normals are the custom ones ({up} of {len(lod.data.loops)} point up)")

    # Symmetry (issue 34): Suzanne, her x < 0 half mirrored back (exact reflections), reduced with
    # the toggle on gives a LOD whose every vertex has its mirror; the report names the plane.
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, -5))
    monkey = bpy.context.active_object
    monkey.name = "Monkey"
    import bmesh
    bm = bmesh.new()
    bm.from_mesh(monkey.data)
    bmesh.ops.delete(bm, geom=[v for v in bm.verts if v.co.x < -1e-5], context="VERTS")
    for v in bm.verts:
        if abs(v.co.x) <= 1e-5:
            v.co.x = 0.0
    bm.to_mesh(monkey.data)
    bm.free()
    bpy.ops.object.select_all(action="DESELECT")
    monkey.select_set(True)
    bpy.context.view_layer.objects.active = monkey
    mirror = monkey.modifiers.new("Mirror", "MIRROR")
    mirror.use_clip = True
    bpy.ops.object.modifier_apply(modifier=mirror.name)

    def unmirrored(mesh):
        points = [tuple(v.co) for v in mesh.vertices]
        tol = 1e-6 * max(1.0, max(abs(c) for p in points for c in p))
        return sum(1 for p in points if min(abs(p[0] + q[0]) + abs(p[1] - q[1]) + abs(p[2] - q[2]) for q in points) > tol)

    check(unmirrored(monkey.data) == 0, "test monkey is mirror-symmetric")
    for toggle, axis in ((True, "AUTO"), (True, "X")):
        for o in list(bpy.data.objects):
            if o.name.startswith("Monkey_LOD"):
                bpy.data.objects.remove(o)
        monkey.select_set(True)
        bpy.context.view_layer.objects.active = monkey
        check(bpy.ops.object.quadlod_lod(levels=1, ratio=0.4, symmetry=toggle, symmetry_axis=axis) == {"FINISHED"},
              f"operator with symmetry {axis}")
        lod = bpy.data.objects.get("Monkey_LOD1")
        check(lod is not None and unmirrored(lod.data) == 0,
              f"symmetry {axis}: every LOD vertex has its mirror ({lod and unmirrored(lod.data)} without)")
        check(lod is not None and lod["quadlod_report"]["symmetry"] == "x",
              f"symmetry {axis}: the report names the x plane")

    # Shape keys travel (issue 34): a grid whose key lifts one vertex gets LODs with the key, its
    # value, and the lifted vertex lifted where it survives.
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=16, y_subdivisions=16, size=2.0, location=(0, 0, 10))
    grid = bpy.context.active_object
    grid.name = "Sheet"
    grid.shape_key_add(name="Basis")
    key = grid.shape_key_add(name="Lift")
    lifted = min(range(len(grid.data.vertices)), key=lambda i: (grid.data.vertices[i].co.x - 0.25) ** 2 + grid.data.vertices[i].co.y ** 2)
    key.data[lifted].co.z += 0.5
    key.value = 0.3
    bpy.ops.object.select_all(action="DESELECT")
    grid.select_set(True)
    bpy.context.view_layer.objects.active = grid
    check(bpy.ops.object.quadlod_lod(levels=1, ratio=0.4) == {"FINISHED"}, "operator on the mesh with a shape key")
    lod = bpy.data.objects.get("Sheet_LOD1")
    keys = lod.data.shape_keys.key_blocks if lod is not None and lod.data.shape_keys else []
    check([k.name for k in keys] == ["Basis", "Lift"], f"LOD has the shape keys ({[k.name for k in keys]})")
    if len(keys) == 2:
        check(abs(keys["Lift"].value - 0.3) < 1e-6, f"LOD key keeps its value ({keys['Lift'].value})")
        moved = [(b.co, k.co) for b, k in zip(keys[0].data, keys[1].data) if (k.co - b.co).length > 1e-6]
        top = max(((k - b).z for b, k in moved), default=0.0)
        check(len(moved) > 0 and top <= 0.5 + 1e-6, f"LOD key moves {len(moved)} vertices, by up to {top:.3f}")
        check(counts(grid.data)["tri_equivalent"] > counts(lod.data)["tri_equivalent"], "LOD is reduced")

    # A mesh without faces: an error report and a cancelled operator, Blender goes on.
    empty_mesh = bpy.data.meshes.new("Empty")
    empty_mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [])
    empty = bpy.data.objects.new("Empty", empty_mesh)
    bpy.context.scene.collection.objects.link(empty)
    bpy.ops.object.select_all(action="DESELECT")
    empty.select_set(True)
    bpy.context.view_layer.objects.active = empty
    try:
        outcome = bpy.ops.object.quadlod_lod(levels=1)
        check(False, f"no-face mesh must be refused, got {outcome}")
    except RuntimeError as error:  # Blender turns an ERROR report into RuntimeError for scripts
        check("has no faces" in str(error), f"no-face mesh refused with a report: {error}")
    check("Empty_LODs" not in bpy.data.collections or not bpy.data.collections["Empty_LODs"].objects,
          "no LOD object made for the refused mesh")

    # Installing the zip again over the enabled add-on (an update) must not crash the session:
    # Blender rewrites the installed files in place, so the extension runs from a private copy.
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    check(bpy.ops.object.quadlod_lod(levels=1) == {"FINISHED"}, "operator runs after re-installing the zip")


if __name__ == "__main__":  # screenshot_panel.py imports make_test_object only
    try:
        main(sys.argv[sys.argv.index("--") + 1])
    except Exception:
        traceback.print_exc()
        failures.append("exception")
    print(f"test_addon: {len(failures)} failure(s)")
    if failures:
        sys.exit(1)
