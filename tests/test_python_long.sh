#!/usr/bin/env bash
# test_python_long.sh - the Python package's long runs (make check):
#   1. the extension built with AddressSanitizer and UndefinedBehaviorSanitizer
#      (build/python-asan), its tests run with gcc's libasan preloaded into
#      the interpreter (ASAN_OPTIONS=detect_leaks=0: the interpreter keeps
#      its own memory to the end);
#   1b. the same with ThreadSanitizer, on the tests of progress, Ctrl-C,
#      two threads and writing;
#   2. the `long` tests: the batch restarted over damaged outputs, a worker
#      killed mid-run, more random and adversarial arrays;
#   3. a fresh virtual environment of Debian's python3 with the system's
#      numpy (venv --system-site-packages), `pip install --no-build-isolation
#      ./python` offline (PIP_NO_INDEX) from a copy of the repository, and
#      the quick tests run from outside the source tree against the
#      installed package.
# Prints one ok/FAIL line per step and "BPTEST <passed> <failed>" (the
# tests' counts added up).
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT" || exit 1
PYTHON=${PYTHON:-/usr/bin/python3}
BUILD=${BUILD:-build}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_python.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_python_long.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_python_long.sh: $*"; failed=$((failed + 1)); }
# run_pytest LABEL LOG COMMAND...: a pytest run, its BPTEST counts added
run_pytest() {
    local label=$1 log=$2 line p f
    shift 2
    "$@" >"$log" 2>&1
    line=$(grep -E '^BPTEST [0-9]+ [0-9]+$' "$log" | tail -n 1)
    if [ -z "$line" ]; then
        cat "$log"; fail "$label: no BPTEST line (see above)"; return
    fi
    p=$(echo "$line" | cut -d' ' -f2); f=$(echo "$line" | cut -d' ' -f3)
    passed=$((passed + p)); failed=$((failed + f))
    if [ "$f" -gt 0 ]; then cat "$log"; echo "FAIL test_python_long.sh: $label: $f failed"; else echo "ok   test_python_long.sh: $label: $p passed"; fi
}

# sanitized_ext DIR CFLAGS: the package with its extension built with CFLAGS
# in DIR/bijparam (the build's log in $TMP/$(basename DIR).log)
sanitized_ext() {
    local dir=$1 flags=$2
    mkdir -p "$dir/bijparam"
    (cd python && BIJPARAM_CFLAGS="-g -O1 -fno-omit-frame-pointer $flags" \
        "$PYTHON" setup.py -q build_ext --build-temp "$ROOT/$dir/temp" --build-lib "$ROOT/$dir/lib") \
        >"$TMP/$(basename "$dir").log" 2>&1 &&
    cp python/bijparam/*.py "$dir/bijparam/" && cp "$dir"/lib/bijparam/_native*.so "$dir/bijparam/"
}

# 1. AddressSanitizer + UBSan
ASAN_DIR=$BUILD/python-asan
if sanitized_ext "$ASAN_DIR" "-fsanitize=address,undefined -fno-sanitize-recover=all"; then
    ok "the extension built with -fsanitize=address,undefined"
    LIBASAN=$(gcc -print-file-name=libasan.so)
    run_pytest "python/tests under AddressSanitizer" "$TMP/asan.log" \
        env PYTHONPATH="$ASAN_DIR" LD_PRELOAD="$LIBASAN" ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
        "$PYTHON" -m pytest -q -p no:cacheprovider python/tests/test_parametrize.py python/tests/test_robust.py
else
    cat "$TMP/python-asan.log"; fail "the AddressSanitizer build of the extension"
fi

# 1b. ThreadSanitizer: the worker thread, the calling thread's wait and the
#     progress handed between them (atomics), two calls on two threads;
#     any report ends the run (no BPTEST line: a failure)
TSAN_DIR=$BUILD/python-tsan
if sanitized_ext "$TSAN_DIR" "-fsanitize=thread"; then
    ok "the extension built with -fsanitize=thread"
    run_pytest "progress, Ctrl-C and two threads under ThreadSanitizer" "$TMP/tsan.log" \
        env PYTHONPATH="$TSAN_DIR" LD_PRELOAD="$(gcc -print-file-name=libtsan.so)" TSAN_OPTIONS=halt_on_error=1:exitcode=66 \
        "$PYTHON" -m pytest -s -q -p no:cacheprovider python/tests/test_parametrize.py python/tests/test_robust.py \
        -k "progress or threads or ctrl_c or write"
else
    cat "$TMP/python-tsan.log"; fail "the ThreadSanitizer build of the extension"
fi

# 2. the long tests
run_pytest "the long tests" "$TMP/long.log" env PYTHONPATH=python "$PYTHON" -m pytest -q -m long -p no:cacheprovider python/tests

# 3. pip install into a fresh virtual environment, offline
mkdir -p "$TMP/repo"
mkdir -p "$TMP/repo/examples" && cp examples/bp_gltf.h "$TMP/repo/examples/" &&
cp bijparam.h "$TMP/repo/" && cp -r python "$TMP/repo/python" && rm -rf "$TMP/repo/python/build" "$TMP/repo/python"/*.egg-info \
    "$TMP/repo/python/bijparam"/*.so
if "$PYTHON" -m venv --system-site-packages "$TMP/venv" >"$TMP/venv.log" 2>&1; then
    ok "python3 -m venv --system-site-packages"
else
    cat "$TMP/venv.log"; fail "python3 -m venv --system-site-packages (Debian: python3-venv)"
fi
if (cd "$TMP/repo" && PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 "$TMP/venv/bin/pip" install --no-build-isolation ./python) \
        >"$TMP/pip.log" 2>&1; then
    ok "pip install --no-build-isolation ./python (offline, the system's numpy)"
else
    tail -30 "$TMP/pip.log"; fail "pip install --no-build-isolation ./python"
fi
where=$(cd "$TMP" && "$TMP/venv/bin/python" -c 'import bijparam, os; print(os.path.dirname(bijparam.__file__))' 2>&1)
case "$where" in
    "$TMP/venv/"*) ok "bijparam imports from the virtual environment ($where)" ;;
    *) fail "bijparam does not import from the virtual environment: $where" ;;
esac
cp -r python/tests "$TMP/tests"
run_pytest "the quick tests against the installed package" "$TMP/installed.log" \
    env -u PYTHONPATH BIJPARAM_TEST_ROOT="$ROOT" "$TMP/venv/bin/python" -m pytest -q -m "not long" -p no:cacheprovider \
    --rootdir "$TMP" "$TMP/tests"

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
