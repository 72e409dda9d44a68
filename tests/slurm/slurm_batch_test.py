#!/usr/bin/env python3
"""docs/jobs/slurm_batch.sh on a real one-node Slurm cluster, with kills (issue 36).

Starts munged, slurmctld and slurmd (config, state and logs in a temp folder, ports of its own)
and stops them at the end whatever happens; writes ~200 assets (the corpus's small meshes,
generated meshes, and broken ones: truncated, NaN, empty); runs the manifest once on this
machine (`quadlod batch`, the reference) and as a job array through slurm_batch.sh, killing
tasks while it runs (scancel of an array task, SIGKILL of a task's quadlod, scontrol requeue)
at seeded moments, then resubmits the tasks that did not complete. A LOD-chain manifest
(--levels) goes through the same. Checks: every good asset has exactly one output, readable
and byte-identical to the reference's, and a record that vouches for it; every broken asset has
a failed line naming its file and error; no temp file is left; the merged shard lines equal the
reference's field for field, times aside (a "skipped" line of a rerun carries the recorded
result of the run that did the work).

Needs root (slurmd starts jobs, munged runs as the munge user) and slurm-wlm + munge
(scripts/bootstrap). Exit 0 = passed, 1 = failed, 77 = skipped (not root).
"""
import argparse
import ctypes
import json
import os
import pwd
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SEED = 36
DEADLINE_SECONDS = 240  # ours; CTest's TIMEOUT (300) is a backstop that cannot clean up
TOOLS = ["munged", "mungekey", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "scontrol", "sinfo"]
# The corpus's small meshes (< 1700 faces, docs: corpus README).
CORPUS_SMALL = ["blender_suzanne.obj", "opensubdiv_bishop_cage.obj", "godot_squash_player_cage.obj",
                "flightgear_head_amelia.obj", "opensubdiv_car_cage.obj", "yofrankie_ram.obj"]
TEMP_RE = re.compile(r"^\..+\.tmp-\d+-[0-9a-f]+$")

T0 = time.monotonic()
failures = []


def log(msg):
    print(f"[{time.monotonic() - T0:6.1f} s] {msg}", flush=True)


def check(ok, what):
    if not ok:
        failures.append(what)
        log("FAIL: " + what)
    return ok


def deadline_left():
    return DEADLINE_SECONDS - (time.monotonic() - T0)


class Interrupted(Exception):
    pass


def on_signal(signum, _frame):
    raise Interrupted(f"signal {signum}")


# ---- the cluster ---------------------------------------------------------------------------------

_libc = ctypes.CDLL(None, use_errno=True)
PR_SET_PDEATHSIG = 1


