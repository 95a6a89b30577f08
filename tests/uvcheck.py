#!/usr/bin/env python3
"""uvcheck.py - an exact check that a UV map (OBJ with vt) is bijective.

    python3 tests/uvcheck.py [--json] [--allow-reorient] [--examples N]
                             OUT.obj [REFERENCE.obj|.off]

Exit status 0 when the map is bijective (and matches REFERENCE), 1 when it
is not, 2 when a file cannot be read.  Python's standard library only; it
shares no code with bijparam.h, so the tests use it as a second opinion.

What is checked, every sign decided exactly
-------------------------------------------
Triangles are the faces (polygons fanned from their first corner); a chart
is a connected set of triangles, two triangles being adjacent when they
share an edge of vt indices.

 1. Every UV triangle is finite and positively oriented (a zero area counts
    as bad, a mirrored chart has every triangle bad).
 2. Every vt edge belongs to at most two triangles, and to two only with
    opposite directions.
 3. The triangles around each vt form one fan: a cycle (an inner vertex)
    whose angles add up to exactly 2 pi, or a chain (a boundary vertex)
    whose angles add up to less than 2 pi.
 4. No two boundary edges (vt edges of one triangle) meet, in one chart or
    in two, except two edges of one chart at the vt they share; touching
    and collinear overlap count.
 5. No chart lies inside another: one point of every boundary loop is
    outside every other chart.

Why these suffice: by 1-3 the map of a chart is a local homeomorphism onto
its image, by 4 its boundary is mapped injectively, and a local
homeomorphism of a compact surface whose boundary goes injectively to
disjoint closed curves is injective (each image point has as many preimages
as the boundary winds around it, and that number is 0 or 1).  Two charts
whose boundaries do not meet overlap only when a boundary curve of one lies
inside the other, which 5 rules out.

With REFERENCE (the mesh that was parameterized) the output must also have
its vertices: as many v, each with the same coordinates, in the same order,
and the same faces in the same order, each with the same vertices up to a
rotation of its corners.  --allow-reorient also accepts a face whose
corners come back in the reverse order (a repaired winding).

Exactness: a double is an integer times a power of two, so differences and
products of the coordinates are exact as Python fractions.  Each
orientation is computed in floating point first and accepted when its
magnitude exceeds a bound on the rounding error (3 roundings of relative
size 2^-53 on each of the two products, bounded generously by 1e-15 times
their sum); otherwise, or near underflow or overflow, it is recomputed with
fractions.  Pairs of boundary edges come from a uniform grid over the UV
bounding box (each edge in every cell its bounding box touches; a pair is
tested once, in the first cell the two share), and the containment test of
5 casts one horizontal ray per boundary loop through the same grid.

--json prints one line: "bijective", the "counts" and "examples" of each
kind of fault, and "symmetric_dirichlet" (mean by 3D area, max), the
distortion measured in floating point beside the checks.
"""
import json
import math
import sys
from fractions import Fraction

BIG = 1e280
SMALL = 1e-280


class Unreadable(Exception):
    pass


def orient(ax, ay, bx, by, cx, cy):
    """Sign of the area of triangle abc: 1 counter-clockwise, -1 clockwise, 0 collinear."""
    l = (bx - ax) * (cy - ay)
    r = (by - ay) * (cx - ax)
    s = abs(l) + abs(r)
    if SMALL < s < BIG:
        d = l - r
        if d > 1e-15 * s:
            return 1
        if d < -1e-15 * s:
            return -1
    ax, ay, bx, by, cx, cy = (Fraction(t) for t in (ax, ay, bx, by, cx, cy))
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (d > 0) - (d < 0)


def dot_sign(ax, ay, bx, by, cx, cy):
    """Sign of (b - a) . (c - a), exactly."""
    ax, ay, bx, by, cx, cy = (Fraction(t) for t in (ax, ay, bx, by, cx, cy))
    d = (bx - ax) * (cx - ax) + (by - ay) * (cy - ay)
    return (d > 0) - (d < 0)


