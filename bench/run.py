"""bench/run: quadlod, its ablations and the installed peer reducers, side by side (issue 6).

Every method reduces every mesh of a folder to the same triangle-equivalent target (quad = 2,
k-gon = k - 2, as quadlod counts it) and every result is measured by `quadlod eval` with the same
samples, seed and thread count. Outputs (all written atomically: temporary file, then rename):

  OUT/results.csv     one row per (mesh, ratio, method); failures are rows with status=failed
  OUT/tables.md       Table 1 (methods per ratio), Table 2 (ablations), seams and UVs, files as
                      they are vs bare geometry, the bar (quadlod against Single), losses,
                      validity, failures
  OUT/fig9_hausdorff.png, OUT/fig9_chamfer.png   QPR against distance (log x), like paper Fig. 9
  OUT/settings.json   the measurement settings and tool versions the rows were measured with
  OUT/runs/MESH/RATIO/METHOD.*   per-run logs, quadlod reports, peer reports, eval JSON

Standard library only (Debian's python3); see bench/README.md.
"""

import argparse
import concurrent.futures
import csv
import datetime
import hashlib
import io
import json
import math
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

# ---------------------------------------------------------------------------------------------
# Methods
# ---------------------------------------------------------------------------------------------

# name -> (kind, extra quadlod flags or peer mode, label in tables)
METHODS = {
    "quadlod": ("quadlod", [], "quadlod"),
    # The corpus file as it is (UVs, normals, materials, groups) instead of the positions +
    # polygons copy every other method reads (issue 32): quadlod then also keeps seams and borders.
    "quadlod-full": ("quadlod", [], "quadlod full file"),
    "quadlod-greedy": ("quadlod", ["--time-limit", "0"], "quadlod greedy"),
    # The paper's Eq. 9 (before issue 19's shape objective), greedy and with the default search.
    "quadlod-paper-greedy": ("quadlod", ["--objective", "paper", "--time-limit", "0"], "Eq. 9 greedy"),
    "quadlod-paper": ("quadlod", ["--objective", "paper"], "Eq. 9 search"),
    "quadlod-no-consistency": ("quadlod", ["--no-consistency"], "w/o Consist."),
    "quadlod-no-segmentation": ("quadlod", ["--no-segmentation"], "w/o Segmt."),
    "quadlod-no-geometry": ("quadlod", ["--no-geometry"], "w/o Geo."),
    "quadlod-no-dual": ("quadlod", ["--no-dual"], "w/o Dual"),
    "single": ("single", ["default"], "Single"),
    "single-rel": ("single", ["rel"], "Single rel-eps"),
    "meshopt": ("meshopt", [], "meshoptimizer"),
    # Vertices split by (position, UV): meshoptimizer's seam-aware input (issue 32).
    "meshopt-uv": ("meshopt", ["--uv"], "meshoptimizer UV"),
    "meshlab": ("meshlab", [], "MeshLab QEC"),
    "blender-collapse": ("blender", ["collapse"], "Blender collapse"),
    "blender-unsubdiv": ("blender", ["unsubdiv"], "Blender un-subdiv"),
}
ABLATIONS = ["quadlod-no-consistency", "quadlod-no-segmentation", "quadlod-no-geometry",
             "quadlod-no-dual"]
PEERS = ["single", "single-rel", "meshopt", "meshopt-uv", "meshlab", "blender-collapse",
         "blender-unsubdiv"]
TABLE1_METHODS = ["quadlod", "quadlod-full", "quadlod-greedy", "quadlod-paper-greedy",
                  "quadlod-paper"] + PEERS
# quadlod methods that reduce the corpus file as it is; every other quadlod method reads the
# positions + polygons copy (OUT/work/MESH.vf.obj) unless --quadlod-input full.
FULL_INPUT_METHODS = {"quadlod-full"}

DEFAULT_RATIOS = "0.8,0.6,0.4,0.2,0.1,0.05"
QUICK_RATIOS = "0.4"

# "files as they are vs bare geometry": quadlod-full against quadlod, and the count of outputs
# whose achieved count is within this fraction of the target.
FULL_VS_BARE = ("quadlod-full", "quadlod")
TARGET_TOLERANCE = 0.03

# Single (Knodt 2025, the author's simple_qem): an external binary, never linked or vendored
# (../shared/peers/single/README.md). `single-rel` sets --abs-eps to this fraction of the input's
# bounding-box max extent (the scale-invariant variant that README describes).
SINGLE_DEFAULT = os.path.normpath(os.path.join(REPO, "..", "shared", "peers", "single", "decimate"))
SINGLE_REL_EPS = 5e-4

# Seams and UVs (docs/metrics.md §6c), as `quadlod eval --json` names them; bench/uv_compare
# reads the same keys (and a few more). Empty cells where eval measured no UVs (uv_error_mean
# null: the output, or the input, has no UVs), e.g. every method that reads or writes positions
# and polygons only: eval still counts the input's seams and islands there, which would read as
# "every island vanished".
UV_COLUMNS = ["seams_torn", "seam_edges_in", "seam_edges_out", "uv_islands_in", "uv_islands_out",
              "uv_error_mean", "uv_error_max"]


def uv_metrics(ev):
    """The UV_COLUMNS of one `quadlod eval --json` object; all None where it measured no UVs."""
    if ev.get("uv_error_mean") is None:
        return {k: None for k in UV_COLUMNS}
    return {k: ev.get(k) for k in UV_COLUMNS}


# The quality bar (--bar-method against --bar-peer, per ratio; see bar_section).
BAR_QFR_MARGIN = 0.10
BAR_CHAMFER_SHARE = 0.60
TABLE2_METHODS = ["quadlod"] + ABLATIONS

COLUMNS = [
    "mesh", "ratio", "method", "status", "error",
    "target", "achieved", "achieved_rel_error",
    "faces_in", "tri_equivalent_in", "faces", "quads", "tris", "ngons",
    "qpr", "qpr_rule", "quad_fraction", "pccd", "pccd_defined", "chamfer", "hausdorff",
    "nonmanifold_edges_new", "nonmanifold_edges", "nonmanifold_vertices",
    "degenerate_faces", "degenerate_faces_in", "duplicate_faces", "duplicate_faces_in",
    "zero_length_edges", "zero_length_edges_in",
    "flipped_faces", "flipped_faces_kept", "boundary_edges", "boundary_edges_in", "components", "components_in",
    "flow_deviation_deg", "flow_deviation_p90_deg", "flow_coverage",
] + UV_COLUMNS + [
    "seconds_read", "seconds_analysis", "seconds_select", "seconds_dual", "seconds_collapse",
    "seconds_write", "seconds_core", "seconds_total", "seconds_eval",
    "time_limit", "solver_status", "solver_gap", "parameter", "note",
]

# The measurement settings a resumed run must share with the rows already in the CSV.
MEASUREMENT_KEYS = ["samples", "seed", "time_limit", "quadlod_threads", "ablation_ratios"]

MESHLAB_MLX = """<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="Simplification: Quadric Edge Collapse Decimation">
  <Param type="RichInt" value="{target}" name="TargetFaceNum"/>
  <Param type="RichFloat" value="0" name="TargetPerc"/>
  <Param type="RichFloat" value="0.3" name="QualityThr"/>
  <Param type="RichBool" value="false" name="PreserveBoundary"/>
  <Param type="RichFloat" value="1" name="BoundaryWeight"/>
  <Param type="RichBool" value="false" name="PreserveNormal"/>
  <Param type="RichBool" value="false" name="PreserveTopology"/>
  <Param type="RichBool" value="true" name="OptimalPlacement"/>
  <Param type="RichBool" value="false" name="PlanarQuadric"/>
  <Param type="RichFloat" value="0.001" name="PlanarWeight"/>
  <Param type="RichBool" value="false" name="QualityWeight"/>
  <Param type="RichBool" value="true" name="AutoClean"/>
  <Param type="RichBool" value="false" name="Selected"/>
 </filter>
</FilterScript>
"""


class RunFailure(Exception):
    """One method failed on one mesh: becomes a CSV row with status=failed."""

    def __init__(self, message, seconds=None):
        super().__init__(message)
        self.seconds = seconds


# ---------------------------------------------------------------------------------------------
# Small utilities
# ---------------------------------------------------------------------------------------------

def log(msg):
    print(msg, flush=True)


def ratio_key(r):
    return "%g" % r


def write_atomic(path, data, mode="w"):
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=d)
    try:
        with os.fdopen(fd, mode) as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def first_error_line(text, fallback="no message"):
    lines = [l.strip() for l in (text or "").splitlines() if l.strip()]
    pattern = re.compile(r"error|fail|abort|assert|cannot|can't|exception|killed|invalid|"
                         r"no such|not found|refus", re.I)
    for l in lines:
        if pattern.search(l):
            return l[:300]
    return lines[0][:300] if lines else fallback


def num(x):
    """CSV cell -> float or None."""
    if x is None or x == "":
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def cell(x):
    if x is None:
        return ""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, float):
        if not math.isfinite(x):
            return ""
        return "%.9g" % x
    return str(x)


def exit_text(rc):
    """'exit 2' or 'killed by SIGSEGV' for a child's return code."""
    if rc is not None and rc < 0:
        try:
            return "killed by %s" % signal.Signals(-rc).name
        except ValueError:
            return "killed by signal %d" % -rc
    return "exit %s" % rc


def llround_target(ratio, tri_in):
    """quadlod's target: std::llround(ratio * tri_in) (round half away from zero)."""
    x = ratio * float(tri_in)
    t = math.floor(x)
    if x - t >= 0.5:
        t += 1
    return int(t)


class Runner:
    """Runs child processes in their own process group so a timeout or Ctrl-C ends the whole
    tree (xvfb-run starts Xvfb and meshlabserver) and nothing else."""

    def __init__(self):
        self.live = set()
        self.lock = threading.Lock()

    def run(self, cmd, timeout, log_path=None, env=None):
        t0 = time.perf_counter()
        try:
            p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 stdin=subprocess.DEVNULL, start_new_session=True, env=env,
                                 text=True, errors="replace")
        except OSError as e:
            raise RunFailure("%s: %s" % (cmd[0], e.strerror or e))
        with self.lock:
            self.live.add(p)
        try:
            try:
                out, err = p.communicate(timeout=timeout)
            except BaseException as e:
                if not isinstance(e, subprocess.TimeoutExpired):
                    self._kill(p)  # interrupted: end the child's whole process group
                    raise
                self._kill(p)
                out, err = p.communicate()
                if log_path:
                    self._log(log_path, cmd, out, err, "timeout")
                raise RunFailure("timeout after %g s: %s" % (timeout, os.path.basename(cmd[0])),
                                 seconds=time.perf_counter() - t0)
        finally:
            with self.lock:
                self.live.discard(p)
        seconds = time.perf_counter() - t0
        if log_path:
            self._log(log_path, cmd, out, err, p.returncode)
        return p.returncode, out, err, seconds

    @staticmethod
    def _kill(p):
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass

    @staticmethod
    def _log(path, cmd, out, err, rc):
        text = "$ %s\n# exit: %s\n--- stdout\n%s\n--- stderr\n%s\n" % (
            " ".join(cmd), rc, out or "", err or "")
        write_atomic(path, text)

    def kill_all(self):
        with self.lock:
            for p in list(self.live):
                self._kill(p)


