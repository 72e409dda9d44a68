"""bench/uv_compare: UVs, seams and materials through quadlod and Blender's collapse decimation
(issue 7).

For every mesh of a folder that has UVs (an `f` record with a `vt` index), at every ratio:
bench/run reduces it with `quadlod simplify` (the file as it is, with its UVs: bench/run's
`quadlod-full`) and with Blender's Decimate modifier in collapse mode to the same
triangle-equivalent target and measures both with `quadlod eval --json`. This script selects the
meshes, runs bench/run (methods quadlod-full and blender-collapse, which keeps
bench/run's resuming, timeouts and per-run files), then reads the eval JSON of every run and
writes (atomically):

  OUT/uv_compare.csv   one row per (mesh, ratio, method) with the UV / seam / material metrics
  OUT/uv_compare.md    per-mesh table and averages per ratio and method

Metric definitions: docs/metrics.md §6c. Standard library only; see bench/README.md.
"""

import argparse
import csv
import io
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run as bench_run  # noqa: E402  (bench/run.py: shared CSV and file helpers)

# quadlod-full: quadlod on the corpus file with its UVs (bench/run's `quadlod` reads a positions +
# polygons copy since the clean-input change, which has no UVs to compare).
METHODS = ["quadlod-full", "blender-collapse"]
LABELS = {"quadlod-full": "quadlod", "blender-collapse": "Blender collapse"}
# bench/run's UV_COLUMNS (the seam/UV keys results.csv also carries), with the island details and
# the material and feature metrics of eval JSON around them.
UV = bench_run.UV_COLUMNS
COLUMNS = [
    "mesh", "ratio", "method", "status", "error", "target", "achieved", "achieved_rel_error",
] + UV[:UV.index("uv_islands_out") + 1] + [
    "uv_islands_vanished", "uv_islands_merged", "uv_islands_split",
] + UV[UV.index("uv_islands_out") + 1:] + [
    "uv_samples", "material_border_error",
    "material_mismatch_fraction", "feature_deviation_max", "feature_deviation_mean",
    "hausdorff", "chamfer", "qpr",
]
EVAL_KEYS = COLUMNS[COLUMNS.index("seams_torn"):]


def has_uvs(path):
    """True when some face record of the OBJ uses a texture coordinate (`f v/vt ...`)."""
    with open(path, "r", errors="replace") as f:
        for line in f:
            if line.startswith("f "):
                parts = line.split()
                if len(parts) > 1:
                    fields = parts[1].split("/")
                    if len(fields) > 1 and fields[1]:
                        return True
    return False


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="bench/uv_compare",
        description="UV error, torn seams, islands and material borders of quadlod and Blender's "
                    "collapse decimation at the same counts, on every mesh with UVs.",
        epilog="Every other option (--jobs, --timeout, --time-limit, --samples, --quadlod, "
               "--blender, --retry-failed, ...) is passed to bench/run; see bench/run --help.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--quick", action="store_true",
                   help="the --quick-meshes smallest meshes with UVs at ratio 0.4, into "
                        "out/uv-compare-quick (fresh each time unless --resume)")
    p.add_argument("--quick-meshes", type=int, default=2, help="meshes in --quick (smallest files)")
    p.add_argument("--mesh-dir", default=os.path.normpath(os.path.join(bench_run.REPO, "..", "shared", "corpus")),
                   help="folder whose *.obj meshes with UVs run")
    p.add_argument("--meshes", default=None, help="comma-separated mesh names (file stems); default: "
                                                  "every mesh with UVs in --mesh-dir")
    p.add_argument("--out", default=None, help="output folder (default out/uv-compare, or "
                                               "out/uv-compare-quick with --quick)")
    p.add_argument("--ratios", default=None, help="comma-separated target ratios "
                                                  "(default 0.8,0.6,0.4,0.2; --quick: 0.4)")
    p.add_argument("--resume", action="store_true", help="with --quick: keep earlier rows")
    p.add_argument("--report-only", action="store_true",
                   help="run nothing: rebuild uv_compare.csv/.md from OUT's bench/run results")
    a, passthrough = p.parse_known_args(argv)
    if a.out is None:
        a.out = os.path.join(bench_run.REPO, "out", "uv-compare-quick" if a.quick else "uv-compare")
    a.ratios = a.ratios or ("0.4" if a.quick else "0.8,0.6,0.4,0.2")
    try:
        a.ratio_list = [float(x) for x in a.ratios.split(",") if x.strip()]
    except ValueError:
        p.error("--ratios: not a comma-separated list of numbers: %s" % a.ratios)
    if not a.ratio_list or any(not (0 < r <= 1) for r in a.ratio_list):
        p.error("--ratios must lie in (0, 1]")
    for flag in ("--methods", "--quick-meshes"):
        if any(x == flag or x.startswith(flag + "=") for x in passthrough):
            p.error("%s is set by bench/uv_compare" % flag)
    a.passthrough = passthrough
    return a


