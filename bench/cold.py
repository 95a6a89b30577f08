#!/usr/bin/env python3
"""bench/cold.py (make bench-cold) - which functions BP__COLD should mark.

bijparam.h compiles a function at -Og under GCC when it is marked BP__COLD
(>>config): a function of more than ten lines that holds less than 0.1% of
the run time of every profiled run.  This script profiles the runs again
and lists where the header's marks disagree with that rule:

  marked but hot    a BP__COLD function holding 0.1% or more of some run
                    (it should lose its mark: it slows that run)
  unmarked but cold an unmarked function of more than ten lines under 0.1%
                    of every run (a mark would save compile time)
  marked but small  a BP__COLD function of ten lines or fewer (a hot
                    caller could not inline it)

The tool is built with -O2 -g and BP__COLD defined empty, so that every
function is compiled as the inner loops are; perf samples each run at
1999 Hz, and a sample counts for every function of its inline chain
(addr2line -i): a function is hot when its own code or code inlined into
it runs.  The runs: every mesh of tests/data plain and with --atlas 1024,
each repeated for RUN_SECONDS (default 3); camelhead with --direction
precond and --energy mips; face with --energy conformal and --start
progressive; spot with --visibility ring; the cow from its input UVs and
repacked; lucy's mean-value start; and, when make bench-generated has
made them, blob-400k and noisy-400k with --atlas 4096 on one and two
threads, blob-400k's start map and the exact check of blob-1m's output.  Needs perf (Debian:
linux-perf) and binutils.  Prints both lists and writes
build/bench/cold.json (every function's largest share and its run).
"""
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "build", "bench", "cold")
DATA = os.path.join(ROOT, "tests", "data")
GEN = os.path.join(ROOT, "build", "bench", "generated")
SECONDS = float(os.environ.get("RUN_SECONDS", "3"))
HOT = 0.1          # percent of a run's samples in the tool
SMALL = 10         # lines: never marked


def runs():
    meshes = sorted(f for f in os.listdir(DATA) if f.endswith((".obj", ".off")))
    out = []
    for m in meshes:
        out.append((m, [os.path.join(DATA, m)], SECONDS))
        out.append((m + " --atlas", [os.path.join(DATA, m), "--atlas", "1024"], SECONDS))
    d = lambda m: os.path.join(DATA, m)
    out += [("camelhead precond", [d("camelhead.off"), "--direction", "precond"], 0),
            ("camelhead mips", [d("camelhead.off"), "--energy", "mips"], 0),
            ("face conformal", [d("face.obj"), "--energy", "conformal"], 0),
            ("face progressive", [d("face.obj"), "--start", "progressive"], 0),
            ("spot visibility", [d("spot.obj"), "--visibility", "ring", "--atlas", "1024"], SECONDS),
            ("cow input", [d("cow_param_withSUV.obj"), "--init", "input"], SECONDS),
            ("cow repack", [d("cow_param_withSUV.obj"), "--repack", "--atlas", "1024"], SECONDS),
            ("lucy mvc", [d("lucy_o_f48275.obj"), "--init-only", "--init", "mvc"], SECONDS)]
    for g in ("blob-400k-s1.obj", "noisy-400k-s1.obj"):
        if os.path.exists(os.path.join(GEN, g)):
            for t in ("1", "2"):
                out.append((g + " t" + t, [os.path.join(GEN, g), "--atlas", "4096", "--threads", t], 0))
    if os.path.exists(os.path.join(GEN, "blob-400k-s1.obj")):
        out.append(("blob-400k start", [os.path.join(GEN, "blob-400k-s1.obj"), "--init-only"], 0))
    if os.path.exists(os.path.join(GEN, "blob-1m-s1.out.obj")):
        out.append(("blob-1m check", ["--check", os.path.join(GEN, "blob-1m-s1.out.obj")], 0))
    return out


def build():
    os.makedirs(OUT, exist_ok=True)
    tool = os.path.join(OUT, "tool")
    subprocess.run(["gcc", "-std=c99", "-O2", "-g", "-DBP__COLD=", "-DBP_USE_PTHREADS", "-pthread",
                    "-I" + ROOT, os.path.join(ROOT, "examples", "bijparam.c"), "-o", tool, "-lm"], check=True)
    return tool


def record(tool, name, args, seconds):
    """Samples of one run (repeated until `seconds` passed): address -> count."""
    data = os.path.join(OUT, "perf.data")
    outobj = os.path.join(OUT, "out.obj")
    cmd = [tool, "-q", "--threads", "1"] + args if "--threads" not in args else [tool, "-q"] + args
    if "--check" not in args:
        cmd += ["-o", outobj]
    loop = "end=$(( $(date +%%s) + %d )); while :; do \"$@\" >/dev/null 2>&1; [ $(date +%%s) -ge $end ] && break; done" % max(1, int(seconds + 0.999))
    subprocess.run(["perf", "record", "-q", "-F", "1999", "-o", data, "--", "sh", "-c", loop, "sh"] + cmd,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    text = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym,symoff,dso"],
                          capture_output=True, text=True).stdout
    counts = collections.Counter()
    for line in text.splitlines():
        p = line.split()
        if len(p) >= 3 and p[-1] == "(%s)" % tool:
            counts[p[1]] += 1
    return counts