# ---------------------------------------------------------------------------------------------
# Mesh preparation: input counts and the fan-triangulated copy for MeshLab
# ---------------------------------------------------------------------------------------------

def read_obj_polygons(path):
    """Positions and 0-based polygons of an OBJ (v and f records only)."""
    verts = []
    faces = []
    with open(path, "r", errors="replace") as f:
        for line_no, line in enumerate(f, 1):
            if line.startswith("v "):
                t = line.split()
                verts.append((float(t[1]), float(t[2]), float(t[3])))
            elif line.startswith("f "):
                poly = []
                for tok in line.split()[1:]:
                    i = int(tok.split("/", 1)[0])
                    i = i - 1 if i > 0 else len(verts) + i
                    if i < 0 or i >= len(verts):
                        raise RunFailure("%s:%d: face index out of range" % (path, line_no))
                    poly.append(i)
                if len(poly) < 3:
                    raise RunFailure("%s:%d: face with fewer than 3 corners" % (path, line_no))
                faces.append(poly)
    return verts, faces


def write_fan_ply(src, dst):
    """Fan-triangulated, positions-only binary PLY of an OBJ: the MeshLab peer's input (Debian's
    meshlab 2020.09 aborts on OBJ import, see bench/README.md). A k-gon v0..v(k-1) becomes
    (v0, vi, vi+1), i = 1..k-2: as many triangles as its triangle-equivalents."""
    verts, faces = read_obj_polygons(src)
    ntri = sum(len(p) - 2 for p in faces)
    out = io.BytesIO()
    out.write(("ply\nformat binary_little_endian 1.0\ncomment quadlod bench: fan triangulation "
               "of %s\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
               "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
               % (os.path.basename(src), len(verts), ntri)).encode())
    vs = struct.Struct("<fff")
    for v in verts:
        out.write(vs.pack(*v))
    fs = struct.Struct("<Biii")
    for p in faces:
        for k in range(1, len(p) - 1):
            out.write(fs.pack(3, p[0], p[k], p[k + 1]))
    write_atomic(dst, out.getvalue(), mode="wb")
    return ntri


def bbox_max_extent(verts):
    """Longest side of the axis-aligned bounding box of a vertex list (0 for none)."""
    if not verts:
        return 0.0
    return max(max(v[k] for v in verts) - min(v[k] for v in verts) for k in range(3))


def write_stripped_obj(src, dst):
    """Positions and polygons only (v and 1-based f records; no vt/vn/usemtl/mtllib/o/g/s): the
    Single peer's input, so it gets the same clean geometry as every peer. Every vertex is kept
    (indices unchanged). Returns the bounding-box max extent of the vertices."""
    verts, faces = read_obj_polygons(src)
    buf = io.StringIO()
    buf.write("# quadlod bench: positions and polygons of %s\n" % os.path.basename(src))
    for v in verts:
        buf.write("v %r %r %r\n" % v)
    for p in faces:
        buf.write("f " + " ".join(str(i + 1) for i in p) + "\n")
    write_atomic(dst, buf.getvalue())
    return bbox_max_extent(verts)


