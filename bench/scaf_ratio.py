#!/usr/bin/env python3
"""bench/scaf_ratio.py - bijparam's time to SCAF's energy (make bench-scaf;
docs/performance.md, "Against SCAF").

The reference numbers are cited: libigl's igl::triangle::scaf with Eigen's
simplicial LDL^T, started from Tutte, tolerance 1e-6, one thread, measured
once on an idle machine of this kind.  For each mesh they give SCAF's final mean
energy E and the seconds from the start of its process until its energy
first came within E x 1.001.  SCAF is not run here: those are cited.

For every mesh and every configuration (a --direction, or a tool binary)
this runs, one thread,

    TOOL MESH -o OUT --json --trace TRACE --threads 1 --direction D

and reports
  t           CPU seconds of the tool's process (the trace's last column,
              reading and start map included) until the trace's mean energy
              first reached SCAF's E x 1.001; "-" when it never did (then
              the ratio is "-" too); when the start map itself is already
              there (no iteration, no trace line) the whole process's CPU.  CPU, not wall: the machines this runs
              on are shared, and with --threads 1 the process's CPU time is
              what an idle machine's wall time would be (SCAF's reference
              times are wall seconds on an idle machine, one thread)
  ratio       t / SCAF's t(1.001 E)
  wall        the same moment in wall seconds since the tool started
  iters       iterations (summed over charts)
  E end       the tool's final mean energy (per_chart energy_end; every
              mesh here is one chart)
  cpu         CPU seconds (user + system) of the whole process
With several runs (SCAF_RUNS), each number is the median of the runs.

Environment:
  SCAF_DIRECTIONS="precond newton"  the --direction values to compare
  SCAF_TOOLS="name=path ..."        extra binaries (e.g. before/after builds),
                                    each run with SCAF_TOOL_DIRECTION
                                    (default newton)
  SCAF_MESHES="camel_b face"        only meshes whose file name starts so
  SCAF_RUNS=N                       runs per configuration (default 1)
  SCAF_MAX_SECONDS=S                --max-seconds per chart, wall (default 600)
  SCAF_TIMEOUT=S                    kill a run after S seconds (default 1200)
  SCAF_OUT=DIR                      outputs and traces (default build/bench)
  TOOL=path                         the tool (default build/bijparam)

Output: the table on stdout (markdown), one JSON line per run on stderr.
Never asserts times: it records them.
"""
import json
import os
import resource
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
MESHDIR = os.path.join(ROOT, "tests", "data")

# (file, label, F, SCAF final E, SCAF t(1.001 E) in seconds): SCAF's, cited.
SCAF = [
    ("camel_b.obj", "camel_b", 3576, 4.0900, 3.81),
    ("cow_param_withSUV.obj", "cow (seams)", 5804, 4.0862, 1.62),
    ("face_holes.off", "face_holes", 8288, 4.0219, 0.36),
    ("mech-holes-shark.off", "mech-holes-shark", 10192, 6.0416, 12.5),
    ("camelhead.off", "camelhead", 22704, 7.4470, 2.70),
    ("hilbert.obj", "hilbert", 32228, 4.0052, 68.6),
    ("horse_cut.obj", "horse_cut", 39698, 4.0948, 10.7),
    ("lucy_o_f48275.obj", "lucy", 48275, 16.061, 48.3),
    ("face.obj", "face", 51712, 7.0127, 1.94),
    ("bimba_i.obj", "bimba", 89215, 7.5708, 9.23),
]


def env(name, default):
    v = os.environ.get(name, "")
    return v if v else default


TOOL = env("TOOL", os.path.join(ROOT, "build", "bijparam"))
OUT = env("SCAF_OUT", os.path.join(ROOT, "build", "bench"))
RUNS = int(env("SCAF_RUNS", "1"))
MAXS = env("SCAF_MAX_SECONDS", "600")
TIMEOUT = float(env("SCAF_TIMEOUT", "1200"))


def configs():
    """[(name, tool, direction)]"""
    out = [(d, TOOL, d) for d in env("SCAF_DIRECTIONS", "precond newton").split()]
    for item in env("SCAF_TOOLS", "").split():
        name, path = item.split("=", 1)
        out.append((name, path, env("SCAF_TOOL_DIRECTION", "newton")))
    return out


