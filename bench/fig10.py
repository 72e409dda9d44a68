#!/usr/bin/env python3
"""The paper's Fig. 10 on a skinned character (issue 24): quadlod against Single, frame by frame.

Input: the ram's bind-pose OBJ (its polygons) with the weights, skeleton and walk of the glb
(`quadlod simplify --rig`). quadlod reduces the OBJ and writes the LOD as OBJ and as a skinned
.glb; Single (an external program, ../shared/peers/single/decimate) reduces the same OBJ's
positions and polygons. Both LODs take their weights by the same projection onto the input
(`quadlod eval --animation`, docs/skinning.md), so only the topology differs. Every frame of the
walk poses the input and both LODs with the same skeleton and measures PCCD, Chamfer, Hausdorff
and flow deviation. Writes OUT/fig10.json, OUT/fig10.md (table + bar) and OUT/fig10.png.

    bench/fig10 [--out DIR] [--ratios 0.2 0.4] [--samples 50000] [--seeds 1 2 3 4 5]
                [--hausdorff-tolerance 1e-5] [--quadlod build/quadlod]

The per-frame Hausdorff is by branch and bound (`eval --hausdorff-tolerance`, default 1e-5 in
normalised units): exact to that tolerance and independent of the sampling seed, which then only
moves Chamfer, PCCD and flow. With several --seeds every LOD is measured once per seed and
OUT/fig10.md gets a table of the bar per seed (the main table is the first seed's).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from run import write_stripped_obj  # noqa: E402  (positions + polygons: what every peer gets)

CORPUS = os.path.normpath(os.path.join(REPO, "..", "shared", "corpus", "animated"))
SINGLE = os.path.normpath(os.path.join(REPO, "..", "shared", "peers", "single", "decimate"))
METRICS = [("pccd", "PCCD"), ("chamfer", "Chamfer"), ("hausdorff", "Hausdorff"), ("flow_deviation_deg", "flow deviation (deg)")]


def log(msg):
    print("fig10: " + msg, file=sys.stderr, flush=True)


def run(cmd, log_path):
    t = time.time()
    with open(log_path, "w") as f:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=f, text=True)
    if p.returncode != 0:
        raise SystemExit("fig10: %s failed (exit %d); see %s" % (cmd[0], p.returncode, log_path))
    return p.stdout, time.time() - t


def tri_equivalents(obj):
    n = 0
    with open(obj) as f:
        for line in f:
            if line.startswith("f "):
                n += len(line.split()) - 3
    return n


def faces_of(obj):
    q = t = o = 0
    with open(obj) as f:
        for line in f:
            if line.startswith("f "):
                k = len(line.split()) - 1
                q, t, o = q + (k == 4), t + (k == 3), o + (k > 4)
    return q, t, o


def median(values):
    v = sorted(x for x in values if x is not None)
    return v[(len(v) - 1) // 2] if v else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="/tmp/quadlod-fig10")
    ap.add_argument("--ratios", type=float, nargs="+", default=[0.2, 0.4])
    ap.add_argument("--samples", type=int, default=50000, help="surface samples per direction and frame")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1], help="eval sampling seeds (the first one is the main table's)")
    ap.add_argument("--hausdorff-tolerance", type=float, default=1e-5,
                    help="eval --hausdorff-tolerance (0 = the maximum over the samples, as before 2026-12-02)")
    ap.add_argument("--quadlod", default=os.path.join(REPO, "build", "quadlod"))
    ap.add_argument("--single", default=os.environ.get("QUADLOD_SINGLE", SINGLE))
    ap.add_argument("--glb", default=os.path.join(CORPUS, "yofrankie_ram_walk.glb"))
    ap.add_argument("--rest", default=os.path.join(CORPUS, "yofrankie_ram_rest.obj"))
    ap.add_argument("--quadlod-input", choices=["clean", "full"], default="clean",
                    help="what quadlod reduces: clean = the positions-and-polygons OBJ Single gets (default, as "
                         "bench/run.py), full = the rest OBJ with UVs, normals and materials (their seams kept)")
    ap.add_argument("--quadlod-args", default="", help="extra arguments for quadlod simplify (one string)")
    ap.add_argument("--case", choices=["ram", "tube"], default="ram",
                    help="ram = the corpus ram walk (--glb / --rest); tube = the generated three-bone bending tube "
                         "(quadlod generate bending-tube --n 32 --m 48 --bones 3: 1536 quads, about the ram's size), "
                         "a second rig to validate skin settings on")
    ap.add_argument("--no-blender", action="store_true", help="skip the Blender re-import of the LOD glb")
    a = ap.parse_args()
    os.makedirs(os.path.join(a.out, "work"), exist_ok=True)
    have_single = os.path.exists(a.single)
    if not have_single:
        log("Single not found at %s: its rows are skipped" % a.single)
    if a.case == "tube":
        a.glb = os.path.join(a.out, "work", "tube.glb")
        a.rest = os.path.join(a.out, "work", "tube_rest.obj")
        run([a.quadlod, "-q", "generate", "bending-tube", "-o", a.glb, "--n", "32", "--m", "48", "--bones", "3"],
            os.path.join(a.out, "work", "generate.log"))
        glb_to_obj(a.glb, a.rest)
    stripped = os.path.join(a.out, "work", "ram_rest.vf.obj")
    write_stripped_obj(a.rest, stripped)
    n0 = tri_equivalents(a.rest)
    results = {"input": a.rest, "rig": a.glb, "quadlod_input": a.quadlod_input, "quadlod_args": a.quadlod_args,
               "tri_equivalent_in": n0, "samples": a.samples, "seeds": a.seeds,
               "hausdorff_tolerance": a.hausdorff_tolerance, "runs": [], "seed_runs": []}
    eval_args = ["--samples", str(a.samples), "--hausdorff-tolerance", repr(a.hausdorff_tolerance)]
    for ratio in a.ratios:
        target = max(1, int(round(ratio * n0)))
        tag = "%g" % ratio
        lods = []
        q_obj = os.path.join(a.out, "quadlod_%s.obj" % tag)
        q_glb = os.path.join(a.out, "quadlod_%s.glb" % tag)
        q_in = stripped if a.quadlod_input == "clean" else a.rest
        out, secs = run([a.quadlod, "-q", "simplify", q_in, "-o", q_obj, "--glb", q_glb, "--rig", a.glb,
                         "--faces", str(target), "--report", os.path.join(a.out, "quadlod_%s.report.json" % tag)] + a.quadlod_args.split(),
                        os.path.join(a.out, "quadlod_%s.log" % tag))
        lods.append(("quadlod", q_obj, secs))
        if have_single:
            s_obj = os.path.join(a.out, "single_%s.obj" % tag)
            _, secs = run([a.single, "-i", stripped, "-o", s_obj, "--tri-number", str(target)],
                          os.path.join(a.out, "single_%s.log" % tag))
            lods.append(("single", s_obj, secs))
        for method, obj, secs in lods:
            for seed in a.seeds[1:]:
                ev, _ = run([a.quadlod, "-q", "eval", a.rest, obj, "--animation", "--rig", a.glb, "--json", "--seed", str(seed)]
                            + eval_args, os.path.join(a.out, "%s_%s.seed%d.eval.log" % (method, tag, seed)))
                j = json.loads(ev)
                results["seed_runs"].append({"method": method, "ratio": ratio, "seed": seed, "frames": j["frames"], "summary": j["summary"]})
            ev, esecs = run([a.quadlod, "-q", "eval", a.rest, obj, "--animation", "--rig", a.glb, "--json",
                             "--seed", str(a.seeds[0])] + eval_args, os.path.join(a.out, "%s_%s.eval.log" % (method, tag)))
            j = json.loads(ev)
            results["seed_runs"].append({"method": method, "ratio": ratio, "seed": a.seeds[0], "frames": j["frames"], "summary": j["summary"]})
            q, t, o = faces_of(obj)
            results["runs"].append({"method": method, "ratio": ratio, "target": target, "output": obj,
                                    "tri_equivalent_out": tri_equivalents(obj), "quads": q, "tris": t, "ngons": o,
                                    "seconds_reduce": secs, "seconds_eval": esecs,
                                    "frames": j["frames"], "summary": j["summary"]})
            log("%s at %s: %d tri-eq, median Chamfer %.4e, Hausdorff %.4e, PCCD %s" % (
                method, tag, tri_equivalents(obj), j["summary"]["chamfer"]["median"],
                j["summary"]["hausdorff"]["median"], j["summary"]["pccd"]["median"]))
        # quadlod's own glb (its weights as written) must measure as its OBJ does.
        ev, _ = run([a.quadlod, "-q", "eval", a.rest, q_glb, "--animation", "--rig", a.glb, "--json",
                     "--seed", str(a.seeds[0])] + eval_args, os.path.join(a.out, "quadlod_%s.glb.eval.log" % tag))
        results["runs"].append({"method": "quadlod-glb", "ratio": ratio, "target": target, "output": q_glb,
                                "frames": json.loads(ev)["frames"], "summary": json.loads(ev)["summary"]})
    if not a.no_blender and shutil.which("blender"):
        results["blender"] = blender_check(a, os.path.join(a.out, "quadlod_%g.glb" % a.ratios[0]))
    with open(os.path.join(a.out, "fig10.json"), "w") as f:
        json.dump(results, f, indent=1)
    write_table(a, results)
    plot(a, results)


def glb_to_obj(glb, obj):
    """The polygons of a glb quadlod wrote (one mesh; fans rebuilt by extras.quadlod_polygon_sizes,
    corners welded by position) as an OBJ of positions and faces."""
    import struct
    data = open(glb, "rb").read()
    n = struct.unpack("<I", data[12:16])[0]
    g = json.loads(data[20:20 + n])
    binary = data[20 + n + 8:]

    def read(acc, fmt, width):
        a = g["accessors"][acc]
        v = g["bufferViews"][a["bufferView"]]
        off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        size = struct.calcsize(fmt)
        return [struct.unpack_from("<" + fmt * width, binary, off + i * size * width) for i in range(a["count"])]

    verts, index_of, faces = [], {}, []
    for prim in g["meshes"][0]["primitives"]:
        pos = read(prim["attributes"]["POSITION"], "f", 3)
        idx = [i[0] for i in read(prim["indices"], "I", 1)]
        sizes = [s[0] for s in read(prim["extras"]["quadlod_polygon_sizes"], "I", 1)]
        ids = []
        for p in pos:
            ids.append(index_of.setdefault(p, len(verts)))
            if len(verts) < len(index_of):
                verts.append(p)
        at = 0
        for k in sizes:
            fan = idx[at:at + 3 * (k - 2)]
            at += 3 * (k - 2)
            faces.append([ids[fan[0]]] + [ids[fan[3 * i + 1]] for i in range(k - 2)] + [ids[fan[-1]]])
    with open(obj, "w") as f:
        for p in verts:
            f.write("v %.9g %.9g %.9g\n" % p)
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def blender_check(a, glb):
    script = os.path.join(HERE, "peers", "blender_skin_check.py")
    p = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python", script, "--", glb],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    line = [l for l in p.stdout.splitlines() if l.startswith("RESULT ")]
    res = {"exit": p.returncode, "result": line[-1][7:] if line else None, "glb": glb}
    log("blender: %s" % res)
    return res


def write_table(a, results):
    lines = ["# Fig. 10 on the ram walk (%s, %d frames)" % (os.path.basename(a.glb), len(results["runs"][0]["frames"])), "",
             "quadlod input: %s%s; Single: the clean OBJ (positions and polygons)." % (
                 a.quadlod_input, (" with `%s`" % a.quadlod_args) if a.quadlod_args else ""), "",
             "Per-frame metrics between the posed input and the posed LOD (normalised by the posed input's bbox);",
             "median and worst frame over the walk. Both LODs take weights by projection onto the input.", "",
             "| ratio | method | tri-eq | quads/tris | " + " | ".join("%s median | %s worst" % (n, n) for _, n in METRICS) + " |",
             "|---|---|---|---|" + "---|---|" * len(METRICS)]
    for r in results["runs"]:
        cells = []
        for key, _ in METRICS:
            s = r["summary"][key]
            fmt = "%.2f" if key == "flow_deviation_deg" else "%.4e"
            cells += [fmt % s["median"] if s["median"] is not None else "–",
                      (fmt % s["worst"] + " (f%d)" % s["worst_frame"]) if s["worst"] is not None else "–"]
        lines.append("| %g | %s | %s | %s | %s |" % (r["ratio"], r["method"], r.get("tri_equivalent_out", "="),
                                                   "%s/%s" % (r["quads"], r["tris"]) if "quads" in r else "=", " | ".join(cells)))
    lines += ["", "## Bar (ratio 0.2)", ""]
    by = {(r["method"], r["ratio"]): r for r in results["runs"]}
    q, s = by.get(("quadlod", 0.2)), by.get(("single", 0.2))
    if q and s:
        qc, sc = q["summary"]["chamfer"]["median"], s["summary"]["chamfer"]["median"]
        qh, sh = q["summary"]["hausdorff"]["median"], s["summary"]["hausdorff"]["median"]
        pairs = [(x["pccd"], y["pccd"]) for x, y in zip(q["frames"], s["frames"]) if x["pccd"] is not None and y["pccd"] is not None]
        lower = sum(1 for x, y in pairs if x < y)
        results["bar"] = {"median_chamfer_ok": qc <= sc, "median_hausdorff_ok": qh <= sh,
                          "pccd_lower_fraction": lower / len(pairs) if pairs else None}
        lines += ["* median Chamfer: quadlod %.4e vs Single %.4e: %s" % (qc, sc, "met" if qc <= sc else "NOT met"),
                  "* median Hausdorff: quadlod %.4e vs Single %.4e: %s" % (qh, sh, "met" if qh <= sh else "NOT met"),
                  "* PCCD lower in %d of %d frames (%.0f %%; bar 80 %%): %s" % (
                      lower, len(pairs), 100.0 * lower / max(1, len(pairs)), "met" if lower >= 0.8 * len(pairs) else "NOT met")]
    lines += seed_table(results) + hausdorff_regions(results)
    if "blender" in results:
        lines += ["* Blender re-import of %s: %s" % (os.path.basename(results["blender"]["glb"]), results["blender"]["result"])]
    with open(os.path.join(a.out, "fig10.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(a.out, "fig10.json"), "w") as f:
        json.dump(results, f, indent=1)
    print("\n".join(lines))


def bar_of(q, s):
    """The issue's bar between two runs (dicts with frames and summary) of quadlod and Single."""
    pairs = [(x["pccd"], y["pccd"]) for x, y in zip(q["frames"], s["frames"]) if x["pccd"] is not None and y["pccd"] is not None]
    return {"chamfer": (q["summary"]["chamfer"]["median"], s["summary"]["chamfer"]["median"]),
            "hausdorff": (q["summary"]["hausdorff"]["median"], s["summary"]["hausdorff"]["median"]),
            "hausdorff_worst": (q["summary"]["hausdorff"]["worst"], s["summary"]["hausdorff"]["worst"]),
            "chamfer_worst": (q["summary"]["chamfer"]["worst"], s["summary"]["chamfer"]["worst"]),
            "pccd_lower": sum(1 for x, y in pairs if x < y), "frames": len(pairs)}


