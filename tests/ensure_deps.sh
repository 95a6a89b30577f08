#!/usr/bin/env bash
# ensure_deps.sh - what `make test` and `make check` need, checked or installed.
#
#   ensure_deps.sh check test     (make test)  verify; if something is missing,
#   ensure_deps.sh check check    (make check) print what, why and the command
#                                 that installs it, and exit 1.  Never installs.
#   ensure_deps.sh install        (make deps)  install what `make test` and
#                                 `make check` need and is missing, with
#                                 apt-get, saying what and why first; as a
#                                 non-root user it prints the command instead.
#
# What each level needs (Debian package in brackets):
#   test:  a C and a C++ compiler [build-essential];
#          OpenMesh [libopenmesh-dev] (tests/test_openmesh.cpp cross-checks
#          against it); cmake [cmake], pkg-config [pkgconf] and python3
#          [python3] only when a tests/test_*.sh script uses them.
#   test:  also, for the Python package, Debian's python3 with its headers,
#          numpy, setuptools, pytest and Dask distributed [python3-dev,
#          python3-numpy, python3-setuptools, python3-pytest,
#          python3-distributed];
#   check: the above, plus clang [clang] (the compile matrix of
#          tests/test_compile.sh and the README example's builds use gcc
#          and clang), venv, pip and wheel [python3-venv, python3-pip,
#          python3-wheel] for the install test, plus the sanitizer runtimes of gcc (AddressSanitizer,
#          UndefinedBehaviorSanitizer, ThreadSanitizer) [libgcc-N-dev, part of
#          build-essential] for make asan / make tsan, clang's libFuzzer
#          [libclang-rt-N-dev, only a Recommends of clang] for tests/test_fuzz.sh,
#          and for tests/test_cross.sh the Windows and aarch64 cross
#          compilers and their runners [gcc-mingw-w64-x86-64, wine64,
#          gcc-aarch64-linux-gnu, libc6-dev-arm64-cross, qemu-user].
set -u
cd "$(dirname "$0")/.." || exit 1

mode=${1:-check}
level=${2:-check}
CC=${CC:-gcc}
CXX=${CXX:-g++}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/bp_deps.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

missing_pkgs=()
missing_why=()
need() {   # need PACKAGE WHY: record a missing package (once)
    local p
    for p in "${missing_pkgs[@]+"${missing_pkgs[@]}"}"; do [ "$p" = "$1" ] && return; done
    missing_pkgs+=("$1"); missing_why+=("$2")
}
compiles() {   # compiles COMPILER FLAGS...: a tiny program builds and runs
    local c=$1; shift
    printf 'int main(void) { return 0; }\n' > "$tmp/t.c"
    "$c" "$@" "$tmp/t.c" -o "$tmp/t" >/dev/null 2>&1 && "$tmp/t" >/dev/null 2>&1
}
major() { "$1" -dumpversion 2>/dev/null | cut -d. -f1; }

# ---- make test ----
command -v "$CC" >/dev/null 2>&1 || need build-essential "the C compiler ($CC) builds the library, the tool and the tests"
command -v "$CXX" >/dev/null 2>&1 || need build-essential "the C++ compiler ($CXX) builds tests/test_openmesh.cpp and the C++11 compile checks"
if [ ! -f /usr/include/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh ]; then
    need libopenmesh-dev "tests/test_openmesh.cpp cross-checks the mesh topology against OpenMesh (headers and libOpenMeshCore)"
fi
if grep -qlw cmake tests/test_*.sh 2>/dev/null && ! command -v cmake >/dev/null 2>&1; then
    need cmake "$(grep -lw cmake tests/test_*.sh | tr '\n' ' ')builds the library with CMake"
fi
if grep -qlw pkg-config tests/test_*.sh 2>/dev/null && ! command -v pkg-config >/dev/null 2>&1; then
    need pkgconf "$(grep -lw pkg-config tests/test_*.sh | tr '\n' ' ')checks the pkg-config file"
fi
if grep -qlw python3 tests/test_*.sh 2>/dev/null && ! command -v python3 >/dev/null 2>&1; then
    need python3 "$(grep -lw python3 tests/test_*.sh | tr '\n' ' ')runs the independent checker (python3)"
fi

# ---- the Python package (python/; tests/test_python.sh, test_python_long.sh) ----
# Debian's own interpreter: the extension is built on its C API and numpy's.
PY=${PYTHON:-/usr/bin/python3}
if [ -f tests/test_python.sh ]; then
    if ! command -v "$PY" >/dev/null 2>&1; then
        need python3 "tests/test_python.sh builds and tests the Python package with $PY"
    else
        pyinc=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])' 2>/dev/null)
        [ -f "$pyinc/Python.h" ] || need python3-dev "make python compiles the extension against Python.h"
        "$PY" -c 'import numpy' >/dev/null 2>&1 || need python3-numpy "the extension is built on numpy's C API"
        "$PY" -c 'import setuptools' >/dev/null 2>&1 || need python3-setuptools "make python builds the extension with setuptools"
        "$PY" -c 'import pytest' >/dev/null 2>&1 || need python3-pytest "tests/test_python.sh runs python/tests with pytest"
        "$PY" -c 'import distributed' >/dev/null 2>&1 || need python3-distributed "python -m bijparam.batch runs on Dask distributed (tested on a LocalCluster)"
    fi
