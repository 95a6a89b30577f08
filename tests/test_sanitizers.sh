#!/usr/bin/env bash
# test_sanitizers.sh - the suite under the sanitizers, as part of make check.
#
#   make asan: every C/C++ test and the tool under AddressSanitizer +
#              UndefinedBehaviorSanitizer (leaks included);
#   make tsan: the tool with the thread pool, the thread_pool example and
#              tests/test_threads.c (quick mode) under ThreadSanitizer.
#
# The counts of the test programs run inside (asan's "N passed, M failed",
# test_threads' BPTEST under tsan) are added to this script's own; each
# target is one more check (it built and ran to the end).  Full logs:
# build/sanitizers_asan.log, build/sanitizers_tsan.log and the per-program
# logs in build/asan/logs/.
cd "$(dirname "$0")/.." || exit 1
pass=0
fail=0
for target in asan tsan; do
    log="build/sanitizers_$target.log"
    mkdir -p build
    rm -f build/tsan/test_threads.log   # no stale count from an earlier run
    make --no-print-directory "$target" > "$log" 2>&1
    rc=$?
    if [ "$target" = asan ]; then
        inner=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$log" | tail -n 1)
    else
        inner=$(tail -n 20 build/tsan/test_threads.log 2>/dev/null | grep -E '^BPTEST [0-9]+ [0-9]+$' | tail -n 1 | sed 's/^BPTEST \([0-9]*\) \([0-9]*\)$/\1 passed, \2 failed/')
    fi
    if [ -n "$inner" ]; then
        pass=$((pass + $(echo "$inner" | cut -d' ' -f1)))
        fail=$((fail + $(echo "$inner" | cut -d' ' -f3)))
    fi
    if [ "$rc" -eq 0 ]; then
        echo "ok   test_sanitizers.sh: make $target: ${inner:+tests inside: $inner; }$(grep -E 'no data race|ran clean' "$log" | tr '\n' ' ')"
        pass=$((pass + 1))
    else
        tail -60 "$log"
        echo "FAIL test_sanitizers.sh: make $target failed${inner:+ (tests inside: $inner)} (log: $log)"
        fail=$((fail + 1))
    fi
done
echo "BPTEST $pass $fail"
