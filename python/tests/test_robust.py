"""Bad, random and adversarial input never crashes the interpreter: it
raises MeshError (a ValueError) naming the element, or MemoryError; every
map that comes back is bijective.  And the GIL: two calls on two threads
run at once, Ctrl-C cancels."""
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings

import numpy as np
import pytest

import bijparam
import independent
from conftest import ROOT, grid, torus


def outcome(*args, **kw):
    """parametrize's result, or the exception it raised (only the expected
    kinds: anything else fails the test).  When the float32 uvs lost
    bijectivity in the rounding, the warning must say so truthfully (the
    library's check refuses them too), and the float64 map is returned."""
    try:
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            r = bijparam.parametrize(*args, **kw)
        if w:
            assert len(w) == 1 and issubclass(w[0].category, bijparam.BijectivityWarning)
            assert r.report["uvs_check"] != "ok"
            v = bijparam.check(np.asarray(args[0], dtype=np.float64), args[1], r.uvs, r.indices)
            assert not v or r.report["repairs"]["total"], "the warning says the float32 map is not bijective"
            r = bijparam.parametrize(*args, **kw, uv_dtype=np.float64)
        else:
            assert r.report["uvs_check"] == "ok"
        return r
    except (bijparam.MeshError, bijparam.ChartsFailedError, bijparam.SolveError, MemoryError) as e:
        return e


def assert_valid(pos, faces, r):
    """A result that came back keeps the faces and is bijective: judged by
    tests/uvcheck.py when nothing was repaired, else (faces re-oriented or
    dropped keep their rows) by the library's check, which repairs the
    same way."""
    if isinstance(r, bijparam.ChartsFailedError):
        r = r.result
    elif isinstance(r, Exception):
        return
    keep = ~r.failed_faces
    assert (r.vmapping[r.indices] == np.asarray(faces, dtype=np.int64)).all()
    if not keep.any():
        return
    sub = r.indices[keep]
    used, local = np.unique(sub, return_inverse=True)
    if r.report["repairs"]["total"] == 0:
        ok, why = independent.bijective(r.uvs[used], local.reshape(-1, 3))
        assert ok, why
    v = bijparam.check(np.asarray(pos, dtype=np.float64), np.asarray(faces)[keep], r.uvs, sub)
    assert v, v.message


