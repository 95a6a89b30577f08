#!/usr/bin/env python3
"""bench/experiments.py - the dissertation's chapter 3 experiments (docs/performance.md), each printing a
Markdown table (bench/experiments.sh is the entry point).

    python3 bench/experiments.py SECTION [SECTION ...]

SECTION is one of
    machine     CPU, cores, compiler, kernel, date, commit of the measured tool
    table31     Table 3.1: mean / max E_D with and without the barrier on
                camel_b, cow and horse_cut, for --direction precond and lbfgs
    metrics     figs 3.2 / 3.7: the five energies with and without E_B on the cow
    directions  gradient descent vs L-BFGS vs preconditioned L-BFGS (camel_b, cow)
    history     fig 3.11: L-BFGS memory m = 1..20 (camel_b, cow), time / time(m=1)
    targets     final energies, hilbert bijective, times against the
                dissertation's
    bench       the `make bench` tables as Markdown (reads build/bench/bench.jsonl)
    all         every section above, in this order

Conventions: every run is `build/bijparam MESH -o OUT --json [options]`
(EXP_TOOL overrides the tool path), with --threads 1 unless the section says
otherwise (timings on this 2-core machine are less noisy single-threaded,
and the dissertation comparison asks for one thread).  A "time" is the median
wall time of EXP_RUNS runs (default 3) of the whole process; runs longer than
EXP_LONG seconds (default 20) are timed once.  Energies are the tool's final
values (deterministic: identical in every run); "bijective" is the exit status
of python3 tests/uvcheck.py --json OUT MESH and the boundary intersections
are the pairs of boundary edges that meet as uvcheck counts them.
"""
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.environ.get("EXP_TOOL") or os.path.join(ROOT, "build", "bijparam")
DATA = os.path.join(ROOT, "tests", "data")
UVCHECK = os.path.join(ROOT, "tests", "uvcheck.py")
WORK = os.environ.get("EXP_OUT") or os.path.join(ROOT, "build", "bench", "exp")
RUNS = int(os.environ.get("EXP_RUNS", "3"))
LONG = float(os.environ.get("EXP_LONG", "20"))

CAMEL = os.path.join(ROOT, "tests", "data", "camel_b.obj")
COW = os.path.join(ROOT, "tests", "data", "cow_param_withSUV.obj")
FACE_HOLES = os.path.join(ROOT, "tests", "data", "face_holes.off")
HORSE = os.path.join(DATA, "horse_cut.obj")
HILBERT = os.path.join(DATA, "hilbert.obj")
NAMES = {CAMEL: "camel_b", COW: "cow", HORSE: "horse_cut", FACE_HOLES: "face_holes",
         HILBERT: "hilbert"}


def log(*a):
    print(*a, file=sys.stderr, flush=True)


CPU = []   # CPU seconds (user + system) of each tool run, in order


def once(mesh, args, out):
    if os.path.exists(out):
        os.remove(out)
    cmd = [TOOL, mesh, "-o", out, "--json"] + list(args)
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
    rep = None
    lines = p.stdout.decode(errors="replace").strip().splitlines()
    if lines:
        try:
            rep = json.loads(lines[-1])
        except ValueError:
            pass
    return p.returncode, wall, rep, p.stderr.decode(errors="replace").strip()


