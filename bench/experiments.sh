#!/usr/bin/env bash
# The dissertation's chapter 3 experiments (docs/performance.md); each section
# prints a Markdown table.
#
#   bash bench/experiments.sh                  every section (~15 min on 2 cores)
#   bash bench/experiments.sh table31 history  only these sections
#
# Sections: machine table31 metrics directions history targets bench
# (bench formats the last `make bench` results, build/bench/bench.jsonl).
# Environment: EXP_RUNS (runs per timing, default 3), EXP_LONG (runs longer
# than this many seconds are timed once, default 20), EXP_GD_ITERS (the
# iteration cap of the directions section, default 30000).  The tool is
# copied to build/bench/bijparam-exp first so that a rebuild during the run
# does not mix two versions.  bench/experiments.py documents each section.
set -eu
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "experiments: build/bijparam missing: run 'make' first" >&2; exit 1; }
mkdir -p build/bench
if [ -z "${EXP_TOOL:-}" ]; then
    cp build/bijparam build/bench/bijparam-exp
    export EXP_TOOL=build/bench/bijparam-exp
fi
exec python3 bench/experiments.py "$@"
