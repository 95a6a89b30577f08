"""make bench-python: the Python package against the command-line tool.

For every bench mesh (tests/data, and those of BENCH_MESH_DIR when set),
the same work both ways, at --atlas 1024 --padding 4 with THREADS threads
(default "2 1"):

  tool    build/bijparam MESH --atlas 1024 --padding 4 --threads T -q -o OUT
          (a process: read, solve, pack, write), wall and CPU of the child;
  python  bijparam.read_mesh, parametrize(mesh, ...), Result.write, in
          this process (the module imported once before), wall and CPU;

alternating tool and python runs, BENCH_RUNS rounds (default 5).  The two
outputs must be the same bytes (checked every round).  Columns: medians of
wall and CPU, "ratio" = python wall / tool wall (medians of one run, the
binding's overhead is ratio - 1), and "binding" = the part of the python
call's wall time outside the library (parametrize's wall minus the
library's own, report["timings"]["total"]).  A table on stdout and one JSON
line per mesh and thread count in build/bench/python.jsonl.  Then two
calls at once on two Python threads (threads=1 each) against one, on
PAIR_MESH (default bimba_i.obj).

    PYTHONPATH=python /usr/bin/python3 bench/python_bench.py
    BENCH_RUNS=3 BENCH_MESHES="camel_b.obj face.obj" THREADS="2" ...
"""
import filecmp
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import bijparam

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.path.join(ROOT, "build", "bijparam")
DATA = os.path.join(ROOT, "tests", "data")
EXTRA = os.environ.get("BENCH_MESH_DIR", "")
RUNS = int(os.environ.get("BENCH_RUNS", "5"))
THREADS = [int(t) for t in os.environ.get("THREADS", "2 1").split()]
EXT = (".obj", ".off", ".ply")


def meshes():
    names = os.environ.get("BENCH_MESHES", "").split()
    found = {}
    for d in (DATA, EXTRA):
        if d and os.path.isdir(d):
            for n in sorted(os.listdir(d)):
                if n.lower().endswith(EXT) and n not in found:
                    found[n] = os.path.join(d, n)
    return [found[n] for n in (names or found) if n in found]


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def self_cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def run_tool(mesh, out, threads):
    c0, t0 = children_cpu(), time.perf_counter()
    subprocess.run([TOOL, mesh, "--atlas", "1024", "--padding", "4", "--threads", str(threads), "-q", "-o", out],
                   check=True)
    return time.perf_counter() - t0, children_cpu() - c0


def run_python(mesh, out, threads):
    c0, t0 = self_cpu(), time.perf_counter()
    m = bijparam.read_mesh(mesh, threads=threads)
    t1 = time.perf_counter()
    r = bijparam.parametrize(m, resolution=1024, padding=4, threads=threads)
    t2 = time.perf_counter()
    r.write(out, threads=threads)
    wall = time.perf_counter() - t0
    return wall, self_cpu() - c0, (t2 - t1) - r.report["timings"]["total"], r.report, len(m.indices)