def test_bad_arrays_raise_value_errors_naming_the_element():
    pos, faces = grid(3)

    def err(*a, **k):
        with pytest.raises(ValueError) as e:
            bijparam.parametrize(*a, **k)
        return e.value

    p = pos.copy()
    p[5, 1] = np.nan
    e = err(p, faces)
    assert e.status == "BP_ERR_NONFINITE" and e.element == "vertex" and e.index == 5 and "positions[5]" in str(e)
    p[5, 1] = -np.inf
    assert err(p, faces).index == 5
    q = pos.copy()
    q[len(pos) - 1] = np.nan                                # a vertex no face uses may be NaN
    unused = np.vstack([pos, [[np.nan, 0, 0]]])
    assert isinstance(bijparam.parametrize(unused, faces, resolution=64), tuple)
    f = faces.copy()
    f[7, 2] = len(pos)
    e = err(pos, f)
    assert e.status == "BP_ERR_INDEX" and e.index == 7 and "indices[7]" in str(e) and "out of range" in str(e)
    f[7, 2] = -3
    e = err(pos, f)
    assert e.index == 7 and "-3" in str(e)
    assert err(pos, faces.astype(np.uint64) + 2 ** 40).index == 0
    assert err(np.zeros((0, 3)), faces).status in ("BP_ERR_EMPTY", "BP_ERR_INDEX")
    assert err(pos, np.zeros((0, 3), int)).status == "BP_ERR_EMPTY"
    for bad_pos in (pos[:, :2], pos.reshape(-1), pos.astype(bool), pos.astype(complex), np.array([["a", "b", "c"]]),
                    np.array([[object(), 1, 2]]), np.zeros((2, 3, 1))):
        assert err(bad_pos, faces).status == "BP_ERR_INVALID_ARGUMENT"
    for bad_faces in (faces.astype(float), faces[:, :2], faces.astype(bool), faces.reshape(-1), [[0, 1]]):
        assert err(pos, bad_faces).status == "BP_ERR_INVALID_ARGUMENT"
    # sizes beyond the library's limits, without the memory they would take
    assert err(np.broadcast_to(np.zeros(3), (2 ** 32, 3)), faces).status == "BP_ERR_TOO_LARGE"
    e = err(pos, np.broadcast_to(np.zeros(3, np.uint32), (bijparam.MAX_TRIANGLES + 1, 3)))
    assert e.status == "BP_ERR_TOO_LARGE" and "at most 1431655764" in str(e)
    # options out of range
    for kw in (dict(resolution=-1), dict(resolution=40000), dict(resolution=8, padding=8), dict(padding=-1),
               dict(resolution=0, padding=2), dict(energy="x"), dict(threads=-1), dict(threads=1.5),
               dict(max_distortion=float("nan")), dict(max_distortion=-1), dict(cut="maybe"), dict(segment=2),
               dict(importance=np.ones(3)), dict(importance=-np.ones(len(faces))), dict(visibility="top"),
               dict(view_dir=(0, 0, 0)), dict(ring_elevation=91), dict(vis_floor=0), dict(uv_dtype=np.int32),
               dict(init="input"), dict(pins={10 ** 12: (0, 0)}, resolution=0), dict(pins=[1, 2, 3], resolution=0),
               dict(max_iterations=-5), dict(memory_limit=-1), dict(seed=-1)):
        assert isinstance(err(pos, faces, **kw), bijparam.MeshError), kw
    with pytest.raises(TypeError):
        bijparam.parametrize(pos, faces, no_such_option=1)


def test_library_refusals_are_value_errors():
    """Defects strict mode refuses; pins the library cannot honour."""
    pos, faces = grid(3)
    f = np.vstack([faces, faces[:1]])                      # a duplicate face
    with pytest.raises(ValueError) as e:
        bijparam.parametrize(pos, f, strict=True)
    assert e.value.status == "BP_ERR_DUPLICATE_FACE"
    r = bijparam.parametrize(pos, f)                        # repaired by default, and reported
    assert r.report["repairs"]["duplicate"]["count"] == 1
    flip = faces.copy()
    flip[4] = flip[4][::-1]
    with pytest.raises(ValueError) as e:
        bijparam.parametrize(pos, flip, strict=True)
    assert e.value.status == "BP_ERR_ORIENTATION"
    r = bijparam.parametrize(pos, flip)
    assert r.report["repairs"]["flipped"]["count"] == 1
    assert bijparam.check(pos, flip, r.uvs, r.indices)      # judged in the repaired orientation
    with pytest.raises(ValueError, match="pin"):
        bijparam.parametrize(pos, faces, pins={0: (0, 0), 1: (0, 0)}, resolution=0)   # two pins on one point


def test_random_arrays_never_crash():
    rng = np.random.default_rng(40)
    for trial in range(60):
        n = int(rng.integers(1, 40))
        m = int(rng.integers(1, 60))
        pos = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-30, 30)
        faces = rng.integers(-2, n + 2, size=(m, 3))
        if trial % 3:
            faces = np.clip(faces, 0, n - 1)
        r = outcome(pos, faces, resolution=int(rng.choice([0, 64, 1024])), threads=int(rng.integers(0, 3)))
        assert_valid(pos, faces, r)


