#!/usr/bin/env bash
# Benchmark (make bench): run build/bijparam on every mesh in tests/data;
# print a table (V, F, charts, loops, iterations, median seconds, final
# mean/max energy, bijectivity by tests/uvcheck.py, peak bytes per face,
# time to 1.01x / 1.001x of the final energy), a 1-vs-2-thread table for the
# meshes above 20K faces, the default thread count against --threads 1 on an
# idle and on a busy machine (one competing CPU-bound process per core,
# started and stopped by the bench; 10,000 one-triangle charts, spot,
# camel_b, camelhead), the photogrammetry-like case of bench/photogrammetry.py
# (4,740 charts, one with 50 holes) with 1 and 2 threads, and one JSON line
# per mesh and case.  bench/bench.py does the work and documents every column.
#
#   bash bench/run.sh                    (or: make bench)      ~20 min on 2 cores
#   BENCH_QUICK=1 bash bench/run.sh      the meshes below 30K faces, 1 run  (~15 s)
#   BENCH_RUNS=5 BENCH_TIMEOUT=300 bash bench/run.sh
#   BENCH_MESHES="camel_b.obj horse_cut.obj" bash bench/run.sh
#   BENCH_BUSY=only bash bench/run.sh    only the idle/busy comparison (~2 min)
#   BENCH_PHOTO=only bash bench/run.sh   only the photogrammetry-like case (~1 min)
#
# Progress (one JSON line per mesh) goes to stderr; the tables and the JSON
# lines go to stdout at the end, and to build/bench/bench.jsonl.
set -u
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "bench: build/bijparam missing: run 'make' first" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench: python3 is needed" >&2; exit 1; }
mkdir -p build/bench
if [ -z "${BENCH_TOOL:-}" ]; then     # a snapshot: a rebuild mid-bench cannot mix versions
    cp build/bijparam build/bench/bijparam-bench
    export BENCH_TOOL=build/bench/bijparam-bench
fi
exec python3 bench/bench.py
