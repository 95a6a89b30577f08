#!/usr/bin/env python3
"""bench/bench.py - the body of `make bench` (bench/run.sh calls it).

For every mesh in tests/data (the larger ones, LARGE, unless BENCH_QUICK), run

    build/bijparam MESH -o OUT --json --trace TRACE

BENCH_RUNS times (default 3) and record, per mesh:

  V, F            as stored in the file
  charts, loops   from the tool's JSON (loops summed over the charts)
  iterations      summed over the charts
  seconds         median wall time of the runs (the whole process: read,
                  charts, start map, optimization, packing, writing)
  opt_seconds     median of the tool's own "optimize" timing
  cpu_seconds     median CPU time (user + system) of the tool process
  E mean / max    final symmetric Dirichlet energy of the atlas: mean weighted
                  by 3D area and the worst triangle, as the independent
                  checker measures them (the tool's own numbers are in the JSON
                  as tool_energy_mean / tool_energy_max)
  bijective       python3 tests/uvcheck.py --json OUT MESH exits 0
  B/face          peak resident memory per face (the tool's bytes_per_face),
                  median of the runs
  t1.01, t1.001   from the trace: seconds since the tool started until the
                  mean energy first came within 1.01x (1.001x) of its final
                  value; with several charts, of every chart (the charts are
                  solved one after another, so this is the last chart's time)

Meshes listed in MUST_REJECT are run once and shown as "rejected" with the
tool's message; any other failure is shown too.  The list is empty since the
tool cuts closed and genus > 0 charts into disks (fertility and
torus_with_holes were rejected before).

For every mesh above BENCH_THREADS_MIN_FACES faces (default 20000) it also
runs --threads 1 and --threads 2 (BENCH_RUNS times each) and reports the
medians and the speed-up t(1)/t(2).  On a 2-core machine the default runs
(--threads 0: all cores) are the --threads 2 runs (the tool's JSON says
"threads":2; otherwise --threads 2 is timed separately).  The runs of the
configurations alternate (default, 1 thread, default, 1 thread, ...) so that
a busy spell of a shared machine hits both alike.  "same" says whether 1 and
2 threads gave bit-identical energies (the library promises they do).
loadavg_1min in the JSON is the 1-minute load average before and after the
mesh's runs: above the core count, other processes were competing.

Default threads against one, idle and busy (the default must never be
slower than --threads 1).  Cases: many_charts_10000 (10,000
separate one-triangle charts, written by the bench itself), spot and camel_b
from tests/data, and camelhead unless BENCH_QUICK.  Each case
runs the default (--threads 0) and --threads 1, BENCH_RUNS times each,
alternated: first on the machine as it is ("idle"), then with one competing
CPU-bound process per core started by the bench, each with setsid
("busy": each is a python loop that stops by itself after BENCH_BUSY_LIMIT seconds, default 600, and
the bench kills them when the busy runs end).  The table gives the median
wall and CPU seconds of both and the ratio default / 1 thread of the wall
medians (below 1: the default is faster); the JSON line of each case holds
every run.  Measured in the same bench run, so both sides of a ratio saw
the same machine.

Many charts, many holes: bench/photogrammetry.py writes a
photogrammetry-like atlas (4,740 charts: 4,739 small curved pieces of 2-200
faces, some thin, some with a hole or two, and one of 4,601 faces with 50
holes; 226,273 faces in all; the same bytes on every machine) and the tool
runs it with --threads 1 and --threads 2, BENCH_RUNS times each, alternated.
The table gives the median wall and CPU seconds of each, the iterations of
all charts, and the large chart's iterations and milliseconds per iteration
(its own "seconds" in the tool's JSON, so wall time), and whether uvcheck
passes the output; "same" says whether both thread counts gave the same
energies bit for bit.

Environment:
  BENCH_QUICK=1        not the LARGE meshes (runs default to 1); threads on camelhead
  BENCH_RUNS=N         runs per configuration (default 3, quick: 1)
  BENCH_TIMEOUT=S      per-run time limit in seconds (default 600)
  BENCH_THREADS_MIN_FACES=N   (default 20000)
  BENCH_MESHES="a b"   only these mesh file names (e.g. "camel_b.obj cow_param_withSUV.obj")
  BENCH_BUSY=0         skip the idle/busy comparison (BENCH_BUSY=only: run only it)
  BENCH_BUSY_LIMIT=S   the competing processes' own time limit (default 600)
  BENCH_PHOTO=0        skip the photogrammetry-like case (BENCH_PHOTO=only: run only it)
  BENCH_OUT=DIR        keep outputs, traces and bench.jsonl there
                       (default build/bench)
  BENCH_TOOL=PATH      the tool to time (run.sh copies build/bijparam to
                       build/bench/bijparam-bench first, so that a rebuild
                       during the bench does not mix two versions)

Output: progress on stderr (one JSON line per mesh as it finishes), then on
stdout a table, a thread table and one JSON line per mesh.  The bench never
asserts times: it records them.  Exit status 0 unless the tool is missing.
"""
import json
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.environ.get("BENCH_TOOL") or os.path.join(ROOT, "build", "bijparam")
DATA = os.path.join(ROOT, "tests", "data")
UVCHECK = os.path.join(ROOT, "tests", "uvcheck.py")
LARGE = ["hilbert.obj", "beetle.off", "horse_cut.obj", "lucy_o_f48275.obj",
         "face.obj", "bimba_i.obj"]