def run(mesh, args, runs=None, check=True, threads1=True):
    """Median wall time over the runs; report of the last run; uvcheck verdict."""
    runs = RUNS if runs is None else runs
    os.makedirs(WORK, exist_ok=True)
    args = list(args) + (["--threads", "1"] if threads1 and "--threads" not in args else [])
    tag = "_".join(a.lstrip("-") for a in args).replace("/", "_")
    out = os.path.join(WORK, "%s_%s.obj" % (NAMES.get(mesh, os.path.basename(mesh)), tag))
    walls, cpus = [], []
    for r in range(runs):
        rc, wall, rep, err = once(mesh, args, out)
        walls.append(wall)
        cpus.append(CPU[-1])
        if rc != 0 or wall > LONG:
            break
    res = {"rc": rc, "wall": statistics.median(walls), "walls": walls, "rep": rep, "err": err,
           "out": out, "cpu": statistics.median(cpus)}
    if rep and rep.get("per_chart"):
        c = rep["per_chart"][0]
        res.update(iters=sum(x["iterations"] for x in rep["per_chart"]), stop=c["stop"],
                   mean=c["energy_end"], max=c["energy_max"], opt=rep["timings"]["optimize"],
                   tool_bi=sum(x.get("boundary_intersections") or 0 for x in rep["per_chart"]))
    if check and rc == 0:
        p = subprocess.run([sys.executable, UVCHECK, "--json", out, mesh],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            d = json.loads(p.stdout.decode())
            res["bij"] = p.returncode == 0
            res["bi"] = d["counts"].get("boundary_intersections", 0)
            res["flipped"] = d["counts"].get("flipped_triangles", 0)
            res["sd_mean"] = d["symmetric_dirichlet"]["mean"]
            res["sd_max"] = d["symmetric_dirichlet"]["max"]
        except Exception:
            res["bij"] = None
    log("  %s %s: rc=%d %.2fs (cpu %.2fs) %s it=%s E=%s" % (NAMES.get(mesh, mesh), " ".join(args), rc,
        res["wall"], res["cpu"], res.get("stop"), res.get("iters"), res.get("mean")))
    return res


def table(head, rows):
    print("| " + " | ".join(head) + " |")
    print("|" + "|".join("---" if i == 0 else "---:" for i in range(len(head))) + "|")
    for r in rows:
        print("| " + " | ".join(str(x) for x in r) + " |")
    print()


def f(x, spec="%.3f"):
    return "-" if x is None else spec % x


def yn(b):
    return {True: "yes", False: "**no**", None: "-"}[b]


def present(*meshes):
    miss = [m for m in meshes if not os.path.isfile(m)]
    for m in miss:
        print("_%s is missing: skipped._\n" % m)
    return [m for m in meshes if m not in miss]


# ---------------------------------------------------------------- sections

def machine():
    def sh(cmd):
        try:
            return subprocess.run(cmd, shell=True, stdout=subprocess.PIPE,
                                  stderr=subprocess.DEVNULL).stdout.decode().strip()
        except Exception:
            return "?"
    model = sh("lscpu | sed -n 's/^Model name: *//p'")
    rows = [
        ("date", time.strftime("%Y-%m-%d %H:%M %Z")),
        ("CPU", model),
        ("cores (nproc)", sh("nproc")),
        ("lscpu", ", ".join(sh("lscpu | sed -n 's/^Thread(s) per core: */threads per core /p; s/^Core(s) per socket: */cores per socket /p; s/^Hypervisor vendor: */hypervisor /p'").splitlines())),
        ("caches", ", ".join(sh("lscpu | sed -n 's/^\\(L[123][a-z]*\\) cache: *\\(.*\\)/\\1 \\2/p'").splitlines())),
        ("tool binary built", time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(TOOL)))),
        ("memory", sh("free -g | awk '/Mem:/{print $2\" GiB\"}'")),
        ("compiler", sh("gcc --version | head -1")),
        ("flags", "-std=c99 -O2 -DBP_USE_PTHREADS -pthread (the Makefile's tool rule)"),
        ("kernel", platform.release()),
        ("python", platform.python_version()),
        ("commit", sh("cd %s && git log -1 --format='%%h %%s' | cut -c1-80" % ROOT)),
        ("bijparam.h sha256", sh("sha256sum %s/bijparam.h | cut -c1-16" % ROOT)
         + (" (uncommitted changes)" if sh("cd %s && git status --short bijparam.h" % ROOT) else "")),
    ]
    table(["what", "value"], rows)