# ---- reading ----------------------------------------------------------------

def _index(tok, n, what, where):
    try:
        i = int(tok)
    except ValueError:
        raise Unreadable("%s: bad %s index '%s'" % (where, what, tok))
    if i < 0:
        i += n + 1
    if i < 1 or i > n:
        raise Unreadable("%s: %s index %s out of range (%d defined)" % (where, what, tok, n))
    return i - 1


def _floats(toks, k, where):
    if len(toks) < k:
        raise Unreadable("%s: expected %d numbers" % (where, k))
    try:
        return [float(t) for t in toks[:k]]
    except ValueError:
        raise Unreadable("%s: bad number in '%s'" % (where, " ".join(toks)))


def read_obj(path, need_vt):
    """v (x, y, z), vt (u, v) and triangles: lists of (v, vt) corners, with
    the face's line number and its corners as written."""
    vs, vts, tris, faces = [], [], [], []
    try:
        f = open(path, "r", encoding="utf-8", errors="replace")
    except OSError as e:
        raise Unreadable("%s: %s" % (path, e.strerror))
    with f:
        for ln, line in enumerate(f, 1):
            t = line.split()
            if not t:
                continue
            where = "%s:%d" % (path, ln)
            if t[0] == "v":
                vs.append(tuple(_floats(t[1:], 3, where)))
            elif t[0] == "vt":
                vts.append(tuple(_floats(t[1:], 2, where)))
            elif t[0] == "f":
                if len(t) < 4:
                    raise Unreadable("%s: a face needs 3 corners" % where)
                corners = []
                for c in t[1:]:
                    p = c.split("/")
                    v = _index(p[0], len(vs), "v", where)
                    if len(p) > 1 and p[1] != "":
                        vt = _index(p[1], len(vts), "vt", where)
                    elif need_vt:
                        raise Unreadable("%s: corner '%s' has no vt" % (where, c))
                    else:
                        vt = -1
                    corners.append((v, vt))
                faces.append((ln, [c[0] for c in corners]))
                for k in range(1, len(corners) - 1):
                    tris.append((corners[0], corners[k], corners[k + 1], ln))
    if not tris:
        raise Unreadable("%s: no faces" % path)
    return vs, vts, tris, faces


def read_off(path):
    try:
        with open(path, "r", encoding="utf-8", errors="replace") as f:
            lines = [(ln, l.split("#", 1)[0].split()) for ln, l in enumerate(f, 1)]
    except OSError as e:
        raise Unreadable("%s: %s" % (path, e.strerror))
    lines = [(ln, t) for ln, t in lines if t]
    if not lines or lines[0][1][0] != "OFF":
        raise Unreadable("%s: no OFF header" % path)
    head = lines[0][1][1:]
    k = 1
    if not head:
        head, k = lines[1][1], 2
    try:
        nv, nf = int(head[0]), int(head[1])
        vs = [tuple(float(x) for x in lines[k + i][1][:3]) for i in range(nv)]
        faces = []
        for i in range(nf):
            ln, t = lines[k + nv + i]
            n = int(t[0])
            idx = [int(x) for x in t[1:1 + n]]
            if n < 3 or len(idx) < n or min(idx) < 0 or max(idx) >= nv:
                raise Unreadable("%s:%d: face %d is malformed" % (path, ln, i + 1))
            faces.append((ln, idx))
    except (IndexError, ValueError):
        raise Unreadable("%s: truncated or malformed" % path)
    if any(len(p) < 3 for p in vs):
        raise Unreadable("%s: a vertex has fewer than 3 coordinates" % path)
    return vs, faces


def read_reference(path):
    if path.lower().endswith(".off"):
        return read_off(path)
    vs, _, _, faces = read_obj(path, False)
    return vs, faces


# ---- the checks -------------------------------------------------------------

