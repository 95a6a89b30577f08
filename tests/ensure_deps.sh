#!/usr/bin/env bash
# Make sure what the tests need is installed: the OpenMesh headers and library
# (Debian package libopenmesh-dev) used by tests/test_openmesh.cpp.
# As root it installs them with apt-get; otherwise it prints the command and fails.
set -euo pipefail

header=/usr/include/OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh
cmd="apt-get update && apt-get install -y libopenmesh-dev"

if [ -f "$header" ]; then
    exit 0
fi
if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "ensure_deps: OpenMesh headers missing, running: $cmd"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update
    apt-get install -y libopenmesh-dev
    [ -f "$header" ] || { echo "ensure_deps: $header still missing after install" >&2; exit 1; }
    exit 0
fi
echo "ensure_deps: OpenMesh headers missing ($header)." >&2
echo "ensure_deps: install them as root with:" >&2
echo "    sudo sh -c '$cmd'" >&2
exit 1
