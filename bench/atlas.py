#!/usr/bin/env python3
"""Atlas benchmark (make bench-atlas): every mesh through --atlas 1024 --padding 4.

For each mesh of tests/data (one at a time: the machine is shared), run

    build/bijparam MESH --atlas RES --padding PX --json -o build/bench/atlas/NAME.obj

and record, per mesh:

  V, F        vertices and faces of the input (from the output's v/f lines)
  charts      charts in the atlas (the tool's JSON)
  cut         edges cut by the automatic seams (sum of per_chart cut_edges)
  util        utilization: exact UV area / atlas area (the tool's JSON)
  E_SD        mean symmetric Dirichlet energy sigma1^2+sigma2^2+sigma1^-2+sigma2^-2,
              weighted by 3D area, with the whole atlas scaled by one factor so
              that its UV area equals the 3D area (one texel density for every
              chart, as the atlas has; 4 is an isometry).  Computed here from
              the output OBJ, not taken from the tool.
  wall, cpu   seconds of the tool's run (cpu = user + system of the child)
  check       tests/uvcheck.py --json OUT MESH: exit 0 = every
              chart bijective, no cross-chart overlap, geometry matches MESH
  in01        every vt of the output in [0, 1] (read here from the file)
  gap         padding actually left, in texels: the least distance between
              boundary segments of two different charts (charts = connected
              components of the output's vt triangles), by brute force over
              all pairs, times RES; "-" for a single chart.  Must be >= PX.
  border      the least distance of any vt from the edge of [0,1]^2, texels
              (read from the file's vt, exact in double).  Must be >=
              ceil(PX / 2): the packer keeps half the padding at the edge, so
              the atlas tiled with wrap-around keeps PX texels across it.
  xatlas      xatlas's utilization at 1024 px / 4 px padding (its own
              charts) where measured: spot, cow, torus_with_holes, fertility
  unseg       with ATLAS_BASELINE=1: the utilization of a second run with
              --segment off (the charts of the file and of the cut alone,
              >>segment), for comparison; "-" otherwise

Besides the meshes of tests/data, build/bench/bimba_closed.obj (made
by bench/atlas.sh with bench/close_base.py: bimba_i.obj closed by a fan
over its base, a closed genus-0 surface of 89,590 triangles) when present.

Environment: ATLAS_RES (1024), ATLAS_PADDING (4), ATLAS_MESHES (names to
restrict to), ATLAS_TIMEOUT (seconds per run, 600), BENCH_TOOL (the binary),
ATLAS_BASELINE (1: the unseg column).
Prints a Markdown table and writes one JSON line per mesh to
build/bench/atlas.jsonl.  Exit status 1 if any run failed or any check failed.
"""
import json
import math
import os
import resource
import subprocess
import sys
import time

XATLAS = {"spot": 0.598, "cow_param_withSUV": 0.608, "torus_with_holes": 0.572, "fertility": 0.488}


def meshes():
    seen, out = set(), []
    for d in ("tests/data",):
        if not os.path.isdir(d):
            continue
        for f in sorted(os.listdir(d)):
            if f.endswith((".obj", ".off")) and f not in seen:
                seen.add(f)
                out.append(os.path.join(d, f))
    if os.path.exists("build/bench/bimba_closed.obj"):
        out.append("build/bench/bimba_closed.obj")
    only = os.environ.get("ATLAS_MESHES", "").split()
    return [m for m in out if not only or os.path.basename(m) in only]


