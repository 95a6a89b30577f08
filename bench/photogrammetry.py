#!/usr/bin/env python3
"""bench/photogrammetry.py - a photogrammetry-like atlas case.

    python3 bench/photogrammetry.py OUT.obj [CHARTS]

writes a seamed OBJ whose charts look like those a photogrammetry pipeline
hands to a parameterizer: thousands of small curved pieces of surface of
very different sizes, some long and thin, some with a hole or two, and one
large piece riddled with holes (a wall or a facade with its windows, a
terrain with the gaps the cameras did not see).  CHARTS (default 4740) is
the number of charts, the large one included.  The file is the same bytes
on every run and every machine: the only randomness is a 64-bit linear
congruential generator with a fixed seed, and every number is written with
a fixed format.

The charts:

  the large one   a bumpy height field (hills, ripples and a crease where
                  a wall meets the ground) over a jittered grid, warped so
                  that its cells vary about 9x in width (a decimated scan),
                  inside a wavy star-shaped outline with a few lobes, with
                  50 holes cut where the cameras saw nothing: 70% star
                  polygons of radius 0.7-2.2 cells, 30% cracks (thin bent
                  ellipses 3-8 cells long), each the triangles whose
                  centroid lies inside it, at random places (a hole that
                  would pinch the boundary or merge with another is drawn
                  again).  4,601 faces, 51 boundary loops.
  the others      sizes from 2 to 200 faces, log-skewed towards the small
                  (log-uniform: f = 2 * 100^u, u uniform; median about 20,
                  mean about 47), of four kinds:
                    strip  up to 6 faces: a short triangle strip;
                    thin   (15% of the rest) a strip one or two quads wide
                           and up to 50 long, bent and twisted in 3D;
                    holed  (12% of those of 40 faces or more) a grid patch
                           with one or two interior quads removed;
                    blob   a grid patch of random aspect with a few corner
                           triangles nibbled off its outline;
                  each on a random quadric with a bump (z = a x^2 + b y^2 +
                  c xy + bump), so no chart is flat.

Each chart has its own vertices and texture vertices (vt = the patch's own
grid coordinates, a placeholder: the tool computes its own map), and every
chart is checked here to be connected, manifold without pinched vertices,
and of genus 0 with the intended number of boundary loops (V - E + F =
2 - b).  The charts lie side by side in 3D, 60 units apart.
"""
import math
import sys


class Rng:
    """64-bit LCG (Knuth's MMIX constants); uniform() from the top 53 bits."""

    def __init__(self, seed):
        self.s = seed & 0xFFFFFFFFFFFFFFFF

    def uniform(self, lo=0.0, hi=1.0):
        self.s = (self.s * 6364136223846793005 + 1442695040888963407) & 0xFFFFFFFFFFFFFFFF
        return lo + (hi - lo) * ((self.s >> 11) / float(1 << 53))

    def integer(self, lo, hi):
        """lo <= n <= hi."""
        return min(hi, lo + int(self.uniform() * (hi - lo + 1)))


def grid(nx, ny, rng, jitter=0.0, removed=()):
    """Vertices (i + dx, j + dy) of an nx x ny grid of quads and its
    triangles, each quad cut along a random diagonal; quads in `removed`
    are left out."""
    pts = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            inner = 0 < i < nx and 0 < j < ny
            dx = rng.uniform(-jitter, jitter) if inner else 0.0
            dy = rng.uniform(-jitter, jitter) if inner else 0.0
            pts.append((i + dx, j + dy))
    tris = []
    removed = set(removed)
    for j in range(ny):
        for i in range(nx):
            a, b = j * (nx + 1) + i, j * (nx + 1) + i + 1
            c, d = a + nx + 1, b + nx + 1
            flip = rng.uniform() < 0.5
            if (i, j) in removed:
                continue
            if flip:
                tris += [(a, b, d), (a, d, c)]
            else:
                tris += [(a, b, c), (b, d, c)]
    return pts, tris


