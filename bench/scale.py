#!/usr/bin/env python3
"""bench/scale.py - time and memory against the face count (make bench-scale;
docs/performance.md, "One chart from 8K to a million faces").

One corpus chart (default tests/data/face_holes.off, the face with six
holes: one disk, seven boundary loops, 8,288 faces) is subdivided by
bench/subdivide.py into N x N triangles per face for each N of
BENCH_SCALE_N (default "1 4 6 11": 8,288 / 132,608 / 298,368 / 1,002,848
faces), written once to
build/bench/scale/ (the generator is deterministic: the same bytes on every
run), and each is parameterized by the tool

    build/bijparam CHART -o OUT.obj --json --threads T

with T = 1 and 2 (above BENCH_SCALE_T1_MAX faces, default 300000, only
T = 2: the one-thread run of the million faces takes as long again).
Columns of the table:

  faces, vertices  of the generated chart
  T                --threads
  wall s           the whole process (read, charts, start map, optimize,
                   pack, write), measured here
  CPU s            user + system of the process (getrusage of the child)
  setup s          the tool's own timings: read + charts + init (the start
                   map: ordering, symbolic and numeric factorization, the
                   Tutte solve) before the first iteration
  opt s, write s   the tool's "optimize" (including the preconditioner's
                   factorization) and "write" timings
  iters            iterations of the optimization
  E mean           final area-weighted mean symmetric Dirichlet energy
  B/face           peak resident memory / faces (the tool's bytes_per_face)
  exact            the library's own exact check of the result (the
                   tool's report: status ok, flipped = degenerate =
                   boundary_intersections = 0): "yes" or what failed
  uvcheck          python3 tests/uvcheck.py OUT exits 0 ("yes"),
                   for charts up to BENCH_SCALE_UVCHECK_MAX faces (default
                   300000; "-" above: the pure-Python checker needs minutes)

and a second table: the speed-up t(1) / t(2) of the wall and of the
optimization where both ran, and whether both gave the same bits (final
energy and output file).  Runs are single (BENCH_SCALE_RUNS to repeat;
the 1 and 2 thread runs alternate); on a shared machine read CPU s and
iterations, not wall s.  One JSON line per run goes to
build/bench/scale.jsonl and to stdout after the tables.

Environment:
  BENCH_SCALE_MESH=PATH     the chart to subdivide (an open disk)
  BENCH_SCALE_N="1 4 6 11"  subdivision factors
  BENCH_SCALE_T1_MAX=F      largest face count also run with 1 thread
  BENCH_SCALE_UVCHECK_MAX=F largest face count checked by uvcheck
  BENCH_SCALE_RUNS=R        runs per configuration (default 1)
  BENCH_SCALE_ARGS="..."    extra tool options (e.g. "--max-seconds 600")
  BENCH_TIMEOUT=S           per-run limit (default 7200)
  BENCH_TOOL=PATH           the tool (bench/scale.sh snapshots build/bijparam)
"""
import filecmp
import json
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.environ.get("BENCH_TOOL") or os.path.join(ROOT, "build", "bijparam")
UVCHECK = os.path.join(ROOT, "tests", "uvcheck.py")
OUT = os.path.join(ROOT, "build", "bench", "scale")


def env_int(name, default):
    v = os.environ.get(name, "")
    return int(v) if v.strip() else default


MESH = os.environ.get("BENCH_SCALE_MESH") or os.path.join(ROOT, "tests", "data", "face_holes.off")
NS = [int(w) for w in os.environ.get("BENCH_SCALE_N", "1 4 6 11").split()]
T1_MAX = env_int("BENCH_SCALE_T1_MAX", 300000)
UV_MAX = env_int("BENCH_SCALE_UVCHECK_MAX", 300000)
RUNS = max(1, env_int("BENCH_SCALE_RUNS", 1))
TIMEOUT = env_int("BENCH_TIMEOUT", 7200)
ARGS = os.environ.get("BENCH_SCALE_ARGS", "").split()


def generate(n):
    """build/bench/scale/<mesh>_n<N>.obj, made once (bench/subdivide.py)."""
    base = os.path.splitext(os.path.basename(MESH))[0]
    path = os.path.join(OUT, "%s_n%d.obj" % (base, n))
    gen = os.path.join(ROOT, "bench", "subdivide.py")
    if not os.path.isfile(path) or os.path.getmtime(path) < os.path.getmtime(gen):
        subprocess.run([sys.executable, gen, MESH, str(n), path], check=True,
                       stdout=subprocess.DEVNULL)
    nv = nf = 0
    with open(path) as fh:
        first = fh.readline()   # "# ...: V vertices, F faces"
    w = first.replace(",", " ").split()
    nv, nf = int(w[w.index("vertices") - 1]), int(w[w.index("faces") - 1])
    return path, nv, nf