MUST_REJECT = set()


def env_int(name, default):
    v = os.environ.get(name, "")
    return int(v) if v.strip() else default


QUICK = os.environ.get("BENCH_QUICK", "") not in ("", "0")
RUNS = max(1, env_int("BENCH_RUNS", 1 if QUICK else 3))
TIMEOUT = env_int("BENCH_TIMEOUT", 600)
THREADS_MIN_FACES = env_int("BENCH_THREADS_MIN_FACES", 20000)
OUT = os.environ.get("BENCH_OUT") or os.path.join(ROOT, "build", "bench")
BUSY = os.environ.get("BENCH_BUSY", "1").strip().lower()
BUSY_LIMIT = env_int("BENCH_BUSY_LIMIT", 600)
PHOTO = os.environ.get("BENCH_PHOTO", "1").strip().lower()


def count_vf(path):
    """V and F as stored in the file (OFF header, or OBJ v/f lines)."""
    with open(path, "rb") as f:
        data = f.read().decode("ascii", "replace")
    if path.lower().endswith(".off"):
        words = [w for line in data.splitlines() for w in line.split("#")[0].split()]
        return int(words[1]), int(words[2])
    lines = data.splitlines()
    return (sum(1 for l in lines if l.startswith("v ")),
            sum(1 for l in lines if l.startswith("f ")))


def read_trace(path):
    """{chart: [(seconds, mean energy), ...]} from a --trace file."""
    charts = {}
    try:
        with open(path) as f:
            for line in f:
                w = line.split()
                if len(w) >= 4:
                    charts.setdefault(int(w[0]), []).append((float(w[2]), float(w[3])))
    except OSError:
        pass
    return charts


def time_to(charts, factor):
    """Seconds until every chart's energy first came within factor x its final value."""
    worst = None
    for pts in charts.values():
        final = pts[-1][1]
        hit = next((t for t, e in pts if e <= factor * final), pts[-1][0])
        worst = hit if worst is None else max(worst, hit)
    return worst


CPU = []   # CPU seconds (user + system) of each tool run