DEFINE = re.compile(r"^(BP__HOT )?(BP__COLD )?(?:static|BPDEF)\b[^;=]*?\b(\w+)\s*\(")


def definitions():
    """Every function the implementation defines, in order: (name, first
    line, lines, marked BP__COLD, marked BP__HOT).  A body runs from a line
    starting with "{" to one starting with "}", or ends its first line."""
    header = open(os.path.join(ROOT, "bijparam.h")).read().split("\n")
    i, out = next(i for i, l in enumerate(header) if l.startswith("/* >>config")), []
    while i < len(header):
        m = DEFINE.match(header[i])
        if m and not header[i].rstrip().endswith(";"):
            k = j = i
            if not header[i].rstrip().endswith("}"):
                while j < len(header) and not header[j].startswith("{") and not header[j].rstrip().endswith(";"):
                    j += 1
                if j == len(header) or not header[j].startswith("{"):
                    i += 1
                    continue
                k = j
                while not header[k].startswith("}"):
                    k += 1
            out.append((m.group(3), i + 1, k - i + 1, bool(m.group(2)), bool(m.group(1))))
            i = k
        i += 1
    return out


def main():
    for prog in ("perf", "addr2line", "nm", "gcc"):
        if not shutil.which(prog):
            sys.exit("bench/cold.py: needs %s (Debian: linux-perf, binutils, gcc)" % prog)
    tool = build()
    symbols = {}
    for line in subprocess.run(["nm", tool], capture_output=True, text=True).stdout.splitlines():
        p = line.split()
        if len(p) == 3:
            symbols[p[2]] = int(p[0], 16)
    samples = {}
    for name, args, seconds in runs():
        t = time.time()
        counts = collections.Counter()
        for symoff, c in record(tool, name, args, seconds).items():
            s, _, off = symoff.rpartition("+")
            if s in symbols:
                counts[symbols[s] + int(off, 16)] += c
        samples[name] = counts
        print("%-40s %7d samples %5.1f s" % (name, sum(counts.values()), time.time() - t), flush=True)
    addrs = sorted(set(a for c in samples.values() for a in c))
    chain, cur = {}, None
    for i in range(0, len(addrs), 20000):
        lines = subprocess.run(["addr2line", "-e", tool, "-i", "-f", "-a"] + [hex(a) for a in addrs[i:i + 20000]],
                               capture_output=True, text=True).stdout.splitlines()
        j = 0
        while j < len(lines):
            if lines[j].startswith("0x"):
                cur = int(lines[j], 16); chain[cur] = set(); j += 1
            else:
                chain[cur].add(lines[j]); j += 2
    share, where = collections.defaultdict(float), {}
    for name, counts in samples.items():
        total = sum(counts.values())
        if total < 500:
            continue
        per = collections.Counter()
        for a, c in counts.items():
            for fn in chain.get(a, ()):
                per[fn] += c
        for fn, c in per.items():
            if 100.0 * c / total > share[fn]:
                share[fn], where[fn] = 100.0 * c / total, name
    funcs = definitions()
    marked_hot = [f for f in funcs if f[3] and share[f[0]] >= HOT]
    unmarked_cold = [f for f in funcs if not f[3] and f[2] > SMALL and share[f[0]] < HOT]
    marked_small = [f for f in funcs if f[3] and f[2] <= SMALL]
    print("\n%d functions, %d marked BP__COLD" % (len(funcs), sum(f[3] for f in funcs)))
    print("marked but hot (%d):" % len(marked_hot))
    for f in marked_hot:
        print("  %-36s line %5d  %.3f%% in %s" % (f[0], f[1], share[f[0]], where[f[0]]))
    print("unmarked but cold, more than %d lines (%d):" % (SMALL, len(unmarked_cold)))
    for f in unmarked_cold:
        print("  %-36s line %5d  %4d lines  %.3f%%" % (f[0], f[1], f[2], share[f[0]]))
    print("marked but %d lines or fewer (%d):" % (SMALL, len(marked_small)))
    for f in marked_small:
        print("  %-36s line %5d  %4d lines" % (f[0], f[1], f[2]))
    json.dump({"runs": {n: sum(c.values()) for n, c in samples.items()},
               "functions": [{"name": f[0], "line": f[1], "lines": f[2], "marked": f[3],
                              "share": share[f[0]], "run": where.get(f[0])} for f in funcs]},
              open(os.path.join(ROOT, "build", "bench", "cold.json"), "w"), indent=1)
    print("wrote build/bench/cold.json")


if __name__ == "__main__":
    main()
