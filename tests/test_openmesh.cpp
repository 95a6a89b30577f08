/* test_openmesh.cpp - cross-check bijparam's chart extraction against OpenMesh.

   For every mesh in tests/data this test builds the charts twice:

   ours         bp_read_mesh + bp_atlas_build with zero options;
   independent  a small parser written here (not the library's), charts by
                union-find over faces (a chart vertex is the pair (v, vt); two
                faces share a chart when they share an edge whose ends are the
                same (v, vt) pairs; without vt, charts are the edge-connected
                components), and one OpenMesh TriMesh_ArrayKernelT per chart.
                OpenMesh's halfedges give the vertex / face / edge counts, the
                Euler characteristic V - E + F and the boundary loops.

   Charts are matched by the smallest mesh triangle they contain, then
   compared: triangle set, V (ours minus split_vertices), F, pinch vertices,
   sorted loop lengths, Euler characteristic.  Our loops are also checked on
   their own: closed, every step a->b a boundary edge of exactly one chart
   triangle (directed a->b, and b->a in none), all boundary edges covered once,
   and loop 0 the longest in 3D.

   Pinch vertices.  A chart vertex whose one-ring has more than one gap (more
   than one outgoing boundary halfedge) is a pinch: the library splits it into
   one vertex per fan.  OpenMesh can hold such a vertex, but its own
   next_halfedge_handle pairs the gaps arbitrarily, so its raw loops may differ
   from the loops after splitting.  We therefore also walk the boundary "per
   fan" on OpenMesh's halfedges (from boundary halfedge h into v, turn around v
   through the faces of h's fan to the next boundary halfedge out of v), which
   is exactly the boundary after splitting; for charts without pinches both
   walks must agree.  If OpenMesh refuses a face (complex vertex or edge) we
   say so and compare only what it holds. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

typedef OpenMesh::TriMesh_ArrayKernelT<> OMesh;

/* ---- the independent reader ------------------------------------------- */

struct RawMesh {
    std::vector<double> pos;  /* 3 per vertex */
    std::vector<int> tri;     /* 3 per triangle, 0-based vertex */
    std::vector<int> tri_vt;  /* 3 per triangle, 0-based vt or -1 */
    int num_vt;
    RawMesh() : num_vt(0) {}
    int nv() const { return (int)(pos.size() / 3); }
    int nf() const { return (int)(tri.size() / 3); }
};

static bool ends_with(const std::string &s, const char *suffix)
{
    size_t n = std::strlen(suffix);
    if (s.size() < n) return false;
    for (size_t i = 0; i < n; i++)
        if (std::tolower((unsigned char)s[s.size() - n + i]) != suffix[i]) return false;
    return true;
}

/* OBJ: v, vt, f with v, v/vt, v/vt/vn, v//vn and negative indices; polygons
   are fanned (none in tests/data).  '\r' is stripped. */
static bool read_obj_raw(const std::string &path, RawMesh &m)
{
    std::ifstream in(path.c_str());
    if (!in) return false;
    std::string line;
    while (std::getline(in, line)) {
        if (!line.empty() && line[line.size() - 1] == '\r') line.erase(line.size() - 1);
        std::istringstream ls(line);
        std::string tag;
        if (!(ls >> tag)) continue;
        if (tag == "v") {
            double x, y, z;
            if (!(ls >> x >> y >> z)) return false;
            m.pos.push_back(x); m.pos.push_back(y); m.pos.push_back(z);
        } else if (tag == "vt") {
            m.num_vt++;
        } else if (tag == "f") {
            std::vector<int> vs, ts;
            std::string tok;
            while (ls >> tok) {
                int v = std::atoi(tok.c_str()), t = 0;
                size_t slash = tok.find('/');
                if (slash != std::string::npos && slash + 1 < tok.size() && tok[slash + 1] != '/')
                    t = std::atoi(tok.c_str() + slash + 1);
                v = v < 0 ? m.nv() + v : v - 1;
                t = t < 0 ? m.num_vt + t : (t == 0 ? -1 : t - 1);
                vs.push_back(v); ts.push_back(t);
            }
            if (vs.size() < 3) return false;
            for (size_t k = 1; k + 1 < vs.size(); k++) {
                m.tri.push_back(vs[0]); m.tri.push_back(vs[k]); m.tri.push_back(vs[k + 1]);
                m.tri_vt.push_back(ts[0]); m.tri_vt.push_back(ts[k]); m.tri_vt.push_back(ts[k + 1]);
            }
        }
    }
    return m.nf() > 0;
}