def obj_vertex_extent(path):
    """bbox_max_extent of the `v` records of an OBJ (a cached stripped copy)."""
    verts = []
    with open(path, "r", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                t = line.split()
                verts.append((float(t[1]), float(t[2]), float(t[3])))
    return bbox_max_extent(verts)


# ---------------------------------------------------------------------------------------------
# The benchmark
# ---------------------------------------------------------------------------------------------

class Bench:
    def __init__(self, args):
        self.args = args
        self.out = os.path.abspath(args.out)
        self.csv_path = os.path.join(self.out, "results.csv")
        self.runner = Runner()
        self.rows = {}  # (mesh, ratio_key, method) -> dict
        self.rows_lock = threading.Lock()
        self.mesh_info = {}
        self.mesh_lock = threading.Lock()
        self.mesh_locks = {}
        self.peer_versions = {}

    # -- tools ----------------------------------------------------------------------------------

    def find_tools(self, methods):
        a = self.args
        available = {}
        q = a.quadlod or os.path.join(REPO, "build", "quadlod")
        self.quadlod = os.path.abspath(q) if os.path.exists(q) else shutil.which(q)
        if not self.quadlod or not os.access(self.quadlod, os.X_OK):
            sys.exit("bench/run: quadlod binary not found at %s (build it with scripts/build release, "
                     "or pass --quadlod PATH)" % q)
        self.quadlod_source = self.quadlod
        self.quadlod = self._snapshot(self.quadlod)
        for m in methods:
            available[m] = METHODS[m][0] == "quadlod"

        meshopt_methods = [m for m in methods if METHODS[m][0] == "meshopt"]
        if meshopt_methods:
            found = self._find_meshopt(meshopt_methods)
            for m in meshopt_methods:
                available[m] = found
        if "meshlab" in methods:
            ml = shutil.which(a.meshlabserver)
            xv = shutil.which("xvfb-run")
            if not ml:
                log("peer meshlab: skipped (%s not found; scripts/bootstrap --peers installs "
                    "meshlab)" % a.meshlabserver)
            elif not xv:
                log("peer meshlab: skipped (xvfb-run not found; scripts/bootstrap --peers installs "
                    "xvfb and xauth)")
            else:
                self.meshlabserver, self.xvfb_run = ml, xv
                available["meshlab"] = True
                self.peer_versions["meshlab"] = dpkg_version("meshlab")
        single_methods = [m for m in methods if METHODS[m][0] == "single"]
        if single_methods:
            available.update(self._find_single(single_methods))
        blender_methods = [m for m in methods if METHODS[m][0] == "blender"]
        if blender_methods:
            b = shutil.which(a.blender)
            if not b:
                log("peer blender (%s): skipped (%s not found; scripts/bootstrap --peers installs "
                    "blender)" % (", ".join(blender_methods), a.blender))
            else:
                self.blender = b
                self.peer_versions["blender"] = dpkg_version("blender")
                for m in blender_methods:
                    available[m] = True
        return available

    def _snapshot(self, binary):
        """Copies the quadlod binary to OUT/bin/ and runs that copy: every row is measured with one
        binary even when build/ is rebuilt during a long run (a binary relinked under a running
        process crashes it)."""
        d = os.path.join(self.out, "bin")
        os.makedirs(d, exist_ok=True)
        dst = os.path.join(d, "quadlod")
        for attempt in range(3):
            fd, tmp = tempfile.mkstemp(prefix=".quadlod.", dir=d)
            os.close(fd)
            try:
                shutil.copy2(binary, tmp)
                os.chmod(tmp, 0o755)
                r = subprocess.run([tmp, "--help"], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL, timeout=60)
                if r.returncode == 0:
                    os.replace(tmp, dst)
                    return dst
            except (OSError, subprocess.TimeoutExpired):
                pass
            if os.path.exists(tmp):
                os.unlink(tmp)
            time.sleep(5)  # being relinked right now: try again
        sys.exit("bench/run: %s does not run (`%s --help` fails); is it being rebuilt?" % (binary, binary))

    def _find_single(self, single_methods):
        """--single PATH, else $QUADLOD_SINGLE, else ../shared/peers/single/decimate."""
        a = self.args
        if a.single:
            path, where = a.single, "--single"
        elif os.environ.get("QUADLOD_SINGLE"):
            path, where = os.environ["QUADLOD_SINGLE"], "QUADLOD_SINGLE"
        else:
            path, where = SINGLE_DEFAULT, "default path"
        found = path if os.path.isfile(path) else (shutil.which(path) if os.sep not in path else None)
        if not found or not os.access(found, os.X_OK):
            log("peer single (%s): skipped (%s not found (%s); set QUADLOD_SINGLE or pass "
                "--single PATH, see ../shared/peers/single/README.md)" % (
                    ", ".join(single_methods), path, where))
            return {}
        self.single = os.path.abspath(found)
        self.peer_versions["single"] = "simple_qem sha256:%s" % sha256(self.single)[:12]
        return {m: True for m in single_methods}

    def _find_meshopt(self, meshopt_methods):
        a = self.args
        what = "peer meshopt (%s)" % ", ".join(meshopt_methods)
        candidates = [a.meshopt_peer] if a.meshopt_peer else [
            os.path.join(REPO, "build-bench", "quadlod_meshopt_peer"),
            os.path.join(REPO, "build", "quadlod_meshopt_peer")]
        header = os.path.exists("/usr/include/meshoptimizer.h")
        if a.build_peers and not a.meshopt_peer and header:
            log("peer meshopt: building quadlod_meshopt_peer in build-bench/")
            bb = os.path.join(REPO, "build-bench")
            for cmd in (["cmake", "-S", REPO, "-B", bb, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                         "-DQUADLOD_BUILD_BENCH=ON", "-DQUADLOD_BUILD_TESTS=OFF"],
                        ["cmake", "--build", bb, "-j2", "--target", "quadlod_meshopt_peer"]):
                r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                if r.returncode != 0:
                    log("%s: skipped (build failed: %s)" % (what, first_error_line(r.stdout)))
                    return False
        for c in candidates:
            if c and os.path.isfile(c) and os.access(c, os.X_OK):
                self.meshopt_peer = os.path.abspath(c)
                self.peer_versions["meshoptimizer"] = dpkg_version("libmeshoptimizer-dev")
                return True
        if a.meshopt_peer:
            log("%s: skipped (%s is not an executable)" % (what, a.meshopt_peer))
        elif header:
            log("%s: skipped (driver not built: bench/run --build-peers, or cmake -S . -B "
                "build-bench -G Ninja -DQUADLOD_BUILD_BENCH=ON && cmake --build build-bench "
                "--target quadlod_meshopt_peer)" % what)
        else:
            log("%s: skipped (libmeshoptimizer-dev not installed; scripts/bootstrap --peers)" % what)
        return False

    # -- CSV ------------------------------------------------------------------------------------

    def load_csv(self):
        if not os.path.exists(self.csv_path):
            return
        with open(self.csv_path, newline="") as f:
            reader = csv.DictReader(f)
            old = not set(UV_COLUMNS) <= set(reader.fieldnames or [])
            for r in reader:
                self.rows[(r["mesh"], r["ratio"], r["method"])] = r
                if old and r.get("status") == "ok":
                    # Written before the UV columns existed: take them from the run's eval JSON.
                    ev = os.path.join(self.out, "runs", r["mesh"], r["ratio"], r["method"] + ".eval.json")
                    try:
                        with open(ev) as fh:
                            r.update({k: cell(v) for k, v in uv_metrics(json.load(fh)).items()})
                    except (OSError, ValueError):
                        pass

    def save_csv(self):
        order = {m: i for i, m in enumerate(METHODS)}
        with self.rows_lock:
            rows = sorted(self.rows.values(),
                          key=lambda r: (r["mesh"], -float(r["ratio"]), order.get(r["method"], 99)))
            buf = io.StringIO()
            w = csv.DictWriter(buf, fieldnames=COLUMNS, extrasaction="ignore", lineterminator="\n")
            w.writeheader()
            for r in rows:
                w.writerow({k: cell(r.get(k)) for k in COLUMNS})
            write_atomic(self.csv_path, buf.getvalue())

    # -- per-mesh preparation -------------------------------------------------------------------

    def info(self, mesh_path):
        """quadlod info --json of an input, once per mesh (raises RunFailure)."""
        with self.mesh_lock:
            lock = self.mesh_locks.setdefault(mesh_path, threading.Lock())
        with lock:
            if mesh_path in self.mesh_info:
                v = self.mesh_info[mesh_path]
                if isinstance(v, RunFailure):
                    raise v
                return v
            rc, out, err, _ = self.runner.run([self.quadlod, "-q", "info", mesh_path, "--json"],
                                              self.args.timeout)
            if rc != 0:
                e = RunFailure("info: %s: %s" % (exit_text(rc), first_error_line(err)))
                self.mesh_info[mesh_path] = e
                raise e
            try:
                v = json.loads(out)
            except ValueError:
                e = RunFailure("info: output is not JSON")
                self.mesh_info[mesh_path] = e
                raise e
            self.mesh_info[mesh_path] = v
            return v

    def fan_ply(self, mesh_path):
        name = os.path.splitext(os.path.basename(mesh_path))[0]
        dst = os.path.join(self.out, "work", name + ".tri.ply")
        with self.mesh_lock:
            lock = self.mesh_locks.setdefault(dst, threading.Lock())
        with lock:
            if not (os.path.exists(dst) and os.path.getmtime(dst) >= os.path.getmtime(mesh_path)):
                try:
                    write_fan_ply(mesh_path, dst)
                except (OSError, ValueError, IndexError) as e:
                    raise RunFailure("fan triangulation: %s" % first_error_line(str(e)))
        return dst

    def stripped_obj(self, mesh_path):
        """OUT/work/MESH.vf.obj (positions + polygons, cached like the fan PLY) and the input's
        bounding-box max extent."""
        name = os.path.splitext(os.path.basename(mesh_path))[0]
        dst = os.path.join(self.out, "work", name + ".vf.obj")
        with self.mesh_lock:
            lock = self.mesh_locks.setdefault(dst, threading.Lock())
        with lock:
            if dst in self.mesh_info:
                return dst, self.mesh_info[dst]
            try:
                if os.path.exists(dst) and os.path.getmtime(dst) >= os.path.getmtime(mesh_path):
                    extent = obj_vertex_extent(dst)
                else:
                    extent = write_stripped_obj(mesh_path, dst)
            except (OSError, ValueError, IndexError) as e:
                raise RunFailure("stripped OBJ: %s" % first_error_line(str(e)))
            self.mesh_info[dst] = extent
        return dst, extent

    # -- one run --------------------------------------------------------------------------------

    def run_one(self, mesh_path, ratio, method):
        a = self.args
        mesh = os.path.splitext(os.path.basename(mesh_path))[0]
        rdir = os.path.join(self.out, "runs", mesh, ratio_key(ratio))
        os.makedirs(rdir, exist_ok=True)
        base = os.path.join(rdir, method)
        row = {"mesh": mesh, "ratio": ratio_key(ratio), "method": method, "status": "failed"}
        notes = []
        output = None
        try:
            info = self.info(mesh_path)
            tri_in = int(info["tri_equivalent"])
            target = max(1, llround_target(ratio, tri_in))
            row.update(target=target, faces_in=info.get("faces"), tri_equivalent_in=tri_in,
                       degenerate_faces_in=info.get("degenerate_faces"),
                       duplicate_faces_in=info.get("duplicate_faces"),
                       boundary_edges_in=info.get("boundary_edges"),
                       components_in=info.get("components"))
            kind, extra, _ = METHODS[method]
            if kind == "quadlod":
                # Every method gets the same clean geometry (positions and polygons, as Single
                # does) unless it is quadlod-full or --quadlod-input full: with UVs and materials
                # quadlod also keeps their seams and borders (meshopt-uv and blender-collapse are
                # the peers that keep UVs too).
                full = method in FULL_INPUT_METHODS or self.args.quadlod_input == "full"
                src = mesh_path if full else self.stripped_obj(mesh_path)[0]
                output = self._run_quadlod(src, ratio, target, extra, base, row, notes)
            elif kind == "meshopt":
                output = self._run_meshopt(mesh_path, target, extra, base, row)
            elif kind == "meshlab":
                output = self._run_meshlab(mesh_path, target, base, row)
            elif kind == "blender":
                output = self._run_blender(mesh_path, target, extra[0], base, row)
            elif kind == "single":
                output = self._run_single(mesh_path, target, extra[0], base, row)
            self._eval(mesh_path, output, base, row)
            row["status"] = "ok"
            row["error"] = ""
        except RunFailure as e:
            row["status"] = "failed"
            row["error"] = str(e).splitlines()[0] if str(e) else "failed"
            if e.seconds is not None and row.get("seconds_total") is None:
                row["seconds_total"] = e.seconds
        except Exception as e:  # a bug in this script must not abort the benchmark either
            row["status"] = "failed"
            row["error"] = "bench/run internal error: %s: %s" % (type(e).__name__, e)
        finally:
            if output and not a.keep_meshes and os.path.exists(output):
                os.unlink(output)
        if notes:
            row["note"] = "; ".join(notes)
        return row

    def _run_quadlod(self, mesh_path, ratio, target, flags, base, row, notes):
        a = self.args
        output = base + ".obj"
        report = base + ".report.json"
        cmd = [self.quadlod, "-q", "simplify", mesh_path, "-o", output, "--ratio", ratio_key(ratio),
               "--report", report, "--threads", str(a.quadlod_threads)] + flags
        if a.time_limit is not None and "--time-limit" not in flags:  # quadlod-greedy has its own
            cmd += ["--time-limit", "%g" % a.time_limit]
        rc, out, err, seconds = self.runner.run(cmd, a.timeout, base + ".log")
        row["seconds_total"] = seconds
        if rc != 0:
            raise RunFailure("simplify: %s: %s" % (exit_text(rc), first_error_line(err)))
        try:
            with open(report) as f:
                rep = json.load(f)
        except (OSError, ValueError) as e:
            raise RunFailure("simplify: no readable report: %s" % e)
        if int(rep.get("target", target)) != target:
            notes.append("quadlod target %s != bench target %d" % (rep.get("target"), target))
            row["target"] = int(rep["target"])
        sel = rep.get("selection", {})
        # `stage_seconds` sums each stage over all select/collapse rounds; the per-stage objects
        # (`selection.seconds`, ...) describe the chosen round only. Older reports lack it.
        stage = rep.get("stage_seconds") or {}
        rounds = rep.get("rounds")
        if isinstance(rounds, list) and rounds:
            row["parameter"] = "rounds=%d" % len(rounds)
        row.update(seconds_read=rep.get("read_seconds"),
                   seconds_analysis=stage.get("analysis", rep.get("analysis", {}).get("seconds")),
                   seconds_select=stage.get("select", sel.get("seconds")),
                   seconds_dual=stage.get("dual", rep.get("dual_repair", {}).get("seconds")),
                   seconds_collapse=stage.get("collapse", rep.get("collapse", {}).get("seconds")),
                   seconds_write=rep.get("write_seconds"),
                   seconds_core=rep.get("seconds"),
                   time_limit=rep.get("options", {}).get("time_limit_seconds"),
                   solver_status=sel.get("solver", {}).get("status", ""),
                   solver_gap=sel.get("solver", {}).get("gap"))
        if rep.get("note"):
            notes.append(str(rep["note"]).splitlines()[0])
        return output

    def _run_meshopt(self, mesh_path, target, flags, base, row):
        output = base + ".obj"
        cmd = [self.meshopt_peer, mesh_path, output, "--target-tris", str(target)] + flags
        rc, out, err, seconds = self.runner.run(cmd, self.args.timeout, base + ".log")
        row["seconds_total"] = seconds
        if rc != 0:
            if rc == 1 and flags and "unknown option" in (err or ""):
                raise RunFailure("meshopt: %s: driver too old for %s (rebuild it: bench/run "
                                 "--build-peers)" % (exit_text(rc), " ".join(flags)))
            raise RunFailure("meshopt: %s: %s" % (exit_text(rc), first_error_line(err)))
        try:
            rep = json.loads(out)
        except ValueError:
            raise RunFailure("meshopt: driver printed no JSON")
        write_atomic(base + ".peer.json", json.dumps(rep, indent=1) + "\n")
        row.update(seconds_read=rep.get("seconds_read"), seconds_write=rep.get("seconds_write"),
                   seconds_core=rep.get("seconds_simplify"),
                   parameter="result_error=%.4g" % rep.get("result_error", float("nan")))
        if rep.get("dropped_triangles"):  # --uv: zero-area triangles on two copies of one vertex
            row["parameter"] += "; dropped_triangles=%d" % rep["dropped_triangles"]
        return output

    def _run_meshlab(self, mesh_path, target, base, row):
        ply = self.fan_ply(mesh_path)
        mlx = base + ".mlx"
        write_atomic(mlx, MESHLAB_MLX.format(target=target))
        output = base + ".ply"
        tmp = os.path.join(os.path.dirname(base), "." + os.path.basename(base) + ".tmp.ply")
        cmd = [self.xvfb_run, "-a", self.meshlabserver, "-i", ply, "-o", tmp, "-s", mlx]
        for attempt in range(2):
            rc, out, err, seconds = self.runner.run(cmd, self.args.timeout, base + ".log")
            text = (out or "") + "\n" + (err or "")
            # xvfb-run -a can lose a race for a display number with a parallel job: retry once.
            if rc != 0 and "Xvfb failed to start" in text and attempt == 0:
                continue
            break
        row["seconds_total"] = seconds
        if rc != 0 or not os.path.exists(tmp) or "saved as" not in text:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise RunFailure("meshlab: %s: %s" % (exit_text(rc), first_error_line(text, "no output written")))
        os.replace(tmp, output)
        m = re.search(r"saved as .*\((\d+) vn (\d+) fn\)", text)
        if m:
            row["parameter"] = "TargetFaceNum=%d; saved %s vn %s fn" % (target, m.group(1), m.group(2))
        return output

    def _run_single(self, mesh_path, target, mode, base, row):
        obj, extent = self.stripped_obj(mesh_path)
        output = base + ".obj"
        tmp = os.path.join(os.path.dirname(base), "." + os.path.basename(base) + ".tmp.obj")
        cmd = [self.single, "-i", obj, "-o", tmp, "--tri-number", str(target)]
        peer = {"input": obj, "tri_number": target, "bbox_max_extent": extent}
        if mode == "rel":
            eps = SINGLE_REL_EPS * extent
            cmd += ["--abs-eps", "%.6g" % eps]
            peer["abs_eps"] = float("%.6g" % eps)
            row["parameter"] = "abs_eps=%.6g (%g x bbox max extent %.6g)" % (eps, SINGLE_REL_EPS, extent)
        else:
            row["parameter"] = "abs_eps=default"
        try:
            rc, out, err, seconds = self.runner.run(cmd, self.args.timeout, base + ".log")
        except BaseException:
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise
        row["seconds_total"] = seconds
        if rc != 0 or not os.path.exists(tmp):
            if os.path.exists(tmp):
                os.unlink(tmp)
            raise RunFailure("single: %s: %s" % (exit_text(rc), first_error_line(
                (err or "") + "\n" + (out or ""), "no output written")), seconds=seconds)
        os.replace(tmp, output)
        peer["seconds_process"] = seconds
        write_atomic(base + ".peer.json", json.dumps(peer, indent=1) + "\n")
        return output

    def _run_blender(self, mesh_path, target, mode, base, row):
        output = base + ".obj"
        script = os.path.join(HERE, "peers", "blender_decimate.py")
        cmd = [self.blender, "-b", "--factory-startup", "--python", script, "--",
               mesh_path, output, mode, str(target)]
        rc, out, err, seconds = self.runner.run(cmd, self.args.timeout, base + ".log")
        row["seconds_total"] = seconds
        rep = None
        for line in (out or "").splitlines():
            if line.startswith("QUADLOD_PEER_ERROR "):
                raise RunFailure("blender %s: %s" % (mode, line[len("QUADLOD_PEER_ERROR "):]))
            if line.startswith("QUADLOD_PEER "):
                rep = json.loads(line[len("QUADLOD_PEER "):])
        if rc != 0 or rep is None or not os.path.exists(output):
            raise RunFailure("blender %s: %s: %s" % (mode, exit_text(rc), first_error_line(
                (err or "") + "\n" + (out or ""), "no result reported")))
        write_atomic(base + ".peer.json", json.dumps(rep, indent=1) + "\n")
        row.update(seconds_read=rep.get("seconds_import"),
                   seconds_core=(rep.get("seconds_search") or 0) + (rep.get("seconds_final") or 0),
                   parameter="; ".join("%s=%s" % (k, ("%.6g" % v) if isinstance(v, float) else v)
                                      for k, v in rep.get("parameter", {}).items())
                   + "; tries=%d" % len(rep.get("tries", [])))
        return output

    def _eval(self, mesh_path, output, base, row):
        a = self.args
        cmd = [self.quadlod, "-q", "eval", mesh_path, output, "--json", "--samples", str(a.samples),
               "--seed", str(a.seed), "--threads", str(a.eval_threads)]
        rc, out, err, seconds = self.runner.run(cmd, a.timeout)
        row["seconds_eval"] = seconds
        if rc != 0:
            raise RunFailure("eval: %s: %s" % (exit_text(rc), first_error_line(err)))
        try:
            ev = json.loads(out)
        except ValueError:
            raise RunFailure("eval: output is not JSON")
        write_atomic(base + ".eval.json", json.dumps(ev, indent=1) + "\n")
        if not ev.get("ok", False):
            raise RunFailure("eval: %s" % ev.get("error", "not ok"))
        val = ev.get("validity", {})
        achieved = ev.get("tri_equivalent_out")
        target = row.get("target")
        row.update(achieved=achieved,
                   achieved_rel_error=(achieved - target) / target if achieved is not None and target else None,
                   faces=ev.get("faces_out"), quads=ev.get("quads_out"), tris=ev.get("tris_out"),
                   ngons=ev.get("ngons_out"), qpr=ev.get("qpr"), qpr_rule=ev.get("qpr_rule"),
                   quad_fraction=ev.get("quad_fraction_out"),
                   pccd=ev.get("pccd"), pccd_defined=ev.get("pccd_defined"),
                   chamfer=ev.get("chamfer"), hausdorff=ev.get("hausdorff"),
                   nonmanifold_edges_new=val.get("new_nonmanifold_edges"),
                   nonmanifold_edges=val.get("nonmanifold_edges"),
                   nonmanifold_vertices=val.get("nonmanifold_vertices"),
                   degenerate_faces=val.get("degenerate_faces"),
                   duplicate_faces=val.get("duplicate_faces"),
                   zero_length_edges=val.get("zero_length_edges"),
                   zero_length_edges_in=val.get("zero_length_edges_in"),
                   flipped_faces=ev.get("flipped_faces", val.get("flipped_faces")),
                   flipped_faces_kept=ev.get("flipped_faces_kept"),
                   boundary_edges=val.get("boundary_edges"), components=val.get("components"),
                   flow_deviation_deg=ev.get("flow_deviation_deg"),
                   flow_deviation_p90_deg=ev.get("flow_deviation_p90_deg"),
                   flow_coverage=ev.get("flow_coverage"))
        row.update(uv_metrics(ev))

    # -- driver ---------------------------------------------------------------------------------

    def run(self, meshes, ratios, methods, available):
        tasks = []
        for mesh_path in meshes:
            mesh = os.path.splitext(os.path.basename(mesh_path))[0]
            for r in ratios:
                for m in methods:
                    if not available.get(m):
                        continue
                    if m in ABLATIONS and self.args.ablation_ratios is not None and \
                            not any(abs(r - x) < 1e-9 for x in self.args.ablation_ratios):
                        continue
                    key = (mesh, ratio_key(r), m)
                    old = self.rows.get(key)
                    if old is not None and (old.get("status") == "ok" or not self.args.retry_failed):
                        continue
                    tasks.append((mesh_path, r, m))
        skipped = sum(1 for _ in self.rows)
        log("bench: %d runs to do (%d rows already in %s)" % (len(tasks), skipped, self.csv_path)
            if skipped else "bench: %d runs to do" % len(tasks))
        t_start = time.perf_counter()
        done = [0]

        def finish(row):
            row = {k: cell(row.get(k)) for k in COLUMNS}  # the CSV's string form, as on resume
            with self.rows_lock:
                self.rows[(row["mesh"], row["ratio"], row["method"])] = row
            self.save_csv()
            done[0] += 1
            if row["status"] == "ok":
                detail = "achieved %s/%s, qpr %.3f, chamfer %.2e, hausdorff %.2e" % (
                    row.get("achieved"), row.get("target"), num(row.get("qpr")) or 0.0,
                    num(row.get("chamfer")) or 0.0, num(row.get("hausdorff")) or 0.0)
            else:
                detail = "FAILED: " + row.get("error", "")
            log("[%d/%d] %-36s %-4s %-24s %6.1f s  %s" % (
                done[0], len(tasks), row["mesh"][:36], row["ratio"], row["method"],
                (num(row.get("seconds_total")) or 0.0) + (num(row.get("seconds_eval")) or 0.0),
                detail))

        try:
            if self.args.jobs <= 1:
                for t in tasks:
                    finish(self.run_one(*t))
            else:
                ex = concurrent.futures.ThreadPoolExecutor(self.args.jobs)
                futures = [ex.submit(self.run_one, *t) for t in tasks]
                try:
                    for fu in concurrent.futures.as_completed(futures):
                        finish(fu.result())
                except KeyboardInterrupt:
                    for fu in futures:
                        fu.cancel()
                    self.runner.kill_all()
                    ex.shutdown(wait=True)
                    raise
                ex.shutdown(wait=True)
        except KeyboardInterrupt:
            self.runner.kill_all()
            log("bench: interrupted; %d finished rows are in %s (bench/run resumes from them)"
                % (done[0], self.csv_path))
            raise
        return time.perf_counter() - t_start, len(tasks)


def dpkg_version(pkg):
    try:
        r = subprocess.run(["dpkg-query", "-W", "-f=${Version}", pkg], stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True)
        return r.stdout.strip() if r.returncode == 0 else ""
    except OSError:
        return ""


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


# ---------------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------------

def fmt_sci(x):
    return "–" if x is None else "%.3e" % x


def fmt_fixed(x, digits=4):
    return "–" if x is None else ("%." + str(digits) + "f") % x


def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def ratio_label(r):
    return "%d%% Δ" % round(float(r) * 100)


def qfr(r):
    """Output quad fraction, quads / faces: eval's `quad_fraction_out` (CSV `quad_fraction`), or
    from the counts for rows written before that column existed."""
    v = num(r.get("quad_fraction"))
    if v is not None:
        return v
    q, f = num(r.get("quads")), num(r.get("faces"))
    return q / f if q is not None and f else None


def invalid_reasons(r):
    """Why an ok output is invalid: new non-manifold edges, more degenerate or duplicate faces
    than the input, or faces flipped against the input surface (eval's `flipped_faces`; input
    faces kept unchanged count in `flipped_faces_kept` and are not flips). [] = valid."""
    probs = []
    if (num(r.get("nonmanifold_edges_new")) or 0) > 0:
        probs.append("%d new non-manifold edges" % num(r["nonmanifold_edges_new"]))
    for k in ("degenerate_faces", "duplicate_faces"):
        if (num(r.get(k)) or 0) > (num(r.get(k + "_in")) or 0):
            probs.append("%s %d (input %d)" % (k.replace("_", " "), num(r[k]), num(r.get(k + "_in")) or 0))
    if (num(r.get("flipped_faces")) or 0) > 0:
        probs.append("%d flipped faces" % num(r["flipped_faces"]))
    return probs


def block_table(rows, ratio, methods, labels):
    """Rows for one ratio block: averages over the meshes where every method that has at least
    one success at this ratio succeeded (so each column averages the same meshes)."""
    at = [r for r in rows if r["ratio"] == ratio and r["method"] in methods]
    by_m = {m: {r["mesh"]: r for r in at if r["method"] == m} for m in methods}
    present = [m for m in methods if any(r["status"] == "ok" for r in by_m[m].values())]
    meshes = sorted({r["mesh"] for r in at})
    common = [x for x in meshes if present and all(
        by_m[m].get(x, {}).get("status") == "ok" for m in present)]
    excluded = [x for x in meshes if x not in common]

    def col(m, f):
        if m not in present:
            return "–"
        return f([by_m[m][x] for x in common])

    def avg(key, fmt):
        return lambda rs: fmt(mean(num(r.get(key)) for r in rs))

    def pccd(rs):
        defined = [r for r in rs if r.get("pccd_defined") == "true"]
        if rs and not defined:
            return "×"
        v = fmt_sci(mean(num(r.get("pccd")) for r in defined))
        return v if len(defined) == len(rs) else "%s (%d/%d)" % (v, len(defined), len(rs))

    def dev(rs):
        v = mean(abs(num(r.get("achieved_rel_error"))) for r in rs
                 if num(r.get("achieved_rel_error")) is not None)
        return "–" if v is None else "%.2f%%" % (100 * v)

    metrics = [
        ("Avg. quad fraction, quads/faces [↑]", lambda rs: fmt_fixed(mean(qfr(r) for r in rs))),
        ("Avg. QPR [↑]", avg("qpr", fmt_fixed)),
        ("Avg. PCCD [↓]", pccd),
        ("Avg. Chamfer [↓]", avg("chamfer", fmt_sci)),
        ("Avg. Hausdorff [↓]", avg("hausdorff", fmt_sci)),
        ("Mean \\|achieved−target\\|/target", dev),
        ("Avg. flow deviation [°] (coverage)", lambda rs: "–" if not rs else "%s (%s)" % (
            fmt_fixed(mean(num(r.get("flow_deviation_deg")) for r in rs), 2),
            fmt_fixed(mean(num(r.get("flow_coverage")) for r in rs), 2))),
        ("Avg. time, process [s]", avg("seconds_total", lambda v: fmt_fixed(v, 2))),
        ("Avg. time, reduction only [s]", avg("seconds_core", lambda v: fmt_fixed(v, 3))),
        ("Meshes ok / run", None),
        ("Invalid outputs / ok", "invalid"),
    ]
    lines = []
    for i, (name, f) in enumerate(metrics):
        if f == "invalid":  # over every ok output of the method at this ratio
            cells = ["%d / %d" % (sum(1 for r in by_m[m].values() if r["status"] == "ok" and invalid_reasons(r)),
                                  sum(1 for r in by_m[m].values() if r["status"] == "ok")) for m in methods]
        elif f is None:
            cells = ["%d / %d" % (sum(1 for r in by_m[m].values() if r["status"] == "ok"),
                                  len(by_m[m])) for m in methods]
        else:
            cells = [col(m, f) for m in methods]
        lines.append("| %s | %s | %s |" % (ratio_label(ratio) if i == 0 else "", name, " | ".join(cells)))
    return lines, common, excluded


def make_tables(rows, settings, bar=None):
    """tables.md; `bar`: the bar section's lines (bar_section), placed after Table 2."""
    rows = list(rows)
    ratios = sorted({r["ratio"] for r in rows}, key=lambda x: -float(x))
    out = []
    out.append("# quadlod benchmark\n")
    out.append("Generated %s by `bench/run` from `results.csv` (%d rows). Every output is measured "
               "by `quadlod eval --samples %s --seed %s`; targets are triangle-equivalents "
               "(quad = 2, k-gon = k − 2), the same for every method. quadlod `--time-limit %s`%s. "
               "Peers: %s.\n" % (
                   datetime.datetime.now().strftime("%Y-%m-%d %H:%M"), len(rows),
                   settings.get("samples"), settings.get("seed"),
                   settings.get("time_limit") if settings.get("time_limit") is not None else "default",
                   " (quadlod greedy: `--time-limit 0`)" if any(r["method"] == "quadlod-greedy" for r in rows) else "",
                   ", ".join("%s %s" % kv for kv in sorted(settings.get("peer_versions", {}).items()))
                   or "none"))
    out.append("Averages in each ratio block run over the meshes where every method with any "
               "success at that ratio succeeded; excluded meshes are listed under the table. "
               "PCCD is × where no output has quads (undefined: a triangle-only output has no "
               "poly-chords), and `(k/n)` where only k of n outputs define it. Times: *process* is "
               "the wall time of the reducing process (start-up and file I/O included; Blender "
               "starts in ~1.5 s); *reduction only* is the time the tool reports for the "
               "reduction itself (quadlod: report `seconds`; meshopt: `meshopt_simplify`; Blender: "
               "modifier evaluations including the parameter search; MeshLab: not reported).\n")

    # Table 1
    methods1 = [m for m in TABLE1_METHODS if any(r["method"] == m for r in rows)]
    if methods1:
        labels = [METHODS[m][2] for m in methods1]
        out.append("## Table 1: quadlod against the peers\n")
        out.append("| | Metric | %s |" % " | ".join(labels))
        out.append("|---|---|%s" % ("---:|" * len(labels)))
        notes = []
        for ratio in ratios:
            lines, common, excluded = block_table(rows, ratio, methods1, labels)
            out.extend(lines)
            if excluded:
                notes.append("%s: averages over %d meshes; excluded (a method failed or did not "
                             "run): %s" % (ratio_label(ratio), len(common), ", ".join(excluded)))
        out.append("")
        out.extend("* " + n for n in notes)
        out.append("")

    # Table 2
    abl = [r for r in rows if r["method"] in ABLATIONS]
    if abl:
        methods2 = TABLE2_METHODS
        labels = ["Full"] + [METHODS[m][2] for m in ABLATIONS]
        for ratio in sorted({r["ratio"] for r in abl}, key=lambda x: -float(x)):
            out.append("## Table 2: ablations at %s\n" % ratio_label(ratio).replace(" Δ", ""))
            out.append("| | Metric | %s |" % " | ".join(labels))
            out.append("|---|---|%s" % ("---:|" * len(labels)))
            lines, common, excluded = block_table(rows, ratio, methods2, labels)
            out.extend(lines)
            out.append("")
            if excluded:
                out.append("* averages over %d meshes; excluded: %s\n" % (len(common), ", ".join(excluded)))

    out.extend(uv_section(rows))
    out.extend(full_vs_bare_section(rows, settings))

    if bar:
        out.extend(bar)

    # Losses
    out.extend(losses_section(rows))
    out.extend(validity_section(rows))

    failed = [r for r in rows if r["status"] != "ok"]
    out.append("## Failed runs (%d)\n" % len(failed))
    if failed:
        out.append("| mesh | ratio | method | error |")
        out.append("|---|---:|---|---|")
        for r in failed:
            out.append("| %s | %s | %s | %s |" % (r["mesh"], r["ratio"], r["method"],
                                                 (r.get("error") or "").replace("|", "\\|")))
    out.append("")
    return "\n".join(out) + "\n"


def uv_section(rows):
    """Seams and UVs per ratio and method (UV_COLUMNS), for the methods with at least one output
    whose UVs eval measured. Counts and means per ratio run over the meshes where every one of
    those methods has an ok output with UV metrics at that ratio (as Table 1's averages)."""
    methods = [m for m in METHODS if any(r["method"] == m and r["status"] == "ok" and
                                         num(r.get("uv_error_mean")) is not None for r in rows)]
    out = ["## Seams and UVs\n"]
    if not methods:
        out.append("No output with UVs measured (methods that keep UVs: quadlod-full, meshopt-uv, "
                   "blender-collapse; meshes without UVs give none).\n")
        return out
    out.append("Methods whose outputs carry UVs, measured by `quadlod eval` (docs/metrics.md §6c). "
               "*torn* = output seam or boundary edges that lie on no input seam or boundary "
               "(`seams_torn`): outputs with any, and their sum; *islands added* = outputs with more "
               "UV islands than the input (`uv_islands_out > uv_islands_in`: a seam cut through an "
               "island, or an island pinched apart at a vertex); *UV error* = texture-space distance over the island's UV diagonal, the "
               "mean over meshes of each output's `uv_error_mean` and `uv_error_max`; *seams out/in* "
               "= mean of `seam_edges_out / seam_edges_in`. Per ratio over the *meshes* where every "
               "method listed has an output with UVs (methods that read or write positions and "
               "polygons only have empty UV cells and are not listed); *with UVs / ok* counts every "
               "ok output of the method at that ratio.\n")
    out.append("| ratio | method | meshes | torn: outputs > 0 | torn: sum | islands added: outputs "
               "| UV error mean | UV error max | seams out/in | with UVs / ok |")
    out.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    notes = []
    uv_ok = lambda r: r is not None and r["status"] == "ok" and num(r.get("uv_error_mean")) is not None
    for ratio in sorted({r["ratio"] for r in rows if r["method"] in methods}, key=lambda x: -float(x)):
        by_m = {m: {r["mesh"]: r for r in rows if r["ratio"] == ratio and r["method"] == m}
                for m in methods}
        present = [m for m in methods if any(uv_ok(r) for r in by_m[m].values())]
        meshes = sorted({x for m in present for x in by_m[m]})
        common = [x for x in meshes if all(uv_ok(by_m[m].get(x)) for m in present)]
        if len(common) < len(meshes):
            notes.append("%s: over %d meshes; excluded (no output with UVs from some method, or a "
                         "method failed): %s" % (ratio_label(ratio), len(common),
                                                 ", ".join(x for x in meshes if x not in common)))
        for m in present:
            rs = [by_m[m][x] for x in common]
            torn = [num(r.get("seams_torn")) for r in rs if num(r.get("seams_torn")) is not None]
            added = sum(1 for r in rs if num(r.get("uv_islands_out")) is not None and
                        num(r.get("uv_islands_in")) is not None and
                        num(r["uv_islands_out"]) > num(r["uv_islands_in"]))
            seams = mean(num(r["seam_edges_out"]) / num(r["seam_edges_in"]) for r in rs
                         if num(r.get("seam_edges_out")) is not None and num(r.get("seam_edges_in")))
            ok = [r for r in by_m[m].values() if r["status"] == "ok"]
            out.append("| %s | %s | %d | %d | %d | %d | %s | %s | %s | %d / %d |" % (
                ratio_label(ratio).replace(" Δ", ""), METHODS[m][2], len(rs),
                sum(1 for t in torn if t > 0), sum(torn), added,
                fmt_sci(mean(num(r.get("uv_error_mean")) for r in rs)),
                fmt_sci(mean(num(r.get("uv_error_max")) for r in rs)),
                fmt_fixed(seams, 3), sum(1 for r in ok if uv_ok(r)), len(ok)))
    out.append("")
    out.extend("* " + n for n in notes)
    if notes:
        out.append("")
    return out


def geomean(xs):
    xs = [x for x in xs if x is not None and x > 0]
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else None


def full_vs_bare_section(rows, settings=None):
    """quadlod-full against quadlod per ratio: geometric means over the meshes where both
    succeeded of Chamfer(full)/Chamfer(bare) and Hausdorff(full)/Hausdorff(bare), and how many
    outputs of each land within TARGET_TOLERANCE of the target."""
    full, bare = FULL_VS_BARE
    if not any(r["method"] == full for r in rows) or not any(r["method"] == bare for r in rows):
        return []
    exact = 1e-12  # distances at or below this are exact reproductions: no meaningful quotient
    out = ["## Files as they are vs bare geometry\n"]
    out.append("`%s` reduces the corpus file as it is (UVs, normals, materials, groups: their seams "
               "and borders are kept), `%s` the positions + polygons copy every peer reads; both are "
               "measured against the corpus file. Per ratio over the meshes where both succeeded: "
               "the geometric mean over meshes of the quotients full / bare (> 1: keeping the "
               "file's attributes costs accuracy), the largest quotient and its mesh, and how many "
               "outputs of each have achieved within ±%g %% of the target (`achieved_rel_error`; "
               "over every ok output at that ratio).\n" % (full, bare, 100 * TARGET_TOLERANCE))
    if settings and settings.get("quadlod_input") == "full":
        out.append("**Note:** these rows were measured with `--quadlod-input full`: `%s` read the "
                   "corpus file too, so both columns are the same reduction.\n" % bare)
    out.append("| ratio | meshes | Chamfer full/bare (geo. mean) | worst (mesh) | Hausdorff full/bare "
               "(geo. mean) | worst (mesh) | full within ±%g %% | bare within ±%g %% |"
               % (100 * TARGET_TOLERANCE, 100 * TARGET_TOLERANCE))
    out.append("|---|---:|---:|---|---:|---|---:|---:|")
    skipped = []

    def within(rs):
        ok = [r for r in rs if r["status"] == "ok"]
        k = sum(1 for r in ok if num(r.get("achieved_rel_error")) is not None and
                abs(num(r["achieved_rel_error"])) <= TARGET_TOLERANCE + 1e-12)
        return "%d / %d" % (k, len(ok))

    for ratio in sorted({r["ratio"] for r in rows if r["method"] in FULL_VS_BARE}, key=lambda x: -float(x)):
        a = {r["mesh"]: r for r in rows if r["ratio"] == ratio and r["method"] == full}
        b = {r["mesh"]: r for r in rows if r["ratio"] == ratio and r["method"] == bare}
        both = sorted(x for x in a if x in b and a[x]["status"] == "ok" and b[x]["status"] == "ok")
        cells = []
        for key in ("chamfer", "hausdorff"):
            q = []
            for x in both:
                u, v = num(a[x].get(key)), num(b[x].get(key))
                if u is None or v is None or u <= exact or v <= exact:
                    skipped.append("%s %s %s" % (ratio_label(ratio).replace(" Δ", ""), x, key))
                    continue
                q.append((u / v, x))
            worst = max(q) if q else None
            cells.append(fmt_fixed(geomean(v for v, _ in q), 3) +
                         ("" if len(q) == len(both) else " (%d)" % len(q)))
            cells.append("–" if worst is None else "%.3f (%s)" % worst)
        out.append("| %s | %d | %s | %s | %s | %s | %s | %s |" % (
            ratio_label(ratio).replace(" Δ", ""), len(both), cells[0], cells[1], cells[2], cells[3],
            within(a.values()), within(b.values())))
    out.append("")
    if skipped:
        out.append("* not in the geometric means (a distance missing or ≤ %g, an exact "
                   "reproduction; the count in parentheses is the meshes used): %s\n"
                   % (exact, ", ".join(skipped)))
    return out


def losses_section(rows):
    """Every (mesh, ratio) where a peer beats quadlod on Hausdorff, Chamfer or QPR."""
    q = {(r["mesh"], r["ratio"]): r for r in rows if r["method"] == "quadlod"}
    losses = []
    quadlod_failed = []
    compared = 0
    for r in rows:
        if r["method"] not in PEERS or r["status"] != "ok":
            continue
        base = q.get((r["mesh"], r["ratio"]))
        if base is None:
            continue
        if base["status"] != "ok":
            quadlod_failed.append((r, base))
            continue
        compared += 1
        for metric, higher_better in (("hausdorff", False), ("chamfer", False), ("qpr", True)):
            a, b = num(base.get(metric)), num(r.get(metric))
            if a is None or b is None:
                continue
            # Distances below 1e-12 (of the unit bounding box) are exact reproductions: a peer
            # at 1e-18 is "infinitely" better, not 1e16 times, and two exact results tie.
            exact = 1e-12
            if higher_better:
                if not b > a:
                    continue
                factor = b / a if a > 0 else float("inf")
            else:
                if not b < a or a <= exact:
                    continue
                factor = a / b if b > exact else float("inf")
            losses.append((r["mesh"], r["ratio"], r["method"], metric, a, b, factor,
                           num(r.get("achieved_rel_error")), num(base.get("achieved_rel_error"))))
    out = ["## Losses: where a peer beats quadlod\n"]
    out.append("Every (mesh, ratio, peer, metric) among Hausdorff, Chamfer and QPR where the peer's "
               "output is better than quadlod's (%d peer results compared). *factor* = how many "
               "times better the peer is (quadlod/peer for distances, peer/quadlod for QPR). Read "
               "it with the *achieved* columns: a peer that stopped above the target kept more "
               "faces than quadlod.\n" % compared)
    summary = {}
    for l in losses:
        summary.setdefault((l[2], l[3]), []).append(l)
    if summary:
        out.append("| peer | metric | losses | of | median factor | worst factor |")
        out.append("|---|---|---:|---:|---:|---:|")
        for (peer, metric), ls in sorted(summary.items()):
            n = sum(1 for r in rows if r["method"] == peer and r["status"] == "ok" and
                    q.get((r["mesh"], r["ratio"]), {}).get("status") == "ok")
            fs = sorted(l[6] for l in ls)
            med = fs[len(fs) // 2] if len(fs) % 2 else 0.5 * (fs[len(fs) // 2 - 1] + fs[len(fs) // 2])
            f2 = lambda v: "∞" if math.isinf(v) else "%.2f" % v
            out.append("| %s | %s | %d | %d | %s | %s |" % (
                METHODS[peer][2], metric, len(ls), n, f2(med), f2(fs[-1])))
        out.append("")
        out.append("| mesh | ratio | peer | metric | quadlod | peer value | factor | peer achieved vs target | quadlod achieved vs target |")
        out.append("|---|---:|---|---|---:|---:|---:|---:|---:|")
        for l in sorted(losses, key=lambda l: (-l[6], l[0], l[1])):
            val = (lambda v: "%.4f" % v) if l[3] == "qpr" else fmt_sci
            pct = lambda v: "–" if v is None else "%+.1f%%" % (100 * v)
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                l[0], l[1], METHODS[l[2]][2], l[3], val(l[4]), val(l[5]),
                "∞" if math.isinf(l[6]) else "%.2f" % l[6], pct(l[7]), pct(l[8])))
    else:
        out.append("No losses.")
    out.append("")
    if quadlod_failed:
        out.append("Peer succeeded where quadlod failed:\n")
        for r, base in quadlod_failed:
            out.append("* %s %s: %s ok; quadlod failed: %s" % (r["mesh"], r["ratio"],
                                                              METHODS[r["method"]][2], base.get("error")))
        out.append("")
    return out


