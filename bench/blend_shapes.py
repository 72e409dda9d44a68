#!/usr/bin/python3
"""Issue 34's bar (docs/blend_shapes.md): .glb files made in Blender, each with one shape key,
reduced by `quadlod simplify IN.glb -o OUT.glb --ratio R`; Blender re-imports the output and must
find the shape key; with the key applied (weight 1) the LOD's Hausdorff to the input with the key
applied must be at most twice the Hausdorff of the bases. Both states of both meshes are written
as OBJ by Blender (bench/blend_shapes/export_states.py) and measured by `quadlod eval --json`.

Usage: bench/blend_shapes.py [--quadlod build/quadlod] [--work DIR] [--ratio 0.4]
                             [--morph-weights 1] (comma list: one run per weight)
Needs Debian's blender. Prints one line per mesh and weight.
"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def blender(script, *args):
    run = subprocess.run(["blender", "-b", "--python-exit-code", "1", "--python",
                          os.path.join(HERE, "blend_shapes", script), "--", *args],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"blender {script} failed:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}")
    return run.stdout


def hausdorff(quadlod, a, b):
    out = subprocess.run([quadlod, "eval", a, b, "--json"], capture_output=True, text=True, check=True).stdout
    return json.loads(out)["hausdorff"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quadlod", default=os.path.join(HERE, "..", "build", "quadlod"))
    ap.add_argument("--work", default="/tmp/quadlod_blend_shapes")
    ap.add_argument("--ratio", default="0.4")
    ap.add_argument("--morph-weights", default="1")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    blender("make_inputs.py", args.work)
    for mesh in ("suzanne_smile", "arm_flex"):
        src = os.path.join(args.work, mesh + ".glb")
        in_base, in_key = (os.path.join(args.work, f"{mesh}_in_{s}.obj") for s in ("base", "key"))
        blender("export_states.py", src, in_base, in_key)
        for weight in args.morph_weights.split(","):
            out = os.path.join(args.work, f"{mesh}_w{weight}.glb")
            subprocess.run([args.quadlod, "-q", "simplify", src, "-o", out, "--ratio", args.ratio,
                            "--morph-weight", weight], check=True, capture_output=True)
            out_base, out_key = (os.path.join(args.work, f"{mesh}_w{weight}_{s}.obj") for s in ("base", "key"))
            log = blender("export_states.py", out, out_base, out_key)
            keys = [line for line in log.splitlines() if line.startswith("SHAPEKEYS")]
            hb, hk = hausdorff(args.quadlod, in_base, out_base), hausdorff(args.quadlod, in_key, out_key)
            print(f"{mesh} ratio {args.ratio} morph_weight {weight}: shape keys re-imported {keys[0].split(' ', 2)[2]}; "
                  f"hausdorff base {hb:.4e}, with the key {hk:.4e}, ratio {hk / hb:.2f} ({'ok' if hk <= 2 * hb else 'FAILS'} <= 2)")


if __name__ == "__main__":
    main()