def seed_table(results):
    """The bar per ratio and seed: medians and worst frames of quadlod against Single."""
    by = {(r["method"], r["ratio"], r["seed"]): r for r in results.get("seed_runs", [])}
    rows = []
    for ratio in sorted({r["ratio"] for r in results.get("seed_runs", [])}):
        for seed in results["seeds"]:
            q, s = by.get(("quadlod", ratio, seed)), by.get(("single", ratio, seed))
            if not q or not s:
                continue
            b = bar_of(q, s)
            ok = lambda x: "**%.4e** / %.4e" % x if x[0] <= x[1] else "%.4e / **%.4e**" % x
            rows.append("| %g | %d | %s | %s | %s | %s | %d / %d | %s |" % (
                ratio, seed, ok(b["chamfer"]), ok(b["chamfer_worst"]), ok(b["hausdorff"]), ok(b["hausdorff_worst"]),
                b["pccd_lower"], b["frames"],
                "met" if b["chamfer"][0] <= b["chamfer"][1] and b["hausdorff"][0] <= b["hausdorff"][1]
                and b["pccd_lower"] >= 0.8 * b["frames"] else "NOT met"))
    if not rows:
        return []
    return ["", "## The bar per eval seed (quadlod / Single; bold = the smaller)", "",
            "Hausdorff tolerance %g (0 = sampled)." % results["hausdorff_tolerance"], "",
            "| ratio | seed | Chamfer median | Chamfer worst | Hausdorff median | Hausdorff worst | PCCD lower | bar |",
            "|---|---|---|---|---|---|---|---|"] + rows


