#!/usr/bin/python3
"""Issue 21's bar: corpus meshes exported by Blender to .glb and .fbx go through
`quadlod simplify` and `quadlod lod`; the FBX outputs keep their quads (counted by Blender
importing them) and reach the quad fraction of the same run from the OBJ (within 1 point).

Usage: bench/scene_bar.py [--quadlod build/quadlod] [--corpus DIR] [--work DIR]
                          [--ratio 0.5] [--levels 0.5,0.25] [MESH.obj ...]
Default meshes: the corpus files under --max-faces faces (default 8000). Needs Debian's blender.
Prints one line per mesh and format, then the largest quad-fraction difference FBX vs OBJ.
"""
import argparse
import json
import os
import re
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))

CONVERT = r"""
import bpy, sys
args = sys.argv[sys.argv.index('--') + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=args[0])
if args[3] == 'smooth':
    # The OBJ has no `vn`: a reader without normals shades smooth; say so to Blender, whose FBX
    # export always writes normals (flat faces would make every edge a normal seam).
    for o in bpy.context.scene.objects:
        if o.type == 'MESH':
            for p in o.data.polygons:
                p.use_smooth = True
bpy.ops.export_scene.fbx(filepath=args[1])
bpy.ops.export_scene.gltf(filepath=args[2], export_format='GLB')
"""

COUNT = r"""
import bpy, sys
args = sys.argv[sys.argv.index('--') + 1:]
for path in args:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    try:
        bpy.ops.import_scene.fbx(filepath=path)
    except Exception as e:
        print('QUADLOD_FAILED', path, str(e).splitlines()[-1:], flush=True)
        continue
    q = t = n = 0
    for o in bpy.context.scene.objects:
        if o.type != 'MESH':
            continue
        for p in o.data.polygons:
            k = len(p.vertices)
            if k == 4: q += 1
            elif k == 3: t += 1
            else: n += 1
    print('QUADLOD_COUNT', path, q, t, n, flush=True)
"""

FACES_RE = re.compile(r"(\d+) quads, (\d+) tris, (\d+) n-gons")