def select_meshes(a):
    """bench/run's selection (--mesh-dir, --meshes, smallest file first), then only the meshes
    with UVs; --quick takes the smallest of those."""
    paths = bench_run.select_meshes(argparse.Namespace(mesh_dir=a.mesh_dir, meshes=a.meshes, quick=False))
    with_uvs = [m for m in paths if has_uvs(m)]
    without = [os.path.basename(m) for m in paths if m not in with_uvs]
    if without:
        bench_run.log("uv_compare: skipping %d meshes without UVs: %s" % (len(without), ", ".join(without)))
    if a.quick and not a.meshes:
        with_uvs = with_uvs[:a.quick_meshes]
    if not with_uvs:
        sys.exit("bench/uv_compare: no .obj mesh with UVs in %s" % a.mesh_dir)
    return [os.path.splitext(os.path.basename(m))[0] for m in with_uvs]


def collect(out, meshes, ratios):
    """Rows of bench/run's results.csv for these meshes/ratios/methods, with the §6c metrics
    from each run's eval JSON."""
    csv_path = os.path.join(out, "results.csv")
    if not os.path.exists(csv_path):
        sys.exit("bench/uv_compare: no %s (bench/run wrote nothing)" % csv_path)
    with open(csv_path, newline="") as f:
        runs = {(r["mesh"], r["ratio"], r["method"]): r for r in csv.DictReader(f)}
    rows = []
    for mesh in meshes:
        for ratio in ratios:
            rk = bench_run.ratio_key(ratio)
            for method in METHODS:
                r = runs.get((mesh, rk, method))
                if r is None:
                    continue
                row = {k: r.get(k, "") for k in ("mesh", "ratio", "method", "status", "error", "target",
                                                   "achieved", "achieved_rel_error")}
                ev_path = os.path.join(out, "runs", mesh, rk, method + ".eval.json")
                if r.get("status") == "ok" and os.path.exists(ev_path):
                    with open(ev_path) as f:
                        ev = json.load(f)
                    if "uv_error_mean" not in ev:
                        row["status"] = "failed"
                        row["error"] = "eval JSON has no uv_error_mean (quadlod binary older than issue 7)"
                    for k in EVAL_KEYS:
                        row[k] = ev.get(k)
                rows.append(row)
    return rows


def write_csv(path, rows):
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: bench_run.cell(r.get(k)) for k in COLUMNS})
    bench_run.write_atomic(path, buf.getvalue())


def fmt_int(x):
    v = bench_run.num(x)
    return "–" if v is None else "%d" % v