def read_obj(path):
    """Positions, texture coordinates and faces as (v index, vt index) corners."""
    v, vt, faces = [], [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                v.append(tuple(float(x) for x in line.split()[1:4]))
            elif line.startswith("vt "):
                vt.append(tuple(float(x) for x in line.split()[1:3]))
            elif line.startswith("f "):
                corners = []
                for c in line.split()[1:]:
                    p = c.split("/")
                    corners.append((int(p[0]) - 1, int(p[1]) - 1 if len(p) > 1 and p[1] else -1))
                for k in range(1, len(corners) - 1):
                    faces.append((corners[0], corners[k], corners[k + 1]))
    return v, vt, faces


def seg_dist(a, b, c, d):
    """Distance between segments ab and cd that do not cross (uvcheck
    verifies that): the least of the four endpoint-to-segment distances."""
    def pd(p, a, b):
        ux, uy = b[0] - a[0], b[1] - a[1]
        L = ux * ux + uy * uy
        t = 0 if L == 0 else max(0, min(1, ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / L))
        return math.hypot(p[0] - a[0] - t * ux, p[1] - a[1] - t * uy)
    return min(pd(a, c, d), pd(b, c, d), pd(c, a, b), pd(d, a, b))


def chart_gap(vt, faces):
    """Least distance between boundary segments of different UV charts."""
    parent = list(range(len(vt)))
    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    count = {}
    for f in faces:
        q = [c[1] for c in f]
        for k in range(3):
            parent[find(q[k])] = find(q[(k + 1) % 3])
            e = (min(q[k], q[(k + 1) % 3]), max(q[k], q[(k + 1) % 3]))
            count[e] = count.get(e, 0) + 1
    segs = [(find(e[0]), vt[e[0]], vt[e[1]]) for e, n in count.items() if n == 1]
    # sweep over u: only pairs whose u-ranges come within the best gap so far
    segs.sort(key=lambda s: min(s[1][0], s[2][0]))
    best = math.inf
    for i, (ci, a, b) in enumerate(segs):
        hi = max(a[0], b[0])
        for cj, c, d in segs[i + 1:]:
            if min(c[0], d[0]) > hi + best:
                break
            if cj != ci:
                best = min(best, seg_dist(a, b, c, d))
    return best


def sub(a, b):
    return [a[i] - b[i] for i in range(len(a))]


def sym_dirichlet(v, vt, faces):
    """Area-weighted mean symmetric Dirichlet energy at one global scale."""
    tris = []
    a3tot = auvtot = 0.0
    for (p0, q0), (p1, q1), (p2, q2) in faces:
        e1, e2 = sub(v[p1], v[p0]), sub(v[p2], v[p0])
        l1 = math.sqrt(sum(x * x for x in e1))
        cx = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        a2 = math.sqrt(sum(x * x for x in cx))        # twice the 3D area
        if not (l1 > 0 and a2 > 0):
            continue                                   # a zero-area input triangle: no energy
        x1, x2, y2 = l1, sum(e1[i] * e2[i] for i in range(3)) / l1, a2 / l1
        u1, u2 = sub(vt[q1], vt[q0]), sub(vt[q2], vt[q0])
        # J = [u1 u2] [[x1 x2] [0 y2]]^-1
        j00, j10 = u1[0] / x1, u1[1] / x1
        j01, j11 = (u2[0] - j00 * x2) / y2, (u2[1] - j10 * x2) / y2
        fro, det = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11, j00 * j11 - j01 * j10
        tris.append((a2, fro, det))
        a3tot += a2
        auvtot += abs(det) * a2
    if not tris or not auvtot > 0:
        return float("nan")
    s2 = a3tot / auvtot                                # scale^2: UV area = 3D area
    e = 0.0
    for a2, fro, det in tris:
        e += a2 * (s2 * fro * (1 + 1 / (s2 * s2 * det * det)) if det != 0 else math.inf)
    return e / a3tot


def run(mesh, tool, res, pad, outdir, timeout):
    name = os.path.splitext(os.path.basename(mesh))[0]
    out = os.path.join(outdir, name + ".obj")
    cmd = [tool, mesh, "--atlas", str(res), "--padding", str(pad), "--json", "-o", out]
    rec = {"mesh": name, "command": " ".join(cmd)}
    if os.path.exists(out):
        os.remove(out)
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        rec.update(status="timeout after %d s" % timeout)
        return rec
    rec["wall"] = time.monotonic() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    rec["cpu"] = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    rec["exit"] = p.returncode
    try:
        j = json.loads(p.stdout)
    except ValueError:
        j = {}
    rec["status"] = j.get("status", "no JSON")
    if p.returncode != 0:
        rec["message"] = (p.stderr.strip() or p.stdout.strip())[-400:]
        return rec
    rec["charts"] = j.get("charts")
    rec["failed_charts"] = j.get("failed_charts")
    rec["cut_edges"] = sum(c.get("cut_edges", 0) for c in j.get("per_chart", []))
    rec["utilization"] = j.get("utilization")
    rec["repairs"] = j.get("repairs", {}).get("total", 0)
    v, vt, faces = read_obj(out)
    rec["V"], rec["F"] = len(v), len(faces)
    rec["in01"] = bool(vt) and all(0 <= a <= 1 and 0 <= b <= 1 for a, b in vt)
    rec["E_SD"] = sym_dirichlet(v, vt, faces)
    gap = chart_gap(vt, faces)
    rec["gap_texels"] = gap * res if gap < math.inf else None
    rec["border_texels"] = min(min(a, 1 - a, b, 1 - b) for a, b in vt) * res if vt else None
    rec["threads"] = j.get("threads")
    rec["timings"] = j.get("timings")      # the tool's phases: read, charts, init, optimize, pack, write
    c = subprocess.run([sys.executable, "tests/uvcheck.py", "--json", out, mesh], capture_output=True, text=True)
    rec["uvcheck_exit"] = c.returncode
    try:
        cj = json.loads(c.stdout)
        rec["uvcheck_reasons"] = ["%d %s" % (n, k) for k, n in sorted(cj.get("counts", {}).items())]
    except ValueError:
        rec["uvcheck_reasons"] = [(c.stdout + c.stderr).strip()[-200:]]
    rec["xatlas"] = XATLAS.get(name)
    if os.environ.get("ATLAS_BASELINE") == "1":
        try:
            b = subprocess.run(cmd[:-2] + ["--segment", "off"], capture_output=True, text=True, timeout=timeout)
            rec["util_unsegmented"] = json.loads(b.stdout).get("utilization")
        except (subprocess.TimeoutExpired, ValueError):
            rec["util_unsegmented"] = None
    return rec


def row(r):
    def f(k, fmt):
        x = r.get(k)
        return fmt % x if isinstance(x, (int, float)) and x is not None else "-"
    if "charts" not in r:
        return "| %s | - | - | - | - | - | - | - | - | %s | **FAILED: %s** | - | - | - | - |" % (
            r["mesh"], f("wall", "%.1f"), r.get("status"), r.get("message", "")[:120].replace("\n", " "))
    chk = "n/a" if "uvcheck_exit" not in r else ("valid" if r["uvcheck_exit"] == 0 else
                                                 "**INVALID** " + "; ".join(r["uvcheck_reasons"])[:120])
    util = f("utilization", "%.3f")
    if r.get("xatlas") is not None:
        util += " (xatlas %.3f%s)" % (r["xatlas"], "" if r["utilization"] >= r["xatlas"] else ", **below**")
    return "| %s | %d | %d | %d | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
        r["mesh"], r["V"], r["F"], r["charts"], r["cut_edges"], util, f("util_unsegmented", "%.3f"), f("E_SD", "%.3f"),
        f("wall", "%.1f"), f("cpu", "%.1f"), chk, "yes" if r["in01"] else "**NO**",
        f("gap_texels", "%.2f"), f("border_texels", "%.6f"))