def topology(tris):
    """(boundary loops, ok): ok when the triangles form one connected
    manifold surface with boundary, no pinched vertex, genus 0."""
    edges, bnext = {}, {}
    for t in tris:
        for k in range(3):
            e = (t[k], t[(k + 1) % 3])
            if e in edges:
                return 0, False
            edges[e] = True
    verts = set(v for t in tris for v in t)
    for (a, b) in edges:
        if (b, a) not in edges:
            if a in bnext:              # two boundary edges leave a: pinched
                return 0, False
            bnext[a] = b
    seen, loops = set(), 0
    for v in bnext:
        if v in seen:
            continue
        loops += 1
        while v not in seen:
            seen.add(v)
            v = bnext[v]
    parent = {v: v for v in verts}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for t in tris:
        parent[find(t[1])] = find(t[0])
        parent[find(t[2])] = find(t[0])
    if len(set(find(v) for v in verts)) != 1:
        return loops, False
    und = set((min(a, b), max(a, b)) for (a, b) in edges)
    chi = len(verts) - len(und) + len(tris)
    return loops, chi == 2 - loops and loops >= 1


def compact(pts, tris):
    """Drop unreferenced vertices, renumber."""
    used = sorted(set(v for t in tris for v in t))
    new = {v: k for k, v in enumerate(used)}
    return [pts[v] for v in used], [tuple(new[v] for v in t) for t in tris]


def big_outline(rng, R):
    """Triangles of a jittered grid inside a wavy star-shaped outline of
    mean radius R cells (with three long lobes), or None when the outline
    pinches."""
    n = int(2.6 * R) + 4
    pts, tris = grid(n, n, rng, jitter=0.2)
    c = n / 2.0
    w = [(rng.uniform(0.1, 0.25), rng.integer(2, 4), rng.uniform(0, 6.3)),
         (rng.uniform(0.05, 0.12), rng.integer(5, 9), rng.uniform(0, 6.3)),
         (rng.uniform(0.02, 0.06), rng.integer(11, 17), rng.uniform(0, 6.3))]

    def radius(th):
        return R * (1.0 + sum(a * math.sin(k * th + ph) for (a, k, ph) in w))
    keep = []
    for t in tris:
        x, y = centroid(pts, t)
        if math.hypot(x - c, y - c) < radius(math.atan2(y - c, x - c)):
            keep.append(t)
    loops, ok = topology(keep)
    return (pts, keep) if ok and loops == 1 else None


def hole_poly(rng, cx, cy):
    """A hole: a star polygon of radius 0.7-2.2 cells (70%) or a crack, a
    thin bent ellipse 3-8 cells long (30%)."""
    if rng.uniform() < 0.7:
        r0 = rng.uniform(0.7, 2.2)
        nv = rng.integer(5, 9)
        ph = rng.uniform(0, 2 * math.pi)
        return [(cx + r0 * rng.uniform(0.6, 1.0) * math.cos(ph + 2 * math.pi * k / nv),
                 cy + r0 * rng.uniform(0.6, 1.0) * math.sin(ph + 2 * math.pi * k / nv)) for k in range(nv)]
    L, W = rng.uniform(1.5, 4.0), rng.uniform(0.5, 0.9)
    ph, bend = rng.uniform(0, math.pi), rng.uniform(-0.25, 0.25)
    poly = []
    for k in range(16):
        th = 2 * math.pi * k / 16
        u, v = L * math.cos(th), W * math.sin(th)
        v += bend * u * u / L
        poly.append((cx + u * math.cos(ph) - v * math.sin(ph), cy + u * math.sin(ph) + v * math.cos(ph)))
    return poly