class Report:
    def __init__(self, examples):
        self.counts = {}
        self.examples = {}
        self.limit = examples

    def add(self, kind, example):
        self.counts[kind] = self.counts.get(kind, 0) + 1
        ex = self.examples.setdefault(kind, [])
        if len(ex) < self.limit:
            ex.append(example)


def find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


def check_map(vts, tris, rep):
    """Checks 1-5; returns the number of charts."""
    U = [p[0] for p in vts]
    V = [p[1] for p in vts]
    nt = len(tris)
    T = [(a[1], b[1], c[1]) for a, b, c, _ in tris]
    line = [t[3] for t in tris]
    good = [False] * nt

    # 1. orientation of every triangle
    for i, (a, b, c) in enumerate(T):
        ax, ay, bx, by, cx, cy = U[a], V[a], U[b], V[b], U[c], V[c]
        if not all(math.isfinite(x) for x in (ax, ay, bx, by, cx, cy)):
            rep.add("nonfinite_triangles", "face at line %d" % line[i])
            continue
        s = orient(ax, ay, bx, by, cx, cy)
        if s > 0:
            good[i] = True
        elif s < 0:
            rep.add("flipped_triangles", "face at line %d (vt %d %d %d)" % (line[i], a + 1, b + 1, c + 1))
        else:
            rep.add("degenerate_triangles", "face at line %d (vt %d %d %d)" % (line[i], a + 1, b + 1, c + 1))

    # 2. edges: directed edge -> triangle; charts by shared edges
    directed = {}
    parent = list(range(nt))
    for i, (a, b, c) in enumerate(T):
        for e in ((a, b), (b, c), (c, a)):
            j = directed.get(e)
            if j is not None:
                rep.add("nonmanifold_edges", "vt %d-%d in the faces at lines %d and %d, same direction"
                        % (e[0] + 1, e[1] + 1, line[j], line[i]))
                parent[find(parent, i)] = find(parent, j)
            else:
                directed[e] = i
    for (a, b), i in directed.items():
        j = directed.get((b, a))
        if j is not None and a < b:
            parent[find(parent, i)] = find(parent, j)
    chart_of_root = {}
    chart = [0] * nt
    for i in range(nt):
        r = find(parent, i)
        chart[i] = chart_of_root.setdefault(r, len(chart_of_root))
    nchart = len(chart_of_root)
    boundary = [e for e in directed if (e[1], e[0]) not in directed]

    # 3. the fan around each vt: spoke x -> y for each triangle (v, x, y)
    spokes = {}
    for i, (a, b, c) in enumerate(T):
        for v, x, y in ((a, b, c), (b, c, a), (c, a, b)):
            spokes.setdefault(v, []).append((x, y, i))
    for v, sp in spokes.items():
        nxt = {}
        ends = set()
        for x, y, i in sp:
            nxt[x] = y
            ends.add(y)
        starts = [x for x in nxt if x not in ends]
        if len(nxt) < len(sp):
            continue            # a repeated directed edge: reported in 2
        first = starts[0] if starts else sp[0][0]
        n, x = 0, first
        while x in nxt and n <= len(sp):
            x = nxt[x]
            n += 1
            if x == first:
                break
        if len(starts) > 1 or n != len(sp):
            rep.add("nonmanifold_vertices", "vt %d: its triangles make more than one fan" % (v + 1))
            continue
        if not all(good[i] for _, _, i in sp):
            continue            # a bad triangle: reported in 1
        # How many sectors [x, y) contain the direction of the first spoke:
        # the winding of a cycle, 1 + the full turns of a chain.
        vx, vy = U[v], V[v]
        dx, dy = U[first], V[first]
        wind = 1
        for x, y, i in sp:
            if x == first or y == first:
                continue
            if orient(vx, vy, U[x], V[x], dx, dy) >= 0 and orient(vx, vy, dx, dy, U[y], V[y]) > 0:
                wind += 1
        if wind != 1:
            rep.add("winding_vertices", "vt %d: its triangles wind %d times around it" % (v + 1, wind))

    # 4. boundary edges that meet
    ne = len(boundary)
    if ne == 0:
        return nchart
    echart = [chart[directed[e]] for e in boundary]
    xs = [U[v] for e in boundary for v in e]
    ys = [V[v] for e in boundary for v in e]
    if not all(math.isfinite(t) for t in xs + ys):
        return nchart           # reported in 1; the grid needs finite points
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    w, h = x1 - x0, y1 - y0
    cells = max(1.0, min(4.0 * ne, 4e6))
    if w > 0 and h > 0:
        size = math.sqrt(w * h / cells)
        nx, ny = int(min(max(w / size, 1), 4096)), int(min(max(h / size, 1), 4096))
    else:
        nx, ny = (int(min(cells, 4096)), 1) if w > 0 else (1, int(min(cells, 4096)) if h > 0 else 1)
    cw = w / nx if w > 0 else 1.0
    ch = h / ny if h > 0 else 1.0

    def cx(x):
        k = int((x - x0) / cw)
        return nx - 1 if k >= nx else k

    def cy(y):
        k = int((y - y0) / ch)
        return ny - 1 if k >= ny else k

    # An edge whose box covers many cells (rare: a long edge among short
    # ones) is kept aside and compared with every edge whose box meets its.
    box = []
    grid = {}
    big = []
    for k, (a, b) in enumerate(boundary):
        ux0, ux1 = (U[a], U[b]) if U[a] <= U[b] else (U[b], U[a])
        vy0, vy1 = (V[a], V[b]) if V[a] <= V[b] else (V[b], V[a])
        i0, i1, j0, j1 = cx(ux0), cx(ux1), cy(vy0), cy(vy1)
        box.append((ux0, ux1, vy0, vy1, i0, j0))
        if (i1 - i0 + 1) * (j1 - j0 + 1) > 64:
            big.append(k)
            continue
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                grid.setdefault(i * ny + j, []).append(k)

    def on_segment(ax, ay, bx, by, px, py):
        return min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by)

    def pairs():
        for key, lst in grid.items():
            ci, cj = divmod(key, ny)
            m = len(lst)
            for s in range(m):
                k = lst[s]
                bk = box[k]
                for t in range(s + 1, m):
                    q = lst[t]
                    bq = box[q]
                    if bk[1] < bq[0] or bq[1] < bk[0] or bk[3] < bq[2] or bq[3] < bk[2]:
                        continue
                    if max(bk[4], bq[4]) == ci and max(bk[5], bq[5]) == cj:
                        yield k, q      # else tested in another cell
        isbig = set(big)
        for k in big:
            bk = box[k]
            for q in range(ne):
                bq = box[q]
                if (q in isbig and q <= k) or bk[1] < bq[0] or bq[1] < bk[0] or bk[3] < bq[2] or bq[3] < bk[2]:
                    continue
                yield k, q

    overlapping = set()
    for k, q in pairs():
        a, b = boundary[k]
        c, d = boundary[q]
        same = echart[k] == echart[q]
        shared = {a, b} & {c, d}
        if shared and same:
            sv = shared.pop()
            x = b if a == sv else a
            y = d if c == sv else c
            if orient(U[sv], V[sv], U[x], V[x], U[y], V[y]) != 0 or \
                    dot_sign(U[sv], V[sv], U[x], V[x], U[y], V[y]) <= 0:
                continue
            hit = True
        else:
            hit = segments_meet(U[a], V[a], U[b], V[b], U[c], V[c], U[d], V[d], on_segment)
        if not hit:
            continue
        what = "boundary edges vt %d-%d and vt %d-%d" % (a + 1, b + 1, c + 1, d + 1)
        if same:
            rep.add("boundary_intersections", what + " (chart %d)" % echart[k])
        else:
            pair = (min(echart[k], echart[q]), max(echart[k], echart[q]))
            if pair not in overlapping:
                overlapping.add(pair)
                rep.add("chart_overlaps", "charts %d and %d: %s meet" % (pair[0], pair[1], what))

    # 5. one point of every boundary loop outside every other chart: a ray
    # to +x through the grid's row, crossings counted per chart
    up = list(range(len(vts)))
    for a, b in boundary:
        up[find(up, a)] = find(up, b)
    rep_of = {}
    for k, (a, b) in enumerate(boundary):
        rep_of.setdefault(find(up, a), (a, echart[k]))
    for p, pc in rep_of.values():
        px, py = U[p], V[p]
        j = cy(py)
        if not (y0 <= py <= y1):
            continue
        seen = set()
        parity = {}
        row = [k for i in range(cx(px), nx) for k in grid.get(i * ny + j, ())]
        for k in row + big:
                if k in seen or echart[k] == pc:
                    continue
                seen.add(k)
                a, b = boundary[k]
                ay, by = V[a], V[b]
                if ay <= py < by:
                    s = orient(U[a], ay, U[b], by, px, py) > 0
                elif by <= py < ay:
                    s = orient(U[a], ay, U[b], by, px, py) < 0
                else:
                    continue
                if s:
                    parity[echart[k]] = parity.get(echart[k], 0) ^ 1
        for c, odd in parity.items():
            pair = (min(c, pc), max(c, pc))
            if odd and pair not in overlapping:
                overlapping.add(pair)
                rep.add("chart_overlaps", "charts %d and %d: vt %d of chart %d lies inside chart %d"
                        % (pair[0], pair[1], p + 1, pc, c))
    return nchart