def blender(script, *args):
    out = subprocess.run(["blender", "-b", "--factory-startup", "--python-expr", script, "--", *args],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError("blender failed: " + out.stderr[-2000:])
    return out.stdout


def blender_counts(paths):
    counts = {}
    for line in blender(COUNT, *paths).splitlines():
        if line.startswith("QUADLOD_COUNT"):
            _, path, q, t, n = line.split()
            counts[path] = (int(q), int(t), int(n))
    return counts


def write_float32_obj(src, dst):
    with open(src) as f, open(dst, "w") as out:
        for line in f:
            if line.startswith(("v ", "vt ", "vn ")):
                p = line.split()
                out.write(p[0] + " " + " ".join(repr(struct.unpack("f", struct.pack("f", float(x)))[0]) for x in p[1:]) + "\n")
            else:
                out.write(line)


def quad_fraction(q, t, n):
    return q / (q + t + n) if q + t + n else 0.0


def run(cmd):
    start = time.time()
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(" ".join(cmd) + ": " + out.stderr.strip())
    return out.stdout, time.time() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quadlod", default=os.path.join(HERE, "..", "build", "quadlod"))
    ap.add_argument("--corpus", default=os.path.join(HERE, "..", "..", "shared", "corpus"))
    ap.add_argument("--work", default="/tmp/quadlod_scene_bar")
    ap.add_argument("--ratio", default="0.5")
    ap.add_argument("--levels", default="0.5,0.25")
    ap.add_argument("--max-faces", type=int, default=8000)
    ap.add_argument("meshes", nargs="*")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    meshes = a.meshes
    if not meshes:
        meshes = []
        for name in sorted(os.listdir(a.corpus)):
            if not name.endswith(".obj"):
                continue
            with open(os.path.join(a.corpus, name)) as f:
                faces = sum(1 for line in f if line.startswith("f "))
            if faces < a.max_faces:
                meshes.append(os.path.join(a.corpus, name))
    worst = {"simplify": 0.0, "lod": 0.0, "simplify32": 0.0, "lod32": 0.0, "fbx_vs_32": 0.0, "lod_fbx_vs_32": 0.0}
    print(f"{'mesh':34} {'fmt':4} {'in quads/tris/ngons':>20} {'simplify out (quadlod)':>24} "
          f"{'out (blender)':>18} {'qf':>6} {'dqf':>7} {'lod qf per level':>22} {'dqf':>7} {'s':>6}")
    for mesh in meshes:
        stem = os.path.splitext(os.path.basename(mesh))[0]
        d = os.path.join(a.work, stem)
        os.makedirs(d, exist_ok=True)
        fbx, glb = os.path.join(d, stem + ".fbx"), os.path.join(d, stem + ".glb")
        if not (os.path.exists(fbx) and os.path.exists(glb)):
            with open(mesh) as f:
                has_normals = any(line.startswith("vn ") for line in f)
            blender(CONVERT, mesh, fbx, glb, "keep" if has_normals else "smooth")
        # The OBJ with every coordinate rounded to float32, as Blender and FBX store them: the
        # reduction's own sensitivity to that rounding is the floor of any FBX-vs-OBJ difference.
        obj32 = os.path.join(d, stem + ".f32.obj")
        if not os.path.exists(obj32):
            write_float32_obj(mesh, obj32)
        results = {}
        for fmt, src in (("obj", mesh), ("obj32", obj32), ("fbx", fbx), ("glb", glb)):
            ext = "obj" if fmt == "obj32" else fmt
            out_file = os.path.join(d, "out_" + fmt + "." + ext)
            stdout, sec = run([a.quadlod, "-q", "simplify", src, "-o", out_file, "--ratio", a.ratio])
            q, t, n = map(int, FACES_RE.search(stdout).groups())
            lod_dir = os.path.join(d, "lod_" + fmt)
            _, lsec = run([a.quadlod, "-q", "lod", src, "-o", lod_dir, "--levels", a.levels, "--format", ext])
            with open(os.path.join(lod_dir, "lods.json")) as f:
                levels = json.load(f)["levels"]
            results[fmt] = {"counts": (q, t, n), "seconds": sec + lsec, "out": out_file,
                            "lod_qf": [lv["quad_fraction"] for lv in levels],
                            "lod_files": [os.path.join(lod_dir, lv["file"]) for lv in levels]}
        # FBX only: Blender 3.4's glTF importer fails on Debian 12 (numpy 1.24 removed np.bool).
        blender_paths = [results["fbx"]["out"], *results["fbx"]["lod_files"]]
        counts = blender_counts(blender_paths)
        ref = quad_fraction(*results["obj"]["counts"])
        for fmt in ("obj", "obj32", "fbx", "glb"):
            r = results[fmt]
            qf = quad_fraction(*r["counts"])
            bl = counts.get(r["out"], None)
            bl_text = "/".join(map(str, bl)) if bl else "-"
            dqf = qf - ref
            lod_d = max(abs(x - y) for x, y in zip(r["lod_qf"], results["obj"]["lod_qf"]))
            if fmt == "obj32":
                worst["simplify32"] = max(worst["simplify32"], abs(dqf))
                worst["lod32"] = max(worst["lod32"], lod_d)
            if fmt == "fbx":
                worst["simplify"] = max(worst["simplify"], abs(dqf))
                worst["lod"] = max(worst["lod"], lod_d)
                # The FBX holds Blender's float32 coordinates: against the float32 OBJ, a
                # difference is the FBX path's own (its input or its normals), not rounding.
                worst["fbx_vs_32"] = max(worst["fbx_vs_32"], abs(qf - quad_fraction(*results["obj32"]["counts"])))
                worst["lod_fbx_vs_32"] = max(worst["lod_fbx_vs_32"], max(
                    abs(x - y) for x, y in zip(r["lod_qf"], results["obj32"]["lod_qf"])))
                # Blender must see the quads quadlod wrote.
                if bl and bl[0] != r["counts"][0]:
                    bl_text += " MISMATCH"
                for lf in r["lod_files"]:
                    if lf in counts and counts[lf][0] == 0:
                        bl_text += " LOD-NO-QUADS"
            print(f"{stem[:34]:34} {fmt:4} {'':>20} {'/'.join(map(str, r['counts'])):>24} {bl_text:>18} "
                  f"{qf:6.3f} {dqf:+7.3f} {','.join(f'{x:.3f}' for x in r['lod_qf']):>22} {lod_d:7.3f} "
                  f"{r['seconds']:6.1f}", flush=True)
    print(f"largest |quad fraction (fbx) - quad fraction (obj)|: simplify {worst['simplify']:.4f}, "
          f"lod {worst['lod']:.4f} (bar: 0.01); the OBJ rounded to float32 against the OBJ: "
          f"simplify {worst['simplify32']:.4f}, lod {worst['lod32']:.4f}; fbx against the float32 OBJ: "
          f"simplify {worst['fbx_vs_32']:.4f}, lod {worst['lod_fbx_vs_32']:.4f}")


if __name__ == "__main__":
    sys.exit(main())