def run(chart, threads, tag):
    out = os.path.join(OUT, "%s.t%d%s.out.obj" % (os.path.basename(chart)[:-4], threads, tag))
    if os.path.exists(out):
        os.remove(out)
    cmd = [TOOL, chart, "-o", out, "--json", "-q", "--threads", str(threads)] + ARGS
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT)
        rc, so, se = p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, so, se = 124, "", "timed out after %d s" % TIMEOUT
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime
    rep = None
    try:
        rep = json.loads(so.strip().splitlines()[-1])
    except (ValueError, IndexError):
        pass
    row = {"threads": threads, "rc": rc, "wall": wall, "cpu": cpu, "out": out,
           "load": os.getloadavg()[0]}
    if rep is None:
        row["error"] = se.strip()[-300:] or "exit %d" % rc
        return row
    ch = rep["per_chart"][0] if rep.get("per_chart") else {}
    tm = rep.get("timings", {})
    row.update({
        "iterations": ch.get("iterations"), "energy": ch.get("energy_end"),
        "energy_max": ch.get("energy_max"), "stop": ch.get("stop"),
        "bytes_per_face": rep.get("bytes_per_face"), "peak_rss": rep.get("peak_rss_bytes"),
        "timings": tm,
        "setup": sum(tm.get(k, 0) for k in ("read", "charts", "init")),
        "exact": "yes" if (rep.get("status") == "ok" and rep.get("charts") == 1 and
                           ch.get("flipped") == 0 and ch.get("degenerate") == 0 and
                           ch.get("boundary_intersections") == 0)
        else "NO (%s, flipped %s, degenerate %s, boundary %s)" % (
            rep.get("status"), ch.get("flipped"), ch.get("degenerate"), ch.get("boundary_intersections")),
    })
    return row


def uvcheck(out):
    if not os.path.isfile(out):
        return "?"
    p = subprocess.run([sys.executable, UVCHECK, out],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return "yes" if p.returncode == 0 else "NO"


def f(x, fmt):
    return "-" if x is None else fmt % x


def main():
    if not os.access(TOOL, os.X_OK):
        raise SystemExit("bench-scale: %s missing: run 'make' first" % TOOL)
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for n in NS:
        chart, nv, nf = generate(n)
        threads = [1, 2] if nf <= T1_MAX else [2]
        for r in range(RUNS):
            for t in threads:
                row = run(chart, t, "" if r == 0 else ".r%d" % r)
                row.update({"mesh": os.path.basename(MESH), "n": n, "faces": nf, "vertices": nv, "run": r})
                row["uvcheck"] = uvcheck(row["out"]) if nf <= UV_MAX and row.get("rc") == 0 else "-"
                rows.append(row)
                sys.stderr.write(json.dumps(row) + "\n")
    print("\n## time and memory against the face count (%s subdivided, %s)\n"
          % (os.path.basename(MESH), " ".join(ARGS) or "default options"))
    print("| faces | vertices | T | wall s | CPU s | setup s | opt s | write s | iters | E mean | B/face | exact | uvcheck |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for r in rows:
        tm = r.get("timings", {})
        print("| %d | %d | %d | %.2f | %.2f | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["faces"], r["vertices"], r["threads"], r["wall"], r["cpu"], f(r.get("setup"), "%.2f"),
            f(tm.get("optimize"), "%.2f"), f(tm.get("write"), "%.2f"), f(r.get("iterations"), "%d"),
            f(r.get("energy"), "%.6f"), f(r.get("bytes_per_face"), "%.0f"),
            r.get("exact", r.get("error", "?")), r["uvcheck"]))
    print("\n## two threads against one (medians of the runs)\n")
    print("| faces | wall 1T / 2T s | speed-up | opt 1T / 2T s | opt speed-up | same bits |")
    print("|---:|---:|---:|---:|---:|---|")
    for n in NS:
        one = [r for r in rows if r["n"] == n and r["threads"] == 1 and r.get("rc") == 0]
        two = [r for r in rows if r["n"] == n and r["threads"] == 2 and r.get("rc") == 0]
        if not one or not two:
            continue
        w1, w2 = statistics.median(r["wall"] for r in one), statistics.median(r["wall"] for r in two)
        o1 = statistics.median(r["timings"]["optimize"] for r in one)
        o2 = statistics.median(r["timings"]["optimize"] for r in two)
        same = one[0]["energy"] == two[0]["energy"] and filecmp.cmp(one[0]["out"], two[0]["out"], shallow=False)
        print("| %d | %.2f / %.2f | %.2f | %.2f / %.2f | %.2f | %s |" % (
            one[0]["faces"], w1, w2, w1 / w2, o1, o2, o1 / o2, "yes" if same else "NO"))
    with open(os.path.join(ROOT, "build", "bench", "scale.jsonl"), "w") as fh:
        for r in rows:
            fh.write(json.dumps(r) + "\n")
    print()
    for r in rows:
        print(json.dumps(r))


if __name__ == "__main__":
    main()
