#!/usr/bin/env bash
# test_sanitizers.sh - the suite under the sanitizers, as part of make test.
#
#   make asan: every C/C++ test and the tool under AddressSanitizer +
#              UndefinedBehaviorSanitizer (leaks included);
#   make tsan: the tool with the thread pool, the thread_pool example and
#              tests/test_threads.c (1-8 threads) under ThreadSanitizer.
#
# Each is one check here; its own output is shown (the asan run prints its
# inner "N passed, M failed" line, which is not this suite's summary).
cd "$(dirname "$0")/.." || exit 1
pass=0
fail=0
for target in asan tsan; do
    log="build/sanitizers_$target.log"
    mkdir -p build
    if make --no-print-directory "$target" > "$log" 2>&1; then
        echo "ok   test_sanitizers.sh: make $target: $(grep -E '^[0-9]+ passed, [0-9]+ failed$|no data race|ran clean' "$log" | tr '\n' ' ')"
        pass=$((pass + 1))
    else
        tail -40 "$log"
        echo "FAIL test_sanitizers.sh: make $target failed (log: $log)"
        fail=$((fail + 1))
    fi
done
echo "BPTEST $pass $fail"
