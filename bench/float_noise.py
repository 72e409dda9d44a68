#!/usr/bin/python3
"""How far float32-sized noise alone moves `quadlod simplify` / `quadlod lod` (issue 21's bar).

Blender (and so its FBX export) stores coordinates as float32: the FBX path reads exactly the OBJ
rounded to float32 (bench/scene_bar.py's obj32 column). This measures the reduction's own spread
at that scale: for each mesh, the OBJ with every coordinate rounded to float32 and then moved by
a random -1, 0 or +1 float32 ulp (seeds 1..N), each reduced like scene_bar.py does.

Usage: bench/float_noise.py [--quadlod build/quadlod] [--seeds 8] [--ratio 0.5] [--levels 0.5,0.25] MESH.obj ...
Prints per mesh: quad fraction from the OBJ, from the float32 OBJ, and min / max over the seeds.
"""
import argparse
import json
import os
import random
import re
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
FACES_RE = re.compile(r"(\d+) quads, (\d+) tris, (\d+) n-gons")


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def ulp_step(x, k):
    """x (a float32 value) moved by k float32 ulps."""
    if k == 0:
        return x
    b = struct.unpack("<i", struct.pack("<f", x))[0]
    # Monotone integer order of floats: negative floats count down.
    if b < 0:
        b = -(b & 0x7FFFFFFF)
    b += k
    if b < 0:
        b = (-b) | -0x80000000
    return struct.unpack("<f", struct.pack("<i", b))[0]


def write_variant(src, dst, seed):
    rng = random.Random(seed)
    with open(src) as f, open(dst, "w") as out:
        for line in f:
            if line.startswith("v "):
                p = line.split()
                xs = [f32(float(x)) for x in p[1:4]]
                if seed:
                    xs = [ulp_step(x, rng.choice((-1, 0, 1))) for x in xs]
                out.write("v " + " ".join(repr(x) for x in xs) + " " + " ".join(p[4:]) + "\n")
            else:
                out.write(line)


def qf(q, t, n):
    return q / (q + t + n) if q + t + n else 0.0


def reduce(quadlod, src, work, ratio, levels):
    out = subprocess.run([quadlod, "-q", "simplify", src, "-o", os.path.join(work, "out.obj"), "--ratio", ratio],
                         capture_output=True, text=True, check=True).stdout
    s = qf(*map(int, FACES_RE.search(out).groups()))
    lod_dir = os.path.join(work, "lod")
    subprocess.run([quadlod, "-q", "lod", src, "-o", lod_dir, "--levels", levels, "--format", "obj", "--no-hausdorff"],
                   capture_output=True, text=True, check=True)
    with open(os.path.join(lod_dir, "lods.json")) as f:
        return s, [lv["quad_fraction"] for lv in json.load(f)["levels"]]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quadlod", default=os.path.join(HERE, "..", "build", "quadlod"))
    ap.add_argument("--work", default="/tmp/quadlod_float_noise")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--ratio", default="0.5")
    ap.add_argument("--levels", default="0.5,0.25")
    ap.add_argument("meshes", nargs="+")
    a = ap.parse_args()
    print(f"{'mesh':34} {'simplify qf: obj / f32 / f32±1ulp min..max':>44} {'lod last level: obj / f32 / min..max':>40}")
    for mesh in a.meshes:
        stem = os.path.splitext(os.path.basename(mesh))[0]
        work = os.path.join(a.work, stem)
        os.makedirs(work, exist_ok=True)
        ref_s, ref_l = reduce(a.quadlod, mesh, work, a.ratio, a.levels)
        runs = []
        for seed in range(0, a.seeds + 1):  # seed 0: the float32 OBJ itself
            src = os.path.join(work, f"v{seed}.obj")
            write_variant(mesh, src, seed)
            runs.append(reduce(a.quadlod, src, work, a.ratio, a.levels))
        s = [r[0] for r in runs[1:]]
        l = [r[1][-1] for r in runs[1:]]
        print(f"{stem[:34]:34} {ref_s:.3f} / {runs[0][0]:.3f} / {min(s):.3f}..{max(s):.3f} (spread {max(s) - min(s):.3f})"
              f"   {ref_l[-1]:.3f} / {runs[0][1][-1]:.3f} / {min(l):.3f}..{max(l):.3f} (spread {max(l) - min(l):.3f})", flush=True)


if __name__ == "__main__":
    sys.exit(main())
