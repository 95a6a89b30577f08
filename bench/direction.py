#!/usr/bin/env python3
"""bench/direction.py - the default direction against both of its choices
on charts of every size, near an isometry and far from one (make
bench-direction; docs/performance.md, "The default direction").

    python3 bench/direction.py [NAMES]

For every chart below (NAMES: a comma-separated subset of the names) it
runs, one thread,

    TOOL CHART -o OUT --json --trace TRACE --threads 1 --direction D

for D = newton, precond and default, and prints one row per chart:

  faces        the chart's triangles
  E0           the start map's mean energy (the report's energy_start;
               symmetric Dirichlet unless BENCH_DIR_ENERGY): the rule's
               second input
  default is   which of the two the default's output equals, byte for
               byte ("NEITHER" would be a bug)
  t newton, t precond, t default
               CPU seconds of the tool's process (the trace's cpu column,
               reading and start map included) until the mean energy first
               reached 1.001 x the lower of Newton's and L-BFGS's final
               energies; "-" when it never did within the time limit
  cpu ...      CPU seconds of the whole run (to the tolerance)
  iters        Newton's / L-BFGS's iterations
  B/face       peak bytes per face, Newton's / L-BFGS's
  default / best
               t default over the smaller of t newton and t precond: 1.00
               when the rule chose the faster direction for this chart

One thread, and CPU seconds rather than wall: on a shared machine the
process's CPU time with one thread is what an idle machine's wall time
would be.  Runs are single (the solver is deterministic; BENCH_DIR_RUNS
repeats them and takes medians).  One JSON line per run goes to stderr.
Never asserts times: it records them.

The charts: the corpus's charts of 20,000-99,999 triangles (camelhead,
hilbert, beetle, face, bimba), face_holes subdivided 2 x 2 (33K, near an isometry),
and charts above 100,000 triangles made by bench/subdivide.py (N x N
triangles per face, a small bump along the normals) from the corpus:
face_holes 4 x 4 (132K; the bench-scale chart), hilbert, beetle, horse_cut,
lucy, face and bimba 2 x 2, mech-holes-shark 4 x 4 and camelhead 3 x 3
(129K-357K).  The subdivided files go to build/bench/direction/ once (the
generator is deterministic).

Environment:
  BENCH_DIR_RUNS=R          runs per configuration (default 1)
  BENCH_DIR_MAX_SECONDS=S   --max-seconds per chart (default 600)
  BENCH_DIR_DIRECTIONS="newton precond default"
  BENCH_DIR_ENERGY=E        --energy E (sd, conformal, mips, iso, maxiso;
                            default sd): the rule keeps the preconditioned
                            L-BFGS for every energy but sd
  TOOL=path                 the tool (default build/bijparam)
"""
import filecmp
import json
import os
import resource
import subprocess
import sys

from scaf_ratio import fmt, med   # the same medians and "-" for a missing number

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHDIR = os.path.join(ROOT, "tests", "data")
OUT = os.path.join(ROOT, "build", "bench", "direction")
TOOL = os.environ.get("TOOL") or os.path.join(ROOT, "build", "bijparam")
RUNS = max(1, int(os.environ.get("BENCH_DIR_RUNS", "1") or 1))
MAXS = os.environ.get("BENCH_DIR_MAX_SECONDS", "600") or "600"
DIRS = (os.environ.get("BENCH_DIR_DIRECTIONS") or "newton precond default").split()
ENERGY = os.environ.get("BENCH_DIR_ENERGY") or "sd"

# (name, corpus file, N: 1 = the file itself, else subdivided N x N)
CHARTS = [
    ("camelhead", "camelhead.off", 1),
    ("hilbert", "hilbert.obj", 1),
    ("face_holes_n2", "face_holes.off", 2),
    ("beetle", "beetle.off", 1),
    ("face", "face.obj", 1),
    ("bimba", "bimba_i.obj", 1),
    ("hilbert_n2", "hilbert.obj", 2),
    ("face_holes_n4", "face_holes.off", 4),
    ("beetle_n2", "beetle.off", 2),
    ("horse_cut_n2", "horse_cut.obj", 2),
    ("shark_n4", "mech-holes-shark.off", 4),
    ("lucy_n2", "lucy_o_f48275.obj", 2),
    ("camelhead_n3", "camelhead.off", 3),
    ("face_n2", "face.obj", 2),
    ("bimba_n2", "bimba_i.obj", 2),
]


def chart_path(name, fname, n):
    src = os.path.join(MESHDIR, fname)
    if n == 1:
        return src
    path = os.path.join(OUT, name + ".obj")
    gen = os.path.join(ROOT, "bench", "subdivide.py")
    if not os.path.isfile(path) or os.path.getmtime(path) < os.path.getmtime(gen):
        subprocess.run([sys.executable, gen, src, str(n), path], check=True, stdout=subprocess.DEVNULL)
    return path


