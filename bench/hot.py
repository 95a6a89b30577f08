#!/usr/bin/env python3
"""bench/hot.py (make bench-hot) - which functions BP__HOT should mark.

Under BP_SMALL (the core library's default, >>config) GCC compiles the
implementation at -Os and the functions marked BP__HOT at -O2.  The rule:
a function is hot when it holds 0.5% or more of the samples of some run
(0.25% keeps a mark that is there: the shares move by about 0.1 between
profiles; a run counts with 500 samples or more, so that one sample
cannot decide), in either of two builds of the README's example as the
core library at -O2 -g:

  plain   BP_SMALL=0 and BP__COLD empty: every function at -O2, so a
          function's share includes what -O2 inlines into it;
  small   the header as it is: a helper that -O2 inlined into a caller
          and -Os did not shows up on its own here;

and every function that -O2 inlines into a hot one is marked too (GCC
inlines only between functions compiled at one level, so a helper left
at -Os becomes a call inside the inner loop).  The inlining is gcc's
-fopt-info-inline-optimized of both builds.  The runs: every mesh of
tests/data, each once.  Prints the functions the rule asks for that are
not marked, and those marked that it does not ask for.  The second list
holds candidates only: a function fast at -O2 may be slow at -Os and hot
without its mark (bp__hash_build: 0.0% marked, 2.3% of cow's run
without), so each is to be tried without its mark and profiled again.
Writes build/bench/hot.json (every function's largest share, its run and
build).  Needs perf (Debian: linux-perf) and gcc.
"""
import collections
import json
import os
import re
import subprocess
import sys

from cold import definitions     # the header's function definitions

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "build", "bench", "hot")
DATA = os.path.join(ROOT, "tests", "data")
HOT = 0.5          # percent of a run's samples that asks for a mark
KEEP = 0.25        # ... and that keeps one (a share near HOT moves by
                   # about 0.1 from one profile to the next)
MIN_SAMPLES = 500
CORE = ["-DBP_NO_NEWTON", "-DBP_NO_ATLAS", "-DBP_NO_VISIBILITY"]
BUILDS = {"plain": ["-DBP_SMALL=0", "-DBP__COLD="], "small": []}


def example():
    """The README's first C block, as tests/test_readme.sh takes it."""
    text, out, on = open(os.path.join(ROOT, "README.md")).read().split("\n"), [], False
    for line in text:
        if line == "```c" and not out:
            on = True
        elif line == "```" and on:
            break
        elif on:
            out.append(line)
    path = os.path.join(OUT, "example.c")
    open(path, "w").write("\n".join(out) + "\n")
    return path


def build(src, name, flags):
    exe = os.path.join(OUT, "example_" + name)
    cmd = ["gcc", "-std=c99", "-O2", "-g"] + CORE + flags + ["-I" + ROOT, src, "-o", exe, "-lm"]
    cmd.append("-fopt-info-inline-optimized=" + os.path.join(OUT, "inline_%s.txt" % name))
    subprocess.run(cmd, check=True)
    return exe


def profile(exe, mesh):
    """{function: samples} of one run, and the run's total."""
    data = os.path.join(OUT, "perf.data")
    subprocess.run(["perf", "record", "-q", "-F", "1999", "-o", data, "--", exe, mesh,
                    os.path.join(OUT, "out.obj")], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rep = subprocess.run(["perf", "report", "-i", data, "--stdio", "--no-children", "--sort", "symbol",
                          "-F", "sample,symbol"], capture_output=True, text=True, check=True).stdout
    per, total = collections.Counter(), 0
    for line in rep.split("\n"):
        m = re.match(r"\s*(\d+)\s+\[(.)\]\s+(\S+)", line)
        if m:
            total += int(m.group(1))
            if m.group(2) == ".":
                per[m.group(3).split(".")[0]] += int(m.group(1))
    return per, total


def marks():
    """{function: marked BP__HOT} for every definition of the header (a
    function defined twice, under #if, counts as marked when both are)."""
    out = {}
    for name, _, _, _, hot in definitions():
        out[name] = out.get(name, True) and hot
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    src = example()
    exes = {name: build(src, name, flags) for name, flags in BUILDS.items()}
    meshes = sorted(f for f in os.listdir(DATA) if f.endswith((".obj", ".off")))
    share, where = collections.defaultdict(float), {}
    for name, exe in exes.items():
        for mesh in meshes:
            per, total = profile(exe, os.path.join(DATA, mesh))
            print("%-6s %-28s %7d samples" % (name, mesh, total), flush=True)
            if total < MIN_SAMPLES:
                continue
            for fn, c in per.items():
                if 100.0 * c / total > share[fn]:
                    share[fn], where[fn] = 100.0 * c / total, "%s %s" % (name, mesh)
    into = collections.defaultdict(set)
    for name in BUILDS:
        for line in open(os.path.join(OUT, "inline_%s.txt" % name)):
            m = re.search(r"Inlin(?:ing|ed) (\w+)/\d+ into (\w+)", line)
            if m:
                into[m.group(2)].add(m.group(1))
    header = marks()
    want, stack = set(), [f for f in share if f in header and share[f] >= (KEEP if header[f] else HOT)]
    while stack:
        f = stack.pop()
        if f not in want and f in header:
            want.add(f)
            stack.extend(into.get(f, ()))
    unmarked = sorted(f for f in want if not header[f])
    extra = sorted(f for f, hot in header.items() if hot and f not in want)
    print("\n%d functions, %d marked BP__HOT, %d asked for by the rule" % (
        len(header), sum(header.values()), len(want)))
    print("\nhot but unmarked (%d):" % len(unmarked))
    for f in unmarked:
        print("  %-32s %6.2f%%  %s" % (f, share.get(f, 0), where.get(f, "inlined into a hot one")))
    print("\nmarked but not hot (%d):" % len(extra))
    for f in extra:
        print("  %-32s %6.2f%%  %s" % (f, share.get(f, 0), where.get(f, "")))
    json.dump({"hot_percent": HOT, "keep_percent": KEEP, "min_samples": MIN_SAMPLES,
               "functions": [{"name": f, "marked": header[f], "wanted": f in want, "share": share.get(f, 0),
                              "run": where.get(f)} for f in sorted(header)]},
              open(os.path.join(ROOT, "build", "bench", "hot.json"), "w"), indent=1)
    print("wrote build/bench/hot.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