DISS_31 = {CAMEL: (9.203, 28.082, 9.351, 27.216), COW: (5.466, 14.763, 5.843, 14.751),
           HORSE: (7.280, 26.499, 7.300, 39.890)}


def table31():
    head = ["mesh", "direction", "E_D avg", "E_D max", "iters", "s", "overlaps",
            "E_D+E_B avg", "E_D+E_B max", "iters", "s", "bijective"]
    rows = []
    for mesh in present(CAMEL, COW, HORSE):
        d = DISS_31[mesh]
        rows.append([NAMES[mesh], "dissertation", "%.3f" % d[0], "%.3f" % d[1], "", "", "",
                     "%.3f" % d[2], "%.3f" % d[3], "", "", "yes"])
        for direction in ("precond", "lbfgs"):
            nb = run(mesh, ["--direction", direction, "--no-barrier"], runs=1)
            b = run(mesh, ["--direction", direction], runs=1)
            rows.append([NAMES[mesh], direction, f(nb.get("mean")), f(nb.get("max")),
                         "%s%s" % (nb.get("iters"), "" if nb.get("stop") == "converged" else " (%s)" % nb.get("stop")),
                         f(nb["wall"], "%.2f"), "%s / %s" % (nb.get("tool_bi", "-"), nb.get("bi", "-")),
                         f(b.get("mean")), f(b.get("max")),
                         "%s%s" % (b.get("iters"), "" if b.get("stop") == "converged" else " (%s)" % b.get("stop")),
                         f(b["wall"], "%.2f"), yn(b.get("bij"))])
    table(head, rows)
    print("\"overlaps\": boundary intersections in the `--no-barrier` result, as the tool's "
          "JSON reports them (bp_check) / as uvcheck counts them (boundary_self_intersections) "
          "(0 flipped triangles in every run unless stated) (0 flipped triangles in every run unless stated); \"bijective\": "
          "uvcheck on the result with the barrier.  One run each, `--threads 1`; "
          "energies are area-weighted means of eq 3.3 (minimum 4).\n")


DISS_T = {"sd": (1.29, 3.63), "conformal": (95.97, 91.23), "mips": (3.42, 19.5),
          "iso": (125.62, 136.71), "maxiso": (114.46, 230.36)}


def metrics():
    head = ["energy", "E_B", "s", "cpu s", "iters", "stop", "mean of the energy", "E_D (sd) mean",
            "bijective", "overlaps", "dissertation s"]
    rows = []
    for e in ("sd", "conformal", "mips", "iso", "maxiso"):
        for barrier in (False, True):
            args = ["--energy", e] + ([] if barrier else ["--no-barrier"])
            r = run(COW, args)
            rows.append([e, "yes" if barrier else "no", f(r["wall"], "%.2f"), f(r["cpu"], "%.2f"),
                         r.get("iters"),
                         r.get("stop"), f(r.get("mean"), "%.4f"), f(r.get("sd_mean"), "%.4f"),
                         yn(r.get("bij")), "%s / %s" % (r.get("tool_bi", "-"), r.get("bi", "-")),
                         "%.2f" % DISS_T[e][1 if barrier else 0]])
    table(head, rows)
    print("Cow (`tests/data/cow_param_withSUV.obj`), `--threads 1`, default direction, "
          "median of %d runs (runs over %g s once).  \"mean of the energy\" is "
          "the tool's final area-weighted mean of the optimized energy (minima: sd 4, "
          "conformal 1, mips 2, iso sqrt 2, maxiso 1); \"E_D (sd) mean\" is the symmetric "
          "Dirichlet mean of the same map as uvcheck measures it (not scale-normalized, so it "
          "is large for the scale-invariant conformal and MIPS energies); \"overlaps\" is the "
          "boundary intersection count of the tool's JSON (bp_check) / of uvcheck "
          "(boundary_self_intersections).  The dissertation's times are fig 3.2 (without "
          "E_B) and fig 3.7 (with), i7-3770K.\n" % (RUNS, LONG))