def bar_section(rows, method="quadlod", peer="single"):
    """The quality bar of `method` against `peer`, per ratio, over the meshes where both succeeded:
    mean quad fraction >= peer's + BAR_QFR_MARGIN; mean Hausdorff, Chamfer, PCCD and flow
    deviation <= the peer's; Chamfer <= the peer's on >= BAR_CHAMFER_SHARE of the meshes; no
    invalid output (invalid_reasons). Returns (Markdown lines, {ratio: passed or None})."""
    lm, lp = METHODS[method][2], METHODS[peer][2]
    out = ["## Bar: %s against %s\n" % (lm, lp)]
    mine = [r for r in rows if r["method"] == method]
    theirs = [r for r in rows if r["method"] == peer]
    if not mine or not theirs:
        out.append("Not checked: no rows for %s.\n" % " and ".join(
            m for m, rs in ((method, mine), (peer, theirs)) if not rs))
        return out, {}
    out.append("Per ratio, over the meshes where both %s and %s succeeded: mean quad fraction "
               "(quads/faces) ≥ %s's + %.2f; mean Hausdorff, Chamfer, PCCD and flow deviation ≤ "
               "%s's (PCCD over the meshes where both define it, flow deviation where both "
               "measure it); %s's Chamfer ≤ %s's on ≥ %d %% of the meshes; every %s output valid "
               "(no new non-manifold edge, no more degenerate or duplicate faces than the input, "
               "no flipped face).\n" % (lm, lp, lp, BAR_QFR_MARGIN, lp, lm, lp,
                                         round(100 * BAR_CHAMFER_SHARE), lm))
    ratios = sorted({r["ratio"] for r in mine} & {r["ratio"] for r in theirs}, key=lambda x: -float(x))
    verdicts = {}
    losses = []
    for ratio in ratios:
        a = {r["mesh"]: r for r in mine if r["ratio"] == ratio}
        b = {r["mesh"]: r for r in theirs if r["ratio"] == ratio}
        both = sorted(x for x in a if x in b and a[x]["status"] == "ok" and b[x]["status"] == "ok")
        a_failed = sorted(x for x in a if x in b and a[x]["status"] != "ok" and b[x]["status"] == "ok")
        title = "### %s: %d meshes where both succeeded" % (ratio_label(ratio).replace(" Δ", ""), len(both))
        out.append(title + (" (of %d with rows for both)\n" % len(set(a) & set(b))))
        if a_failed:
            out.append("%s failed where %s succeeded (not counted): %s\n" % (lm, lp, ", ".join(a_failed)))
        if not both:
            out.append("Not checked: no mesh where both succeeded.\n")
            verdicts[ratio] = None
            continue
        crit = []

        def less_equal(name, key, fmt, defined=None):
            pairs = [(num(a[x].get(key)), num(b[x].get(key))) for x in both
                     if defined is None or defined(a[x], b[x])]
            pairs = [(u, v) for u, v in pairs if u is not None and v is not None]
            if not pairs:
                crit.append((name, "–", "–", None))
                return
            mu, mv = mean(u for u, _ in pairs), mean(v for _, v in pairs)
            sub = "" if len(pairs) == len(both) else " (%d of %d meshes)" % (len(pairs), len(both))
            crit.append((name + sub, fmt(mu), fmt(mv), mu <= mv))

        qa, qb = mean(qfr(a[x]) for x in both), mean(qfr(b[x]) for x in both)
        crit.append(("mean quad fraction ≥ %s + %.2f" % (lp, BAR_QFR_MARGIN), fmt_fixed(qa),
                     "%s (+%.2f = %s)" % (fmt_fixed(qb), BAR_QFR_MARGIN,
                                          fmt_fixed(None if qb is None else qb + BAR_QFR_MARGIN)),
                     None if qa is None or qb is None else qa >= qb + BAR_QFR_MARGIN - 1e-12))
        less_equal("mean Hausdorff ≤", "hausdorff", fmt_sci)
        less_equal("mean Chamfer ≤", "chamfer", fmt_sci)
        less_equal("mean PCCD ≤", "pccd", fmt_sci,
                   lambda u, v: u.get("pccd_defined") == "true" and v.get("pccd_defined") == "true")
        less_equal("mean flow deviation [°] ≤", "flow_deviation_deg", lambda v: fmt_fixed(v, 2))
        wins, n = 0, 0
        for x in both:
            u, v = num(a[x].get("chamfer")), num(b[x].get("chamfer"))
            if u is None or v is None:
                continue
            n += 1
            if u <= v:
                wins += 1
            else:
                losses.append((x, ratio, u, v))
        crit.append(("Chamfer ≤ %s's on ≥ %d %% of meshes" % (lp, round(100 * BAR_CHAMFER_SHARE)),
                     "%d / %d = %.1f %%" % (wins, n, 100.0 * wins / n) if n else "–", "",
                     wins >= BAR_CHAMFER_SHARE * n - 1e-9 if n else None))
        bad = [x for x in both if invalid_reasons(a[x])]
        crit.append(("every output valid", "%d invalid of %d" % (len(bad), len(both)),
                     "%d invalid" % sum(1 for x in both if invalid_reasons(b[x])), not bad))
        out.append("| criterion | %s | %s | result |" % (lm, lp))
        out.append("|---|---:|---:|---|")
        for name, u, v, ok in crit:
            out.append("| %s | %s | %s | %s |" % (name, u, v, "n/a" if ok is None else ("PASS" if ok else "FAIL")))
        if bad:
            out.append("")
            out.extend("* invalid: %s: %s" % (x, "; ".join(invalid_reasons(a[x]))) for x in bad)
        failed = sum(1 for c in crit if c[3] is False)
        unknown = sum(1 for c in crit if c[3] is None)
        verdicts[ratio] = failed == 0 and unknown == 0
        out.append("")
        out.append("**%s: %s** (%d of %d criteria failed%s)\n" % (
            ratio_label(ratio).replace(" Δ", ""), "PASS" if verdicts[ratio] else "FAIL", failed,
            len(crit), ", %d not measurable" % unknown if unknown else ""))
    out.append("Chamfer losses (%s's Chamfer > %s's): %d\n" % (lm, lp, len(losses)))
    if losses:
        out.append("| mesh | ratio | %s Chamfer | %s Chamfer | %s / %s |" % (lm, lp, lm, lp))
        out.append("|---|---:|---:|---:|---:|")
        for x, ratio, u, v in sorted(losses, key=lambda l: (-float(l[1]), -(l[2] / l[3] if l[3] > 0 else math.inf))):
            out.append("| %s | %s | %s | %s | %s |" % (x, ratio, fmt_sci(u), fmt_sci(v),
                                                      "∞" if v <= 0 else "%.2f" % (u / v)))
        out.append("")
    checked = {k: v for k, v in verdicts.items() if v is not None}
    out.append("**Bar %s vs %s: %s** (%s)\n" % (
        lm, lp, "PASS" if checked and all(checked.values()) and len(checked) == len(verdicts) else "FAIL",
        ", ".join("%s %s" % (ratio_label(k).replace(" Δ", ""),
                             "n/a" if v is None else ("PASS" if v else "FAIL")) for k, v in verdicts.items())
        or "no ratio checked"))
    return out, verdicts