def run_once(chart, name, d, r):
    base = os.path.join(OUT, "%s.%s.%s.r%d" % (name, ENERGY, d, r))
    out, trace = base + ".obj", base + ".trace"
    cmd = [TOOL, chart, "-o", out, "--json", "--trace", trace, "--threads", "1",
           "--direction", d, "--energy", ENERGY, "--max-seconds", MAXS, "-q"]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rep = None
    try:
        rep = json.loads(p.stdout.decode(errors="replace").strip().splitlines()[-1])
    except (ValueError, IndexError):
        pass
    res = {"chart": name, "energy": ENERGY, "direction": d, "run": r, "rc": p.returncode, "out": out, "trace": trace,
           "cpu": r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime, "load": os.getloadavg()[0]}
    if rep and rep.get("per_chart"):
        c = rep["per_chart"][0]
        res.update(faces=c["faces"], E0=c["energy_start"], E=c["energy_end"], iters=c["iterations"],
                   stop=c["stop"], bpf=rep.get("bytes_per_face"),
                   exact=rep.get("status") == "ok" and not c["flipped"] and not c["degenerate"]
                   and not c["boundary_intersections"])
    else:
        res["error"] = p.stderr.decode(errors="replace").strip()[-300:]
    return res


def time_to(trace, target, whole_cpu):
    """CPU seconds at the first trace line at or below target (the whole
    run's CPU when the start itself is there: no iteration, no line)."""
    try:
        with open(trace) as f:
            lines = [w.split() for w in f]
    except OSError:
        return None
    for w in lines:
        if len(w) >= 6 and float(w[3]) <= target:
            return float(w[5])
    return whole_cpu if not lines else None


def main():
    only = sys.argv[1].split(",") if len(sys.argv) > 1 else None
    os.makedirs(OUT, exist_ok=True)
    rows = []
    for name, fname, n in CHARTS:
        if only and name not in only:
            continue
        chart = chart_path(name, fname, n)
        res = {d: [] for d in DIRS}
        for r in range(RUNS):
            for d in DIRS:
                x = run_once(chart, name, d, r)
                res[d].append(x)
                print(json.dumps(x), file=sys.stderr, flush=True)
        ends = [x["E"] for d in ("newton", "precond") if d in res for x in res[d] if "E" in x]
        target = 1.001 * min(ends) if ends else None
        for d in res:
            for x in res[d]:
                x["t"] = time_to(x["trace"], target, x["cpu"]) if target and "E" in x else None
        rows.append((name, res))
    print("energy %s; one thread; t = CPU seconds until" % ENERGY)
    print("the mean energy first reached 1.001 x the lower of")
    print("Newton's and L-BFGS's final energies; cpu = the whole run; median of %d run(s)\n" % RUNS)
    print("| chart | faces | E0 | default is | t newton | t precond | t default | default / best "
          "| cpu newton / precond | iters newton / precond | E newton / precond | B/face newton / precond | exact |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---|---|---|---|---|")
    for name, res in rows:
        first = next(x for d in res for x in res[d])
        t = {d: (med([x["t"] for x in res[d]]) if all(x["t"] is not None for x in res[d]) else None) for d in res}
        c = {d: med([x["cpu"] for x in res[d]]) for d in res}
        it = {d: med([x.get("iters") for x in res[d]]) for d in res}
        e = {d: med([x.get("E") for x in res[d]]) for d in res}
        b = {d: med([x.get("bpf") for x in res[d]]) for d in res}
        chosen = "-"
        if "default" in res:
            same = [d for d in ("newton", "precond") if d in res and
                    os.path.isfile(res[d][0]["out"]) and os.path.isfile(res["default"][0]["out"]) and
                    filecmp.cmp(res[d][0]["out"], res["default"][0]["out"], shallow=False)]
            chosen = same[0] if len(same) == 1 else ("NEITHER" if not same else "both")
        best = min([t[d] for d in ("newton", "precond") if t.get(d) is not None] or [None]) \
            if any(t.get(d) is not None for d in ("newton", "precond")) else None
        ratio = t["default"] / best if t.get("default") is not None and best else None
        exact = all(x.get("exact") for d in res for x in res[d])
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s / %s | %s / %s | %s / %s | %s / %s | %s |" % (
            name, fmt(first.get("faces"), "%d"), fmt(first.get("E0"), "%.4g"), chosen,
            fmt(t.get("newton")), fmt(t.get("precond")), fmt(t.get("default")), fmt(ratio),
            fmt(c.get("newton"), "%.1f"), fmt(c.get("precond"), "%.1f"),
            fmt(it.get("newton"), "%d"), fmt(it.get("precond"), "%d"),
            fmt(e.get("newton"), "%.5f"), fmt(e.get("precond"), "%.5f"),
            fmt(b.get("newton"), "%.0f"), fmt(b.get("precond"), "%.0f"), "yes" if exact else "NO"))
    sys.stdout.flush()


if __name__ == "__main__":
    main()
