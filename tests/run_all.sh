#!/usr/bin/env bash
# Run every test program given on the command line (binaries, or tests/*.sh
# scripts run with bash), show its output, and add up the "BPTEST <passed>
# <failed>" line each one prints last.  A program that crashes, times out or
# prints no BPTEST line counts as 1 failed.  Ends with "N passed, M failed"
# and exits 1 when M > 0.  Run it from the repository root (the tests open
# tests/data/... by relative path).
set -u

per_test_timeout=${BP_TEST_TIMEOUT:-600}
if [ "$#" -eq 0 ]; then
    echo "run_all: no test programs given"
    echo "0 passed, 1 failed"
    exit 1
fi
total_passed=0
total_failed=0
bad=()

for t in "$@"; do
    [ -e "$t" ] || { echo "run_all: $t does not exist"; total_failed=$((total_failed + 1)); bad+=("$t (missing)"); continue; }
    echo "== $t"
    out=$(mktemp)
    case "$t" in
        *.sh) timeout "$per_test_timeout" bash "$t" >"$out" 2>&1 ;;
        */*)  timeout "$per_test_timeout" "$t" >"$out" 2>&1 ;;
        *)    timeout "$per_test_timeout" "./$t" >"$out" 2>&1 ;;
    esac
    rc=$?
    cat "$out"
    line=$(grep -E '^BPTEST [0-9]+ [0-9]+$' "$out" | tail -n 1)
    rm -f "$out"
    if [ -z "$line" ]; then
        if [ "$rc" -eq 124 ]; then why="timed out after ${per_test_timeout}s"; else why="exit status $rc, no BPTEST line"; fi
        echo "run_all: $t: $why: counted as 1 failed"
        total_failed=$((total_failed + 1)); bad+=("$t ($why)")
        continue
    fi
    p=$(echo "$line" | cut -d' ' -f2)
    f=$(echo "$line" | cut -d' ' -f3)
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        # printed BPTEST with no failure but then crashed or returned an error
        echo "run_all: $t: exit status $rc after 'BPTEST $p 0': counted as 1 failed"
        f=1; bad+=("$t (exit status $rc)")
    elif [ "$f" -gt 0 ]; then
        bad+=("$t ($f failed)")
    fi
    total_passed=$((total_passed + p))
    total_failed=$((total_failed + f))
done

echo
if [ "${#bad[@]}" -gt 0 ]; then
    echo "Failing test programs:"
    for b in "${bad[@]}"; do echo "  $b"; done
fi
echo "$total_passed passed, $total_failed failed"
[ "$total_failed" -eq 0 ]
