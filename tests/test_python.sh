#!/usr/bin/env bash
# test_python.sh - the Python package's quick tests (python/tests without
# the `long` ones, about 20 s) against the in-place build of make python:
# parametrize on camel_b, spot and a closed torus, the tool's report and
# output byte for byte, dtypes and layouts, bad and random arrays, a
# callback's exception, two threads at once, Ctrl-C, and the batch on a
# LocalCluster of two processes.  pytest prints "BPTEST <passed> <failed>"
# last (python/tests/conftest.py).
set -u
cd "$(dirname "$0")/.." || exit 1
PYTHON=${PYTHON:-/usr/bin/python3}
PYTHONPATH=python exec "$PYTHON" -m pytest -q -m "not long" -p no:cacheprovider python/tests