def die_with_parent():
    """preexec_fn: the daemon gets SIGTERM when this script dies, however it dies."""
    _libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def as_user(name):
    entry = pwd.getpwnam(name)

    def preexec():
        os.setgroups([])
        os.setgid(entry.pw_gid)
        os.setuid(entry.pw_uid)
        die_with_parent()  # after setuid, which clears the parent-death signal
    return preexec


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    def __init__(self, root):
        self.root = root
        self.conf = root / "slurm.conf"
        self.daemons = []  # (name, Popen)
        self.env = dict(os.environ, SLURM_CONF=str(self.conf))

    def run(self, args, **kw):
        return subprocess.run(args, env=kw.pop("env", self.env), capture_output=True, text=True, **kw)

    def start(self):
        munge = self.root / "munge"
        munge.mkdir()
        shutil.chown(munge, "munge", "munge")
        os.chmod(munge, 0o755)  # munged wants the socket's folder searchable by all
        key = munge / "munge.key"
        subprocess.run(["mungekey", "-c", "-k", str(key)], preexec_fn=as_user("munge"), check=True)
        socket_path = munge / "munge.socket"
        self.spawn("munged", ["munged", "-F", "-S", str(socket_path), f"--key-file={key}",
                              f"--pid-file={munge}/munged.pid", f"--log-file={munge}/munged.log",
                              f"--seed-file={munge}/munged.seed"], as_user("munge"))
        wait_for(lambda: socket_path.exists(), 10, "munged's socket")

        node = self.run(["slurmd", "-C"]).stdout.splitlines()[0]  # NodeName=… CPUs=… RealMemory=…
        self.host = re.search(r"NodeName=(\S+)", node).group(1)
        self.cpus = int(re.search(r"CPUs=(\d+)", node).group(1))
        self.memory_mb = int(re.search(r"RealMemory=(\d+)", node).group(1))
        for d in ("state", "spool", "log"):
            (self.root / d).mkdir()
        # Addresses given, so that a host name without DNS (a container) still works.
        # Memory is not a consumable (CR_Core): the script's --mem=4G is a request per task, and
        # with memory consumable a task without --mem would take the whole node.
        # cred_expire=5 and sched/bf interval 1: a requeued task starts ~6 s later, not ~2 min.
        self.conf.write_text(f"""ClusterName=quadlodtest
SlurmctldHost={self.host}(127.0.0.1)
SlurmUser=root
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={socket_path},cred_expire=5
StateSaveLocation={self.root}/state
SlurmdSpoolDir={self.root}/spool
SlurmctldPidFile={self.root}/slurmctld.pid
SlurmdPidFile={self.root}/slurmd.pid
SlurmctldLogFile={self.root}/log/slurmctld.log
SlurmdLogFile={self.root}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerParameters=bf_interval=1,sched_interval=1
ReturnToService=2
MailProg=/bin/true
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
{node} NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=quadlod Nodes={self.host} Default=YES MaxTime=INFINITE State=UP
""")
        self.spawn("slurmctld", ["slurmctld", "-D", "-f", str(self.conf)], die_with_parent)
        self.spawn("slurmd", ["slurmd", "-D", "-f", str(self.conf)], die_with_parent)
        wait_for(lambda: self.run(["sinfo", "-h", "-o", "%T"]).stdout.strip() == "idle", 30, "the node to be idle")
        log(f"cluster up: node {self.host}, {self.cpus} CPUs, {self.memory_mb} MB, config {self.conf}")

    def spawn(self, name, args, preexec):
        out = open(self.root / f"{name}.stdout", "wb")
        self.daemons.append((name, subprocess.Popen(args, stdout=out, stderr=subprocess.STDOUT,
                                                    preexec_fn=preexec, env=self.env)))

    def stop(self):
        if any(p.poll() is None for n, p in self.daemons if n == "slurmctld"):
            self.run(["scancel", "--user=root"], timeout=20)
            try:
                wait_for(lambda: not self.run(["squeue", "-h"], timeout=20).stdout.strip(), 20, "jobs to end")
            except Exception as e:  # noqa: BLE001 — stopping anyway
                log(f"stop: {e}")
        for name, p in reversed(self.daemons):  # slurmd, slurmctld, munged
            if p.poll() is None:
                p.terminate()
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
        self.daemons = []


def wait_for(predicate, seconds, what):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.1)
    raise RuntimeError(f"timed out after {seconds} s waiting for {what}")


# ---- the assets ----------------------------------------------------------------------------------

