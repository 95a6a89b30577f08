#!/usr/bin/env bash
# run_fuzzers.sh SECONDS FUZZER...  (make fuzz)
#
# Runs every libFuzzer binary for SECONDS, all at once (one process each),
# from the repository root.  Each fuzzer NAME (build/fuzz/fuzz_NAME) grows
# its own corpus in build/fuzz/corpus/NAME, seeded from tests/fuzz/corpus/NAME
# (read only: new inputs never land in the repository), and writes crashes,
# leaks and timeouts to build/fuzz/artifacts/NAME-*.  Logs: build/fuzz/NAME.log.
# Prints one summary line per fuzzer and exits 1 if any of them found a
# problem.  Extra libFuzzer flags: FUZZ_FLAGS="...".
set -u
secs=${1:?usage: run_fuzzers.sh SECONDS FUZZER...}
shift
root=build/fuzz
mkdir -p "$root/artifacts"
pids=()
names=()
for f in "$@"; do
    name=$(basename "$f"); name=${name#fuzz_}
    mkdir -p "$root/corpus/$name"
    echo "fuzz: $f for ${secs}s (corpus $root/corpus/$name + tests/fuzz/corpus/$name)"
    maxlen=4096; [ "$name" = gltf ] && maxlen=8192      # a .glb of two meshes is 6 KB
    # shellcheck disable=SC2086
    "$f" -max_total_time="$secs" -max_len=$maxlen -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$root/artifacts/$name-" ${FUZZ_FLAGS:-} \
        "$root/corpus/$name" "tests/fuzz/corpus/$name" >"$root/$name.log" 2>&1 &
    pids+=($!)
    names+=("$name")
done
bad=0
for i in "${!pids[@]}"; do
    wait "${pids[$i]}"; rc=$?
    name=${names[$i]}
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$root/$name.log" | tail -n 1)
    cov=$(grep -o 'cov: [0-9]*' "$root/$name.log" | tail -n 1)
    corp=$(ls "$root/corpus/$name" | wc -l)
    if [ "$rc" -ne 0 ]; then
        bad=1
        echo "fuzz: $name: FAILED (exit $rc) after ${runs:-?} runs; see $root/$name.log and $root/artifacts/$name-*"
        grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz property violated)' "$root/$name.log" | head -n 5
    else
        echo "fuzz: $name: ok, ${runs:-?} runs in ${secs}s, $cov, corpus $corp files"
    fi
done
exit $bad