def validity_section(rows):
    bad = []
    for r in rows:
        if r["status"] != "ok":
            continue
        probs = invalid_reasons(r)
        k = "zero_length_edges"  # listed here, not counted as invalid (Table 1, bar)
        if (num(r.get(k)) or 0) > (num(r.get(k + "_in")) or 0):
            probs.append("zero length edges %d (input %d)" % (num(r[k]), num(r.get(k + "_in")) or 0))
        if probs:
            bad.append((r, probs))
    out = ["## Validity: outputs worse than their input\n"]
    out.append("Outputs with new non-manifold edges, or more degenerate or duplicate faces than the "
               "input, or faces flipped against the input surface (`flipped_faces`, docs/metrics.md "
               "§6b): these count as *invalid* in Table 1 and the bar. Outputs with more zero-length "
               "edges than the input (two vertices on one point) are listed too, but not counted.\n")
    if bad:
        out.append("| mesh | ratio | method | problems |")
        out.append("|---|---:|---|---|")
        for r, probs in bad:
            out.append("| %s | %s | %s | %s |" % (r["mesh"], r["ratio"], r["method"], "; ".join(probs)))
    else:
        out.append("None.")
    out.append("")
    return out


# ---------------------------------------------------------------------------------------------
# Plots (paper Fig. 9): QPR against Hausdorff / Chamfer, distance on a log x axis
# ---------------------------------------------------------------------------------------------