/* OFF: "OFF", then "V F E", V lines "x y z", F lines "n i0 .. in-1";
   '#' comments and blank lines skipped, CRLF tolerated. */
static bool read_off_raw(const std::string &path, RawMesh &m)
{
    std::ifstream in(path.c_str());
    if (!in) return false;
    std::vector<std::string> lines;
    std::string line;
    while (std::getline(in, line)) {
        size_t hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        while (!line.empty() && std::isspace((unsigned char)line[line.size() - 1])) line.erase(line.size() - 1);
        size_t first = line.find_first_not_of(" \t");
        if (first == std::string::npos) continue;
        lines.push_back(line.substr(first));
    }
    if (lines.empty() || lines[0].compare(0, 3, "OFF") != 0) return false;
    size_t li = 1;
    std::string counts = lines[0].substr(3);
    if (counts.find_first_not_of(" \t") == std::string::npos) {
        if (li >= lines.size()) return false;
        counts = lines[li++];
    }
    std::istringstream cs(counts);
    int nv = 0, nf = 0;
    if (!(cs >> nv >> nf) || nv <= 0 || nf <= 0) return false;
    if (lines.size() < li + (size_t)nv + (size_t)nf) return false;
    for (int i = 0; i < nv; i++) {
        std::istringstream ls(lines[li++]);
        double x, y, z;
        if (!(ls >> x >> y >> z)) return false;
        m.pos.push_back(x); m.pos.push_back(y); m.pos.push_back(z);
    }
    for (int i = 0; i < nf; i++) {
        std::istringstream ls(lines[li++]);
        int n;
        if (!(ls >> n) || n < 3) return false;
        std::vector<int> vs((size_t)n);
        for (int k = 0; k < n; k++)
            if (!(ls >> vs[(size_t)k])) return false;
        for (int k = 1; k + 1 < n; k++) {
            m.tri.push_back(vs[0]); m.tri.push_back(vs[(size_t)k]); m.tri.push_back(vs[(size_t)k + 1]);
            m.tri_vt.push_back(-1); m.tri_vt.push_back(-1); m.tri_vt.push_back(-1);
        }
    }
    return true;
}

/* ---- independent charts, held in OpenMesh ------------------------------ */

struct RefChart {
    std::vector<int> faces;        /* mesh triangles, ascending */
    int nv, nf_added, ne, chi;     /* from OpenMesh */
    int failed_faces;              /* faces OpenMesh's add_face refused */
    int pinch_vertices;            /* vertices with > 1 gap */
    int pinch_extra;               /* sum of (gaps - 1): vertices a split adds */
    std::vector<int> om_loops;     /* lengths via next_halfedge_handle, sorted desc */
    std::vector<int> fan_loops;    /* lengths after splitting pinches, sorted desc */
    std::vector<int> mesh_vertices;/* distinct mesh vertices, ascending */
};

static int uf_find(std::vector<int> &p, int x)
{
    while (p[(size_t)x] != x) { p[(size_t)x] = p[(size_t)p[(size_t)x]]; x = p[(size_t)x]; }
    return x;
}