def make_assets(cli, assets, corpus, count, rng):
    """Returns [(file name, kind)] with kind "good" or the expected error's pattern."""
    assets.mkdir(parents=True)
    made = []
    if corpus and corpus.is_dir():
        for name in CORPUS_SMALL:
            if (corpus / name).is_file():
                shutil.copyfile(corpus / name, assets / name)
                made.append((name, "good"))
    else:
        log(f"no corpus at {corpus}: generated meshes only")
    # Broken on purpose; each pattern is what the error must say besides the file's name.
    def gen(kind, path, n, m=None):
        args = [cli, "generate", kind, "-o", str(path), "--n", str(n)] + (["--m", str(m)] if m else [])
        subprocess.run(args, check=True, capture_output=True)
    gen("torus", assets / "src_t.obj", 10, 6)
    text = (assets / "src_t.obj").read_text()
    cut = text.index("\nv ", len(text) // 3) + 6  # inside a vertex line
    (assets / "broken_truncated.obj").write_text(text[:cut])
    gen("torus", assets / "src_t.ply", 10, 6)
    data = (assets / "src_t.ply").read_bytes()
    (assets / "broken_truncated.ply").write_bytes(data[:len(data) * 2 // 3])
    subprocess.run([cli, "-q", "simplify", str(assets / "src_t.obj"), "-o", str(assets / "src_t.glb"), "--ratio", "0.9"],
                   check=True, capture_output=True)
    data = (assets / "src_t.glb").read_bytes()
    (assets / "broken_truncated.glb").write_bytes(data[:len(data) // 2])
    (assets / "broken_nan.obj").write_text(re.sub(r"^v (\S+)", "v nan", text, count=1, flags=re.M))
    (assets / "broken_inf.off").write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n1 inf 0\n0 1 0\n4 0 1 2 3\n")
    (assets / "broken_empty.obj").write_bytes(b"")
    (assets / "broken_empty.ply").write_bytes(b"")
    for p in ("src_t.obj", "src_t.ply", "src_t.glb"):
        (assets / p).unlink()
    made += [("broken_truncated.obj", r"coordinates|truncated|unexpected end"),
             ("broken_truncated.ply", r"truncated"),
             ("broken_truncated.glb", r"byteLength|truncated|GLTF|glTF"),
             ("broken_nan.obj", r"non-finite"),
             ("broken_inf.off", r"non-finite"),
             ("broken_empty.obj", r"no faces|empty"),
             ("broken_empty.ply", r"empty|header|magic|not a PLY|ply")]
    kinds = [("torus", 6, 24, 4, 12), ("cylinder", 6, 24, 2, 10), ("cube", 2, 8, 0, 0),
             ("grid", 4, 20, 4, 20), ("vase", 8, 24, 6, 14)]
    i = 0
    while len(made) < count:
        kind, n0, n1, m0, m1 = kinds[i % len(kinds)]
        ext = (".obj", ".ply", ".off")[rng.randrange(3)]
        name = f"gen{i:03d}_{kind}{ext}"
        gen(kind, assets / name, rng.randint(n0, n1), rng.randint(m0, m1) if m1 else None)
        made.append((name, "good"))
        i += 1
    rng.shuffle(made)
    return made


def write_manifest(path, lines):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(line) + "\n" for line in lines))


def reduction_manifest(assets, rng):
    lines = []
    for name, _ in assets:
        stem = Path(name).stem
        ext = (".obj", ".glb", ".ply")[rng.randrange(3)]
        line = {"input": f"../assets/{name}", "output": f"out/{stem}{ext}"}
        if rng.random() < 0.2:
            line["faces"] = rng.choice([40, 80, 120])
        else:
            line["ratio"] = rng.choice([0.3, 0.4, 0.5, 0.6])
        lines.append(line)
    return lines


def lod_manifest(assets, rng):
    lines = []
    for name, _ in assets:
        line = {"input": f"../assets/{name}", "output": f"lods/{Path(name).stem}", "levels": [0.5, 0.25]}
        if rng.random() < 0.5:
            line["format"] = "glb"
        lines.append(line)
    return lines


# ---- runs and kills ------------------------------------------------------------------------------

def count_lines(path):
    try:
        return path.read_bytes().count(b"\n")
    except FileNotFoundError:
        return 0


class ArrayRun:
    """One sbatch of slurm_batch.sh from `folder`, and the kills planned for it."""

    def __init__(self, cluster, script, folder, manifest, tasks, shards=None, mem=None):
        self.cluster, self.folder = cluster, folder
        args = ["sbatch", "--parsable", f"--array={tasks}"] + ([f"--mem={mem}"] if mem else []) + [str(script), manifest]
        if shards:
            args.append(str(shards))
        r = cluster.run(args, cwd=folder)
        if r.returncode != 0:
            raise RuntimeError(f"sbatch failed: {r.stderr.strip()}")
        self.job = r.stdout.strip().split(";")[0]
        self.kills = []  # dicts: task, how, after (lines), done, at
        log(f"submitted array {self.job} ({tasks}) in {folder.name}: {' '.join(args[1:])}")

    def plan(self, task, how, after):
        self.kills.append({"task": task, "how": how, "after": after, "done": False})

    def tasks(self):
        """{task index: {JobId, JobState, ExitCode, Restarts}} of this array, from scontrol."""
        r = self.cluster.run(["scontrol", "-o", "show", "job", self.job])
        tasks = {}
        for line in r.stdout.splitlines():
            f = dict(re.findall(r"(\w+)=(\S*)", line))
            if "ArrayTaskId" in f and re.fullmatch(r"\d+", f["ArrayTaskId"]):
                tasks[int(f["ArrayTaskId"])] = f
        return tasks

    def pending(self):
        return bool(self.cluster.run(["squeue", "-h", "-j", self.job]).stdout.strip())

    def poll_kills(self, cli):
        """Does each planned kill as soon as its task has printed `after` result lines (a task
        prints one line per asset as it finishes it, so the kill lands inside a later asset)."""
        for k in self.kills:
            if k["done"]:
                continue
            lines = count_lines(self.folder / "results" / f"shard-{k['task']}.jsonl")
            if lines < k["after"]:
                continue
            target = f"{self.job}_{k['task']}"
            if k["how"] == "scancel":
                ok = self.cluster.run(["scancel", target]).returncode == 0
            elif k["how"] == "requeue":
                ok = self.cluster.run(["scontrol", "requeue", target]).returncode == 0
            else:  # SIGKILL the task's quadlod, found by its executable and its Slurm environment
                pids = quadlod_pids_of(cli, self.job, k["task"])
                if not pids:
                    continue  # not started yet, or already ended: the check below reports it
                os.kill(pids[0], signal.SIGKILL)
                ok = True
                k["pid"] = pids[0]
            k["done"], k["at_lines"] = ok, lines
            log(f"kill: {k['how']} of task {target} after {lines} result lines (planned {k['after']})"
                + (f", quadlod pid {k['pid']}" if "pid" in k else ""))

    def wait(self, cli, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.poll_kills(cli)
            if not self.pending():
                return
            time.sleep(0.05)
        raise RuntimeError(f"array {self.job} still running after {seconds:.0f} s")


def quadlod_pids_of(cli, array_job, task):
    """The PIDs of the quadlod processes of array task `array_job`_`task` (its environment holds
    SLURM_ARRAY_JOB_ID and SLURM_ARRAY_TASK_ID): exactly that task's, nothing found by name."""
    want = {f"SLURM_ARRAY_JOB_ID={array_job}".encode(), f"SLURM_ARRAY_TASK_ID={task}".encode()}
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            if os.path.realpath(f"/proc/{entry}/exe") != cli:
                continue
            with open(f"/proc/{entry}/environ", "rb") as f:
                if want <= set(f.read().split(b"\0")):
                    found.append(int(entry))
        except OSError:
            continue  # ended meanwhile
    return found


# ---- checks --------------------------------------------------------------------------------------

def normalised(line, base):
    """A result line as compared: paths relative to the manifest's folder, no times, and a
    skipped line (the work was recorded by an earlier run) counted as done."""
    def strip(j):
        if isinstance(j, dict):
            return {k: strip(v) for k, v in j.items() if not k.endswith("seconds")}
        if isinstance(j, list):
            return [strip(v) for v in j]
        return j
    out = strip(dict(line))
    for key in ("input", "output"):
        if key in out:
            out[key] = os.path.relpath(os.path.join(base, out[key]), base)  # a relative path is the run's
    if "error" in out:
        out["error"] = out["error"].replace(str(base) + "/", "")
    if out.get("status") == "skipped":
        out["status"] = "done"
    return out


def read_lines(paths):
    lines = []
    for p in paths:
        for text in p.read_text().splitlines():
            if text.strip():
                lines.append(json.loads(text))
    return lines


def stamp(path):
    st = os.stat(path)
    return {"size": st.st_size, "mtime_ns": st.st_mtime_ns}


def check_run(name, cli, folder, ref_folder, manifest_lines, kinds, ref_lines, is_lod):
    """Every check of one manifest's Slurm run against the one-machine reference."""
    shard_files = sorted((folder / "results").glob("shard-*.jsonl"))
    got = read_lines(shard_files)
    got_by_input = {}
    for line in got:
        key = os.path.relpath(os.path.join(folder, line["input"]), folder)
        check(key not in got_by_input, f"{name}: {key} has more than one line in the merged results")
        got_by_input[key] = line
    want_by_input = {os.path.relpath(os.path.join(ref_folder, line["input"]), ref_folder): line for line in ref_lines}
    check(len(got) == len(manifest_lines), f"{name}: {len(got)} merged lines for {len(manifest_lines)} assets")
    outputs_expected = set()
    statuses = {}
    info_checked = 0
    for entry in manifest_lines:
        key, out_rel = entry["input"], entry["output"]
        asset = Path(key).name
        line, want = got_by_input.get(key), want_by_input.get(key)
        if not check(line is not None and want is not None, f"{name}: {key}: no line (slurm {line is not None}, "
                                                            f"reference {want is not None})"):
            continue
        statuses[line["status"]] = statuses.get(line["status"], 0) + 1
        check(normalised(line, folder) == normalised(want, ref_folder),
              f"{name}: {key}: fields differ from the reference:\n  slurm     {normalised(line, folder)}\n"
              f"  reference {normalised(want, ref_folder)}")
        out, ref_out = folder / out_rel, ref_folder / out_rel
        kind = kinds[asset]
        if kind != "good":
            check(line["status"] == "failed", f"{name}: {key}: broken on purpose but {line['status']}")
            error = line.get("error", "")
            check(asset in error and re.search(kind, error), f"{name}: {key}: error {error!r} should name the file and match /{kind}/")
            check(not out.exists(), f"{name}: {key}: broken on purpose but has an output")
            continue
        if not check(line["status"] in ("done", "skipped"), f"{name}: {key}: {line['status']} {line.get('error', '')}"):
            continue
        outputs_expected.add(out.name)
        files = sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) if is_lod else [out.name]
        if is_lod:
            ref_files = sorted(p.name for p in ref_out.iterdir() if not p.name.startswith("."))
            check(files == ref_files, f"{name}: {key}: chain files {files} != reference {ref_files}")
            got_report = json.loads((out / "lods.json").read_text())
            ref_report = json.loads((ref_out / "lods.json").read_text())
            check(normalised(got_report, folder) == normalised(ref_report, ref_folder),
                  f"{name}: {key}: lods.json differs from the reference's (times aside)")
        for f in files:
            p, r = (out / f, ref_out / f) if is_lod else (out, ref_out)
            if f == "lods.json":
                continue
            check(p.read_bytes() == r.read_bytes(), f"{name}: {key}: {p.name} differs from the reference's bytes")
            # Read back: `quadlod info` for the formats it reads, `simplify --ratio 1` (the scene
            # reader) for glTF.
            cmd = [cli, "info", str(p)] if p.suffix != ".glb" else [cli, "-q", "simplify", str(p), "-o", str(folder / "readback.obj"), "--ratio", "1"]
            r2 = subprocess.run(cmd, capture_output=True, text=True)
            check(r2.returncode == 0, f"{name}: {key}: {p.name} does not read back: {r2.stderr.strip()}")
            info_checked += 1
        # Current: the record vouches for the input and every file as they are now.
        record_path = out.parent / f".{out.name}.batch.json"
        if check(record_path.is_file(), f"{name}: {key}: no record {record_path.name}"):
            record = json.loads(record_path.read_text())
            check(record["input"] == stamp(folder / key), f"{name}: {key}: the record's input stamp is not the input's")
            base = out if is_lod else out.parent
            for f in record["files"]:
                check({"size": f["size"], "mtime_ns": f["mtime_ns"]} == stamp(base / f["name"]),
                      f"{name}: {key}: the record's stamp of {f['name']} is not the file's")
            check(os.stat(out if not is_lod else out / "lods.json").st_mtime_ns >= os.stat(folder / key).st_mtime_ns,
                  f"{name}: {key}: output older than its input")
    (folder / "readback.obj").unlink(missing_ok=True)
    # Exactly one output per good asset, nothing else: the records, no temp file anywhere.
    top = {p.name for p in (folder / ("lods" if is_lod else "out")).iterdir()}
    visible = {n for n in top if not n.startswith(".")}
    check(visible == outputs_expected, f"{name}: outputs {sorted(visible ^ outputs_expected)} unexpected or missing")
    hidden = {n for n in top if n.startswith(".")}
    check(hidden == {f".{n}.batch.json" for n in outputs_expected},
          f"{name}: hidden entries besides the records: {sorted(hidden - {f'.{n}.batch.json' for n in outputs_expected})}")
    temps = [str(p) for p in folder.rglob("*") if TEMP_RE.match(p.name)]
    check(not temps, f"{name}: temp files left: {temps}")
    log(f"{name}: {len(got)} lines from {len(shard_files)} shard files {statuses}; {info_checked} output files read back, "
        f"{len(outputs_expected)} outputs byte-identical to the reference")


def record_vouches(folder, entry, is_lod):
    """True when the asset's record matches its input and every file it lists, as they are now
    (what batch_output_is_current checks, options aside)."""
    out = folder / entry["output"]
    record_path = out.parent / f".{out.name}.batch.json"
    try:
        record = json.loads(record_path.read_text())
        base = out if is_lod else out.parent
        return record["input"] == stamp(folder / entry["input"]) and all(
            {"size": f["size"], "mtime_ns": f["mtime_ns"]} == stamp(base / f["name"]) for f in record["files"])
    except (OSError, ValueError, KeyError):
        return False


def same_outputs(out, ref, is_lod):
    """The output's bytes equal the reference's (a chain: every level file; lods.json holds times)."""
    if not is_lod:
        return out.is_file() and out.read_bytes() == ref.read_bytes()
    names = sorted(p.name for p in ref.iterdir() if p.name != "lods.json")
    return out.is_dir() and sorted(p.name for p in out.iterdir() if p.name != "lods.json") == names and all(
        (out / n).read_bytes() == (ref / n).read_bytes() for n in names)


def temps_under(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if TEMP_RE.match(p.name))


def shard_of(lines, index, count, key="input"):
    return [line[key] for i, line in enumerate(lines) if i % count == index]


# ---- main ----------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", required=True, help="the quadlod executable")
    ap.add_argument("--script", required=True, help="docs/jobs/slurm_batch.sh")
    ap.add_argument("--corpus", help="the corpus folder (its small meshes join the assets)")
    ap.add_argument("--assets", type=int, default=200)
    ap.add_argument("--lod-assets", type=int, default=32)
    ap.add_argument("--keep", action="store_true", help="keep the temp folder (printed)")
    args = ap.parse_args()

    # The daemons live in /usr/sbin, which a user's PATH may lack.
    os.environ["PATH"] = os.environ.get("PATH", "/usr/bin:/bin") + ":/usr/sbin:/sbin"
    missing = [t for t in TOOLS if not shutil.which(t)]
    if missing:
        print(f"slurm_batch_test: FAILED: {', '.join(missing)} not installed; `apt-get install slurm-wlm munge` "
              f"(scripts/bootstrap installs them)", file=sys.stderr)
        return 1
    if os.geteuid() != 0:
        print("slurm_batch_test: SKIPPED: needs root (slurmd starts the jobs, munged runs as the munge user)",
              file=sys.stderr)
        return 77

    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, on_signal)
    cli = os.path.realpath(args.cli)
    script = os.path.realpath(args.script)
    root = Path(tempfile.mkdtemp(prefix="quadlod-slurm-"))
    os.chmod(root, 0o755)
    cluster = Cluster(root)
    # The jobs find quadlod on PATH (sbatch exports the submitting environment).
    cluster.env["PATH"] = os.path.dirname(cli) + os.pathsep + cluster.env.get("PATH", "")
    rng = random.Random(SEED)
    try:
        # Assets and manifests: data/assets, data/ref (one machine), data/slurm, data/slurm-lod.
        data = root / "data"
        assets = make_assets(cli, data / "assets", Path(args.corpus) if args.corpus else None, args.assets, rng)
        kinds = dict(assets)
        red_lines = reduction_manifest(assets, rng)
        good = [a for a in assets if a[1] == "good" and not a[0].startswith(tuple(CORPUS_SMALL))]
        lod_assets = [a for a in assets if a[1] != "good"][:2] + good[: args.lod_assets - 2]
        rng.shuffle(lod_assets)
        lod_lines = lod_manifest(lod_assets, rng)
        for folder in ("ref", "slurm"):
            write_manifest(data / folder / "assets.jsonl", red_lines)
        for folder in ("ref", "slurm-lod"):
            write_manifest(data / folder / "lods.jsonl", lod_lines)
        n_broken = sum(k != "good" for _, k in assets)
        log(f"{len(assets)} assets ({n_broken} broken on purpose) in {data / 'assets'}; {len(lod_lines)} LOD chains")

        # The reference, on this machine, while the cluster starts.
        t = time.monotonic()
        ref = [subprocess.Popen([cli, "-q", "batch", str(data / "ref" / m)], stdout=subprocess.PIPE, text=True)
               for m in ("assets.jsonl", "lods.jsonl")]
        cluster.start()
        ref_out = [p.communicate()[0] for p in ref]
        check(all(p.returncode == 2 for p in ref), f"reference runs exit {[p.returncode for p in ref]}, expected 2 (broken assets)")
        ref_red = [json.loads(x) for x in ref_out[0].splitlines() if x.strip()]
        ref_lod = [json.loads(x) for x in ref_out[1].splitlines() if x.strip()]
        log(f"reference (one machine, `quadlod batch`, both manifests at once): {time.monotonic() - t:.1f} s")

        mem = None if cluster.memory_mb >= 4096 else f"{cluster.memory_mb // 2}M"
        if mem:
            log(f"the node has {cluster.memory_mb} MB: sbatch --mem={mem} instead of the script's 4G")

        # First submission, kills while it runs. Shards: 8 for the reductions, 4 for the chains.
        t = time.monotonic()
        red_n, lod_n = 8, 4
        red = ArrayRun(cluster, script, data / "slurm", "assets.jsonl", f"0-{red_n - 1}", mem=mem)
        lod = ArrayRun(cluster, script, data / "slurm-lod", "lods.jsonl", f"0-{lod_n - 1}", mem=mem)
        a, b, c = rng.sample(range(red_n), 3)
        size = lambda i, n, lines: len(shard_of(lines, i, n))  # noqa: E731
        # Each after a seeded number of result lines in the first half of its shard: the other
        # half is the slack the kill needs to land while the task still runs.
        red.plan(a, "scancel", rng.randint(2, size(a, red_n, red_lines) // 2))
        red.plan(b, "sigkill", rng.randint(2, size(b, red_n, red_lines) // 2))
        red.plan(c, "requeue", rng.randint(2, size(c, red_n, red_lines) // 2))
        d, e = rng.sample(range(lod_n), 2)
        lod.plan(d, "sigkill", rng.randint(1, size(d, lod_n, lod_lines) // 2))
        lod.plan(e, "scancel", rng.randint(1, size(e, lod_n, lod_lines) // 2))
        end = time.monotonic() + deadline_left() - 60
        while red.pending() or lod.pending():
            if time.monotonic() > end:
                raise RuntimeError("the first submission did not finish in time")
            for _ in range(10):  # the kills watch closely; squeue above is polled less often
                red.poll_kills(cli)
                lod.poll_kills(cli)
                time.sleep(0.01)
        log(f"first submission ended: {time.monotonic() - t:.1f} s")
        for run, n in ((red, red_n), (lod, lod_n)):
            for k in run.kills:
                check(k["done"], f"array {run.job}: the {k['how']} of task {k['task']} never happened "
                                 f"(the task ended before {k['after']} lines)")
        # What the kills did, as Slurm saw it.
        resubmit = {}
        for run, n in ((red, red_n), (lod, lod_n)):
            tasks = run.tasks()
            states = {i: f"{tasks[i]['JobState']} {tasks[i]['ExitCode']} restarts={tasks[i]['Restarts']}" for i in sorted(tasks)}
            log(f"array {run.job} tasks: {states}")
            for k in run.kills:
                info = tasks[k["task"]]
                if k["how"] == "scancel":
                    check(info["JobState"] == "CANCELLED", f"scancelled task {k['task']} is {info['JobState']}")
                elif k["how"] == "sigkill":
                    # bash (set -e) exits 128 + 9 when its quadlod dies of SIGKILL
                    check(info["JobState"] == "FAILED" and info["ExitCode"] == "137:0",
                          f"SIGKILLed task {k['task']}: {info['JobState']} {info['ExitCode']}")
                else:
                    check(info["Restarts"] == "1" and info["JobState"] in ("COMPLETED", "FAILED"),
                          f"requeued task {k['task']}: {info['JobState']} restarts={info['Restarts']}")
            resubmit[run] = [i for i in sorted(tasks) if tasks[i]["JobState"] != "COMPLETED"]
        log(f"temp files after the first submission: reductions {temps_under(data / 'slurm')}, "
            f"chains {temps_under(data / 'slurm-lod')}")
        # The state the kills left: every asset a record vouches for, or a printed line calls
        # done, has exactly the reference's output (nothing missing or stale counts as done).
        for folder, lines, is_lod in ((data / "slurm", red_lines, False), (data / "slurm-lod", lod_lines, True)):
            printed = {os.path.relpath(os.path.join(folder, l["input"]), folder)
                       for l in read_lines(sorted((folder / "results").glob("shard-*.jsonl"))) if l["status"] == "done"}
            vouched = 0
            for entry in lines:
                out = folder / entry["output"]
                if entry["input"] in printed or record_vouches(folder, entry, is_lod):
                    vouched += 1
                    check(record_vouches(folder, entry, is_lod), f"after the kills: {entry['input']} printed done, no current record")
                    check(same_outputs(out, data / "ref" / entry["output"], is_lod),
                          f"after the kills: {entry['input']} counts as done but its output is not the reference's")
            log(f"after the kills, {folder.name}: {vouched} of {len(lines)} assets count as done, each with the reference's bytes")
        # A temp file as a SIGKILL in the middle of a write leaves it (tests/test_batch.cpp hits
        # that moment on purpose), planted for an asset of the SIGKILLed shards.
        planted = []
        for run, folder, lines, n, k_task in ((red, data / "slurm", red_lines, red_n, b),
                                              (lod, data / "slurm-lod", lod_lines, lod_n, d)):
            entry = next(l for i, l in enumerate(lines) if i % n == k_task and kinds[Path(l["input"]).name] == "good")
            out = folder / entry["output"]
            where = out if out.is_dir() else out.parent
            name = f".{Path(entry['input']).stem}.lod1.glb.tmp-4242-dead" if out.is_dir() else f".{out.name}.tmp-4242-dead"
            where.mkdir(parents=True, exist_ok=True)
            (where / name).write_text("half a file")
            planted.append(where / name)
        log(f"planted {[str(p.relative_to(data)) for p in planted]}")

        # Resubmit what did not complete, with the shard count (the array is only some indices).
        t = time.monotonic()
        again = []
        for run, folder, manifest, n in ((red, data / "slurm", "assets.jsonl", red_n),
                                         (lod, data / "slurm-lod", "lods.jsonl", lod_n)):
            tasks = ",".join(map(str, resubmit[run]))
            check(len(resubmit[run]) >= 2, f"array {run.job}: only {resubmit[run]} to resubmit")
            again.append(ArrayRun(cluster, script, folder, manifest, tasks, shards=n, mem=mem))
        for run in again:
            run.wait(cli, max(10, deadline_left() - 30))
        log(f"resubmission ended: {time.monotonic() - t:.1f} s")
        for run in again:
            tasks = run.tasks()
            log(f"array {run.job} tasks: " + str({i: f"{tasks[i]['JobState']} {tasks[i]['ExitCode']}" for i in sorted(tasks)}))
            for i, info in tasks.items():
                check(info["JobState"] in ("COMPLETED", "FAILED") and info["ExitCode"] in ("0:0", "2:0"),
                      f"resubmitted task {i}: {info['JobState']} {info['ExitCode']} (0: all done, 2: a broken asset)")
        for p in planted:
            check(not p.exists(), f"planted temp {p.name} survived the resubmission")

        check_run("reductions", cli, data / "slurm", data / "ref", red_lines, kinds, ref_red, False)
        check_run("LOD chains", cli, data / "slurm-lod", data / "ref", lod_lines, kinds, ref_lod, True)
        logs = sorted(p.name for p in (data / "slurm").glob("quadlod-batch-*.out"))
        check(len(logs) >= red_n, f"Slurm logs in the submit folder: {logs}")
    except Interrupted as e:
        check(False, f"interrupted by {e}")
    except Exception as e:  # noqa: BLE001 — reported, then the cluster is stopped
        check(False, f"{type(e).__name__}: {e}")
    finally:
        cluster.stop()
        if failures or args.keep:
            log(f"kept {root} (slurm logs in {root / 'log'})")
        else:
            shutil.rmtree(root, ignore_errors=True)
    log(f"{'FAILED: ' + str(len(failures)) + ' checks' if failures else 'passed'} in {time.monotonic() - T0:.1f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