def run_tool(mesh, out, trace, extra=()):
    """One run: (exit code, wall seconds, JSON report or None, stderr text)."""
    for p in (out, trace):
        if os.path.exists(p):
            os.remove(p)
    cmd = [TOOL, mesh, "-o", out, "--json", "--trace", trace] + list(extra)
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=TIMEOUT)
        rc, so, se = p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, so, se = 124, "", "timed out after %d s" % TIMEOUT
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
    rep = None
    lines = so.strip().splitlines()
    if lines:
        try:
            rep = json.loads(lines[-1])
        except ValueError:
            rep = None
    return rc, wall, rep, se.strip()


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class Config:
    """The runs of one configuration (tool options) of one mesh."""

    def __init__(self, mesh, tag, extra):
        base = os.path.join(OUT, os.path.basename(mesh) + tag)
        self.mesh, self.extra = mesh, list(extra)
        self.out, self.trace = base + ".out.obj", base + ".trace"
        self.walls, self.cpus, self.opts, self.bpf, self.t101, self.t1001 = [], [], [], [], [], []
        self.rc, self.stderr, self.rep, self.failed = 0, "", None, False

    def run(self):
        if self.failed:
            return
        rc, wall, rep, se = run_tool(self.mesh, self.out, self.trace, self.extra)
        self.rc, self.stderr = rc, se
        if rc != 0 or rep is None:
            self.failed = True
            if rep is not None or self.rep is None:
                self.rep = rep
            return
        self.rep = rep
        self.walls.append(wall)
        self.cpus.append(CPU[-1])
        self.opts.append(rep.get("timings", {}).get("optimize"))
        self.bpf.append(rep.get("bytes_per_face"))
        tr = read_trace(self.trace)
        self.t101.append(time_to(tr, 1.01))
        self.t1001.append(time_to(tr, 1.001))

    def summary(self):
        return {"rc": self.rc, "stderr": self.stderr, "rep": self.rep, "out": self.out,
                "walls": self.walls, "cpu": med(self.cpus), "opt": med(self.opts), "bpf": med(self.bpf),
                "t101": med(self.t101), "t1001": med(self.t1001)}


def measure(mesh, configs, runs):
    """Run every configuration `runs` times, interleaved (a, b, a, b, ...), so
    that a slow spell of a shared machine hits all of them alike."""
    for _ in range(runs):
        for c in configs:
            c.run()
    return [c.summary() for c in configs]


def uvcheck(out, mesh):
    if not os.path.isfile(UVCHECK) or not os.path.isfile(out):
        return None, None
    try:
        p = subprocess.run([sys.executable, UVCHECK, "--json", out, mesh],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT)
        d = json.loads(p.stdout.decode())
        return p.returncode, d
    except Exception:
        return -1, None


def rnd(x, n=4):
    return None if x is None else round(x, n)


def bench_mesh(mesh):
    name = os.path.basename(mesh)
    V, F = count_vf(mesh)
    row = {"mesh": name, "V": V, "F": F}
    big = F > THREADS_MIN_FACES and name not in MUST_REJECT
    default = Config(mesh, "", [])
    configs = [default]
    if big:
        # the 1-thread runs alternate with the default ones; the default
        # runs count as the 2-thread measurement when they used 2 threads
        one = Config(mesh, ".t1", ["--threads", "1"])
        configs.append(one)
        if (os.cpu_count() or 1) != 2:
            two = Config(mesh, ".t2", ["--threads", "2"])
            configs.append(two)
    load0 = os.getloadavg()[0]
    res = measure(mesh, configs, 1 if name in MUST_REJECT else RUNS)
    m = res[0]
    rep = m["rep"]
    if m["rc"] != 0 or rep is None:
        msg = (rep or {}).get("error") or m["stderr"] or "exit %d" % m["rc"]
        row.update({"status": "rejected" if m["rc"] == 1 else "failed",
                    "exit": m["rc"], "error": msg,
                    "expected_rejection": name in MUST_REJECT})
        return row
    pc = rep.get("per_chart", [])
    faces = sum(c["faces"] for c in pc) or 1
    row.update({
        "status": "ok", "exit": 0,
        "charts": rep.get("charts"),
        "loops": sum(len(c.get("loops", [])) for c in pc),
        "iterations": sum(c.get("iterations", 0) for c in pc),
        "stop": sorted({c.get("stop") for c in pc}),
        "runs": len(m["walls"]),
        "seconds": rnd(med(m["walls"])),
        "seconds_all": [rnd(w) for w in m["walls"]],
        "opt_seconds": rnd(m["opt"]),
        "cpu_seconds": rnd(m["cpu"]),
        "tool_energy_mean": rnd(sum(c["energy_end"] * c["faces"] for c in pc) / faces, 6),
        "tool_energy_max": rnd(max(c["energy_max"] for c in pc), 6),
        "threads": rep.get("threads"),
        "bytes_per_face": rnd(m["bpf"], 1),
        "t_1.01": rnd(m["t101"]), "t_1.001": rnd(m["t1001"]),
    })
    code, d = uvcheck(m["out"], mesh)
    if code is None:
        row["bijective"] = None
    else:
        row["bijective"] = code == 0
        if d:
            sd = d.get("symmetric_dirichlet", {})
            v = d.get("counts", {})
            row["energy_mean"] = rnd(sd.get("mean"), 6)
            row["energy_max"] = rnd(sd.get("max"), 6)
            row["uvcheck_boundary_intersections"] = v.get("boundary_intersections", 0)
            row["uvcheck_flipped"] = v.get("flipped_triangles", 0)
            if code != 0:
                row["uvcheck_reasons"] = sorted(v)
    if "energy_mean" not in row:
        row["energy_mean"], row["energy_max"] = row["tool_energy_mean"], row["tool_energy_max"]
    # threads 1 vs 2 on the larger charts
    row["loadavg_1min"] = [round(load0, 2), round(os.getloadavg()[0], 2)]
    if big:
        t1 = res[1]
        if rep.get("threads") == 2:
            t2, reused = m, True
        elif len(res) > 2:
            t2, reused = res[2], False
        else:   # the default used another count: time --threads 2 now
            t2, reused = measure(mesh, [Config(mesh, ".t2", ["--threads", "2"])], RUNS)[0], False
        s1, s2 = med(t1["walls"]), med(t2["walls"])
        same = None
        if t1["rep"] and t2["rep"]:
            same = ([c["energy_end"] for c in t1["rep"]["per_chart"]] ==
                    [c["energy_end"] for c in t2["rep"]["per_chart"]])
        row["threads_cmp"] = {
            "t1_seconds": rnd(s1), "t2_seconds": rnd(s2),
            "t1_all": [rnd(w) for w in t1["walls"]], "t2_all": [rnd(w) for w in t2["walls"]],
            "t1_cpu": rnd(t1["cpu"]), "t2_cpu": rnd(t2["cpu"]),
            "t1_opt": rnd(t1["opt"]), "t2_opt": rnd(t2["opt"]),
            "speedup": rnd(s1 / s2, 3) if s1 and s2 else None,
            "speedup_opt": rnd(t1["opt"] / t2["opt"], 3) if t1["opt"] and t2["opt"] else None,
            "t1_bytes_per_face": rnd(t1["bpf"], 1), "t2_bytes_per_face": rnd(t2["bpf"], 1),
            "t2_reused_default_runs": reused, "same_result": same,
            "t1_exit": t1["rc"], "t2_exit": t2["rc"]}
    return row