static void build_reference(const RawMesh &m, std::vector<RefChart> &charts)
{
    /* chart vertex = (v, vt) */
    std::map<std::pair<int, int>, int> cv_of;
    std::vector<int> corner_cv(m.tri.size());
    std::vector<int> cv_vertex;
    for (size_t c = 0; c < m.tri.size(); c++) {
        std::pair<int, int> key(m.tri[c], m.tri_vt[c]);
        std::map<std::pair<int, int>, int>::iterator it = cv_of.find(key);
        if (it == cv_of.end()) {
            it = cv_of.insert(std::make_pair(key, (int)cv_vertex.size())).first;
            cv_vertex.push_back(m.tri[c]);
        }
        corner_cv[c] = it->second;
    }
    /* faces sharing an undirected chart-vertex edge are one chart */
    int nf = m.nf();
    std::vector<int> parent((size_t)nf);
    for (int f = 0; f < nf; f++) parent[(size_t)f] = f;
    std::unordered_map<uint64_t, int> edge_face;
    for (int f = 0; f < nf; f++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = (uint64_t)corner_cv[(size_t)(3 * f + k)];
            uint64_t b = (uint64_t)corner_cv[(size_t)(3 * f + (k + 1) % 3)];
            uint64_t key = a < b ? (a << 32 | b) : (b << 32 | a);
            std::unordered_map<uint64_t, int>::iterator it = edge_face.find(key);
            if (it == edge_face.end()) edge_face[key] = f;
            else {
                int r1 = uf_find(parent, f), r2 = uf_find(parent, it->second);
                if (r1 != r2) parent[(size_t)std::max(r1, r2)] = std::min(r1, r2);
            }
        }
    std::map<int, size_t> chart_of_root;  /* roots are the smallest face */
    for (int f = 0; f < nf; f++) {
        int r = uf_find(parent, f);
        if (!chart_of_root.count(r)) {
            chart_of_root[r] = charts.size();
            charts.push_back(RefChart());
        }
        charts[chart_of_root[r]].faces.push_back(f);
    }

    for (size_t ci = 0; ci < charts.size(); ci++) {
        RefChart &rc = charts[ci];
        OMesh om;
        std::map<int, OMesh::VertexHandle> vh_of;
        std::vector<int> mv;
        rc.failed_faces = 0;
        for (size_t i = 0; i < rc.faces.size(); i++) {
            int f = rc.faces[i];
            OMesh::VertexHandle vh[3];
            for (int k = 0; k < 3; k++) {
                int cv = corner_cv[(size_t)(3 * f + k)];
                std::map<int, OMesh::VertexHandle>::iterator it = vh_of.find(cv);
                if (it == vh_of.end()) {
                    const double *p = &m.pos[(size_t)(3 * cv_vertex[(size_t)cv])];
                    it = vh_of.insert(std::make_pair(cv, om.add_vertex(OMesh::Point((float)p[0], (float)p[1], (float)p[2])))).first;
                    mv.push_back(cv_vertex[(size_t)cv]);
                }
                vh[k] = it->second;
            }
            if (!om.add_face(vh[0], vh[1], vh[2]).is_valid()) rc.failed_faces++;
        }
        std::sort(mv.begin(), mv.end());
        mv.erase(std::unique(mv.begin(), mv.end()), mv.end());
        rc.mesh_vertices = mv;
        rc.nv = (int)om.n_vertices();
        rc.nf_added = (int)om.n_faces();
        rc.ne = (int)om.n_edges();
        rc.chi = rc.nv - rc.ne + rc.nf_added;

        /* pinches: vertices with more than one outgoing boundary halfedge */
        rc.pinch_vertices = rc.pinch_extra = 0;
        for (OMesh::VertexIter v = om.vertices_begin(); v != om.vertices_end(); ++v) {
            int gaps = 0;
            for (OMesh::VertexOHalfedgeIter h = om.voh_iter(*v); h.is_valid(); ++h)
                if (om.is_boundary(*h)) gaps++;
            if (gaps > 1) { rc.pinch_vertices++; rc.pinch_extra += gaps - 1; }
        }

        /* loops as OpenMesh links them, and loops per fan */
        size_t nh = om.n_halfedges();
        std::vector<char> seen(nh, 0), seen_fan(nh, 0);
        for (OMesh::HalfedgeIter h = om.halfedges_begin(); h != om.halfedges_end(); ++h) {
            if (!om.is_boundary(*h)) continue;
            if (!seen[(size_t)h->idx()]) {
                int len = 0;
                OMesh::HalfedgeHandle g = *h;
                do { seen[(size_t)g.idx()] = 1; len++; g = om.next_halfedge_handle(g); }
                while (g != *h && len <= (int)nh);
                rc.om_loops.push_back(len);
            }
            if (!seen_fan[(size_t)h->idx()]) {
                int len = 0;
                OMesh::HalfedgeHandle g = *h;
                do {
                    seen_fan[(size_t)g.idx()] = 1; len++;
                    /* turn around to_vertex(g) through g's fan */
                    OMesh::HalfedgeHandle t = om.opposite_halfedge_handle(g);
                    int guard = 0;
                    do { t = om.opposite_halfedge_handle(om.prev_halfedge_handle(t)); }
                    while (!om.is_boundary(t) && ++guard <= (int)nh);
                    g = t;
                } while (g != *h && len <= (int)nh);
                rc.fan_loops.push_back(len);
            }
        }
        std::sort(rc.om_loops.rbegin(), rc.om_loops.rend());
        std::sort(rc.fan_loops.rbegin(), rc.fan_loops.rend());
    }
}

