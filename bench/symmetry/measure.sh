#!/bin/sh
# What --symmetry costs and buys (issue 34, docs/symmetry.md): each MESH reduced at each ratio
# with --symmetry off and auto (and x when asked: MODES="off auto x"), then `quadlod eval --json`;
# one line per run: mesh, ratio, mode, plane found, target, achieved, deviation, Chamfer,
# Hausdorff, share of output vertices mirrored within 1e-4 of the diagonal, seconds.
#
#   bench/symmetry/measure.sh OUTDIR MESH.obj... ; RATIOS="0.4 0.2" MODES="off auto" by default
set -e
QUADLOD=${QUADLOD:-build/quadlod}
RATIOS=${RATIOS:-"0.4 0.2"}
MODES=${MODES:-"off auto"}
out=$1
shift
mkdir -p "$out"
printf '%-32s %5s %-5s %-5s %8s %8s %7s %11s %11s %8s %7s\n' mesh ratio mode plane target achieved dev chamfer hausdorff mirrored seconds
for mesh in "$@"; do
  name=$(basename "$mesh" .obj)
  for ratio in $RATIOS; do
    for mode in $MODES; do
      o="$out/$name.$ratio.$mode"
      nice "$QUADLOD" -q simplify "$mesh" -o "$o.obj" --ratio "$ratio" --symmetry "$mode" --report "$o.report.json" >/dev/null
      nice "$QUADLOD" -q eval "$mesh" "$o.obj" --json >"$o.eval.json"
      python3 - "$name" "$ratio" "$mode" "$o" <<'PY'
import json, sys
name, ratio, mode, o = sys.argv[1:]
r = json.load(open(o + ".report.json"))
e = json.load(open(o + ".eval.json"))
s = e.get("symmetry", {})
print("%-32s %5s %-5s %-5s %8d %8d %+6.1f%% %11.4e %11.4e %7.2f%% %7.2f" % (
    name, ratio, mode, r["symmetry"]["axis"], r["target"], r["achieved"], 100 * r["deviation"], e["chamfer"],
    e["hausdorff"], 100 * s.get("output_mirrored_fraction", float("nan")), r["seconds"]))
PY
    done
  done
done