def run_once(tool, direction, mesh, tag, target):
    base = os.path.join(OUT, "scaf_" + os.path.basename(mesh) + "." + tag)
    out, trace = base + ".obj", base + ".trace"
    cmd = [tool, mesh, "-o", out, "--json", "--trace", trace, "--threads", "1",
           "--direction", direction, "--max-seconds", MAXS, "-q"]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT)
        rc, so = p.returncode, p.stdout.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, so = 124, ""
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime
    rep = None
    try:
        rep = json.loads(so.strip().splitlines()[-1])
    except (ValueError, IndexError):
        pass
    hit, hitc, last = None, None, None
    try:
        with open(trace) as f:
            for line in f:
                w = line.split()
                if len(w) >= 4:
                    last = (float(w[2]), float(w[3]))
                    if hit is None and float(w[3]) <= target:
                        hit = float(w[2])
                        hitc = float(w[5]) if len(w) >= 6 else None
    except OSError:
        pass
    iters = sum(c["iterations"] for c in rep["per_chart"]) if rep else None
    eend = rep["per_chart"][0]["energy_end"] if rep and rep["per_chart"] else None
    if hit is None and iters == 0 and eend is not None and eend <= target:
        # the start map itself is below the target (hilbert's conformal map
        # is an isometry): no trace line was written, so t is bounded by the
        # whole process (reading, start, writing), wall and CPU
        t = rep["timings"]
        hit = sum(t[k] for k in ("read", "charts", "init", "optimize", "pack", "write"))
        hitc = cpu
    stop = ",".join(sorted(set(c["stop"] for c in rep["per_chart"]))) if rep else "failed rc %d" % rc
    bij = bool(rep) and all(not c["flipped"] and not c["degenerate"] and not c["boundary_intersections"]
                            for c in rep["per_chart"])
    return {"rc": rc, "t": hit, "tcpu": hitc, "iters": iters, "E": eend, "cpu": cpu, "stop": stop, "bijective": bij,
            "opt": rep["timings"]["optimize"] if rep else None, "last": last}


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def fmt(x, f="%.2f"):
    return "-" if x is None else f % x


def main():
    os.makedirs(OUT, exist_ok=True)
    only = env("SCAF_MESHES", "").split()
    cfgs = configs()
    rows = []
    for fname, label, F, E, T in SCAF:
        if only and not any(fname.startswith(o) for o in only):
            continue
        mesh = os.path.join(MESHDIR, fname)
        if not os.path.exists(mesh):
            print("scaf_ratio: %s missing, skipped" % mesh, file=sys.stderr)
            continue
        res = {}
        for run in range(RUNS):                  # alternate the configurations
            for name, tool, d in cfgs:
                r = run_once(tool, d, mesh, name, 1.001 * E)
                r.update(mesh=label, config=name, run=run, loadavg=os.getloadavg()[0])
                print(json.dumps(r), file=sys.stderr, flush=True)
                res.setdefault(name, []).append(r)
        rows.append((label, F, E, T, res))
    names = [c[0] for c in cfgs]
    print("one thread; SCAF's E and t are cited reference numbers (not run here);")
    print("t = CPU seconds of the tool's process (the trace's cpu column: reading included)")
    print("until its mean energy first reached 1.001 x SCAF's E (wall: the same in wall")
    print("seconds, inflated on a busy machine); ratio = t / SCAF's t; cpu = the whole")
    print("run's CPU seconds; median of %d run(s)\n" % RUNS)
    head = "| mesh | F | SCAF E | SCAF t |"
    sep = "|---|---:|---:|---:|"
    for n in names:
        head += " %s t | ratio | wall | iters | E end | cpu |" % n
        sep += "---:|---:|---:|---:|---:|---:|"
    print(head)
    print(sep)
    for label, F, E, T, res in rows:
        line = "| %s | %d | %.4f | %.2f |" % (label, F, E, T)
        for n in names:
            rs = res.get(n, [])
            tc = [r["tcpu"] for r in rs]
            tw = [r["t"] for r in rs]
            t = med(tc) if rs and all(x is not None for x in tc) else None
            w = med(tw) if rs and all(x is not None for x in tw) else None
            ok = all(r["bijective"] for r in rs)
            line += " %s | %s | %s | %s | %s%s | %s |" % (
                fmt(t), fmt(t / T if t is not None else None), fmt(w), fmt(med([r["iters"] for r in rs]), "%d"),
                fmt(med([r["E"] for r in rs]), "%.4f"), "" if ok else " NOT BIJECTIVE",
                fmt(med([r["cpu"] for r in rs]), "%.1f"))
        print(line)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