PLOT_METHODS = TABLE1_METHODS
COLOURS = {"quadlod": "#1f77b4", "quadlod-full": "#393b79", "quadlod-greedy": "#17becf",
           "single": "#8c564b", "single-rel": "#e377c2", "meshopt": "#ff7f0e",
           "meshopt-uv": "#bcbd22", "meshlab": "#2ca02c",
           "blender-collapse": "#d62728", "blender-unsubdiv": "#9467bd"}


def plot_data(rows):
    ratios = sorted({r["ratio"] for r in rows if r["method"] in PLOT_METHODS}, key=lambda x: -float(x))
    data = {}
    for r in rows:
        if r["status"] != "ok" or r["method"] not in PLOT_METHODS:
            continue
        for metric in ("hausdorff", "chamfer"):
            d, q = num(r.get(metric)), num(r.get("qpr"))
            if d is not None and d > 0 and q is not None:
                data.setdefault((metric, r["ratio"], r["method"]), []).append((d, q))
    return ratios, data


def make_plots(rows, out_dir):
    ratios, data = plot_data(rows)
    if not data:
        return "plots: no successful rows to plot"
    gp = shutil.which("gnuplot")
    if gp:
        return plots_gnuplot(gp, ratios, data, out_dir)
    py = "/usr/bin/python3"
    if os.path.exists(py) and subprocess.run([py, "-c", "import matplotlib"], stderr=subprocess.DEVNULL).returncode == 0:
        return plots_matplotlib(py, ratios, data, out_dir)
    return "plots: skipped (neither gnuplot nor python3-matplotlib installed; scripts/bootstrap --peers)"