def make_markdown(rows, ratios):
    sci, num, mean = bench_run.fmt_sci, bench_run.num, bench_run.mean
    lines = ["# UVs, seams and materials: quadlod vs Blender collapse (issue 7)", "",
             "Both methods reduce each mesh to the same triangle-equivalent target; `quadlod eval` "
             "measures both (definitions: docs/metrics.md §6c). uv err = texture-space distance over "
             "the input island's UV diagonal; torn = output seam/boundary edges not on an input "
             "seam/boundary; islands = UV islands with area (in → out; v/m/s = vanished, merged, split); mat. border = distance of "
             "output material borders to the input's (normalised units; – when none); hausdorff "
             "in units of the input's longest bbox side.", "",
             "## Averages per ratio", "",
             "| ratio | method | runs | achieved/target | uv err mean | uv err max | torn | islands out/in "
             "| mat. border | hausdorff |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for ratio in ratios:
        rk = bench_run.ratio_key(ratio)
        for method in METHODS:
            sel = [r for r in rows if r["ratio"] == rk and r["method"] == method and r["status"] == "ok"]
            if not sel:
                continue
            ach = mean([num(r["achieved"]) / num(r["target"]) for r in sel
                        if num(r.get("achieved")) is not None and num(r.get("target"))])
            isl = mean([num(r["uv_islands_out"]) / num(r["uv_islands_in"]) for r in sel
                        if num(r.get("uv_islands_out")) is not None and num(r.get("uv_islands_in"))])
            lines.append("| %s | %s | %d | %s | %s | %s | %s | %s | %s | %s |" % (
                bench_run.ratio_label(rk), LABELS[method], len(sel), bench_run.fmt_fixed(ach, 3),
                sci(mean([num(r.get("uv_error_mean")) for r in sel])),
                sci(mean([num(r.get("uv_error_max")) for r in sel])),
                bench_run.fmt_fixed(mean([num(r.get("seams_torn")) for r in sel]), 1),
                bench_run.fmt_fixed(isl, 3),
                sci(mean([num(r.get("material_border_error")) for r in sel])),
                sci(mean([num(r.get("hausdorff")) for r in sel]))))
    lines += ["", "Averages are over the runs that succeeded (`runs`); achieved/target and islands "
              "out/in are means of per-mesh ratios.", "",
              "## Per mesh", "",
              "| mesh | ratio | method | achieved / target | islands in → out | v/m/s | torn | uv err mean "
              "| uv err max | mat. border | hausdorff |",
              "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        if r["status"] != "ok":
            lines.append("| %s | %s | %s | failed: %s | | | | | | | |" % (
                r["mesh"], bench_run.ratio_label(r["ratio"]), LABELS[r["method"]],
                (r.get("error") or "").replace("|", "/")[:120]))
            continue
        lines.append("| %s | %s | %s | %s / %s | %s → %s | %s/%s/%s | %s | %s | %s | %s | %s |" % (
            r["mesh"], bench_run.ratio_label(r["ratio"]), LABELS[r["method"]],
            fmt_int(r.get("achieved")), fmt_int(r.get("target")),
            fmt_int(r.get("uv_islands_in")), fmt_int(r.get("uv_islands_out")),
            fmt_int(r.get("uv_islands_vanished")), fmt_int(r.get("uv_islands_merged")),
            fmt_int(r.get("uv_islands_split")),
            fmt_int(r.get("seams_torn")), sci(num(r.get("uv_error_mean"))),
            sci(num(r.get("uv_error_max"))), sci(num(r.get("material_border_error"))),
            sci(num(r.get("hausdorff")))))
    return "\n".join(lines) + "\n"


def main(argv):
    a = parse_args(argv)
    meshes = select_meshes(a)
    if not a.report_only:
        cmd = [sys.executable, os.path.join(HERE, "run.py"), "--methods", ",".join(METHODS),
               "--meshes", ",".join(meshes), "--ratios", a.ratios, "--out", a.out,
               "--mesh-dir", a.mesh_dir]
        if a.quick and not a.resume:
            cmd.append("--fresh")
        cmd += a.passthrough
        bench_run.log("uv_compare: %d meshes with UVs, ratios %s -> %s" % (len(meshes), a.ratios, a.out))
        rc = subprocess.call(cmd)
        if rc != 0:
            return rc
    rows = collect(a.out, meshes, a.ratio_list)
    csv_path = os.path.join(a.out, "uv_compare.csv")
    md_path = os.path.join(a.out, "uv_compare.md")
    write_csv(csv_path, rows)
    md = make_markdown(rows, a.ratio_list)
    bench_run.write_atomic(md_path, md)
    print(md.split("## Per mesh")[0].rstrip())
    bench_run.log("uv_compare: wrote %s, %s" % (csv_path, md_path))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