def segments_meet(ax, ay, bx, by, cx, cy, dx, dy, on_segment):
    """Do the closed segments ab and cd have a point in common?"""
    d1 = orient(cx, cy, dx, dy, ax, ay)
    d2 = orient(cx, cy, dx, dy, bx, by)
    d3 = orient(ax, ay, bx, by, cx, cy)
    d4 = orient(ax, ay, bx, by, dx, dy)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True
    return ((d1 == 0 and on_segment(cx, cy, dx, dy, ax, ay)) or
            (d2 == 0 and on_segment(cx, cy, dx, dy, bx, by)) or
            (d3 == 0 and on_segment(ax, ay, bx, by, cx, cy)) or
            (d4 == 0 and on_segment(ax, ay, bx, by, dx, dy)))


def energy(vs, vts, tris):
    """The symmetric Dirichlet energy |J|^2 + |J^-1|^2 of each triangle, J
    the map from the triangle in 3D (the output's own v) to its UV triangle;
    for a 2x2 matrix |J^-1|^2 = |J|^2 / det(J)^2.  Floating point, not exact:
    a measurement beside the checks.  Mean weighted by 3D area and max;
    infinite when a triangle is flipped or flat in UV, triangles of zero 3D
    area skipped."""
    total = area_sum = 0.0
    worst = 0.0
    for (a, ta), (b, tb), (c, tc), _ in tris:
        p, q, r = vs[a], vs[b], vs[c]
        e1 = [q[i] - p[i] for i in range(3)]
        e2 = [r[i] - p[i] for i in range(3)]
        l1 = math.sqrt(sum(x * x for x in e1))
        n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
        twice = math.sqrt(sum(x * x for x in n))
        if l1 == 0 or twice == 0 or not math.isfinite(twice):
            continue
        x2, y2 = sum(e1[i] * e2[i] for i in range(3)) / l1, twice / l1
        u1 = (vts[tb][0] - vts[ta][0], vts[tb][1] - vts[ta][1])
        u2 = (vts[tc][0] - vts[ta][0], vts[tc][1] - vts[ta][1])
        # J = [u1 u2] [[l1, x2], [0, y2]]^-1
        j00, j10 = u1[0] / l1, u1[1] / l1
        j01, j11 = (u2[0] - j00 * x2) / y2, (u2[1] - j10 * x2) / y2
        det = j00 * j11 - j01 * j10
        fro = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11
        e = fro * (1 + 1 / (det * det)) if det > 0 else math.inf
        total += e * twice
        area_sum += twice
        worst = max(worst, e)
    mean = total / area_sum if area_sum > 0 else math.nan
    return {"mean": mean if math.isfinite(mean) else None, "max": worst if math.isfinite(worst) else None}


