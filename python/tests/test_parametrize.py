"""parametrize: xatlas-python's call and shapes, bijective atlases, the
tool's report and output, every dtype and layout, the options."""
import filecmp
import json
import os
import subprocess

import numpy as np
import pytest

import bijparam
import independent
from conftest import grid, torus


def assert_atlas(pos, faces, result, resolution=1024, padding=4):
    """What parametrize promises, proved without the library: xatlas's
    shapes and dtypes, every face's vertices in their order, uvs in [0,1],
    the map bijective (tests/uvcheck.py, exact), the charts `padding`
    texels apart."""
    vmapping, indices, uvs = result
    assert vmapping.dtype == np.uint32 and vmapping.ndim == 1
    assert indices.dtype == np.uint32 and indices.shape == (len(faces), 3)
    assert uvs.dtype == np.float32 and uvs.shape == (len(vmapping), 2)
    assert (vmapping[indices] == np.asarray(faces)).all(), "a face lost its vertices or their order"
    assert vmapping.max() < len(pos)
    assert len(np.unique(indices)) == len(vmapping), "an output vertex no face uses"
    assert uvs.min() >= 0 and uvs.max() <= 1
    ok, why = independent.bijective(uvs, indices)
    assert ok, why
    if padding:
        gap = independent.chart_gap(uvs, indices, 2 * padding / resolution) * resolution
        assert gap >= padding * (1 - 1e-4), f"charts {gap} texels apart, padding {padding}"
    assert result.report["status"] == "ok" and result.report["uvs_check"] == "ok"


@pytest.fixture(scope="module")
def camel(data):
    m = bijparam.read_mesh(data("camel_b.obj"))
    return m, bijparam.parametrize(m.positions, m.indices, resolution=1024, padding=4)


@pytest.fixture(scope="module")
def spot(data):
    m = bijparam.read_mesh(data("spot.obj"))
    return m, bijparam.parametrize(m.positions, m.indices, resolution=1024, padding=4)


def test_camel_bijective_atlas(camel):
    m, r = camel
    assert_atlas(m.positions, m.indices, r)
    assert bijparam.check(m.positions, m.indices, r.uvs, r.indices)


def test_spot_bijective_atlas(spot):
    m, r = spot
    assert_atlas(m.positions, m.indices, r)
    assert r.charts > 1
    assert bijparam.check(m.positions, m.indices, r.uvs, r.indices)


def test_closed_torus_without_seams():
    """Genus 1, closed, no seams: cut into disks, bijective."""
    pos, faces = torus()
    r = bijparam.parametrize(pos, faces, resolution=1024, padding=4)
    assert_atlas(pos, faces, r)
    assert sum(c["cut_edges"] for c in r.report["per_chart"]) > 0
    # refused without cutting: the library's message says why
    with pytest.raises(bijparam.MeshError, match="genus 1") as e:
        bijparam.parametrize(pos, faces, cut="none", resolution=0)
    assert e.value.status == "BP_ERR_TOPOLOGY" and e.value.element == "chart"
    # beside a disk, only the torus fails: the disk's atlas comes with the error
    gp, gf = grid(4)
    both_pos = np.vstack([pos, gp + 5])
    both = np.vstack([faces, gf + len(pos)])
    with pytest.raises(bijparam.ChartsFailedError, match="1 of 2 charts failed") as e:
        bijparam.parametrize(both_pos, both, cut="none", resolution=0)
    r = e.value.result
    assert np.array_equal(r.failed_faces, np.arange(len(both)) < len(faces))
    assert np.isnan(r.uvs[r.indices[r.failed_faces]]).all()
    assert np.isfinite(r.uvs[r.indices[~r.failed_faces]]).all()


def test_torus_with_holes(data):
    m = bijparam.read_mesh(data("torus_with_holes.obj"))
    r = bijparam.parametrize(m.positions, m.indices)
    assert_atlas(m.positions, m.indices, r)


def test_the_checks_can_fail(spot):
    """Both checkers see a flipped triangle and a chart moved onto another."""
    m, r = spot
    uv = r.uvs.copy()
    a, b, c = r.indices[0]
    uv[a], uv[b] = uv[b].copy(), uv[a].copy()
    assert not independent.bijective(uv, r.indices)[0]
    v = bijparam.check(m.positions, m.indices, uv, r.indices)
    assert not v and v.counts["flipped"] + v.counts["boundary_intersections"] > 0
    # one chart translated onto another: no triangle flips, the charts overlap
    label = independent.components(r.indices, len(uv))
    uv = r.uvs.copy()
    ids, counts = np.unique(label, return_counts=True)
    big, small = ids[np.argsort(counts)[-1]], ids[np.argsort(counts)[0]]
    target = r.uvs[label == big].mean(axis=0)
    uv[label == small] += target - r.uvs[label == small].mean(axis=0)
    assert not independent.bijective(uv, r.indices)[0]
    v = bijparam.check(m.positions, m.indices, uv, r.indices)
    assert not v and "chart" in v.message or not v


