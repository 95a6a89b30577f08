#!/usr/bin/env python3
"""Large charts for the scaling benchmark (make bench-scale).

    python3 bench/subdivide.py IN.(obj|off) N OUT.obj [--bump A]

Splits every triangle of IN into N x N similar triangles: each edge is cut
into N equal segments and the triangle into the grid of points

    P(i, j) = a + (i/N)(b - a) + (j/N)(c - a),   i, j >= 0, i + j <= N,

with N*N triangles per input triangle (N = 2 is the usual 1-to-4 midpoint
subdivision; N = 2^k is k rounds of it).  The points on an edge are shared
by the two triangles of that edge, so a disk stays a disk with the same
boundary loops and every orientation is kept: F' = N^2 F,
V' = V + (N - 1) E + (N - 1)(N - 2)/2 F.

Flat subdivision alone would be too easy (every small triangle similar to
its parent, the optimum the old map refined), so every new point moves
along the interpolated vertex normal by  A * h * noise(id),  where h is
the input's mean edge length divided by N, id the new vertex's number and
noise() an integer hash mapped to [-1, 1].  The default A = 0.05 keeps the
triangles close to their parents' shape (no fold, no sliver) while no two
are exactly alike.  Everything is a function of the input and N: the
output file is the same bytes on every run and machine (no random seed,
no dictionary order that varies: Python's dicts keep insertion order).

Only 'v' and 'f' lines are read (an OBJ face's first index of each
'v/vt/vn' group, negative indices allowed; OFF with or without CRLF);
polygons are fanned into triangles.  The output has no vt: the tool
computes the map from scratch.
"""
import math
import sys


def read_mesh(path):
    verts, faces = [], []
    with open(path, "r", encoding="latin-1") as fh:
        if path.lower().endswith(".off"):
            toks = fh.read().split()
            if not toks or not toks[0].upper().endswith("OFF"):
                raise SystemExit("%s: not an OFF file" % path)
            nv, nf = int(toks[1]), int(toks[2])
            k = 4
            for _ in range(nv):
                verts.append((float(toks[k]), float(toks[k + 1]), float(toks[k + 2])))
                k += 3
            for _ in range(nf):
                m = int(toks[k])
                poly = [int(t) for t in toks[k + 1:k + 1 + m]]
                k += 1 + m
                for t in range(1, m - 1):
                    faces.append((poly[0], poly[t], poly[t + 1]))
            return verts, faces
        for line in fh:
            if line.startswith("v "):
                p = line.split()
                verts.append((float(p[1]), float(p[2]), float(p[3])))
            elif line.startswith("f "):
                poly = []
                for g in line.split()[1:]:
                    i = int(g.split("/")[0])
                    poly.append(i - 1 if i > 0 else len(verts) + i)
                for t in range(1, len(poly) - 1):
                    faces.append((poly[0], poly[t], poly[t + 1]))
    return verts, faces


def vertex_normals(verts, faces):
    """Area-weighted vertex normals (the sum of the faces' cross products)."""
    nrm = [[0.0, 0.0, 0.0] for _ in verts]
    for a, b, c in faces:
        pa, pb, pc = verts[a], verts[b], verts[c]
        u = (pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2])
        v = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        for i in (a, b, c):
            nrm[i][0] += n[0]
            nrm[i][1] += n[1]
            nrm[i][2] += n[2]
    return nrm


def noise(i):
    """An integer hash of i (a 32-bit finalizer) mapped to [-1, 1]."""
    h = (i * 0x9E3779B1 + 0x7F4A7C15) & 0xFFFFFFFF
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & 0xFFFFFFFF
    h ^= h >> 16
    return h / 2147483647.5 - 1.0


def subdivide(verts, faces, n, bump):
    nv0 = len(verts)
    el, ne = 0.0, 0
    for f in faces:
        for k in range(3):
            p, q = verts[f[k]], verts[f[(k + 1) % 3]]
            el += math.sqrt((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2)
            ne += 1
    h = el / max(ne, 1) / n
    nrm = vertex_normals(verts, faces)
    out = list(verts)
    edge_pts = {}   # (lo, hi) -> ids of the n-1 points from lo to hi

    def new_point(wa, wb, wc, a, b, c):
        pa, pb, pc = verts[a], verts[b], verts[c]
        na, nb, nc = nrm[a], nrm[b], nrm[c]
        p = [wa * pa[k] + wb * pb[k] + wc * pc[k] for k in range(3)]
        d = [wa * na[k] + wb * nb[k] + wc * nc[k] for k in range(3)]
        dl = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        s = bump * h * noise(len(out)) / dl if dl > 0 else 0.0
        out.append((p[0] + s * d[0], p[1] + s * d[1], p[2] + s * d[2]))
        return len(out) - 1

    def edge_points(u, v, w):
        """Ids of the n-1 points on edge u->v (w: the face's third corner,
        only for the normal interpolation's weights, which it does not get)."""
        lo, hi = (u, v) if u < v else (v, u)
        ids = edge_pts.get((lo, hi))
        if ids is None:
            ids = [new_point(1 - k / n, k / n, 0.0, lo, hi, w) for k in range(1, n)]
            edge_pts[(lo, hi)] = ids
        return ids if lo == u else ids[::-1]

    tris = []
    for a, b, c in faces:
        # grid[i][j] = id of P(i, j)
        grid = [[-1] * (n + 1 - i) for i in range(n + 1)]
        grid[0][0], grid[n][0], grid[0][n] = a, b, c
        ab, ac, bc = edge_points(a, b, c), edge_points(a, c, b), edge_points(b, c, a)
        for k in range(1, n):
            grid[k][0] = ab[k - 1]
            grid[0][k] = ac[k - 1]
            grid[n - k][k] = bc[k - 1]
        for i in range(1, n):
            for j in range(1, n - i):
                grid[i][j] = new_point(1 - (i + j) / n, i / n, j / n, a, b, c)
        for i in range(n):
            for j in range(n - i):
                tris.append((grid[i][j], grid[i + 1][j], grid[i][j + 1]))
                if i + j < n - 1:
                    tris.append((grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]))
    assert len(tris) == n * n * len(faces)
    return out, tris, nv0


def write_obj(path, verts, tris, comment):
    with open(path, "w") as fh:
        fh.write("# %s\n" % comment)
        fh.write("".join("v %.9g %.9g %.9g\n" % p for p in verts))
        fh.write("".join("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1) for t in tris))


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    bump = 0.05
    if "--bump" in argv:
        bump = float(argv[argv.index("--bump") + 1])
        args.remove(argv[argv.index("--bump") + 1])
    if len(args) != 3:
        raise SystemExit(__doc__.split("\n\n")[1])
    src, n, dst = args[0], int(args[1]), args[2]
    if n < 1:
        raise SystemExit("N must be >= 1")
    verts, faces = read_mesh(src)
    out, tris, _ = subdivide(verts, faces, n, bump)
    write_obj(dst, out, tris, "bench/subdivide.py %s %d --bump %g: %d vertices, %d faces"
              % (src.split("/")[-1], n, bump, len(out), len(tris)))
    print("%s: %d vertices, %d faces" % (dst, len(out), len(tris)))


if __name__ == "__main__":
    main(sys.argv)