def test_adversarial_meshes():
    pos, faces = grid(4)
    cases = []
    cases.append((np.zeros((3, 3)), np.array([[0, 1, 2]])))                     # one point
    cases.append((pos, np.array([[0, 0, 0], [1, 1, 2]])))                        # repeated vertices
    cases.append((np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]), np.array([[0, 1, 2]])))   # collinear
    cases.append((pos * 1e300, faces))
    cases.append((pos * 1e-300, faces))
    cases.append((pos * 5e-324, faces))                                          # subnormal
    cases.append((np.where(np.arange(len(pos))[:, None] % 2, pos * 1e300, pos * 1e-300), faces))
    cases.append((-0.0 * pos, faces))
    # a bow tie: two triangles touching at one vertex
    cases.append((np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0.0]]), np.array([[0, 1, 2], [0, 3, 4]])))
    # ten triangles on one edge
    fan = np.array([[0, 0, 0], [1, 0, 0]] + [[0.5, np.cos(a), np.sin(a)] for a in np.linspace(0, 6, 10)])
    cases.append((fan, np.array([[0, 1, k] for k in range(2, 12)])))
    # a Moebius strip
    k = 12
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    ring = np.concatenate([np.stack([np.cos(t) * (1 + s * np.cos(t / 2)), np.sin(t) * (1 + s * np.cos(t / 2)),
                                     s * np.sin(t / 2)], -1) for s in (-0.3, 0.3)])
    mf = []
    for i in range(k):
        j = (i + 1) % k
        a, b, c, d = i, j, k + j, k + i
        if j == 0:
            c, b = j, k + j                                                       # the half twist
        mf += [(a, b, c), (a, c, d)]
    cases.append((ring, np.array(mf)))
    # the same triangle twice, wound both ways
    cases.append((pos, np.vstack([faces, faces[:1, ::-1]])))
    cases.append((torus(8, 4)[0], torus(8, 4)[1]))
    for p, f in cases:
        for res in (0, 256):
            r = outcome(p, f, resolution=res)
            assert_valid(p, f, r)


def test_allocation_failures_raise_memory_error():
    """Every allocation of the library may fail: under budgets from 1 KB to
    beyond what the call needs, each call is either MemoryError or a
    bijective map (the budget allocator refuses past its limit)."""
    pos, faces = torus(16, 8)
    seen = set()
    for limit in np.unique(np.geomspace(1_000, 4_000_000, 70).astype(int)):
        r = outcome(pos, faces, resolution=256, memory_limit=int(limit), threads=int(limit % 3))
        seen.add(type(r).__name__)
        assert not isinstance(r, bijparam.Error) or "memory" in str(r).lower(), r
        assert_valid(pos, faces, r)
    assert {"MemoryError", "Result"} <= seen


def test_native_layer_checks_its_arguments():
    """The private layer refuses anything but its exact arrays (never reads past them)."""
    pos, faces = grid(2)
    p = np.ascontiguousarray(pos)
    f = np.ascontiguousarray(faces, dtype=np.uint32)
    args = [p, f, None, None, None, None, 0, {}, None, None, None, False, None]
    bad = [(0, pos.astype(np.float32)), (0, np.asfortranarray(p)), (0, p[:, :2].copy()), (1, faces),
           (1, f[::2]), (0, [[0, 0, 0]]), (2, f[:1]), (4, np.zeros(3, np.uint32)), (7, []), (8, np.ones(2)),
           (9, (1, 2)), (10, np.ones((2, 3))), (12, 5)]
    for k, v in bad:
        a = list(args)
        a[k] = v
        with pytest.raises((TypeError, ValueError)):
            bijparam._native.parametrize(*a)
    with pytest.raises((TypeError, ValueError)):
        bijparam._native.check(p, f, f, np.zeros((3, 3)), 0)
    with pytest.raises(TypeError):
        bijparam._native.parametrize(p)