def plots_gnuplot(gp, ratios, data, out_dir):
    made = []
    work = tempfile.mkdtemp(prefix=".plots.", dir=out_dir)
    try:
        for metric, title in (("hausdorff", "Hausdorff"), ("chamfer", "Chamfer")):
            png = os.path.join(out_dir, "fig9_%s.png" % metric)
            tmp_png = os.path.join(work, "fig.png")
            cols = 2 if len(ratios) > 1 else 1
            nrows = (len(ratios) + cols - 1) // cols
            script = ["set terminal pngcairo size %d,%d font 'sans,10'" % (520 * cols, 420 * nrows),
                      "set output '%s'" % tmp_png,
                      "set datafile separator ','",
                      "set multiplot layout %d,%d title 'QPR against %s (paper Fig. 9; up-left is better)'"
                      % (nrows, cols, title),
                      "set logscale x", "set format x '10^{%L}'", "set grid",
                      "set xlabel '%s (normalised)'" % title, "set ylabel 'QPR'",
                      "set yrange [0:*]", "set offsets graph 0.03, graph 0.03, graph 0.08, 0",
                      "set key outside below horizontal font ',9'"]
            for ratio in ratios:
                plots = []
                for m in PLOT_METHODS:
                    pts = data.get((metric, ratio, m))
                    if not pts:
                        continue
                    f = os.path.join(work, "%s_%s_%s.csv" % (metric, ratio, m))
                    with open(f, "w") as fh:
                        fh.write("".join("%.9g,%.9g\n" % p for p in pts))
                    plots.append("'%s' using 1:2 with points pt 7 ps 0.8 lc rgb '%s' title '%s'"
                                 % (f, COLOURS.get(m, "black"), METHODS[m][2]))
                script.append("set title '%s'" % ratio_label(ratio).replace(" Δ", ""))
                script.append("plot " + ", ".join(plots) if plots else "plot NaN notitle")
            script.append("unset multiplot")
            script.append("set output")
            sp = os.path.join(work, "fig.gp")
            with open(sp, "w") as fh:
                fh.write("\n".join(script) + "\n")
            r = subprocess.run([gp, sp], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            if r.returncode != 0 or not os.path.exists(tmp_png):
                return "plots: gnuplot failed: %s" % first_error_line(r.stdout)
            os.replace(tmp_png, png)
            made.append(png)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return "plots (gnuplot): " + ", ".join(made)


MPL_SCRIPT = r"""
import json, sys, os
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
spec = json.load(open(sys.argv[1]))
for metric, title in (("hausdorff", "Hausdorff"), ("chamfer", "Chamfer")):
    ratios = spec["ratios"]
    cols = 2 if len(ratios) > 1 else 1
    nrows = (len(ratios) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 4.2 * nrows), squeeze=False)
    for i, ratio in enumerate(ratios):
        ax = axes[i // cols][i % cols]
        for m in spec["methods"]:
            pts = spec["data"].get("%s|%s|%s" % (metric, ratio, m))
            if pts:
                ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=12, c=spec["colours"][m],
                           label=spec["labels"][m])
        ax.set_xscale("log"); ax.grid(True, alpha=0.3)
        ax.set_title(spec["ratio_titles"][ratio]); ax.set_xlabel(title + " (normalised)"); ax.set_ylabel("QPR")
        ax.legend(fontsize=7, loc="lower right")
    for j in range(len(ratios), nrows * cols):
        axes[j // cols][j % cols].axis("off")
    fig.suptitle("QPR against %s (paper Fig. 9; up-left is better)" % title)
    fig.tight_layout()
    fig.savefig(spec["tmp"][metric], dpi=100)
"""


def plots_matplotlib(py, ratios, data, out_dir):
    work = tempfile.mkdtemp(prefix=".plots.", dir=out_dir)
    try:
        spec = {"ratios": ratios, "methods": PLOT_METHODS, "colours": COLOURS,
                "labels": {m: METHODS[m][2] for m in PLOT_METHODS},
                "ratio_titles": {r: ratio_label(r).replace(" Δ", "") for r in ratios},
                "data": {"%s|%s|%s" % k: v for k, v in data.items()},
                "tmp": {m: os.path.join(work, m + ".png") for m in ("hausdorff", "chamfer")}}
        sp, script = os.path.join(work, "spec.json"), os.path.join(work, "plot.py")
        with open(sp, "w") as f:
            json.dump(spec, f)
        with open(script, "w") as f:
            f.write(MPL_SCRIPT)
        r = subprocess.run([py, script, sp], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if r.returncode != 0:
            return "plots: matplotlib failed: %s" % first_error_line(r.stdout)
        made = []
        for m in ("hausdorff", "chamfer"):
            dst = os.path.join(out_dir, "fig9_%s.png" % m)
            os.replace(spec["tmp"][m], dst)
            made.append(dst)
        return "plots (matplotlib): " + ", ".join(made)
    finally:
        shutil.rmtree(work, ignore_errors=True)


# ---------------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------------

def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="bench/run",
        description="quadlod, its ablations and the installed peers (Single, meshoptimizer, "
                    "MeshLab, Blender) side by side, all measured by `quadlod eval`, and the bar "
                    "(quadlod against Single).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--quick", action="store_true",
                   help="daily check: the --quick-meshes smallest meshes at ratio 0.4, every method, "
                        "into out/bench-quick (fresh each time unless --resume)")
    p.add_argument("--quick-meshes", type=int, default=3, help="meshes in --quick (smallest files)")
    p.add_argument("--mesh-dir", default=os.path.normpath(os.path.join(REPO, "..", "shared", "corpus")),
                   help="folder whose *.obj meshes run")
    p.add_argument("--meshes", default=None,
                   help="comma-separated mesh names (file stems) to run from --mesh-dir; default all")
    p.add_argument("--out", default=None, help="output folder (default out/bench, or "
                                               "out/bench-quick with --quick)")
    p.add_argument("--ratios", default=None, help="comma-separated target ratios "
                                                  "(default %s; --quick: %s)" % (DEFAULT_RATIOS, QUICK_RATIOS))
    p.add_argument("--methods", default="all",
                   help="comma-separated among: %s; or 'all', 'peers', 'ablations'" % ", ".join(METHODS))
    p.add_argument("--ablation-ratios", default="0.4",
                   help="ratios at which the quadlod ablations run (paper Table 2 is at 0.4); 'all' = "
                        "every --ratios value")
    p.add_argument("--jobs", type=int, default=1, help="runs in parallel")
    p.add_argument("--time-limit", type=float, default=None,
                   help="passed to quadlod simplify --time-limit (default: quadlod's own default)")
    p.add_argument("--quadlod-threads", type=int, default=1, help="quadlod simplify --threads")
    p.add_argument("--samples", type=int, default=200000, help="quadlod eval --samples")
    p.add_argument("--seed", type=int, default=1, help="quadlod eval --seed")
    p.add_argument("--eval-threads", type=int, default=1,
                   help="quadlod eval --threads (results do not depend on it)")
    p.add_argument("--timeout", type=float, default=3600,
                   help="seconds after which one run is killed and recorded as failed")
    p.add_argument("--quadlod", default=None, help="quadlod binary (default build/quadlod)")
    p.add_argument("--meshopt-peer", default=None,
                   help="meshoptimizer driver (default build-bench/ or build/quadlod_meshopt_peer)")
    p.add_argument("--build-peers", action="store_true",
                   help="configure build-bench/ and build quadlod_meshopt_peer first")
    p.add_argument("--blender", default="blender", help="Blender executable")
    p.add_argument("--quadlod-input", choices=["clean", "full"], default="clean",
                   help="what every quadlod method reads: clean = the positions-and-polygons OBJ "
                        "Single gets (default; quadlod-full still reads the corpus file), full = the "
                        "corpus file with UVs, normals and materials")
    p.add_argument("--single", default=None,
                   help="Single (Knodt 2025) decimate binary (default $QUADLOD_SINGLE, else "
                        "../shared/peers/single/decimate)")
    p.add_argument("--bar-method", default="quadlod",
                   help="method(s) checked against the bar (comma-separated, e.g. "
                        "quadlod,quadlod-greedy)")
    p.add_argument("--bar-peer", default="single", help="the peer the bar compares against")
    p.add_argument("--meshlabserver", default="meshlabserver", help="meshlabserver executable")
    p.add_argument("--keep-meshes", action="store_true",
                   help="keep every output mesh under OUT/runs/ (default: deleted after eval)")
    p.add_argument("--fresh", action="store_true", help="discard the rows already in OUT/results.csv")
    p.add_argument("--resume", action="store_true", help="with --quick: keep earlier rows")
    p.add_argument("--retry-failed", action="store_true",
                   help="re-run rows whose status is failed (ok rows are always kept)")
    p.add_argument("--report-only", action="store_true",
                   help="run nothing: rebuild tables and plots from OUT/results.csv")
    a = p.parse_args(argv)
    if a.jobs < 1:
        p.error("--jobs must be >= 1")
    if a.time_limit is not None and not (0 <= a.time_limit <= 86400):
        p.error("--time-limit must be in [0, 86400]")
    if a.samples < 1000:
        p.error("--samples must be >= 1000 (quadlod eval's minimum)")
    if a.fresh and a.resume:
        p.error("--fresh and --resume exclude each other")
    try:
        ratios = a.ratios or (QUICK_RATIOS if a.quick else DEFAULT_RATIOS)
        a.ratio_list = [float(x) for x in ratios.split(",") if x.strip()]
    except ValueError:
        p.error("--ratios: not a comma-separated list of numbers: %s" % a.ratios)
    if not a.ratio_list or any(not (0 < r <= 1) for r in a.ratio_list):
        p.error("--ratios must lie in (0, 1]")
    if a.ablation_ratios.strip() == "all":
        a.ablation_ratios = None
    else:
        try:
            a.ablation_ratios = [float(x) for x in a.ablation_ratios.split(",") if x.strip()]
        except ValueError:
            p.error("--ablation-ratios: not a list of numbers or 'all'")
    methods = []
    for m in a.methods.split(","):
        m = m.strip()
        if m == "all":
            methods += list(METHODS)
        elif m == "peers":
            methods += PEERS
        elif m == "ablations":
            methods += ABLATIONS
        elif m in METHODS:
            methods.append(m)
        elif m:
            p.error("--methods: unknown method %r (known: %s)" % (m, ", ".join(METHODS)))
    a.method_list = [m for m in METHODS if m in methods]
    a.bar_methods = [m.strip() for m in a.bar_method.split(",") if m.strip()]
    for m in a.bar_methods + [a.bar_peer]:
        if m not in METHODS:
            p.error("--bar-method/--bar-peer: unknown method %r (known: %s)" % (m, ", ".join(METHODS)))
    if not a.method_list:
        p.error("--methods selects nothing")
    if a.out is None:
        a.out = os.path.join(REPO, "out", "bench-quick" if a.quick else "bench")
    if a.quick and not a.resume:
        a.fresh = True
    return a


def select_meshes(a):
    d = a.mesh_dir
    if not os.path.isdir(d):
        sys.exit("bench/run: mesh folder %s not found (pass --mesh-dir DIR)" % d)
    meshes = sorted(os.path.join(d, f) for f in os.listdir(d) if f.lower().endswith(".obj"))
    if a.meshes:
        want = [x.strip() for x in a.meshes.split(",") if x.strip()]
        stems = {os.path.splitext(os.path.basename(m))[0]: m for m in meshes}
        want = [w[:-4] if w.lower().endswith(".obj") else w for w in want]
        missing = [w for w in want if w not in stems]
        if missing:
            sys.exit("bench/run: not in %s: %s" % (d, ", ".join(missing)))
        meshes = [stems[w] for w in want]
    # Smallest first: early rows arrive early, and --quick takes the head of this order.
    meshes.sort(key=lambda m: (os.path.getsize(m), m))
    if a.quick and not a.meshes:
        meshes = meshes[:a.quick_meshes]
    if not meshes:
        sys.exit("bench/run: no .obj meshes in %s" % d)
    return meshes


def _terminate(signum, frame):
    raise KeyboardInterrupt


def main(argv):
    signal.signal(signal.SIGTERM, _terminate)
    a = parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    bench = Bench(a)
    settings_path = os.path.join(bench.out, "settings.json")
    settings = {}
    if os.path.exists(settings_path):
        with open(settings_path) as f:
            settings = json.load(f)

    if a.report_only:
        bench.load_csv()
        if not bench.rows:
            sys.exit("bench/run: no rows in %s" % bench.csv_path)
        finish_reports(bench, settings)
        return 0

    meshes = select_meshes(a)
    available = bench.find_tools(a.method_list)
    now = {"samples": a.samples, "seed": a.seed, "time_limit": a.time_limit,
           "quadlod_threads": a.quadlod_threads, "ablation_ratios": a.ablation_ratios,
           "eval_threads": a.eval_threads, "quadlod": bench.quadlod_source,
           "quadlod_sha256": sha256(bench.quadlod), "peer_versions": bench.peer_versions,
           "host_cpus": os.cpu_count(), "jobs": a.jobs, "quadlod_input": a.quadlod_input}
    if a.fresh:
        for f in (bench.csv_path, settings_path):
            if os.path.exists(f):
                os.unlink(f)
        settings = {}
    else:
        bench.load_csv()
        if bench.rows and settings:
            diff = [k for k in MEASUREMENT_KEYS if settings.get(k) != now.get(k)]
            if diff:
                sys.exit("bench/run: %s holds rows measured with other settings (%s: %s, now %s); "
                         "use another --out, the same settings, or --fresh" % (
                             bench.csv_path, ", ".join(diff),
                             ", ".join(str(settings.get(k)) for k in diff),
                             ", ".join(str(now.get(k)) for k in diff)))
            if settings.get("quadlod_sha256") != now["quadlod_sha256"]:
                log("bench: warning: the quadlod binary changed since the rows in %s were measured; "
                    "kept rows are from the old binary (--fresh re-measures everything)" % bench.csv_path)
    peers_seen = dict(settings.get("peer_versions", {}))
    peers_seen.update(bench.peer_versions)
    now["peer_versions"] = peers_seen
    write_atomic(settings_path, json.dumps(now, indent=1, sort_keys=True) + "\n")

    log("bench: %d meshes from %s, ratios %s, methods %s -> %s" % (
        len(meshes), os.path.abspath(a.mesh_dir), ",".join(ratio_key(r) for r in a.ratio_list),
        ",".join(m for m in a.method_list if available.get(m)), bench.out))
    try:
        seconds, n = bench.run(meshes, a.ratio_list, a.method_list, available)
    except KeyboardInterrupt:
        return 130
    log("bench: %d runs in %.1f s" % (n, seconds))
    finish_reports(bench, now)
    failed = sum(1 for r in bench.rows.values() if r.get("status") != "ok")
    if failed:
        log("bench: %d failed rows (status=failed in results.csv, listed in tables.md)" % failed)
    return 0


def finish_reports(bench, settings):
    rows = list(bench.rows.values())
    bar = []
    for m in bench.args.bar_methods:
        bar += bar_section(rows, m, bench.args.bar_peer)[0]
    md = make_tables(rows, settings, bar)
    md_path = os.path.join(bench.out, "tables.md")
    write_atomic(md_path, md)
    log(plot_msg(bench, rows))
    # Print Table 1 and Table 2 and the loss summary (not the long per-case list), then the bar.
    printing = True
    in_bar = False
    for line in md.splitlines():
        if line.startswith("## "):
            in_bar = line.startswith("## Bar")
        if line.startswith("## Validity") or line.startswith("## Failed"):
            printing = False
        if line.startswith("| mesh | ratio | peer"):
            printing = False
        if printing and not in_bar:
            print(line)
    for line in bar:
        print(line)
    log("bench: wrote %s, %s" % (bench.csv_path, md_path))


def plot_msg(bench, rows):
    try:
        return make_plots(rows, bench.out)
    except OSError as e:
        return "plots: failed: %s" % e


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
