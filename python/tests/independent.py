"""The properties of an atlas the tests prove without the library.

bijective() hands the map to tests/uvcheck.py, the project's own exact
checker of UV maps, which shares no code with bijparam.h (its docstring
says what it checks and why that suffices); components() and chart_gap()
measure how far apart the packer put the charts.
"""
import importlib.util
import os
from collections import defaultdict

import numpy as np

from conftest import ROOT

_spec = importlib.util.spec_from_file_location("uvcheck", os.path.join(ROOT, "tests", "uvcheck.py"))
uvcheck = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(uvcheck)


def bijective(uvs, tris):
    """(True, "") when the map -- uvs (K, 2), triangles (T, 3) into them,
    counter-clockwise when valid -- is bijective, else (False, the faults)."""
    vts = [tuple(p) for p in np.asarray(uvs, dtype=np.float64).tolist()]
    T = [((a, a), (b, b), (c, c), k) for k, (a, b, c) in enumerate(np.asarray(tris, dtype=np.int64).tolist())]
    rep = uvcheck.Report(3)
    uvcheck.check_map(vts, T, rep)
    return not rep.counts, "" if not rep.counts else f"{rep.counts} {rep.examples}"


def _grid_pairs(lo, hi, cell):
    """Pairs (i, j), i < j, of boxes [lo, hi] sharing a grid cell."""
    buckets = defaultdict(list)
    a = np.floor(lo / cell).astype(np.int64)
    b = np.floor(hi / cell).astype(np.int64)
    for i in range(len(lo)):
        for x in range(a[i, 0], b[i, 0] + 1):
            for y in range(a[i, 1], b[i, 1] + 1):
                buckets[(x, y)].append(i)
    pairs = set()
    for items in buckets.values():
        for k in range(len(items)):
            for m in range(k + 1, len(items)):
                pairs.add((items[k], items[m]))
    return pairs


def components(tris, n):
    """The connected piece (chart) of each of n vertices, by shared vertices."""
    parent = np.arange(n)

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b, c in np.asarray(tris).tolist():
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    return np.array([find(v) for v in range(n)])


def chart_gap(uvs, tris, reach):
    """The least distance between boundary edges of different charts, when
    below `reach` (else inf): the padding the packer left."""
    uvs = np.asarray(uvs, dtype=np.float64)
    tris = np.asarray(tris, dtype=np.int64)
    label = components(tris, len(uvs))
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    n = len(uvs)
    key = directed[:, 0] * n + directed[:, 1]
    rev = directed[:, 1] * n + directed[:, 0]
    boundary = directed[~np.isin(rev, key)]
    lo = np.minimum(uvs[boundary[:, 0]], uvs[boundary[:, 1]]) - reach / 2
    hi = np.maximum(uvs[boundary[:, 0]], uvs[boundary[:, 1]]) + reach / 2
    cell = max(float(np.median(hi - lo)) * 2, reach)
    best = np.inf

    def pd(p, a, b):
        ab = b - a
        t = np.clip(np.dot(p - a, ab) / max(np.dot(ab, ab), 1e-300), 0, 1)
        return np.linalg.norm(p - (a + t * ab))

    for i, j in _grid_pairs(lo, hi, cell):
        (p, q), (r, s) = boundary[i], boundary[j]
        if label[p] == label[r] or (hi[i] < lo[j]).any() or (hi[j] < lo[i]).any():
            continue
        d = min(pd(uvs[p], uvs[r], uvs[s]), pd(uvs[q], uvs[r], uvs[s]),
                pd(uvs[r], uvs[p], uvs[q]), pd(uvs[s], uvs[p], uvs[q]))
        best = min(best, d)
    return best