fi

# ---- make check ----
if [ "$level" = check ] || [ "$mode" = install ]; then
    command -v clang >/dev/null 2>&1 || need clang "tests/test_compile.sh (in make check) checks that bijparam.h compiles warning-free with clang as well as gcc"
    if [ -f tests/test_python_long.sh ] && command -v "$PY" >/dev/null 2>&1; then
        "$PY" -c 'import ensurepip' >/dev/null 2>&1 || need python3-venv "tests/test_python_long.sh installs the package into a fresh virtual environment"
        "$PY" -m pip --version >/dev/null 2>&1 || need python3-pip "tests/test_python_long.sh runs pip install --no-build-isolation ./python"
        "$PY" -c 'import wheel' >/dev/null 2>&1 || need python3-wheel "pip builds the package's wheel with it (--no-build-isolation)"
    fi
    command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1 ||
        need gcc-mingw-w64-x86-64 "tests/test_cross.sh (in make check) builds the tool for Windows with mingw-w64"
    [ -x /usr/lib/wine/wine64 ] || command -v wine64 >/dev/null 2>&1 ||
        need wine64 "tests/test_cross.sh runs the Windows build under wine"
    command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 ||
        need gcc-aarch64-linux-gnu "tests/test_cross.sh builds the tool for aarch64"
    if command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 && ! aarch64-linux-gnu-gcc -static -x c - -o "$tmp/a" \
        >/dev/null 2>&1 <<<'int main(void) { return 0; }'; then
        need libc6-dev-arm64-cross "tests/test_cross.sh links the aarch64 build against the aarch64 C library"
    fi
    command -v qemu-aarch64 >/dev/null 2>&1 || need qemu-user "tests/test_cross.sh runs the aarch64 build under qemu-aarch64"
    if command -v "$CC" >/dev/null 2>&1; then
        if ! compiles "$CC" -fsanitize=address,undefined || ! compiles "$CC" -fsanitize=thread; then
            need "libgcc-$(major "$CC")-dev" "make asan / make tsan (in make check) link gcc's AddressSanitizer, UBSan and ThreadSanitizer runtimes"
        fi
    fi
    if command -v clang >/dev/null 2>&1; then
        printf 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' > "$tmp/f.c"
        if ! clang -fsanitize=fuzzer,address,undefined "$tmp/f.c" -o "$tmp/f" >/dev/null 2>&1; then
            need "libclang-rt-$(clang --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -n 1)-dev" \
                "tests/test_fuzz.sh (in make check) fuzzes with clang's libFuzzer, which Debian ships apart from clang"
        fi
    fi
fi

if [ "${#missing_pkgs[@]}" -eq 0 ]; then
    if [ "$mode" = install ]; then echo "deps: everything make test and make check need is installed"; fi
    exit 0
fi
cmd="apt-get update && apt-get install -y --no-install-recommends ${missing_pkgs[*]}"

if [ "$mode" = check ]; then
    {
        echo "deps: make $level needs packages that are not installed:"
        for i in "${!missing_pkgs[@]}"; do echo "  ${missing_pkgs[$i]}: ${missing_why[$i]}"; done
        echo "deps: nothing was installed. Install them with 'make deps' (as root), or:"
        echo "    sudo sh -c '$cmd'"
    } >&2
    exit 1
fi

if [ "$(id -u)" -ne 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    {
        echo "deps: make test / make check need packages that are not installed:"
        for i in "${!missing_pkgs[@]}"; do echo "  ${missing_pkgs[$i]}: ${missing_why[$i]}"; done
        echo "deps: installing needs root and apt-get (Debian); run this yourself:"
        echo "    sudo sh -c '$cmd'"
    } >&2
    exit 1
fi
echo "deps: installing ${missing_pkgs[*]} with apt-get (Debian), because:"
for i in "${!missing_pkgs[@]}"; do echo "  ${missing_pkgs[$i]}: ${missing_why[$i]}"; done
echo "deps: apt-get also installs what these depend on and may upgrade packages they need newer versions of; it lists them first."
export DEBIAN_FRONTEND=noninteractive
echo "deps: running: $cmd"
apt-get update || exit 1
# shellcheck disable=SC2068
apt-get install -y --no-install-recommends ${missing_pkgs[@]} || exit 1
# A clang installed just now may still lack its libFuzzer runtime: one more
# round installs it, then a plain check says whether anything is left.
if [ -z "${BP_DEPS_AGAIN:-}" ]; then BP_DEPS_AGAIN=1 exec bash "$0" install check; fi
exec bash "$0" check check
