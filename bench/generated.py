#!/usr/bin/env python3
"""bench/generated.py - marching-cubes meshes at 150K-4M faces through the
whole pipeline (make bench-generated).

The meshes are those bench/mcmesh.c makes (a noisy four-legged creature,
marching cubes: about 1.2% of the triangles under 1 degree, 0.1% with
less than 1e-4 of the mean area), written once to build/bench/generated/
(the generator is deterministic: the same bytes for the same kind, face
count and seed; a newer bench/mcmesh.c makes them again):

  blob-150k, blob-400k, blob-1m, blob-4m   genus 0, one piece
  noisy-400k                               genus about 17 (20 handles) and
                                           13 floating pieces

Each is parameterized by the tool as a pipeline would call it,

    build/bijparam MESH --atlas 4096 --padding 4 --threads 2 --json -o OUT.obj

and OUT.obj is then checked by `build/bijparam --check OUT.obj` (every
chart bijective and no two charts overlapping, by exact predicates; its
time is not in the table).  Columns:

  faces, genus, pieces  of the generated mesh (genus summed over the pieces)
  wall s, CPU s         the whole process, measured here (CPU: user +
                        system of the child, all threads)
  read .. write         the tool's own stage timings (--json "timings"):
                        read, cut (bp_atlas_build: repairs, seams),
                        segment (bp_atlas_segment), solve (start maps and
                        optimization of every chart), pack, write; the
                        CPU seconds of each stage are in the JSON
                        ("cpu_timings")
  MB, B/face            peak resident memory (the tool's peak_rss_bytes)
                        and that per face
  charts, util          charts in the atlas, their UV area over the square
  seams                 3D length of the cut edges over the square root of
                        the mesh's area (the tool's "seams": "relative")
  exact                 the --check of OUT.obj: "yes" or what it said

On a shared machine read CPU s, the per-stage CPU in the JSON, and ratios
measured in one run; wall times are inflated by the other load (the
"load" field of each JSON line is the 1-minute load average at the end).
One JSON line per run goes to build/bench/generated.jsonl and to stdout.

Environment:
  BENCH_GEN_MESHES="blob-150k ..."  the meshes (default: all five)
  BENCH_GEN_THREADS=T               --threads (default 2)
  BENCH_GEN_RES=R / BENCH_GEN_PAD=P --atlas and --padding (4096, 4)
  BENCH_GEN_RUNS=N                  runs per mesh (default 1)
  BENCH_GEN_ARGS="..."              extra tool options
  BENCH_GEN_SEED=S                  generator seed (default 1)
  BENCH_TIMEOUT=S                   per-run limit (default 3600)
  BENCH_TOOL=PATH                   the tool (make bench-generated snapshots
                                    build/bijparam)
"""
import hashlib
import json
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.environ.get("BENCH_TOOL") or os.path.join(ROOT, "build", "bijparam")
GEN = os.path.join(ROOT, "build", "bench", "mcmesh")
GEN_SRC = os.path.join(ROOT, "bench", "mcmesh.c")
OUT = os.path.join(ROOT, "build", "bench", "generated")

MESHES = {                      # name: (kind, faces)
    "blob-150k": ("blob", 150000),
    "blob-400k": ("blob", 400000),
    "noisy-400k": ("noisy", 400000),
    "blob-1m": ("blob", 1000000),
    "blob-4m": ("blob", 4000000),
}


def env_int(name, default):
    v = os.environ.get(name, "")
    return int(v) if v.strip() else default


NAMES = os.environ.get("BENCH_GEN_MESHES", " ".join(MESHES)).split()
THREADS = env_int("BENCH_GEN_THREADS", 2)
RES = env_int("BENCH_GEN_RES", 4096)
PAD = env_int("BENCH_GEN_PAD", 4)
RUNS = max(1, env_int("BENCH_GEN_RUNS", 1))
SEED = env_int("BENCH_GEN_SEED", 1)
TIMEOUT = env_int("BENCH_TIMEOUT", 3600)
ARGS = os.environ.get("BENCH_GEN_ARGS", "").split()


def generator_hash():
    with open(GEN_SRC, "rb") as fh:
        return hashlib.sha1(fh.read()).hexdigest()[:12]


def generate(name):
    """build/bench/generated/NAME-sSEED.obj and its statistics (.json), made
    once per version of bench/mcmesh.c."""
    kind, faces = MESHES[name]
    path = os.path.join(OUT, "%s-s%d.obj" % (name, SEED))
    meta = path[:-4] + ".json"
    h = generator_hash()
    try:
        with open(meta) as fh:
            st = json.load(fh)
        if st.get("generator") == h and os.path.isfile(path):
            return path, st
    except (OSError, ValueError):
        pass
    p = subprocess.run([GEN, kind, str(faces), str(SEED), path], stdout=subprocess.PIPE, check=True)
    st = json.loads(p.stdout.decode())
    st["generator"] = h
    with open(meta, "w") as fh:
        json.dump(st, fh)
    return path, st


