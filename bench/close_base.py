#!/usr/bin/env python3
"""Close a mesh's boundary loops by fans: python3 bench/close_base.py IN.obj OUT.obj

Every boundary loop (edges used by one triangle) gets a new vertex at the
mean of its vertices and a fan of triangles to it, oriented like the rest
of the mesh, so that a disk-like scan becomes a closed surface (the closed
bimba of the atlas bench: bimba_i.obj, open at its base, becomes a closed
genus-0 surface of 89,590 triangles).  Only v and f are written (vt, vn
dropped)."""
import sys


def main(src, dst):
    V, F = [], []
    for line in open(src):
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            V.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            idx = [int(q.split("/")[0]) for q in p[1:]]
            idx = [i - 1 if i > 0 else len(V) + i for i in idx]
            for k in range(1, len(idx) - 1):
                F.append((idx[0], idx[k], idx[k + 1]))
    use = {}
    for a, b, c in F:
        for e in ((a, b), (b, c), (c, a)):
            use[e] = use.get(e, 0) + 1
    nxt = {a: b for (a, b) in use if (b, a) not in use}
    seen = set()
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = nxt[v]
        c = len(V)
        V.append([sum(V[i][k] for i in loop) / len(loop) for k in range(3)])
        for i in range(len(loop)):
            a, b = loop[i], loop[(i + 1) % len(loop)]
            F.append((b, a, c))          # the edge a->b is used the other way
    with open(dst, "w") as out:
        for v in V:
            out.write("v %.17g %.17g %.17g\n" % tuple(v))
        for f in F:
            out.write("f %d %d %d\n" % (f[0] + 1, f[1] + 1, f[2] + 1))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
