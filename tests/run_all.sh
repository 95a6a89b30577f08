#!/usr/bin/env bash
# Run every test program given on the command line (binaries, or tests/*.sh
# scripts run with bash) and add up the "BPTEST <passed> <failed>" line each
# one prints last.  A program that crashes, times out or prints no BPTEST
# line counts as 1 failed.
#
# Quiet: one line per program (name, passed and failed counts, seconds); the
# full output of a failing program is shown.  Every program's full output is
# kept in $BP_TEST_LOGDIR/<name>.log (default build/logs); BP_TEST_VERBOSE=1
# shows every output as it used to.  BP_TEST_JOBS (default: the number of
# cores) programs run at a time; the report keeps the order given.  Ends with "N passed, M failed" (CI
# reads that line) and exits 1 when M > 0.  BP_TEST_TIMEOUT (default 600)
# limits each program, in seconds.  Run it from the repository root (the
# tests open tests/data/... by relative path).
set -u

per_test_timeout=${BP_TEST_TIMEOUT:-600}
logdir=${BP_TEST_LOGDIR:-build/logs}
verbose=${BP_TEST_VERBOSE:-0}
jobs=${BP_TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
if [ "$#" -eq 0 ]; then
    echo "run_all: no test programs given"
    echo "0 passed, 1 failed"
    exit 1
fi
mkdir -p "$logdir" || { echo "run_all: cannot create $logdir"; echo "0 passed, 1 failed"; exit 1; }
total_passed=0
total_failed=0
bad=()
start_all=$(date +%s%N)
secs_since() { awk -v a="$1" -v b="$(date +%s%N)" 'BEGIN { printf "%.1f", (b - a) / 1e9 }'; }

# Phase 1: start the programs, at most $jobs at a time, each in the
# background writing its output to its log and "<exit status> <seconds>"
# to a status file.  Phase 2 below reports them in the order given, so the
# output does not depend on which finishes first.
statusdir=$(mktemp -d "${TMPDIR:-/tmp}/bp_run_all.XXXXXX")
trap 'rm -rf "$statusdir"' EXIT
pids=()
k=0
for t in "$@"; do
    k=$((k + 1))
    pids+=("")
    [ -e "$t" ] || continue
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n 2>/dev/null || sleep 0.2; done
    (
        log="$logdir/$(basename "$t").log"
        t0=$(date +%s%N)
        case "$t" in
            *.sh) timeout "$per_test_timeout" bash "$t" </dev/null >"$log" 2>&1 ;;
            */*)  timeout "$per_test_timeout" "$t" </dev/null >"$log" 2>&1 ;;
            *)    timeout "$per_test_timeout" "./$t" </dev/null >"$log" 2>&1 ;;
        esac
        rc=$?
        echo "$rc $(secs_since "$t0")" > "$statusdir/$k"
    ) &
    pids[$((k - 1))]=$!
done

k=0
for t in "$@"; do
    k=$((k + 1))
    name=$(basename "$t")
    log="$logdir/$name.log"
    if [ ! -e "$t" ]; then
        printf '%-24s missing (%s does not exist): counted as 1 failed\n' "$name" "$t"
        total_failed=$((total_failed + 1)); bad+=("$t (missing)"); continue
    fi
    wait "${pids[$((k - 1))]}" 2>/dev/null
    read -r rc secs < "$statusdir/$k" || { rc=1; secs=0; }
    [ "$verbose" = 1 ] && cat "$log"
    line=$(grep -E '^BPTEST [0-9]+ [0-9]+$' "$log" | tail -n 1)
    why=""
    if [ -z "$line" ]; then
        if [ "$rc" -eq 124 ]; then why="timed out after ${per_test_timeout}s"; else why="exit status $rc, no BPTEST line"; fi
        p=0; f=1
    else
        p=$(echo "$line" | cut -d' ' -f2)
        f=$(echo "$line" | cut -d' ' -f3)
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
            # printed BPTEST with no failure but then crashed or returned an error
            why="exit status $rc after 'BPTEST $p 0'"; f=1
        fi
    fi
    printf '%-24s %5d passed %3d failed %7s s%s\n' "$name" "$p" "$f" "$secs" "${why:+  ($why: counted as 1 failed)}"
    if [ "$f" -gt 0 ]; then
        if [ "$verbose" != 1 ]; then
            echo "---- $t: full output (also in $log)"
            cat "$log"
            echo "---- end of $t"
        fi
        bad+=("$t (${why:-$f failed}; log $log)")
    fi
    total_passed=$((total_passed + p))
    total_failed=$((total_failed + f))
done

echo "($# programs in $(secs_since "$start_all") s; full outputs in $logdir/)"
if [ "${#bad[@]}" -gt 0 ]; then
    echo "Failing test programs:"
    for b in "${bad[@]}"; do echo "  $b"; done
fi
echo "$total_passed passed, $total_failed failed"
[ "$total_failed" -eq 0 ]