def run(name, mesh, r):
    out = os.path.join(OUT, "%s-s%d.out%s.obj" % (name, SEED, "" if r == 0 else ".r%d" % r))
    if os.path.exists(out):
        os.remove(out)
    cmd = [TOOL, mesh, "--atlas", str(RES), "--padding", str(PAD), "--threads", str(THREADS),
           "--json", "-q", "-o", out] + ARGS
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT)
        rc, so, se = p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        rc, so, se = 124, "", "timed out after %d s" % TIMEOUT
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    row = {"mesh": name, "run": r, "threads": THREADS, "rc": rc, "wall": wall,
           "cpu": r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime}
    try:
        rep = json.loads(so.strip().splitlines()[-1])
    except (ValueError, IndexError):
        row["error"] = se.strip()[-300:] or "exit %d" % rc
        row["load"] = os.getloadavg()[0]
        return row
    per = rep.get("per_chart", [])
    row.update({
        "status": rep.get("status"), "charts": rep.get("charts"), "failed": rep.get("failed_charts"),
        "utilization": rep.get("utilization"), "peak_rss": rep.get("peak_rss_bytes"),
        "bytes_per_face": rep.get("bytes_per_face"), "timings": rep.get("timings"),
        "cpu_timings": rep.get("cpu_timings"), "seams": rep.get("seams"),
        "repairs": rep.get("repairs", {}).get("total"),
        "largest_chart": max((c["faces"] for c in per), default=0),
        "energy_start_max": max((c["energy_start"] for c in per if c.get("energy_start") is not None), default=None),
        "energy_end_max": max((c["energy_end"] for c in per if c.get("energy_end") is not None), default=None),
        "newton_charts": sum(1 for c in per if c.get("direction") == "newton"),
    })
    if rc == 0 and os.path.isfile(out):
        c = subprocess.run([TOOL, "--check", out], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        last = (c.stdout.decode(errors="replace").strip().splitlines() or ["?"])[-1]
        row["exact"] = "yes" if c.returncode == 0 else "NO: " + last
    else:
        row["exact"] = "-"
    row["load"] = os.getloadavg()[0]
    return row


def f(x, fmt):
    return "-" if x is None else fmt % x


def main():
    for p in (TOOL, GEN):
        if not os.access(p, os.X_OK):
            raise SystemExit("bench-generated: %s missing: run 'make bench-generated'" % p)
    for n in NAMES:
        if n not in MESHES:
            raise SystemExit("bench-generated: unknown mesh %s (%s)" % (n, " ".join(MESHES)))
    os.makedirs(OUT, exist_ok=True)
    rows, stats = [], {}
    for name in NAMES:
        mesh, st = generate(name)
        stats[name] = st
        for r in range(RUNS):
            row = run(name, mesh, r)
            row.update({"faces": st["faces"], "genus": st["genus"], "pieces": st["components"],
                        "slivers": st["slivers"]})
            rows.append(row)
            sys.stderr.write(json.dumps(row) + "\n")
    print("\n## generated marching-cubes meshes, --atlas %d --padding %d, %d threads%s\n"
          % (RES, PAD, THREADS, (", " + " ".join(ARGS)) if ARGS else ""))
    print("| mesh | faces | genus | pieces | wall s | CPU s | read | cut | segment | solve | pack | write "
          "| MB | B/face | charts | util | seams | exact |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for name in NAMES:
        rs = [r for r in rows if r["mesh"] == name]
        ok = [r for r in rs if r.get("timings")]
        if not ok:
            for r in rs:
                print("| %s | %d | %d | %d | %s |" % (name, r["faces"], r["genus"], r["pieces"], r.get("error")))
            continue
        med = lambda key: statistics.median(r[key] for r in ok)
        tm = lambda key: statistics.median(r["timings"][key] for r in ok)
        r = ok[0]
        print("| %s | %d | %d | %d | %.1f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f "
              "| %d | %.3f | %s | %s |" % (
                  name, r["faces"], r["genus"], r["pieces"], med("wall"), med("cpu"), tm("read"), tm("cut"),
                  tm("segment"), tm("optimize"), tm("pack"), tm("write"), med("peak_rss") / 1e6,
                  med("bytes_per_face"), r["charts"], r["utilization"],
                  f((r.get("seams") or {}).get("relative"), "%.1f"),
                  ", ".join(sorted(set(x["exact"] for x in rs)))))
    print("\nCPU seconds per stage (all threads; the tool's cpu_timings), medians:\n")
    print("| mesh | read | cut | segment | solve | pack | write |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in NAMES:
        ok = [r for r in rows if r["mesh"] == name and r.get("cpu_timings")]
        if ok:
            c = lambda key: statistics.median(r["cpu_timings"][key] for r in ok)
            print("| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |" % (
                name, c("read"), c("cut"), c("segment"), c("optimize"), c("pack"), c("write")))
    print("\nmeshes: " + "; ".join("%s %d faces, %.2f%% under 1 degree, %.2f%% tiny, grid %d" % (
        n, s["faces"], 100 * s["slivers"], 100 * s["tiny"], s["grid"]) for n, s in stats.items()))
    with open(os.path.join(ROOT, "build", "bench", "generated.jsonl"), "w") as fh:
        for r in rows:
            fh.write(json.dumps(r) + "\n")
    print()
    for r in rows:
        print(json.dumps(r))


if __name__ == "__main__":
    main()