def directions():
    cap = int(os.environ.get("EXP_GD_ITERS", "30000"))
    head = ["mesh", "direction", "iters", "stop", "s", "cpu s", "ms / iter", "E_D avg", "bijective"]
    rows = []
    for mesh in present(CAMEL, COW):
        for d in ("gd", "lbfgs", "precond"):
            r = run(mesh, ["--direction", d, "--max-iters", str(cap)])
            rows.append([NAMES[mesh], d, r.get("iters"),
                         r.get("stop") if r.get("stop") != "max_iterations" else "**cap %d**" % cap,
                         f(r["wall"], "%.2f"), f(r["cpu"], "%.2f"),
                         f(1000 * r["opt"] / r["iters"] if r.get("iters") else None, "%.2f"),
                         f(r.get("mean"), "%.4f"), yn(r.get("bij"))])
    table(head, rows)
    print("With the barrier, `--threads 1`, `--max-iters %d`, default tolerance (stop when "
          "the relative decrease is below 1e-7 three times running); median of %d runs "
          "(runs over %g s once).\n" % (cap, RUNS, LONG))


def history():
    ms = [1, 2, 3, 4, 5, 7, 10, 15, 20]
    meshes = present(CAMEL, COW)
    res = {}
    for mesh in meshes:
        for d in ("lbfgs", "precond"):
            for m in ms:
                res[mesh, d, m] = run(mesh, ["--direction", d, "--history", str(m)], check=False)
    head = ["m"] + ["%s %s" % (NAMES[mesh], d) for mesh in meshes for d in ("lbfgs", "precond")]
    rows = []
    for m in ms:
        row = [m]
        for mesh in meshes:
            for d in ("lbfgs", "precond"):
                r, r1 = res[mesh, d, m], res[mesh, d, 1]
                row.append("%.2f / %.2f (%.2f s, %s it)" % (r["wall"] / r1["wall"], r["cpu"] / r1["cpu"],
                                                        r["wall"], r.get("iters")))
        rows.append(row)
    table(head, rows)
    print("Each cell: wall time / CPU time, both normalized to m = 1, then the wall seconds "
          "and the iterations; `--threads 1`, "
          "with the barrier, median of %d runs.  The library default is m = 5.\n" % RUNS)


TARGET_E = [(CAMEL, 4.095), (COW, 4.09), (HORSE, 4.10), (FACE_HOLES, 4.025)]
DISS_TIME = {CAMEL: 6.13, COW: 3.63, HORSE: 35.48}


def targets():
    head = ["mesh", "target mean E_D", "final mean E_D", "max", "met", "bijective",
            "1-thread s", "cpu s", "dissertation s (4 thr)", "ratio"]
    rows = []
    for mesh, target in TARGET_E:
        if not present(mesh):
            continue
        r = run(mesh, [])
        ok = r.get("mean") is not None and r["mean"] <= target
        ds = DISS_TIME.get(mesh)
        rows.append([NAMES[mesh], "<= %.3f" % target, f(r.get("mean"), "%.4f"),
                     f(r.get("max"), "%.2f"), "yes" if ok else "**NO**", yn(r.get("bij")),
                     f(r["wall"], "%.2f"), f(r["cpu"], "%.2f"), "-" if ds is None else "%.2f" % ds,
                     "-" if ds is None else "%.1fx faster" % (ds / r["wall"]) if r["wall"] < ds
                     else "%.1fx slower" % (r["wall"] / ds)])
    if present(HILBERT):
        r = run(HILBERT, [], runs=1)
        rows.append(["hilbert", "ends bijective", f(r.get("mean"), "%.4f"), f(r.get("max"), "%.2f"),
                     "yes" if r.get("bij") else "**NO**", yn(r.get("bij")),
                     f(r["wall"], "%.2f"), f(r["cpu"], "%.2f"), "-", "-"])
    table(head, rows)
    print("Default options (`--direction precond`, m = 5, barrier on) with `--threads 1`; "
          "time is the median wall time of %d runs of the whole tool (hilbert: 1 run).  "
          "The dissertation's times are Table 3.2 (4 threads, i7-3770K, 2013).\n" % RUNS)