def test_check_names_rows(spot):
    m, r = spot
    uv = r.uvs.astype(np.float64)
    t = 17
    a, b, c = r.indices[t]
    uv[c] = uv[a] + (uv[a] - uv[c])             # mirror one corner: flips face 17
    v = bijparam.check(m.positions, m.indices, uv, r.indices)
    assert not v.bijective and "face " in v.message and v.status != "BP_OK"


def test_same_file_and_report_as_the_tool(data, tool, tmp_path):
    """read_mesh + parametrize(mesh) + write: the tool's -o output byte for
    byte, and its --json report field for field (times and memory aside)."""
    for name in ("camel_b.obj", "fertility.off"):
        out_tool = str(tmp_path / f"tool_{name}.obj")
        p = subprocess.run([tool, data(name), "--atlas", "1024", "--padding", "4", "--threads", "2", "--json",
                            "-o", out_tool], capture_output=True, text=True, check=True)
        want = json.loads(p.stdout)
        m = bijparam.read_mesh(data(name))
        r = bijparam.parametrize(m, threads=2)
        out = str(tmp_path / f"py_{name}.obj")
        r.write(out)
        assert filecmp.cmp(out_tool, out, shallow=False), name
        got = r.report
        assert [k for k in got if k in want] == list(want), "the keys, in the tool's order"
        for k in want:
            if k in ("timings", "cpu_timings", "peak_rss_bytes", "bytes_per_face", "input", "output"):
                assert k not in ("timings", "cpu_timings") or list(got[k])[:len(want[k])] == list(want[k])
                continue
            if k == "per_chart":
                for a, b in zip(want[k], got[k]):
                    assert {x: y for x, y in a.items() if x != "seconds"} == \
                           {x: y for x, y in b.items() if x != "seconds"}
            else:
                assert got[k] == want[k], k
        assert got["output"] == out and os.path.basename(got["input"]) == name


def test_dtypes_and_layouts_give_the_same_bits():
    pos, faces = grid(6, 5, z=lambda x, y: 0.3 * np.sin(x) * np.cos(y))
    ref = bijparam.parametrize(pos, faces, resolution=256, padding=2, threads=1)
    variants = []
    for dt in (np.int8, np.uint8, np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64):
        variants.append((pos, faces.astype(dt)))
    variants.append((np.asfortranarray(pos), np.asfortranarray(faces)))
    wide = np.zeros((len(pos), 7))
    wide[:, 2:5] = pos
    strided = np.zeros((2 * len(faces), 3), dtype=np.int64)
    strided[::2] = faces
    variants.append((wide[:, 2:5], strided[::2]))                  # non-contiguous views
    variants.append((pos.tolist(), faces.tolist()))                 # lists
    variants.append((pos.astype(">f8"), faces.astype(">i4")))       # big-endian
    for p, f in variants:
        r = bijparam.parametrize(p, f, resolution=256, padding=2, threads=1)
        for x, y in zip(r, ref):
            assert x.dtype == y.dtype and np.array_equal(x, y)
    # float32 positions: the map of those very values in float64
    p32 = pos.astype(np.float32)
    a = bijparam.parametrize(p32, faces, resolution=256, padding=2, threads=1)
    b = bijparam.parametrize(p32.astype(np.float64), faces, resolution=256, padding=2, threads=1)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    # float64 uvs: the library's map itself, whose float32 rounding is the default's
    c = bijparam.parametrize(pos, faces, resolution=256, padding=2, threads=1, uv_dtype=np.float64)
    assert c.uvs.dtype == np.float64 and np.array_equal(c.uvs.astype(np.float32), ref.uvs)


def test_threads_give_the_same_bits(data):
    m = bijparam.read_mesh(data("face_holes.off"))
    a = bijparam.parametrize(m.positions, m.indices, threads=1, resolution=512)
    b = bijparam.parametrize(m.positions, m.indices, threads=2, resolution=512)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert a.report["threads"] == 1 and b.report["threads"] == 2