def hausdorff_regions(results):
    """Where the per-frame Hausdorff is attained: the dominant joint at that point, per method."""
    lines = []
    for r in results["runs"]:
        if r["method"] not in ("quadlod", "single"):
            continue
        joints = {}
        for f in r["frames"]:
            if "hausdorff_joint" in f:
                key = "%s (%s)" % (f["hausdorff_joint"], f.get("hausdorff_on", "?"))
                joints[key] = joints.get(key, 0) + 1
        if joints:
            lines.append("* %s at %g: %s" % (r["method"], r["ratio"], ", ".join(
                "%s %d" % kv for kv in sorted(joints.items(), key=lambda kv: -kv[1]))))
    if not lines:
        return []
    return ["", "## Where the per-frame Hausdorff is (dominant joint at the point; on which surface: frames)", ""] + lines


def plot(a, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(METRICS), len(a.ratios), figsize=(6 * len(a.ratios), 2.6 * len(METRICS)), squeeze=False)
    colours = {"quadlod": "#1f77b4", "single": "#8c564b"}
    for c, ratio in enumerate(a.ratios):
        for r_, (key, name) in enumerate(METRICS):
            ax = axes[r_][c]
            for r in results["runs"]:
                if r["ratio"] != ratio or r["method"] not in colours:
                    continue
                frames = [f["time"] * 40.0 for f in r["frames"]]
                ax.plot(frames, [f[key] if f[key] is not None else float("nan") for f in r["frames"]],
                        label=r["method"], color=colours[r["method"]])
            ax.set_title("%s at %g" % (name, ratio), fontsize=9)
            ax.set_xlabel("frame", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "fig10.png"), dpi=110)


if __name__ == "__main__":
    main()
