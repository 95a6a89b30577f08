"""Shared fixtures of the Python package's tests, and the BPTEST line.

The tests import the `bijparam` found on sys.path: the in-place build
(make python; tests/test_python.sh sets PYTHONPATH=python) or an installed
package (tests/test_python_long.sh installs it into a fresh virtual
environment and runs the tests from outside the source tree).  Test meshes
come from the repository's tests/data.  Long cases carry the `long` marker
and run in make check.

At the end a line "BPTEST <passed> <failed>" is printed for
tests/run_all.sh; a skipped test counts as failed (no test is skipped
silently)."""
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.environ.get("BIJPARAM_TEST_ROOT") or os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.path.join(ROOT, "tests", "data")
TOOL = os.path.join(ROOT, "build", "bijparam")
sys.path.insert(0, os.path.dirname(__file__))      # independent.py


def pytest_configure(config):
    config.addinivalue_line("markers", "long: a long case, run by make check")


def pytest_terminal_summary(terminalreporter):
    st = terminalreporter.stats
    passed = len(st.get("passed", []))
    failed = len(st.get("failed", [])) + len(st.get("error", [])) + len(st.get("skipped", [])) + \
        len(st.get("xpassed", [])) + len(st.get("xfailed", []))
    terminalreporter.write_line(f"BPTEST {passed} {failed}")


@pytest.fixture(scope="package")
def data():
    return lambda name: os.path.join(DATA, name)


@pytest.fixture(scope="package")
def tool():
    assert os.access(TOOL, os.X_OK), f"{TOOL} is missing: make builds it (make test does)"
    return TOOL


def torus(n_major=48, n_minor=24, R=1.0, r=0.35):
    """A closed torus without seams: genus 1, every vertex shared."""
    i, j = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    u = 2 * np.pi * i / n_major
    v = 2 * np.pi * j / n_minor
    pos = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1).reshape(-1, 3)
    idx = lambda a, b: (a % n_major) * n_minor + (b % n_minor)
    faces = []
    for a in range(n_major):
        for b in range(n_minor):
            p, q, s, t = idx(a, b), idx(a + 1, b), idx(a + 1, b + 1), idx(a, b + 1)
            faces += [(p, q, s), (p, s, t)]
    return pos, np.array(faces, dtype=np.int64)


def grid(n=8, m=None, z=None):
    """A flat n x m grid of squares split into triangles, counter-clockwise."""
    m = m or n
    x, y = np.meshgrid(np.arange(n + 1), np.arange(m + 1), indexing="ij")
    pos = np.stack([x, y, np.zeros_like(x) if z is None else z(x, y)], -1).reshape(-1, 3).astype(np.float64)
    idx = lambda a, b: a * (m + 1) + b
    faces = []
    for a in range(n):
        for b in range(m):
            faces += [(idx(a, b), idx(a + 1, b), idx(a + 1, b + 1)), (idx(a, b), idx(a + 1, b + 1), idx(a, b + 1))]
    return pos, np.array(faces, dtype=np.int64)