def two_threads(mesh):
    """One parametrize call (threads=1) against two at once on two Python
    threads (threads=1 each), and the same with tool processes (what the
    machine's cores allow at the moment), alternating, RUNS rounds:
    medians of wall and CPU.  With the GIL released the pair of calls
    scales as the pair of processes does."""
    m = bijparam.read_mesh(mesh)
    call = lambda: bijparam.parametrize(m.positions, m.indices, resolution=1024, padding=4, threads=1)
    args = [TOOL, mesh, "--atlas", "1024", "--padding", "4", "--threads", "1", "-q"]

    def pair_of_tools():
        ps = [subprocess.Popen(args + ["-o", os.devnull]) for _ in range(2)]
        for p in ps:
            p.wait()
    runs = {"call": [], "two calls": [], "tool": [], "two tools": []}
    for k in range(RUNS):
        for name in (list(runs) if k % 2 == 0 else list(runs)[::-1]):
            c0, cc0, t0 = self_cpu(), children_cpu(), time.perf_counter()
            if name == "call":
                call()
            elif name == "two calls":
                th = [threading.Thread(target=call) for _ in range(2)]
                for t in th:
                    t.start()
                for t in th:
                    t.join()
            elif name == "tool":
                subprocess.run(args + ["-o", os.devnull], check=True)
            else:
                pair_of_tools()
            runs[name].append((time.perf_counter() - t0, self_cpu() - c0 + children_cpu() - cc0))
    med = statistics.median
    w = {k: med(x[0] for x in v) for k, v in runs.items()}
    c = {k: med(x[1] for x in v) for k, v in runs.items()}
    print(f"bench-python: {os.path.basename(mesh)}, threads=1, medians of {RUNS} (wall / CPU seconds): one call "
          f"{w['call']:.3f} / {c['call']:.3f}, two calls on two Python threads {w['two calls']:.3f} / "
          f"{c['two calls']:.3f} (wall ratio {w['two calls'] / w['call']:.2f}); the tool {w['tool']:.3f} / "
          f"{c['tool']:.3f}, two tool processes at once {w['two tools']:.3f} / {c['two tools']:.3f} (wall ratio "
          f"{w['two tools'] / w['tool']:.2f}); load average {os.getloadavg()[0]:.1f}", flush=True)
    return dict(mesh=os.path.basename(mesh), wall=w, cpu=c)


def main():
    if not os.access(TOOL, os.X_OK):
        sys.exit("bench-python: build/bijparam is missing (make)")
    os.makedirs(os.path.join(ROOT, "build", "bench"), exist_ok=True)
    jsonl = open(os.path.join(ROOT, "build", "bench", "python.jsonl"), "w")
    head = (f"{'mesh':24} {'faces':>7} {'thr':>3} {'tool wall':>9} {'tool cpu':>8} {'py wall':>9} {'py cpu':>8} "
            f"{'ratio':>6} {'binding':>8} same")
    print(f"bench-python: {RUNS} alternating rounds, --atlas 1024 --padding 4, medians (seconds)", flush=True)
    print(head, flush=True)
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in meshes():
            for threads in THREADS:
                a_out, b_out = os.path.join(tmp, "tool.obj"), os.path.join(tmp, "py.obj")
                tw, tc, pw, pc, bind = [], [], [], [], []
                same = True
                for k in range(RUNS):
                    order = (0, 1) if k % 2 == 0 else (1, 0)
                    for which in order:
                        if which == 0:
                            w, c = run_tool(mesh, a_out, threads)
                            tw.append(w)
                            tc.append(c)
                        else:
                            w, c, b, report, faces = run_python(mesh, b_out, threads)
                            pw.append(w)
                            pc.append(c)
                            bind.append(b)
                    same = same and filecmp.cmp(a_out, b_out, shallow=False)
                med = statistics.median
                ratio = med(pw) / med(tw)
                ratios.append(ratio)
                row = dict(mesh=os.path.basename(mesh), faces=faces, threads=threads, runs=RUNS,
                           tool_wall=med(tw), tool_cpu=med(tc), python_wall=med(pw), python_cpu=med(pc),
                           ratio=ratio, binding_seconds=med(bind), same_output=same, charts=report["charts"])
                jsonl.write(json.dumps(row) + "\n")
                jsonl.flush()
                print(f"{row['mesh']:24} {faces:>7} {threads:>3} {row['tool_wall']:9.3f} {row['tool_cpu']:8.3f} "
                      f"{row['python_wall']:9.3f} {row['python_cpu']:8.3f} {ratio:6.3f} {row['binding_seconds']:8.4f} "
                      f"{'yes' if same else 'NO'}", flush=True)
    print(f"bench-python: median ratio python/tool {statistics.median(ratios):.3f} over {len(ratios)} rows "
          f"(max {max(ratios):.3f}); JSON: build/bench/python.jsonl")
    pair = [m for m in meshes() if os.path.basename(m) == os.environ.get("PAIR_MESH", "bimba_i.obj")]
    if pair:
        jsonl.write(json.dumps(dict(two_threads=two_threads(pair[0]))) + "\n")


if __name__ == "__main__":
    main()