def bench():
    path = os.path.join(ROOT, "build", "bench", "bench.jsonl")
    if not os.path.isfile(path):
        print("_%s is missing: run `make bench` first._\n" % path)
        return
    rows = [json.loads(l) for l in open(path)]
    head = ["mesh", "V", "F", "charts", "loops", "iters", "median s", "cpu s", "E mean", "E max",
            "bijective", "bytes/face", "t to 1.01x", "t to 1.001x"]
    out = []
    for r in rows:
        if r["status"] != "ok":
            out.append([r["mesh"], r["V"], r["F"], "", "", "", "", "", "", "",
                        "%s: %s" % (r["status"], r["error"]), "", "", ""])
            continue
        out.append([r["mesh"], r["V"], r["F"], r["charts"], r["loops"], r["iterations"],
                    f(r["seconds"], "%.3f"), f(r.get("cpu_seconds"), "%.3f"), f(r["energy_mean"], "%.4f"), f(r["energy_max"], "%.2f"),
                    yn(r["bijective"]), f(r["bytes_per_face"], "%.0f"),
                    f(r["t_1.01"], "%.3f"), f(r["t_1.001"], "%.3f")])
    table(head, out)
    th = [r for r in rows if "threads_cmp" in r]
    if th:
        out = []
        for r in th:
            t = r["threads_cmp"]
            out.append([r["mesh"], r["F"], f(t["t1_seconds"], "%.2f"), f(t["t2_seconds"], "%.2f"),
                        f(t["speedup"], "%.2f"), f(t["t1_opt"], "%.2f"), f(t["t2_opt"], "%.2f"),
                        f(t["speedup_opt"], "%.2f"), f(t.get("t1_cpu"), "%.2f"), f(t.get("t2_cpu"), "%.2f"),
                        "%.1f-%.1f" % tuple(r.get("loadavg_1min", [0, 0])), f(t["t1_bytes_per_face"], "%.0f"),
                        f(t["t2_bytes_per_face"], "%.0f"), yn(t["same_result"])])
        table(["mesh", "F", "1 thread s", "2 threads s", "speed-up", "opt 1 thr s",
               "opt 2 thr s", "opt speed-up", "cpu 1 thr s", "cpu 2 thr s", "load",
               "bytes/face 1 thr", "bytes/face 2 thr",
               "identical result"], out)


SECTIONS = {"machine": machine, "table31": table31, "metrics": metrics,
            "directions": directions, "history": history, "targets": targets, "bench": bench}
ORDER = ["machine", "table31", "metrics", "directions", "history", "targets", "bench"]


def main(argv):
    names = argv or ["all"]
    if names == ["all"]:
        names = ORDER
    bad = [n for n in names if n not in SECTIONS]
    if bad:
        print(__doc__, file=sys.stderr)
        return 2
    if not os.access(TOOL, os.X_OK):
        print("experiments: %s missing: run 'make' first" % TOOL, file=sys.stderr)
        return 1
    for n in names:
        t0 = time.perf_counter()
        print("<!-- bench/experiments.sh %s -->" % n)
        l0 = os.getloadavg()[0]
        SECTIONS[n]()
        if n not in ("machine", "bench"):
            print("_Section ran %s, %.0f s; 1-minute load average %.1f at the start, %.1f at "
                  "the end (%d cores)._\n" % (time.strftime("%H:%M"), time.perf_counter() - t0,
                                              l0, os.getloadavg()[0], os.cpu_count() or 0))
        log("%s: %.0f s" % (n, time.perf_counter() - t0))
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