def check_reference(vs, faces, ref_vs, ref_faces, allow_reorient, rep):
    if len(vs) != len(ref_vs):
        rep.add("reference_vertices", "%d v in the output, %d in the reference" % (len(vs), len(ref_vs)))
    else:
        for i, (p, q) in enumerate(zip(vs, ref_vs)):
            if p != q:
                rep.add("reference_vertices", "v %d is (%r, %r, %r), (%r, %r, %r) in the reference"
                        % ((i + 1,) + p + q))
    if len(faces) != len(ref_faces):
        rep.add("reference_faces", "%d faces in the output, %d in the reference" % (len(faces), len(ref_faces)))
        return
    for k, ((ln, f), (rln, g)) in enumerate(zip(faces, ref_faces)):
        if len(f) == len(g):
            n = len(f)
            rot = any(f[i:] + f[:i] == g for i in range(n))
            if rot:
                continue
            r = f[::-1]
            if any(r[i:] + r[:i] == g for i in range(n)):
                rep.add("reversed_faces", "face %d (line %d) has the corners of reference face %d reversed"
                        % (k + 1, ln, rln))
                continue
        rep.add("reference_faces", "face %d (line %d): vertices %s, the reference's %s"
                % (k + 1, ln, " ".join(str(v + 1) for v in f), " ".join(str(v + 1) for v in g)))