def test_two_threads_run_at_once(data):
    """With the GIL released, two calls on two threads (threads=1 each)
    run at the same time: each one's optimization reports arrive while the
    other one is optimizing.  (Holding the GIL, the second call could not
    even start before the first returned.)  The wall times are printed;
    make bench-python measures them."""
    m = bijparam.read_mesh(data("camel_b.obj"))
    t0 = time.perf_counter()
    bijparam.parametrize(m.positions, m.indices, resolution=0, threads=1)
    alone = time.perf_counter() - t0
    stamps = {0: [], 1: []}

    def run(k):
        bijparam.parametrize(m.positions, m.indices, resolution=0, threads=1,
                             progress=lambda s, f: s == "optimize" and stamps[k].append(time.perf_counter()))
    th = [threading.Thread(target=run, args=(k,)) for k in (0, 1)]
    t0 = time.perf_counter()
    for t in th:
        t.start()
    # meanwhile this thread runs Python: the GIL is free
    ticks = 0
    while any(t.is_alive() for t in th):
        ticks += 1
        time.sleep(0.001)
    both = time.perf_counter() - t0
    a, b = stamps[0], stamps[1]
    assert len(a) > 2 and len(b) > 2
    inside = sum(a[0] < x < a[-1] for x in b) + sum(b[0] < x < b[-1] for x in a)
    assert inside >= 2, "the two calls did not overlap"
    assert ticks > 10
    print(f"one call {alone:.3f} s, two calls on two threads {both:.3f} s (ratio {both / alone:.2f})")


CTRL_C_CHILD = textwrap.dedent("""
    import sys, time, bijparam
    m = bijparam.read_mesh(sys.argv[1])
    reports = []
    def progress(stage, fraction):
        reports.append(stage)
        if stage == "optimize" and reports.count("optimize") == 1:
            print("optimizing", flush=True)
    try:
        bijparam.parametrize(m.positions, m.indices, resolution=0, tolerance=1e-300, max_iterations=100000,
                             direction="lbfgs", threads=1, progress=progress)
        print("finished")
    except KeyboardInterrupt:
        t = time.perf_counter()
        print("interrupted", reports.count("optimize"), flush=True)
    r = bijparam.parametrize(m.positions, m.indices, resolution=64)   # the next call is unharmed
    print("again", r.report["status"])
""")


def test_ctrl_c_cancels(data):
    env = dict(os.environ)
    child = subprocess.Popen([sys.executable, "-c", CTRL_C_CHILD, data("fertility.off")], stdout=subprocess.PIPE,
                             text=True, env=env)
    line = child.stdout.readline()
    assert line.strip() == "optimizing"
    time.sleep(0.3)
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 0
    lines = out.split("\n")
    assert lines[0].startswith("interrupted"), out
    assert lines[1] == "again ok"


def test_random_files_never_crash(tmp_path, data):
    """Random bytes, and real files cut short or with bytes flipped, under
    every extension the readers take: MeshError or FileError, or a mesh."""
    rng = np.random.default_rng(41)
    seeds = [open(data("spot.obj"), "rb").read(), open(data("fertility.off"), "rb").read(),
             open(data(os.path.join("gltf", "BoxTextured.glb")), "rb").read()]
    for trial in range(80):
        ext = [".obj", ".off", ".ply", ".glb", ".gltf"][trial % 5]
        if trial % 3 == 0:
            blob = rng.integers(0, 256, size=int(rng.integers(0, 400)), dtype=np.uint8).tobytes()
        else:
            b = bytearray(seeds[trial % 3])
            b = b[: int(rng.integers(1, len(b) + 1))]
            for _ in range(int(rng.integers(0, 8))):
                if b:
                    b[int(rng.integers(0, len(b)))] = int(rng.integers(0, 256))
            blob = bytes(b)
        path = tmp_path / f"f{trial}{ext}"
        path.write_bytes(blob)
        try:
            m = bijparam.read_mesh(str(path))
        except (bijparam.MeshError, bijparam.FileError, MemoryError):
            continue
        assert m.indices.shape[1] == 3 and (m.indices < max(len(m.positions), 1)).all()
