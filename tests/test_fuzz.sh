#!/usr/bin/env bash
# test_fuzz.sh - the fuzz harnesses (tests/fuzz/) as part of make check.
#
# 1. Always: each harness is compiled with the C compiler ($CC, default gcc)
#    and -fsanitize=address,undefined against tests/fuzz/standalone_main.c,
#    and fed its seed corpus plus FUZZ_MUTATIONS (default 300) deterministic
#    mutations of every seed.
# 2. If clang can build libFuzzer binaries (clang + libclang-rt-N-dev):
#    each harness is built with -fsanitize=fuzzer,address,undefined, run
#    over its seed corpus, then fuzzed for FUZZ_TEST_SECONDS (default 20)
#    from a scratch copy of the corpus (the fuzzers run side by side).
#    Without libFuzzer this part is skipped with a note and the standalone
#    run gets 10x the mutations instead.  (make fuzz installs libFuzzer and
#    fuzzes for longer.)
# Any sanitizer report, property violation (abort), leak or timeout fails.
# Prints "BPTEST <passed> <failed>" last (tests/run_all.sh).  Run from the
# repository root.
set -u
cc=${CC:-gcc}
mutations=${FUZZ_MUTATIONS:-300}
secs=${FUZZ_TEST_SECONDS:-20}
out=build/fuzz/test
mkdir -p "$out"
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_fuzz.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_fuzz.sh: $2"; fi
}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
san="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all"

have_libfuzzer=0
if command -v clang >/dev/null 2>&1; then
    printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' > "$out/probe.c"
    if clang -fsanitize=fuzzer,address,undefined "$out/probe.c" -o "$out/probe" >/dev/null 2>&1; then have_libfuzzer=1; fi
fi
[ "$have_libfuzzer" -eq 1 ] || mutations=$((mutations * 10))
elapsed() { awk -v a="$1" -v b="$(date +%s%N)" 'BEGIN { printf "%.2f", (b - a) / 1e9 }'; }

# Builds: bijparam.h is compiled once per compiler (tests/fuzz/bp_impl.c)
# and linked into each harness; the gcc and clang builds run side by side.
build_gcc() {
    $cc -std=c99 -Wall -Wextra -pedantic -Werror $san -I. -c tests/fuzz/bp_impl.c -o "$out/impl_gcc.o" || return 1
    for h in obj off ply pipeline gltf; do
        $cc -std=c99 -Wall -Wextra -pedantic -Werror $san -DBP_FUZZ_EXTERNAL_IMPL -I. -Itests/fuzz \
            tests/fuzz/fuzz_$h.c tests/fuzz/standalone_main.c "$out/impl_gcc.o" -o "$out/standalone_$h" -lm || return 1
    done
}
build_clang() {
    clang $san -fsanitize=fuzzer-no-link -I. -c tests/fuzz/bp_impl.c -o "$out/impl_clang.o" || return 1
    for h in obj off ply pipeline gltf; do
        clang $san -fsanitize=fuzzer -DBP_FUZZ_EXTERNAL_IMPL -I. -Itests/fuzz tests/fuzz/fuzz_$h.c \
            "$out/impl_clang.o" -o "$out/fuzz_$h" -lm || return 1
    done
}
t0=$(date +%s%N)
build_gcc > "$out/build_gcc.log" 2>&1 &
gpid=$!
if [ "$have_libfuzzer" -eq 1 ]; then build_clang > "$out/build_clang.log" 2>&1 & cpid=$!; fi
wait "$gpid"; grc=$?
[ "$grc" -ne 0 ] && cat "$out/build_gcc.log"
check "$grc" "$cc builds the 5 harnesses with standalone_main.c under ASan+UBSan"
if [ "$have_libfuzzer" -eq 1 ]; then
    wait "$cpid"; crc=$?
    [ "$crc" -ne 0 ] && cat "$out/build_clang.log"
    check "$crc" "clang builds the 5 libFuzzer harnesses (ASan+UBSan)"
    [ "$crc" -eq 0 ] || have_libfuzzer=0
fi
echo "     builds: $(elapsed "$t0") s"

if [ "$grc" -eq 0 ]; then
    for h in obj off ply pipeline gltf; do
        t0=$(date +%s%N)
        timeout 600 "$out/standalone_$h" -m "$mutations" "tests/fuzz/corpus/$h" > "$out/standalone_$h.log" 2>&1
        rc=$?
        n=$(sed -n 's/^standalone: \([0-9]*\) inputs/\1/p' "$out/standalone_$h.log")
        [ "$rc" -ne 0 ] && tail -n 30 "$out/standalone_$h.log"
        check "$rc" "standalone fuzz_$h: ${n:-?} inputs (seeds + $mutations mutations each), no sanitizer report or property violation ($(elapsed "$t0") s)"
    done
fi

if [ "$have_libfuzzer" -eq 1 ]; then
    pids=()
    for h in obj off ply pipeline gltf; do
        bin="$out/fuzz_$h"
        # the seed corpus, every file once (libFuzzer runs file arguments and exits)
        timeout 300 "$bin" -timeout=30 tests/fuzz/corpus/$h/* > "$out/fuzz_$h.corpus.log" 2>&1
        rc=$?
        [ "$rc" -ne 0 ] && tail -n 30 "$out/fuzz_$h.corpus.log"
        check "$rc" "libFuzzer fuzz_$h: the $(ls tests/fuzz/corpus/$h | wc -l) seed files pass"
        rm -rf "$out/corpus_$h" "$out/artifacts_$h"; mkdir -p "$out/corpus_$h" "$out/artifacts_$h"
        maxlen=4096; [ "$h" = gltf ] && maxlen=8192       # a .glb of two meshes is 6 KB
        timeout $((secs + 120)) "$bin" -max_total_time="$secs" -max_len=$maxlen -timeout=30 -rss_limit_mb=2048 \
            -seed=1 -print_final_stats=1 -artifact_prefix="$out/artifacts_$h/" \
            "$out/corpus_$h" "tests/fuzz/corpus/$h" > "$out/fuzz_$h.log" 2>&1 &
        pids+=("$!:$h")
    done
    for p in "${pids[@]}"; do
        pid=${p%%:*}; h=${p#*:}
        wait "$pid"; rc=$?
        runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/fuzz_$h.log" | tail -n 1)
        if [ "$rc" -ne 0 ]; then
            grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz property violated)' "$out/fuzz_$h.log" | head -n 5
            tail -n 20 "$out/fuzz_$h.log"
            echo "test_fuzz.sh: the input is in $out/artifacts_$h/"
        fi
        check "$rc" "libFuzzer fuzz_$h: ${secs}s, ${runs:-?} runs, no crash, leak or timeout"
    done
else
    echo "skip: clang's libFuzzer is not available (install libclang-rt-N-dev, or run make fuzz as root); ran the standalone driver with $mutations mutations per seed instead"
fi
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