/* ---- helpers ------------------------------------------------------------ */

static std::string list_str(const std::vector<int> &v)
{
    std::ostringstream s;
    s << "[";
    for (size_t i = 0; i < v.size(); i++) s << (i ? "," : "") << v[i];
    s << "]";
    return s.str();
}

static std::string lower(const char *s)
{
    std::string r(s);
    for (size_t i = 0; i < r.size(); i++) r[i] = (char)std::tolower((unsigned char)r[i]);
    return r;
}

/* What tests/data/README.md states about each file. */
struct Expect {
    const char *path;
    int nv, nf;
    bool reject;          /* bp_atlas_build with BP_CUT_NONE must say BP_ERR_TOPOLOGY */
    int charts;           /* -1: not stated */
    int split;            /* pinch vertices split in all charts */
    int chi;              /* Euler characteristic of the whole mesh (uncut) */
    int nloops;           /* boundary loops of every chart (after splitting) */
    std::vector<int> loops; /* of the single chart, longest first; empty: not stated */
};

/* Our loops on their own: closed, made of boundary edges in triangle
   orientation, covering every boundary edge once; loop 0 longest in 3D. */
static void check_our_loops(const char *name, uint32_t ci, const bp_chart &c, const bp_mesh &mesh)
{
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (uint32_t t = 0; t < c.num_triangles; t++)
        for (int k = 0; k < 3; k++)
            directed[std::make_pair(c.triangles[3 * t + k], c.triangles[3 * t + (k + 1) % 3])]++;
    size_t boundary_edges = 0;
    for (std::map<std::pair<uint32_t, uint32_t>, int>::iterator it = directed.begin(); it != directed.end(); ++it)
        if (!directed.count(std::make_pair(it->first.second, it->first.first))) boundary_edges++;

    bool closed_ok = true, edges_ok = true;
    std::string why;
    std::map<std::pair<uint32_t, uint32_t>, int> used;
    std::vector<double> len3d(c.num_loops, 0.0);
    for (uint32_t l = 0; l < c.num_loops; l++) {
        uint32_t s = c.loop_start[l], e = c.loop_start[l + 1];
        if (e - s < 3) { closed_ok = false; why = "loop shorter than 3"; continue; }
        for (uint32_t i = s; i < e; i++) {
            uint32_t a = c.loop_vertices[i], b = c.loop_vertices[i + 1 < e ? i + 1 : s];
            if (a >= c.num_vertices || b >= c.num_vertices) { edges_ok = false; why = "loop vertex out of range"; continue; }
            std::pair<uint32_t, uint32_t> ab(a, b), ba(b, a);
            std::map<std::pair<uint32_t, uint32_t>, int>::iterator it = directed.find(ab);
            if (it == directed.end() || it->second != 1 || directed.count(ba)) {
                if (edges_ok) {
                    std::ostringstream w;
                    w << "loop " << l << " step " << a << "->" << b << " is "
                      << (it == directed.end() ? (directed.count(ba) ? "reversed (b->a in a triangle)" : "in no triangle")
                                               : "not a boundary edge");
                    why = w.str();
                }
                edges_ok = false;
            }
            used[ab]++;
            const double *pa = mesh.positions + 3 * (size_t)c.vertex[a];
            const double *pb = mesh.positions + 3 * (size_t)c.vertex[b];
            len3d[l] += std::sqrt((pa[0] - pb[0]) * (pa[0] - pb[0]) + (pa[1] - pb[1]) * (pa[1] - pb[1]) +
                                  (pa[2] - pb[2]) * (pa[2] - pb[2]));
        }
    }
    bool once = used.size() == boundary_edges;
    for (std::map<std::pair<uint32_t, uint32_t>, int>::iterator it = used.begin(); it != used.end(); ++it)
        if (it->second != 1) once = false;
    BPT_CHECK(closed_ok && edges_ok, "%s chart %u: every loop step a->b is a boundary edge a->b of exactly one chart triangle%s%s",
              name, ci, why.empty() ? "" : ": ", why.c_str());
    BPT_CHECK(once, "%s chart %u: the loops cover each of the %zu boundary edges exactly once (%zu distinct loop edges)",
              name, ci, boundary_edges, used.size());
    bool longest = true;
    for (uint32_t l = 1; l < c.num_loops; l++)
        if (len3d[l] > len3d[0] * (1 + 1e-12)) longest = false;
    if (c.num_loops > 1)
        BPT_CHECK(longest, "%s chart %u: loop 0 is the longest in 3D (%.6g; loop 1: %.6g)", name, ci, len3d[0], len3d[1]);
}

