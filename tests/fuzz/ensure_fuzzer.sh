#!/usr/bin/env bash
# Make sure clang can build libFuzzer harnesses (-fsanitize=fuzzer): clang
# itself and the libFuzzer runtime, which Debian ships in libclang-rt-N-dev
# (only a Recommends of clang, so `apt-get install --no-install-recommends
# clang` leaves it out).  As root with apt-get it installs what is missing;
# otherwise it prints the command and fails.  Used by `make fuzz`;
# tests/test_fuzz.sh does not install anything (it falls back to the
# standalone driver).
set -euo pipefail
cc=${FUZZ_CC:-clang}

works() {
    local dir; dir=$(mktemp -d)
    printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' > "$dir/t.c"
    "$cc" -fsanitize=fuzzer,address,undefined "$dir/t.c" -o "$dir/t" >/dev/null 2>&1
    local rc=$?
    rm -rf "$dir"
    return $rc
}

if command -v "$cc" >/dev/null 2>&1 && works; then exit 0; fi
pkgs="clang"
if command -v "$cc" >/dev/null 2>&1; then
    major=$("$cc" --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -n 1)
    [ -n "$major" ] && pkgs="libclang-rt-$major-dev"
fi
cmd="apt-get update && apt-get install -y --no-install-recommends $pkgs"
if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "ensure_fuzzer: $cc cannot build -fsanitize=fuzzer, running: $cmd"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update
    # shellcheck disable=SC2086
    apt-get install -y --no-install-recommends $pkgs
    if ! works && [ "$pkgs" = clang ]; then
        major=$("$cc" --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -n 1)
        apt-get install -y --no-install-recommends "libclang-rt-$major-dev"
    fi
    works || { echo "ensure_fuzzer: $cc -fsanitize=fuzzer still fails after the install" >&2; exit 1; }
    exit 0
fi
echo "ensure_fuzzer: $cc cannot build -fsanitize=fuzzer (libFuzzer missing)." >&2
echo "ensure_fuzzer: install it as root with:  sudo sh -c '$cmd'" >&2
exit 1