def test_xatlas_signature_and_tuple():
    pos, faces = grid(4)
    normals = np.tile([0.0, 0.0, 1.0], (len(pos), 1))
    r = bijparam.parametrize(pos, faces, normals)                  # xatlas's third positional
    vmapping, indices, uvs = r
    assert isinstance(r, tuple) and len(r) == 3
    assert r.vmapping is vmapping and r.indices is indices and r.uvs is uvs
    import pickle
    back = pickle.loads(pickle.dumps(r))
    assert back.report == r.report and all(np.array_equal(x, y) for x, y in zip(back, r))


def test_options_take_effect(data):
    pos, faces = grid(12, z=lambda x, y: 0.02 * (x - 6) ** 2 + 0.05 * y * y)
    base = bijparam.parametrize(pos, faces, resolution=0)
    assert base.charts == 1 and base.report["atlas_resolution"] == 0
    # energy, max_iterations, init, direction are the library's
    r = bijparam.parametrize(pos, faces, resolution=0, energy="mips", max_iterations=3, init="tutte",
                             start="plain", direction="lbfgs")
    ch = r.report["per_chart"][0]
    assert ch["iterations"] <= 3 and ch["start_map"] == "tutte" and ch["direction"] == "lbfgs"
    assert ch["energy_end"] >= 2 - 1e-12                            # MIPS' minimum is 2
    # max_charts with segmentation on
    tp, tf = torus(24, 12)
    s = [bijparam.parametrize(tp, tf, resolution=256, max_charts=k).charts for k in (3, 0)]
    assert 1 < s[0] <= 3 < s[1]
    assert [bijparam.parametrize(tp, tf, resolution=256, segment=v).charts for v in ("off", False)] == [1, 1]
    # importance: the heavy half of the faces gets more of the uv area
    imp = np.where(np.arange(len(faces)) < len(faces) // 2, 8.0, 1.0)
    w = bijparam.parametrize(pos, faces, resolution=0, importance=imp, uv_dtype=np.float64)

    def share(res):
        uv = res.uvs[res.indices]
        area = 0.5 * np.abs(np.cross(uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]))
        return area[: len(faces) // 2].sum() / area.sum()
    assert share(w) > share(base) + 0.15
    # visibility: a report of the view model's run (a front view of a bowl)
    v = bijparam.parametrize(pos, faces, resolution=0, visibility="front", view_dir=(0, 0, 1), vis_samples=8)
    assert v.report["status"] == "ok"


def test_pins_land_exactly():
    pos, faces = grid(6, z=lambda x, y: 0.1 * x * y)
    targets = {0: (0.0, 0.0), 6: (6.5, 0.0)}
    r = bijparam.parametrize(pos, faces, pins=targets, uv_dtype=np.float64)
    for v, t in targets.items():
        k = np.flatnonzero(r.vmapping == v)
        assert len(k) == 1 and tuple(r.uvs[k[0]]) == t
    assert r.report["per_chart"][0]["pins"] == 2
    with pytest.raises(bijparam.MeshError):                          # pins cannot be packed into [0,1]
        bijparam.parametrize(pos, faces, pins=targets, resolution=1024)


def test_own_uvs_as_the_start(spot):
    m, r = spot
    again = bijparam.parametrize(m.positions, m.indices, uvs=r.uvs, uv_indices=r.indices, resolution=1024,
                                 max_iterations=1)
    assert all(c["init_used"] == 1 and c["start_map"] == "input" for c in again.report["per_chart"])
    assert again.charts == r.charts                                  # the seams of the uv indices kept
    assert_atlas(m.positions, m.indices, again)


def test_progress_on_the_calling_thread(data):
    import threading
    m = bijparam.read_mesh(data("camel_b.obj"))
    seen = []
    bijparam.parametrize(m.positions, m.indices, progress=lambda s, f: seen.append((s, f, threading.get_ident())))
    assert seen and all(t == threading.get_ident() for _, _, t in seen)
    stages = [s for s, _, _ in seen]
    assert stages[0] == "charts" and "optimize" in stages and stages[-1] == "pack" and seen[-1][1] == 1
    assert all(0 <= f <= 1 for _, f, _ in seen)
    order = ["read", "charts", "start", "visibility", "optimize", "pack", "write"]
    firsts = sorted(set(stages), key=stages.index)
    assert firsts[:2] == ["charts", "start"] and set(firsts) <= set(order)


def test_progress_exception_propagates(data):
    m = bijparam.read_mesh(data("fertility.off"))

    class Stop(Exception):
        pass
    calls = []

    def progress(stage, fraction):
        calls.append(stage)
        if stage == "optimize":
            raise Stop("from the callback")
    with pytest.raises(Stop, match="from the callback"):
        bijparam.parametrize(m.positions, m.indices, resolution=0, progress=progress)
    assert calls.count("optimize") == 1, "the callable is not called again after it raised"


def test_write_keeps_the_users_file(data, tmp_path):
    """An OBJ input streams through bp_write_obj_from: every line but the
    vt lines and the faces' vt indices comes back as it was."""
    src = tmp_path / "in.obj"
    text = open(data("camel_b.obj"), encoding="ascii").read()
    src.write_text("# my comment\nmtllib my.mtl\n" + text.replace("\nf ", "\nusemtl skin\nf ", 1))
    m = bijparam.read_mesh(str(src))
    r = bijparam.parametrize(m)
    out = tmp_path / "out.obj"
    os.chmod(src, 0o640)
    r.write(str(out))
    before = [ln for ln in src.read_text().splitlines() if not ln.startswith(("vt ", "f "))]
    after = [ln for ln in out.read_text().splitlines() if not ln.startswith(("vt ", "f ")) and not ln.startswith("# bijparam")]
    assert [ln for ln in after if ln] == [ln for ln in before if ln] or after[-len(before):] == before
    fin = [ln.split() for ln in src.read_text().splitlines() if ln.startswith("f ")]
    fout = [ln.split() for ln in out.read_text().splitlines() if ln.startswith("f ")]
    assert [[c.split("/")[0] for c in f] for f in fin] == [[c.split("/")[0] for c in f] for f in fout]
    assert r.report["output"] == str(out)
    # the new file is the user's umask's; no temporary is left beside it
    assert sorted(os.listdir(tmp_path)) == ["in.obj", "out.obj"]
    # refused onto the input unless force
    with pytest.raises(bijparam.FileError):
        r.write(str(src))
    r.write(str(src), force=True)
    assert oct(os.stat(src).st_mode & 0o777) == oct(0o640), "a replaced file keeps its mode"
    v = bijparam.read_mesh(str(src))
    assert bijparam.check(v.positions, v.indices, v.uvs, v.uv_indices)


def test_write_is_whole_or_nothing(data, tmp_path):
    m = bijparam.read_mesh(data("spot.obj"))
    r = bijparam.parametrize(m)
    out = tmp_path / "keep.obj"
    out.write_text("precious\n")

    def stop(stage, fraction):
        if stage == "write":
            raise KeyError("stop writing")
    with pytest.raises(KeyError):
        r.write(str(out), progress=stop)
    assert out.read_text() == "precious\n" and sorted(os.listdir(tmp_path)) == ["keep.obj"]
    with pytest.raises(bijparam.FileError):
        r.write(str(tmp_path / "no" / "such" / "dir.obj"))
    r.write(str(out), source=False)                                   # from the mesh alone
    lines = out.read_text().splitlines()
    assert sum(ln.startswith("f ") for ln in lines) == m.num_faces


def test_read_mesh_formats(data, tmp_path):
    off = bijparam.read_mesh(data("fertility.off"))
    assert off.format == "obj" or off.format == "off"
    assert off.positions.dtype == np.float64 and off.indices.dtype == np.uint32 and off.uvs is None
    ply = tmp_path / "t.ply"
    pos, faces = grid(3)
    ply.write_text("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(pos), len(faces))
                   + "".join("%g %g %g\n" % tuple(p) for p in pos) + "".join("3 %d %d %d\n" % tuple(f) for f in faces))
    m = bijparam.read_mesh(str(ply))
    assert np.array_equal(m.positions, pos) and np.array_equal(m.indices, faces)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")
    with pytest.raises(bijparam.MeshError) as e:
        bijparam.read_mesh(str(bad))
    assert e.value.line == 4 and "line 4" in str(e.value)
    with pytest.raises(bijparam.FileError):
        bijparam.read_mesh(str(tmp_path / "missing.obj"))


def test_export_is_xatlas_export(spot, tmp_path):
    m, r = spot
    path = tmp_path / "x.obj"
    bijparam.export(str(path), m.positions[r.vmapping], r.indices, r.uvs)
    back = bijparam.read_mesh(str(path))
    assert np.array_equal(back.indices, r.indices)
    assert np.array_equal(back.uvs.astype(np.float32), r.uvs)
    assert np.array_equal(back.positions, m.positions[r.vmapping])        # float64 read back exactly
