"""python -m bijparam.batch on a LocalCluster of 2 worker processes: six
meshes (OBJ, OFF and a .glb), six bijective outputs; a restart skips what is done and redoes
what is not; a worker killed mid-run loses nothing."""
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import bijparam
import independent

GLB = "BoxTextured.glb"      # tests/data/gltf: glTF in and out
MESHES = ("camel_b.obj", "spot.obj", "torus_with_holes.obj", "fertility.off", "face_holes.off", GLB)


def run_batch(in_dir, out_dir, *extra, wait=True):
    env = dict(os.environ)
    args = [sys.executable, "-m", "bijparam.batch", str(in_dir), str(out_dir), "--workers", "2", "--threads", "1",
            *extra]
    if not wait:
        return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    p = subprocess.run(args, capture_output=True, text=True, env=env, timeout=600)
    return p


def reports_of(stdout):
    lines = stdout.strip().split("\n")
    return [json.loads(x) for x in lines[:-1]], lines[-1]


def out_name(n):
    stem, ext = os.path.splitext(n)
    return stem + (ext if ext in (".glb", ".gltf") else ".obj")


def assert_outputs(in_dir, out_dir, names):
    """Each input has its output: the same triangles, every face mapped,
    bijective by tests/uvcheck.py; no temporary file left."""
    assert sorted(os.listdir(out_dir)) == sorted(out_name(n) for n in names)
    for n in names:
        a = bijparam.read_mesh(os.path.join(in_dir, n))
        b = bijparam.read_mesh(os.path.join(out_dir, out_name(n)))
        assert np.array_equal(a.positions[a.indices], b.positions[b.indices]), n
        assert b.uvs is not None and len(b.uv_indices) == len(b.indices)
        assert b.uvs.min() >= 0 and b.uvs.max() <= 1
        ok, why = independent.bijective(b.uvs, b.uv_indices)
        assert ok, f"{n}: {why}"


@pytest.fixture
def folder(tmp_path, data):
    src = tmp_path / "in"
    src.mkdir()
    for n in MESHES:
        shutil.copy(data(os.path.join("gltf", n) if n == GLB else n), src / n)
    (src / "notes.txt").write_text("not a mesh\n")
    return src, tmp_path / "out"


def test_six_meshes_six_bijective_outputs(folder):
    src, out = folder
    p = run_batch(src, out, "--resolution", "512")
    assert p.returncode == 0, p.stderr
    reports, summary = reports_of(p.stdout)
    assert len(reports) == 6 and all(r["status"] == "ok" for r in reports)
    assert sorted(os.path.basename(r["input"]) for r in reports) == sorted(MESHES)
    assert summary.startswith("bijparam.batch: 6 meshes: 6 written, 0 skipped")
    assert_outputs(src, out, MESHES)


@pytest.mark.long
def test_restart_skips_what_is_done(folder):
    src, out = folder
    assert run_batch(src, out).returncode == 0
    stamp = {n: os.stat(out / n).st_mtime_ns for n in os.listdir(out)}
    # one output damaged (a face's vt made to repeat a corner), one removed, one stale temporary
    spot = (out / "spot.obj").read_text().split("\n")
    k = next(i for i, ln in enumerate(spot) if ln.startswith("f "))
    corners = [c.split("/") for c in spot[k].split()[1:]]
    spot[k] = "f " + " ".join("/".join([c[0], corners[0][1]] + c[2:]) for c in corners)   # one vt for all
    (out / "spot.obj").write_text("\n".join(spot))
    os.unlink(out / "camel_b.obj")
    (out / ".fertility.obj.x.bijparam-tmp").write_text("half")
    p = run_batch(src, out)
    assert p.returncode == 0, p.stderr
    reports, summary = reports_of(p.stdout)
    by = {os.path.basename(r["input"]): r["status"] for r in reports}
    assert by == {"camel_b.obj": "ok", "spot.obj": "ok", "torus_with_holes.obj": "skipped", "fertility.off": "skipped",
                  "face_holes.off": "skipped", GLB: "skipped"}
    assert "2 written, 4 skipped" in summary
    for n in ("torus_with_holes.obj", "fertility.obj", "face_holes.obj", GLB):
        assert os.stat(out / n).st_mtime_ns == stamp[n], "a finished output was rewritten"
    assert_outputs(src, out, MESHES)


def busy_workers(batch_pid):
    """The batch's worker processes that are using the processor now."""
    def children(pid):          # of every thread (the nannies start the workers from theirs)
        out = []
        for task in glob.glob(f"/proc/{pid}/task/*/children"):
            try:
                with open(task) as f:
                    out += [int(x) for x in f.read().split()]
            except OSError:
                pass
        return out

    def ticks(pid):
        try:
            with open(f"/proc/{pid}/stat") as f:
                s = f.read().rsplit(")", 1)[1].split()
            return int(s[11]) + int(s[12])
        except OSError:
            return 0

    def cmd(pid):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                return f.read().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            return ""
    procs = [c for c in children(batch_pid) if "multiprocessing" in cmd(c) and "resource_tracker" not in cmd(c)]
    before = {c: ticks(c) for c in procs}
    time.sleep(0.3)
    return [c for c in procs if ticks(c) - before[c] >= 2]


@pytest.mark.long
def test_a_worker_killed_mid_run_loses_nothing(folder, data):
    src, out = folder
    # heavier meshes, so that a worker is surely in the middle of one
    for n in ("camelhead.off", "mech-holes-shark.off"):
        shutil.copy(data(n), src / n)
    names = MESHES + ("camelhead.off", "mech-holes-shark.off")
    proc = run_batch(src, out, "--resolution", "2048", wait=False)
    victim = None
    deadline = time.time() + 300
    while victim is None and time.time() < deadline and proc.poll() is None:
        busy = busy_workers(proc.pid)
        if busy and os.path.isdir(out) and len(os.listdir(out)) >= 1:
            victim = busy[0]
            os.kill(victim, signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=600)
    assert victim is not None, "no busy worker was found to kill"
    assert proc.returncode == 0, stderr
    reports, summary = reports_of(stdout)
    assert len(reports) == len(names) and all(r["status"] == "ok" for r in reports), stdout
    assert summary.startswith(f"bijparam.batch: {len(names)} meshes: {len(names)} written")
    assert_outputs(src, out, names)
    assert not glob.glob(str(out / ".*"))


@pytest.mark.long
def test_on_a_scheduler_with_workers_as_on_several_machines(folder, tmp_path):
    """dask-scheduler and two dask-worker processes, as the README runs them
    on several machines (here on one), and the batch given --scheduler."""
    src, out = folder
    port_file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                               "--port", "0", "--no-dashboard", "--scheduler-file", str(port_file)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.time() + 60
        while not port_file.exists() and time.time() < deadline:
            time.sleep(0.2)
        address = json.loads(port_file.read_text())["address"]
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nworkers", "2",
                                       "--nthreads", "1", "--no-dashboard"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        p = subprocess.run([sys.executable, "-m", "bijparam.batch", str(src), str(out), "--scheduler", address,
                            "--threads", "1", "--resolution", "512"], capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr
        reports, summary = reports_of(p.stdout)
        assert len(reports) == 6 and "6 written" in summary and f"scheduler {address}" in summary
        assert_outputs(src, out, MESHES)
    finally:
        for q in reversed(procs):
            q.terminate()
            q.wait(timeout=60)