def write_many_charts(path, n):
    """n separate triangles (each its own chart), on a 100-wide grid, the
    third vertex lifted so that no chart is flat already."""
    with open(path, "w") as f:
        for i in range(n):
            x, y = 2.0 * (i % 100), 2.0 * (i // 100)
            f.write("v %g %g 0\nv %g %g 0\nv %g %g 0.5\n" % (x, y, x + 1, y, x, y + 1))
        for i in range(n):
            f.write("f %d %d %d\n" % (3 * i + 1, 3 * i + 2, 3 * i + 3))


def start_competitors(n):
    """n CPU-bound processes, each ending by itself after BUSY_LIMIT s."""
    code = "import time\nt = time.time() + %d\nwhile time.time() < t:\n    pass\n" % BUSY_LIMIT
    # started with setsid, like work started from another terminal or job:
    # Linux's autogroup scheduler then shares the cores between them and
    # the tool's group
    return [subprocess.Popen([sys.executable, "-c", code], preexec_fn=os.setsid) for _ in range(n)]


def stop_competitors(procs):
    for p in procs:
        p.kill()
    for p in procs:
        p.wait()


def busy_cases():
    cases = []
    many = os.path.join(OUT, "many_charts_10000.obj")
    write_many_charts(many, 10000)
    cases.append(("many_charts_10000", many))
    for name in ("spot.obj", "camel_b.obj"):
        cases.append((name, os.path.join(ROOT, "tests", "data", name)))
    cam = os.path.join(DATA, "camelhead.off")
    if not QUICK and os.path.isfile(cam):
        cases.append(("camelhead.off", cam))
    return [(n, p) for n, p in cases if os.path.isfile(p)]


def bench_busy():
    """Default threads vs --threads 1 on each case, idle then busy."""
    ncomp = os.cpu_count() or 1
    rows = []
    for state in ("idle", "busy"):
        procs = start_competitors(ncomp) if state == "busy" else []
        try:
            if procs:
                time.sleep(0.5)         # let them reach the cores
            for name, path in busy_cases():
                d = Config(path, ".%s.t0" % state, [])
                one = Config(path, ".%s.t1" % state, ["--threads", "1"])
                load0 = os.getloadavg()[0]
                res = measure(path, [d, one], RUNS)
                V, F = count_vf(path)
                r0, r1 = res
                w0, w1 = med(r0["walls"]), med(r1["walls"])
                rows.append({
                    "busy_case": name, "state": state, "competitors": len(procs), "F": F,
                    "charts": (r0["rep"] or {}).get("charts"),
                    "threads_default": (r0["rep"] or {}).get("threads"),
                    "default_seconds": rnd(w0), "t1_seconds": rnd(w1),
                    "default_cpu": rnd(r0["cpu"]), "t1_cpu": rnd(r1["cpu"]),
                    "default_all": [rnd(w) for w in r0["walls"]], "t1_all": [rnd(w) for w in r1["walls"]],
                    "ratio_default_over_t1": rnd(w0 / w1, 3) if w0 and w1 else None,
                    "default_exit": r0["rc"], "t1_exit": r1["rc"],
                    "loadavg_1min": [round(load0, 2), round(os.getloadavg()[0], 2)]})
                print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
        finally:
            stop_competitors(procs)
    return rows


def bench_photo():
    """The photogrammetry-like case with 1 and 2 threads (see the module text)."""
    sys.path.insert(0, os.path.join(ROOT, "bench"))
    import photogrammetry
    path = os.path.join(OUT, "photogrammetry_4740.obj")
    nchart, nface, _ = photogrammetry.write(path)
    one = Config(path, ".t1", ["--threads", "1"])
    two = Config(path, ".t2", ["--threads", "2"])
    load0 = os.getloadavg()[0]
    r1, r2 = measure(path, [one, two], RUNS)
    row = {"photo_case": os.path.basename(path), "charts": nchart, "F": nface,
           "loadavg_1min": [round(load0, 2), round(os.getloadavg()[0], 2)]}
    for tag, r in (("t1", r1), ("t2", r2)):
        rep = r["rep"] or {}
        pc = rep.get("per_chart", [])
        big = max(pc, key=lambda c: c["faces"]) if pc else {}
        row.update({
            tag + "_exit": r["rc"], tag + "_seconds": rnd(med(r["walls"])), tag + "_cpu": rnd(r["cpu"]),
            tag + "_all": [rnd(w) for w in r["walls"]], tag + "_opt": rnd(r["opt"]),
            tag + "_iterations": sum(c.get("iterations", 0) for c in pc),
            tag + "_big_faces": big.get("faces"), tag + "_big_loops": len(big.get("loops", [])),
            tag + "_big_iterations": big.get("iterations"),
            tag + "_big_ms_per_iteration": rnd(1000.0 * big["seconds"] / big["iterations"], 3)
            if big.get("iterations") else None})
    if r1["rep"] and r2["rep"]:
        row["same_result"] = ([c["energy_end"] for c in r1["rep"]["per_chart"]] ==
                              [c["energy_end"] for c in r2["rep"]["per_chart"]])
    code, _ = uvcheck(r1["out"], path)
    row["bijective"] = None if code is None else code == 0
    print(json.dumps(row), file=sys.stderr, flush=True)
    return [row]


def fmt(x, spec):
    return "-" if x is None else spec % x


def main():
    if not os.access(TOOL, os.X_OK):
        print("bench: %s missing: run 'make' first" % TOOL, file=sys.stderr)
        return 1
    os.makedirs(OUT, exist_ok=True)
    meshes = sorted(os.path.join(DATA, f) for f in os.listdir(DATA)
                    if f.endswith((".obj", ".off")) and f not in LARGE)
    if not QUICK:
        meshes += [os.path.join(DATA, f) for f in LARGE]
    only = os.environ.get("BENCH_MESHES", "").split()
    if only:
        meshes = [m for m in meshes if os.path.basename(m) in only]
    rows = []
    t_start = time.perf_counter()
    if BUSY == "only" or PHOTO == "only":
        meshes = []
    for mesh in meshes:
        row = bench_mesh(mesh)
        rows.append(row)
        print(json.dumps(row), file=sys.stderr, flush=True)
    photo = bench_photo() if PHOTO not in ("0", "no", "") and BUSY != "only" else []
    busy = bench_busy() if BUSY not in ("0", "no", "") and PHOTO != "only" else []
    with open(os.path.join(OUT, "bench.jsonl"), "w") as f:
        for r in rows + photo + busy:
            f.write(json.dumps(r) + "\n")

    print("bench: %s, %d run(s) per configuration, %.0f s in all%s" % (
        time.strftime("%Y-%m-%d %H:%M"), RUNS, time.perf_counter() - t_start,
        " (BENCH_QUICK)" if QUICK else ""))
    print()
    h = "%-22s %6s %6s %3s %3s %6s %8s %8s %8s %4s %6s %7s %7s"
    print(h % ("mesh", "V", "F", "ch", "lp", "iters", "median s", "E mean", "E max",
               "bij", "B/face", "t1.01", "t1.001"))
    for r in rows:
        if r["status"] != "ok":
            print("%-22s %6d %6d  %s: %s" % (r["mesh"], r["V"], r["F"], r["status"], r["error"]))
            continue
        bij = {True: "yes", False: "NO", None: "-"}[r["bijective"]]
        print(h % (r["mesh"], r["V"], r["F"], r["charts"], r["loops"], r["iterations"],
                   fmt(r["seconds"], "%.3f"), fmt(r["energy_mean"], "%.4f"),
                   fmt(r["energy_max"], "%.3f"), bij, fmt(r["bytes_per_face"], "%.0f"),
                   fmt(r["t_1.01"], "%.3f"), fmt(r["t_1.001"], "%.3f")))
    th = [r for r in rows if "threads_cmp" in r]
    if th:
        print()
        h2 = "%-22s %6s %9s %9s %8s %8s %6s"
        print(h2 % ("threads (F>%d)" % THREADS_MIN_FACES, "F", "1 thr s", "2 thr s",
                    "speedup", "opt x", "same"))
        for r in th:
            t = r["threads_cmp"]
            print(h2 % (r["mesh"], r["F"], fmt(t["t1_seconds"], "%.3f"),
                        fmt(t["t2_seconds"], "%.3f"), fmt(t["speedup"], "%.2f"),
                        fmt(t["speedup_opt"], "%.2f"),
                        {True: "yes", False: "no", None: "-"}[t["same_result"]]))
    if photo:
        print()
        h4 = "%-26s %7s %6s %8s %8s %8s %8s %7s %6s %8s %4s %5s"
        print(h4 % ("many charts, many holes", "F", "charts", "1 thr s", "1thr cpu", "2 thr s", "2thr cpu",
                    "iters", "big it", "big ms/it", "bij", "same"))
        for r in photo:
            print(h4 % (r["photo_case"], r["F"], r["charts"], fmt(r["t1_seconds"], "%.3f"), fmt(r["t1_cpu"], "%.3f"),
                        fmt(r["t2_seconds"], "%.3f"), fmt(r["t2_cpu"], "%.3f"), r["t1_iterations"],
                        fmt(r["t1_big_iterations"], "%d"), fmt(r["t1_big_ms_per_iteration"], "%.3f"),
                        {True: "yes", False: "NO", None: "-"}[r["bijective"]],
                        {True: "yes", False: "no", None: "-"}[r.get("same_result")]))
        print("(medians of %d runs each, alternated; big = the 4,601-face chart with 51 loops, ms/it from its wall time)" % RUNS)
    if busy:
        print()
        h3 = "%-20s %-5s %6s %6s %9s %9s %7s %8s %8s"
        print(h3 % ("default vs 1 thread", "", "F", "charts", "default s", "1 thr s", "ratio",
                    "def cpu", "1thr cpu"))
        for r in busy:
            print(h3 % (r["busy_case"], r["state"], r["F"], fmt(r["charts"], "%d"),
                        fmt(r["default_seconds"], "%.3f"), fmt(r["t1_seconds"], "%.3f"),
                        fmt(r["ratio_default_over_t1"], "%.2f"),
                        fmt(r["default_cpu"], "%.3f"), fmt(r["t1_cpu"], "%.3f")))
        print("(busy: %d competing CPU-bound processes, each with setsid; ratio = median wall default / median wall 1 thread)"
              % (os.cpu_count() or 1))
    print()
    for r in rows + photo + busy:
        print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