static void check_mesh(const Expect &x)
{
    const char *name = x.path;
    RawMesh raw;
    bool raw_ok = ends_with(x.path, ".obj") ? read_obj_raw(x.path, raw) : read_off_raw(x.path, raw);
    if (!BPT_CHECK(raw_ok, "%s: independent parser reads it", name)) return;
    BPT_CHECK(raw.nv() == x.nv && raw.nf() == x.nf, "%s: independent parser: V=%d F=%d (README: %d, %d)",
              name, raw.nv(), raw.nf(), x.nv, x.nf);

    std::vector<RefChart> ref;
    build_reference(raw, ref);

    /* facts of the reference alone, against the README */
    {
        int failed = 0, pinch_extra = 0;
        for (size_t i = 0; i < ref.size(); i++) { failed += ref[i].failed_faces; pinch_extra += ref[i].pinch_extra; }
        BPT_CHECK(failed == 0, "%s: OpenMesh accepts every face of every chart (%d refused)", name, failed);
        if (x.charts >= 0)
            BPT_CHECK((int)ref.size() == x.charts, "%s: OpenMesh side: %zu charts (README: %d)", name, ref.size(), x.charts);
        BPT_CHECK(pinch_extra == x.split, "%s: OpenMesh side: splitting the pinches adds %d vertices (README: %d)",
                  name, pinch_extra, x.split);
        if (x.charts == 1 || x.reject) {
            /* the whole mesh, uncut: chi = 2 - 2g - b */
            OMesh om;
            for (int v = 0; v < raw.nv(); v++)
                om.add_vertex(OMesh::Point((float)raw.pos[(size_t)(3 * v)], (float)raw.pos[(size_t)(3 * v + 1)], (float)raw.pos[(size_t)(3 * v + 2)]));
            for (int f = 0; f < raw.nf(); f++)
                om.add_face(om.vertex_handle((unsigned)raw.tri[(size_t)(3 * f)]), om.vertex_handle((unsigned)raw.tri[(size_t)(3 * f + 1)]),
                            om.vertex_handle((unsigned)raw.tri[(size_t)(3 * f + 2)]));
            int whole = (int)om.n_vertices() - (int)om.n_edges() + (int)om.n_faces();
            BPT_CHECK(whole == x.chi && (int)om.n_faces() == raw.nf(),
                      "%s: OpenMesh, whole mesh without seams: chi = V-E+F = %d (README genus/loops give %d), %u of %d faces",
                      name, whole, x.chi, (unsigned)om.n_faces(), raw.nf());
        }
        bool nloops_ok = true;
        for (size_t i = 0; i < ref.size(); i++)
            if ((int)ref[i].fan_loops.size() != x.nloops) nloops_ok = false;
        BPT_CHECK(nloops_ok, "%s: OpenMesh side: every chart has %d boundary loops after splitting pinches", name, x.nloops);
        if (!x.loops.empty() && ref.size() == 1)
            BPT_CHECK(ref[0].om_loops == x.loops, "%s: OpenMesh loops %s (README: %s)", name,
                      list_str(ref[0].om_loops).c_str(), list_str(x.loops).c_str());
    }

    /* our side */
    bp_mesh mesh;
    bp_error err;
    std::memset(&mesh, 0, sizeof mesh);
    std::memset(&err, 0, sizeof err);
    bp_status st = bp_read_mesh(x.path, &mesh, NULL, &err);
    if (!BPT_CHECK(st == BP_OK, "%s: bp_read_mesh: %s", name, st == BP_OK ? "ok" : err.message)) return;
    BPT_CHECK((int)mesh.num_vertices == raw.nv() && (int)mesh.num_triangles == raw.nf(),
              "%s: bp_read_mesh gives V=%u F=%u, independent parser %d %d", name, mesh.num_vertices,
              mesh.num_triangles, raw.nv(), raw.nf());
    bool same_tris = mesh.num_triangles == (uint32_t)raw.nf();
    for (uint32_t i = 0; same_tris && i < 3 * mesh.num_triangles; i++)
        if ((int)mesh.triangles[i] != raw.tri[i]) same_tris = false;
    BPT_CHECK(same_tris, "%s: bp_read_mesh triangles equal the independent parser's, corner by corner", name);

    bp_atlas atlas;
    bp_options opt;
    std::memset(&atlas, 0, sizeof atlas);
    std::memset(&opt, 0, sizeof opt);
    std::memset(&err, 0, sizeof err);
    if (x.reject) opt.cut = BP_CUT_NONE;   /* the default would cut it into a disk (test_cut.c) */
    st = bp_atlas_build(&atlas, &mesh, &opt, &err);

    if (x.reject) {
        /* Default (tolerant) mode: the mesh's only chart fails, so nothing
           is usable: the call fails with the chart's own status and the
           atlas is freed (with several charts the others would be kept). */
        std::string msg = lower(err.message);
        BPT_CHECK(st == BP_ERR_TOPOLOGY && err.status == BP_ERR_TOPOLOGY && atlas.num_charts == 0,
                  "%s: bp_atlas_build rejects it with BP_ERR_TOPOLOGY and an empty atlas (got %s)", name,
                  bp_status_string(st));
        BPT_CHECK(err.message[0] != '\0' && msg.find("seam") != std::string::npos,
                  "%s: the error message says seams are needed: \"%s\"", name, err.message);
        BPT_CHECK(err.element == BP_ELEMENT_CHART && err.index >= 0 && msg.find("chart") != std::string::npos &&
                  msg.find("others") == std::string::npos,
                  "%s: the error names a chart and does not speak of other charts (element %d, index %lld)", name,
                  (int)err.element, (long long)err.index);
        bp_atlas_free(&atlas);
        /* Strict mode: the whole call fails with the chart's status. */
        opt.strict = 1;
        st = bp_atlas_build(&atlas, &mesh, &opt, &err);
        msg = lower(err.message);
        BPT_CHECK(st == BP_ERR_TOPOLOGY && err.status == BP_ERR_TOPOLOGY && atlas.num_charts == 0,
                  "%s: strict bp_atlas_build rejects it with BP_ERR_TOPOLOGY and an empty atlas (got %s)", name,
                  bp_status_string(st));
        BPT_CHECK(msg.find("seam") != std::string::npos && msg.find("chart") != std::string::npos,
                  "%s: the strict error names the chart and says seams are needed: \"%s\"", name, err.message);
        bp_atlas_free(&atlas);   /* zeroed after a failure: safe */
        bp_mesh_free(&mesh, NULL);
        return;
    }
    if (!BPT_CHECK(st == BP_OK, "%s: bp_atlas_build: %s", name, st == BP_OK ? "ok" : err.message)) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    BPT_CHECK(atlas.num_charts == ref.size(), "%s: %u charts, OpenMesh side %zu", name, atlas.num_charts, ref.size());
    if (x.charts >= 0)
        BPT_CHECK((int)atlas.num_charts == x.charts, "%s: %u charts (README: %d)", name, atlas.num_charts, x.charts);
    uint32_t split_sum = 0;
    for (uint32_t i = 0; i < atlas.num_charts; i++) split_sum += atlas.charts[i].split_vertices;
    BPT_CHECK(atlas.num_split == (uint32_t)x.split && split_sum == (uint32_t)x.split,
              "%s: split vertices: atlas.num_split %u, sum over charts %u (README: %d)", name, atlas.num_split,
              split_sum, x.split);

    /* corner maps agree with the charts */
    bool corners_ok = atlas.num_corners == 3 * mesh.num_triangles && atlas.corner_chart && atlas.corner_vertex;
    for (uint32_t c = 0; corners_ok && c < atlas.num_corners; c++) {
        uint32_t ch = atlas.corner_chart[c], cv = atlas.corner_vertex[c];
        if (ch >= atlas.num_charts || cv >= atlas.charts[ch].num_vertices || atlas.charts[ch].vertex[cv] != mesh.triangles[c])
            corners_ok = false;
    }
    BPT_CHECK(corners_ok, "%s: corner_chart/corner_vertex name a chart vertex of the corner's mesh vertex", name);

    std::map<int, size_t> ref_by_min;
    for (size_t i = 0; i < ref.size(); i++) ref_by_min[ref[i].faces[0]] = i;

    for (uint32_t ci = 0; ci < atlas.num_charts; ci++) {
        const bp_chart &c = atlas.charts[ci];
        std::vector<int> faces(c.face, c.face + c.num_triangles);
        std::sort(faces.begin(), faces.end());
        if (!BPT_CHECK(!faces.empty() && ref_by_min.count(faces[0]), "%s chart %u: a reference chart has smallest triangle %d",
                       name, ci, faces.empty() ? -1 : faces[0]))
            continue;
        const RefChart &rc = ref[ref_by_min[faces[0]]];
        bool pinched = rc.pinch_vertices > 0;
        const char *note = pinched ? " (chart has pinch vertices: OpenMesh holds them unsplit)" : "";

        BPT_CHECK(faces == rc.faces, "%s chart %u: same triangle set as the reference (%zu vs %zu triangles)", name, ci,
                  faces.size(), rc.faces.size());
        BPT_CHECK((int)c.num_triangles == rc.nf_added, "%s chart %u: F %u, OpenMesh %d%s", name, ci, c.num_triangles,
                  rc.nf_added, rc.failed_faces ? " (OpenMesh refused some faces)" : "");
        BPT_CHECK((int)(c.num_vertices - c.split_vertices) == rc.nv, "%s chart %u: V - split = %u - %u, OpenMesh V %d%s",
                  name, ci, c.num_vertices, c.split_vertices, rc.nv, note);
        BPT_CHECK((int)c.split_vertices == rc.pinch_extra, "%s chart %u: split_vertices %u, OpenMesh pinch gaps add %d (%d pinch vertices)",
                  name, ci, c.split_vertices, rc.pinch_extra, rc.pinch_vertices);
        /* a split vertex is a second chart vertex with the same (v, vt) */
        std::map<std::pair<uint32_t, uint32_t>, int> pairs;
        for (uint32_t v = 0; v < c.num_vertices; v++)
            pairs[std::make_pair(c.vertex[v], c.vertex_uv ? c.vertex_uv[v] : UINT32_MAX)]++;
        BPT_CHECK(c.num_vertices - pairs.size() == c.split_vertices,
                  "%s chart %u: %u chart vertices, %zu distinct (v, vt) pairs: the copies are the %u split vertices",
                  name, ci, c.num_vertices, pairs.size(), c.split_vertices);
        std::vector<int> mv(c.vertex, c.vertex + c.num_vertices);
        std::sort(mv.begin(), mv.end());
        mv.erase(std::unique(mv.begin(), mv.end()), mv.end());
        BPT_CHECK(mv == rc.mesh_vertices, "%s chart %u: same mesh vertices as the reference (%zu vs %zu)", name, ci,
                  mv.size(), rc.mesh_vertices.size());

        /* Euler characteristic: ours from V, F and the edges of its triangles */
        std::map<std::pair<uint32_t, uint32_t>, int> edges;
        for (uint32_t t = 0; t < c.num_triangles; t++)
            for (int k = 0; k < 3; k++) {
                uint32_t a = c.triangles[3 * t + k], b = c.triangles[3 * t + (k + 1) % 3];
                edges[std::make_pair(std::min(a, b), std::max(a, b))]++;
            }
        int chi = (int)c.num_vertices - (int)edges.size() + (int)c.num_triangles;
        BPT_CHECK(chi - (int)c.split_vertices == rc.chi, "%s chart %u: Euler characteristic %d (%d before splitting), OpenMesh %d%s",
                  name, ci, chi, chi - (int)c.split_vertices, rc.chi, note);
        BPT_CHECK((int)c.num_loops == x.nloops, "%s chart %u: %u loops (README: %d)", name, ci, c.num_loops, x.nloops);
        BPT_CHECK(chi == 2 - (int)c.num_loops && c.num_loops >= 1,
                  "%s chart %u: a disk with holes after splitting: chi %d == 2 - %u loops", name, ci, chi, c.num_loops);

        std::vector<int> ours;
        for (uint32_t l = 0; l < c.num_loops; l++) ours.push_back((int)(c.loop_start[l + 1] - c.loop_start[l]));
        std::sort(ours.rbegin(), ours.rend());
        BPT_CHECK(ours == rc.fan_loops, "%s chart %u: loop lengths %s, OpenMesh per-fan walk %s%s", name, ci,
                  list_str(ours).c_str(), list_str(rc.fan_loops).c_str(), note);
        if (!pinched)
            BPT_CHECK(ours == rc.om_loops, "%s chart %u: loop lengths %s, OpenMesh next_halfedge loops %s", name, ci,
                      list_str(ours).c_str(), list_str(rc.om_loops).c_str());
        else
            BPT_CHECK(std::accumulate(ours.begin(), ours.end(), 0) == std::accumulate(rc.om_loops.begin(), rc.om_loops.end(), 0),
                      "%s chart %u: total boundary length %d equals OpenMesh's (its own next_halfedge loops %s pair the pinch gaps arbitrarily)",
                      name, ci, std::accumulate(ours.begin(), ours.end(), 0), list_str(rc.om_loops).c_str());
        if (!x.loops.empty() && atlas.num_charts == 1)
            BPT_CHECK(ours == x.loops, "%s: loops %s (README: %s)", name, list_str(ours).c_str(), list_str(x.loops).c_str());
        check_our_loops(name, ci, c, mesh);
    }
    if (x.split > 0) {
        int pinched_charts = 0;
        for (uint32_t ci = 0; ci < atlas.num_charts; ci++) pinched_charts += atlas.charts[ci].split_vertices > 0;
        BPT_CHECK(pinched_charts == 2, "%s: %d charts have split vertices (README: 2)", name, pinched_charts);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

int main(void)
{
    static const int l_bishop[] = {16}, l_camel[] = {486}, l_face[] = {136, 36, 32, 28, 28, 28, 16},
                     l_shark[] = {96, 80, 80, 48}, l_camelhead[] = {56}, l_torus[] = {50, 34};
#define LOOPS(a) std::vector<int>(a, a + sizeof(a) / sizeof(a[0]))
    /* path, V, F, reject, charts, split, chi of the whole uncut mesh, loops
       per chart, loop lengths (tests/data/README.md) */
    Expect all[] = {
        {"tests/data/bishop_part_f1000.obj", 509, 1000, false, 1, 0, 1, 1, LOOPS(l_bishop)},
        {"tests/data/torus_with_holes.obj", 959, 1838, true, 1, 0, -2, 2, LOOPS(l_torus)},
        {"tests/data/camel_b.obj", 2032, 3576, false, 1, 0, 1, 1, LOOPS(l_camel)},
        {"tests/data/cow_param_withSUV.obj", 2904, 5804, false, 1, 0, 2, 1, std::vector<int>()},
        {"tests/data/spot.obj", 2930, 5856, false, 13, 4, 2, 1, std::vector<int>()},
        {"tests/data/face_holes.off", 4291, 8288, false, 1, 0, -5, 7, LOOPS(l_face)},
        {"tests/data/fertility.off", 4494, 9000, true, 1, 0, -6, 0, std::vector<int>()},
        {"tests/data/mech-holes-shark.off", 5246, 10192, false, 1, 0, -2, 4, LOOPS(l_shark)},
        {"tests/data/camelhead.off", 11381, 22704, false, 1, 0, 1, 1, LOOPS(l_camelhead)},
    };
#undef LOOPS
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) check_mesh(all[i]);
    return bpt_finish();
}