def main():
    tool = os.environ.get("BENCH_TOOL", "build/bijparam")
    res = int(os.environ.get("ATLAS_RES", "1024"))
    pad = int(os.environ.get("ATLAS_PADDING", "4"))
    timeout = int(os.environ.get("ATLAS_TIMEOUT", "600"))
    outdir = "build/bench/atlas"
    os.makedirs(outdir, exist_ok=True)
    recs, bad = [], 0
    with open("build/bench/atlas.jsonl", "w") as jl:
        for m in meshes():
            r = run(m, tool, res, pad, outdir, timeout)
            recs.append(r)
            line = json.dumps(r, sort_keys=True)
            jl.write(line + "\n")
            jl.flush()
            print(line, file=sys.stderr, flush=True)
            if ("charts" not in r or r.get("uvcheck_exit", 0) != 0 or not r.get("in01")
                    or (r.get("gap_texels") is not None and r["gap_texels"] < pad)
                    or (r.get("border_texels") is not None and r["border_texels"] < (pad + 1) // 2)):
                bad += 1
    print("| mesh | V | F | charts | cut edges | utilization | unseg | E_SD | wall s | CPU s | uvcheck | UV in [0,1] | gap texels | border texels |")
    print("|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---|---|---:|---:|")
    for r in recs:
        print(row(r))
    print("\n%d meshes, %d failed (--atlas %d --padding %d)" % (len(recs), bad, res, pad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