def main(argv):
    args, files, examples, as_json, allow_reorient = list(argv), [], 5, False, False
    while args:
        a = args.pop(0)
        if a == "--json":
            as_json = True
        elif a == "--allow-reorient":
            allow_reorient = True
        elif a == "--examples" and args:
            examples = int(args.pop(0))
        elif a.startswith("-") and a != "-":
            sys.stderr.write("uvcheck: unknown option %s\n" % a)
            return 2
        else:
            files.append(a)
    if not 1 <= len(files) <= 2:
        sys.stderr.write(__doc__.split("\n\n")[1] + "\n")
        return 2
    rep = Report(examples)
    try:
        vs, vts, tris, faces = read_obj(files[0], True)
        ref = read_reference(files[1]) if len(files) == 2 else None
    except Unreadable as e:
        sys.stderr.write("uvcheck: %s\n" % e)
        return 2
    nchart = check_map(vts, tris, rep)
    if ref is not None:
        check_reference(vs, faces, ref[0], ref[1], allow_reorient, rep)
    bad = [k for k in rep.counts if k != "reversed_faces" or not allow_reorient]
    result = {
        "file": files[0], "reference": files[1] if ref is not None else None,
        "triangles": len(tris), "vt": len(vts), "charts": nchart,
        "bijective": not bad, "counts": rep.counts, "examples": rep.examples,
        "symmetric_dirichlet": energy(vs, vts, tris),
    }
    if as_json:
        print(json.dumps(result, sort_keys=True))
    else:
        print("%s: %d triangles, %d charts: %s" % (files[0], len(tris), nchart,
              "bijective" + (", matches the reference" if ref is not None else "") if not bad
              else "NOT bijective" if any(k not in ("reference_vertices", "reference_faces", "reversed_faces") for k in bad)
              else "bijective, but does NOT match the reference"))
        for k in sorted(rep.counts):
            print("  %s: %d" % (k, rep.counts[k]))
            for ex in rep.examples[k]:
                print("    " + ex)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
