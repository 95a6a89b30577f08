#!/usr/bin/env python3
"""bench/threads.py - two threads against one on the charts above 50K faces,
on an idle machine and on a busy one (make bench-threads; docs/performance.md,
"Threads").

    python3 bench/threads.py [RUNS] [idle|busy] [MESHES]

For face (51,712 F, Newton by default), bimba (89,215 F, Newton),
face_holes subdivided 4 x 4 (132,608 F, L-BFGS) and 11 x 11 (1,002,848 F,
one run only) it runs

    TOOL CHART -o OUT --json --threads T -q        T = 1, 2 alternated

RUNS times (default 3) and prints one JSON line per run (wall and CPU
seconds of the process, the chart's solve -- the tool's start map and
optimization, without reading, building the charts, packing and
writing --, iterations, final energy, bytes per face, the tool's exact
verdict, the load average) and one Markdown row per chart: median wall 1
thread, 2 threads, their ratio, the median of the runs' own ratios (each
1-thread run against the 2-thread run right after it), the median solve
times and their ratio, median CPU 1 / 2 threads, iterations, bytes per
face, and whether both outputs are the same bytes.
On an idle machine, with RUNS above 1, each round also runs two
one-thread processes side by side, one per core, and the row gives the
machine's ceiling: 2 w1 / wp, w1 the round's one-thread wall and wp the
mean wall of the pair.  The two cores share the last-level cache (and,
on a virtual machine, the host's other guests share it too), so each of
the pair may run slower than alone; a two-thread run that split its work
perfectly, with no serial part and no waiting, would take wp / 2, so
2 w1 / wp is the most two threads can gain on this machine in these
minutes.  "share" is the speed-up divided by it.
"busy" starts two processes that spin on the two cores for the whole
run. MESHES: a comma-separated subset of face,bimba,n4_132K,n11_1M.
TOOL (environment) defaults to build/bijparam. Never asserts times.
"""
import json
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHDIR = os.path.join(ROOT, "tests", "data")
OUT = os.path.join(ROOT, "build", "bench", "threads")
TOOL = os.environ.get("TOOL") or os.path.join(ROOT, "build", "bijparam")


def subdivided(n):
    path = os.path.join(ROOT, "build", "bench", "scale", "face_holes_n%d.obj" % n)
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        subprocess.check_call([sys.executable, os.path.join(ROOT, "bench", "subdivide.py"),
                               os.path.join(MESHDIR, "face_holes.off"), str(n), path])
    return path


def run(path, name, T):
    out = os.path.join(OUT, "%s_%d.obj" % (name, T))
    r0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.time()
    p = subprocess.run([TOOL, path, "-o", out, "--json", "--threads", str(T), "-q"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    wall, r1 = time.time() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    rep = json.loads(p.stdout.decode().strip().splitlines()[-1])
    pc = rep["per_chart"]
    tm = rep.get("timings", {})
    return {"mesh": name, "T": T, "wall": wall, "cpu": r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime,
            "solve": tm.get("init", 0) + tm.get("optimize", 0),
            "iters": sum(c["iterations"] for c in pc), "E": pc[0]["energy_end"], "bpf": rep.get("bytes_per_face"),
            "exact": all(not c["flipped"] and not c["degenerate"] and not c["boundary_intersections"] for c in pc),
            "load": os.getloadavg()[0]}


def side_by_side(path, name):
    """Two one-thread runs at once; the mean of their walls."""
    t0 = time.time()
    procs = [subprocess.Popen([TOOL, path, "-o", os.path.join(OUT, "%s_pair%d.obj" % (name, k)), "--threads", "1",
                               "-q"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for k in (0, 1)]
    walls, codes = [None, None], [None, None]
    while None in codes:                  # each one's own end, whichever ends first
        for k, p in enumerate(procs):
            if codes[k] is None and p.poll() is not None:
                codes[k], walls[k] = p.returncode, time.time() - t0
        time.sleep(0.001)
    if any(codes):
        raise SystemExit("side-by-side run of %s failed (exit %s)" % (name, codes))
    return sum(walls) / 2


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    busy = len(sys.argv) > 2 and sys.argv[2] == "busy"
    meshes = [("face", lambda: os.path.join(MESHDIR, "face.obj"), runs),
              ("bimba", lambda: os.path.join(MESHDIR, "bimba_i.obj"), runs),
              ("n4_132K", lambda: subdivided(4), runs), ("n11_1M", lambda: subdivided(11), 1)]
    if len(sys.argv) > 3:
        meshes = [m for m in meshes if m[0] in sys.argv[3].split(",")]
    os.makedirs(OUT, exist_ok=True)
    hogs = [subprocess.Popen(["sh", "-c", "while :; do :; done"]) for _ in range(2)] if busy else []
    rows = []
    try:
        for name, path_of, R in meshes:
            path, res, ceil = path_of(), {1: [], 2: []}, []
            for _ in range(R):
                for T in (1, 2):
                    r = run(path, name, T)
                    r["busy"] = busy
                    res[T].append(r)
                    print(json.dumps(r), flush=True)
                if not busy and R > 1:
                    wp = side_by_side(path, name)
                    ceil.append(2 * res[1][-1]["wall"] / wp)
                    print(json.dumps({"mesh": name, "pair_wall": wp, "ceiling": ceil[-1]}), flush=True)
            w1, w2 = (statistics.median(x["wall"] for x in res[T]) for T in (1, 2))
            c1, c2 = (statistics.median(x["cpu"] for x in res[T]) for T in (1, 2))
            s1, s2 = (statistics.median(x["solve"] for x in res[T]) for T in (1, 2))
            pairs = sorted(a["wall"] / b["wall"] for a, b in zip(res[1], res[2]))
            same = subprocess.run(["cmp", "-s"] + [os.path.join(OUT, "%s_%d.obj" % (name, T)) for T in (1, 2)]).returncode == 0
            cm = statistics.median(ceil) if ceil else None
            rows.append("| %s | %.2f | %.2f | %.2f | %.2f | %s | %s | %.2f / %.2f | %.2f | %.2f / %.2f | %d | %.0f | %s |" % (
                name, w1, w2, w1 / w2, statistics.median(pairs), "%.2f" % cm if cm else "-",
                "%.2f" % (w1 / w2 / cm) if cm else "-", s1, s2, s1 / s2, c1, c2, res[1][0]["iters"],
                res[2][0]["bpf"] or 0, "yes" if same else "NO"))
    finally:
        for h in hogs:
            h.kill()
    print("\n| chart | wall 1 thread | wall 2 threads | speed-up | median of pairs | ceiling | share "
          "| solve 1 / 2 | solve speed-up | CPU 1 / 2 | iters | B/face | same bytes |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
