"""Blender Decimate peer of bench/run (issue 6). Runs inside Blender (Debian blender 3.4):

    blender -b --factory-startup --python bench/peers/blender_decimate.py -- \
        INPUT.obj OUTPUT.obj MODE TARGET

MODE is `collapse` (Decimate modifier, collapse mode, use_collapse_triangulate=False: Blender
triangulates internally, collapses edges and joins the remaining triangles back into quads where
it can) or `unsubdiv` (un-subdivide mode). TARGET is the wanted triangle-equivalent count
(quad = 2, k-gon = k - 2), the same one quadlod is given.

* collapse: ratio = TARGET / input triangle-equivalents; when the result misses the target by
  more than 0.5 %, the ratio is rescaled by target/achieved and tried again (at most 4 tries); the
  try nearest to the target wins.
* unsubdiv: iterations 1, 2, ... are tried until the count stops falling or drops below the
  target; the iteration count nearest to the target wins.

The OBJ is imported with the C++ importer (bpy.ops.wm.obj_import, Blender 3.2+) with the identity
axis mapping (forward Y, up Z), all mesh objects are joined, and the evaluated mesh is written by
this script (positions, polygons, the active UV layer as `vt` and material slots as `usemtl`, in
the input's coordinates; issue 7's UV comparison, bench/uv_compare, measures the UVs) to a
temporary file next to OUTPUT, then renamed. UVs are written one `vt` per distinct value, so
seams (different values at one vertex) survive and nothing else is split. One line `QUADLOD_PEER {json}` on stdout reports the mode, the parameter
chosen, every try, the achieved count and the seconds of the modifier evaluations. Any failure
prints `QUADLOD_PEER_ERROR message` and exits with status 2.
"""

import json
import os
import sys
import tempfile
import time
import traceback

import bpy


def fail(message):
    print("QUADLOD_PEER_ERROR " + message.replace("\n", " "), flush=True)
    sys.stdout.flush()
    os._exit(2)


def tri_equivalent(mesh):
    return sum(len(p.vertices) - 2 for p in mesh.polygons)


def main(argv):
    if len(argv) != 4:
        fail("usage: blender -b --python blender_decimate.py -- INPUT OUTPUT collapse|unsubdiv TARGET")
    src, dst, mode, target = argv[0], argv[1], argv[2], int(argv[3])
    if mode not in ("collapse", "unsubdiv"):
        fail("unknown mode " + mode)
    if target < 1:
        fail("TARGET must be >= 1")

    bpy.ops.wm.read_factory_settings(use_empty=True)
    t0 = time.perf_counter()
    result = bpy.ops.wm.obj_import(filepath=src, forward_axis="Y", up_axis="Z")
    if "FINISHED" not in result:
        fail(src + ": OBJ import failed")
    objs = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if not objs:
        fail(src + ": no mesh imported")
    bpy.ops.object.select_all(action="DESELECT")
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]
    if len(objs) > 1:
        bpy.ops.object.join()
    obj = bpy.context.view_layer.objects.active
    seconds_import = time.perf_counter() - t0
    tri_in = tri_equivalent(obj.data)
    if tri_in < 1:
        fail(src + ": no faces")

    mod = obj.modifiers.new(name="quadlod_bench", type="DECIMATE")
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def evaluate():
        depsgraph.update()
        ev = obj.evaluated_get(depsgraph)
        m = ev.to_mesh()
        n = tri_equivalent(m)
        ev.to_mesh_clear()
        return n

    tries = []
    t1 = time.perf_counter()
    if mode == "collapse":
        mod.decimate_type = "COLLAPSE"
        mod.use_collapse_triangulate = False
        ratio = min(1.0, target / tri_in)
        for _ in range(4):
            mod.ratio = ratio
            n = evaluate()
            tries.append({"ratio": ratio, "achieved": n})
            if abs(n - target) <= 0.005 * target or n == 0:
                break
            new_ratio = min(1.0, ratio * target / n)
            if abs(new_ratio - ratio) < 1e-7:
                break
            ratio = new_ratio
        best = min(tries, key=lambda t: abs(t["achieved"] - target))
        mod.ratio = best["ratio"]
        parameter = {"ratio": best["ratio"]}
    else:
        mod.decimate_type = "UNSUBDIV"
        previous = tri_in
        for it in range(1, 33):
            mod.iterations = it
            n = evaluate()
            tries.append({"iterations": it, "achieved": n})
            if n >= previous or n <= target:
                break
            previous = n
        best = min(tries, key=lambda t: (abs(t["achieved"] - target), t["iterations"]))
        mod.iterations = best["iterations"]
        parameter = {"iterations": best["iterations"]}
    seconds_search = time.perf_counter() - t1

    # The final mesh, then written by hand: positions, polygons, UVs (active layer), materials.
    t2 = time.perf_counter()
    depsgraph.update()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    seconds_final = time.perf_counter() - t2
    mw = obj.matrix_world
    achieved = tri_equivalent(mesh)
    quads = sum(1 for p in mesh.polygons if len(p.vertices) == 4)
    tris = sum(1 for p in mesh.polygons if len(p.vertices) == 3)
    directory = os.path.dirname(os.path.abspath(dst))
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(dst) + ".", dir=directory)
    try:
        with os.fdopen(fd, "w") as out:
            out.write("# quadlod bench peer: Blender %s Decimate %s %s\n"
                      % (bpy.app.version_string, mode, json.dumps(parameter)))
            identity = all(abs(mw[i][j] - (1.0 if i == j else 0.0)) < 1e-12
                           for i in range(4) for j in range(4))
            for v in mesh.vertices:
                co = v.co if identity else mw @ v.co
                out.write("v %.9g %.9g %.9g\n" % (co.x, co.y, co.z))
            uv_layer = mesh.uv_layers.active
            loop_vt = []
            if uv_layer is not None:
                vt_of = {}
                for d in uv_layer.data:
                    key = (d.uv[0], d.uv[1])
                    if key not in vt_of:
                        vt_of[key] = len(vt_of) + 1
                        out.write("vt %.9g %.9g\n" % key)
                    loop_vt.append(vt_of[key])
            names = [slot.material.name if slot.material else "" for slot in obj.material_slots]
            current = None
            for p in mesh.polygons:
                if names and p.material_index < len(names) and names[p.material_index] != current:
                    current = names[p.material_index]
                    out.write("usemtl %s\n" % current)
                if loop_vt:
                    out.write("f " + " ".join("%d/%d" % (mesh.loops[li].vertex_index + 1, loop_vt[li])
                                              for li in p.loop_indices) + "\n")
                else:
                    out.write("f " + " ".join(str(i + 1) for i in p.vertices) + "\n")
        os.replace(tmp, dst)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    ev.to_mesh_clear()
    report = {
        "peer": "blender", "version": bpy.app.version_string, "mode": mode,
        "parameter": parameter, "tries": tries, "target": target,
        "tri_equivalent_in": tri_in, "achieved": achieved, "quads": quads, "tris": tris,
        "seconds_import": seconds_import, "seconds_search": seconds_search,
        "seconds_final": seconds_final,
    }
    print("QUADLOD_PEER " + json.dumps(report), flush=True)


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(args)
    except SystemExit:
        raise
    except BaseException as e:  # noqa: BLE001 - every failure becomes one line
        traceback.print_exc()
        fail("%s: %s" % (type(e).__name__, str(e).splitlines()[0] if str(e) else ""))
    sys.stdout.flush()
    os._exit(0)