def big_chart(rng, target=4600, nholes=50):
    """About `target` faces with `nholes` holes (see the module's text)."""
    R = math.sqrt(target / (2 * math.pi)) * 1.08
    for attempt in range(100):
        got = big_outline(rng, R)
        if got is None:
            continue
        pts, tris = got
        if abs(len(tris) - target * 1.09) < 0.02 * target:
            break
        R *= math.sqrt(target * 1.09 / len(tris))
    else:
        raise RuntimeError("photogrammetry: no outline")
    xs = [centroid(pts, t) for t in tris]
    holes = 0
    while holes < nholes:
        cx, cy = xs[rng.integer(0, len(xs) - 1)]
        poly = hole_poly(rng, cx, cy)
        keep = [t for t in tris if not inside(poly, centroid(pts, t))]
        if len(keep) == len(tris):
            continue
        loops, ok = topology(keep)
        if ok and loops == holes + 2:
            tris = keep
            holes += 1
    pts, tris = compact(pts, tris)
    # graded like a decimated scan: the grid warped so that cells vary
    # about 9x in width across the chart
    Lx = max(p[0] for p in pts)
    pts = [(x + 0.8 * Lx / (2 * math.pi) * math.sin(2 * math.pi * x / Lx),
            y + 0.8 * Lx / (3 * math.pi) * math.sin(1.5 * math.pi * y / Lx + 0.7)) for (x, y) in pts]
    x0 = sum(p[0] for p in pts) / len(pts)

    def height(x, y):       # hills, ripples and a crease (a wall meeting the ground)
        return 3.0 * (1.5 * math.sin(0.21 * x) * math.cos(0.17 * y) + 0.6 * math.sin(0.9 * x + 0.4 * y)
                      + 0.35 * math.cos(1.3 * y - 0.5 * x) + 1.2 * max(0.0, x - x0))
    return [(x, y, height(x, y)) for (x, y) in pts], tris, holes + 1


def centroid(pts, t):
    return ((pts[t[0]][0] + pts[t[1]][0] + pts[t[2]][0]) / 3.0,
            (pts[t[0]][1] + pts[t[1]][1] + pts[t[2]][1]) / 3.0)


def inside(poly, p):
    """Point in a simple polygon (crossing number)."""
    x, y = p
    c = False
    n = len(poly)
    for k in range(n):
        (x0, y0), (x1, y1) = poly[k], poly[(k + 1) % n]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            c = not c
    return c


def quadric(rng, pts, size):
    """Lift planar patch points onto a random curved surface."""
    cx = sum(p[0] for p in pts) / len(pts)
    cy = sum(p[1] for p in pts) / len(pts)
    L = max(size, 1.0)
    a, b, c = rng.uniform(-0.8, 0.8) / L, rng.uniform(-0.8, 0.8) / L, rng.uniform(-0.5, 0.5) / L
    amp, fx, fy = rng.uniform(0.0, 0.15) * L, rng.uniform(0.5, 2.0) / L, rng.uniform(0.5, 2.0) / L
    out = []
    for (x, y) in pts:
        u, v = x - cx, y - cy
        out.append((x, y, a * u * u + b * v * v + c * u * v + amp * math.sin(6.0 * fx * u) * math.cos(6.0 * fy * v)))
    return out


def strip_chart(rng, f):
    """A triangle strip of f triangles: p_k = (k/2 + jitter, k mod 2)."""
    pts = [(0.5 * k + rng.uniform(-0.1, 0.1), float(k % 2)) for k in range(f + 2)]
    tris = [(k, k + 2, k + 1) if k % 2 == 0 else (k, k + 1, k + 2) for k in range(f)]
    return quadric(rng, pts, 0.5 * f + 1), tris, 1


def thin_chart(rng, f):
    rows = 1 if f < 24 or rng.uniform() < 0.6 else 2
    n = max(1, f // (2 * rows))
    w = rng.uniform(0.25, 1.0)
    pts, tris = grid(n, rows, rng, jitter=0.1)
    R = n / rng.uniform(0.5, 3.0)
    tau = rng.uniform(-0.15, 0.15)
    out = []
    for (x, y) in pts:
        th, yy = x / R, y * w
        out.append((R * math.sin(th), yy * math.cos(tau * x), R * (1 - math.cos(th)) + yy * math.sin(tau * x)))
    return out, tris, 1


def holed_chart(rng, f):
    nholes = 1 if f < 100 or rng.uniform() < 0.6 else 2
    cells = max(9, f // 2 + nholes)
    nx = max(3, int(round(math.sqrt(cells * rng.uniform(0.7, 1.4)))))
    ny = max(3, int(round(cells / nx)))
    removed = [(rng.integer(1, nx - 2), rng.integer(1, ny - 2))]
    if nholes == 2:
        for _ in range(20):
            c = (rng.integer(1, nx - 2), rng.integer(1, ny - 2))
            if abs(c[0] - removed[0][0]) >= 2 or abs(c[1] - removed[0][1]) >= 2:
                removed.append(c)
                break
    pts, tris = grid(nx, ny, rng, jitter=0.2, removed=removed)
    pts, tris = compact(pts, tris)
    return quadric(rng, pts, max(nx, ny)), tris, 1 + len(removed)


def blob_chart(rng, f):
    cells = max(1, (f + 1) // 2)
    aspect = rng.uniform(1.0, 3.0)
    nx = max(1, int(round(math.sqrt(cells * aspect))))
    ny = max(1, (cells + nx - 1) // nx)
    pts, tris = grid(nx, ny, rng, jitter=0.2)
    nibble = rng.integer(0, max(0, min(6, len(tris) // 8)))
    for _ in range(nibble):     # remove a triangle with two boundary edges
        es = set((u[k], u[(k + 1) % 3]) for u in tris for k in range(3))
        cand = [k for k, t in enumerate(tris)
                if sum((t[(i + 1) % 3], t[i]) not in es for i in range(3)) == 2]
        if not cand:
            break
        k = cand[rng.integer(0, len(cand) - 1)]
        keep = tris[:k] + tris[k + 1:]
        if topology(keep) == (1, True):
            tris = keep
    pts, tris = compact(pts, tris)
    return quadric(rng, pts, max(nx, ny)), tris, 1


def small_chart(rng):
    f = int(2 * 100 ** rng.uniform())
    kind = rng.uniform()
    if f <= 6:
        return strip_chart(rng, f)
    if kind < 0.15:
        return thin_chart(rng, f)
    if f >= 40 and kind < 0.15 + 0.12:
        return holed_chart(rng, f)
    return blob_chart(rng, f)


def write(path, nchart=4740, seed=20261123):
    rng = Rng(seed)
    charts = [big_chart(rng)] + [small_chart(rng) for _ in range(nchart - 1)]
    nv = 0
    vlines, flines = [], []
    for k, (pts, tris, loops) in enumerate(charts):
        got, ok = topology(tris)
        if not ok or got != loops:
            raise RuntimeError("photogrammetry: chart %d has %d loops (want %d), ok %s" % (k, got, loops, ok))
        ox, oy = 60.0 * (k % 80), 60.0 * (k // 80)
        for (x, y, z) in pts:
            vlines.append("v %.6f %.6f %.6f\n" % (x + ox, y + oy, z))
        for (x, y, z) in pts:
            vlines.append("vt %.6f %.6f\n" % (x / 64.0, y / 64.0))
        for t in tris:
            a, b, c = t[0] + nv + 1, t[1] + nv + 1, t[2] + nv + 1
            flines.append("f %d/%d %d/%d %d/%d\n" % (a, a, b, b, c, c))
        nv += len(pts)
    # vertices and texture vertices interleaved per chart above would break
    # the one-to-one numbering: write all v first, then all vt
    with open(path, "w") as out:
        out.write("# bench/photogrammetry.py: %d charts, %d faces\n" % (len(charts), len(flines)))
        out.writelines(l for l in vlines if l.startswith("v "))
        out.writelines(l for l in vlines if l.startswith("vt "))
        out.writelines(flines)
    return len(charts), len(flines), charts[0]


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.stderr.write("usage: photogrammetry.py OUT.obj [CHARTS]\n")
        sys.exit(2)
    n, nf, big = write(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 4740)
    print("%s: %d charts, %d faces; the large chart %d faces, %d boundary loops"
          % (sys.argv[1], n, nf, len(big[1]), big[2]))
