"""bijparam: bijective free-boundary UV parameterization for numpy arrays.

    import bijparam as xatlas            # was: import xatlas
    vmapping, indices, uvs = xatlas.parametrize(positions, faces)

`parametrize` takes and gives exactly what xatlas-python's does -- positions
(N, 3) floats and faces (M, 3) integers in; vmapping (K,) uint32, indices
(M, 3) uint32 (face order and corner order kept) and uvs (K, 2) float32 in
[0, 1] out -- but every chart is bijective (no flipped triangle, no overlap
within or between charts), proved with exact predicates.  The result is
also an object with the report the command-line tool's --json gives.

The library itself is bijparam.h, compiled into bijparam._native; the
README beside this package is the reference.
"""
import os
import stat
import tempfile
import urllib.parse
import warnings

import numpy as np

from . import _native

__all__ = [
    "parametrize", "check", "read_mesh", "export", "Mesh", "Result", "CheckResult",
    "Error", "MeshError", "ChartsFailedError", "SolveError", "FileError", "BijectivityWarning",
    "LIBRARY_VERSION", "__version__",
]

LIBRARY_VERSION = _native.LIBRARY_VERSION
__version__ = LIBRARY_VERSION

_UINT32_MAX = 0xFFFFFFFF


# ---- errors -----------------------------------------------------------------

class Error(Exception):
    """Base of the errors the library reports.

    status   the library's status name, e.g. "BP_ERR_INDEX"
    element  what `index` names: "vertex", "triangle", "edge", "chart",
             "line" or "none"
    index    0-based index of that element, or -1 (index2: an edge's second
             vertex, or -1)
    line     1-based line of the input file when known, else 0
    """

    def __init__(self, message, status="", element="none", index=-1, index2=-1, line=0):
        super().__init__(message)
        self.status, self.element, self.index, self.index2, self.line = status, element, index, index2, line


class MeshError(Error, ValueError):
    """The input cannot be parameterized as given (a ValueError): a wrong
    shape or dtype, an index out of range, a NaN or infinite coordinate, no
    triangles, a size beyond the library's limits, a malformed file, an
    option out of range, or (strict=True) a mesh defect."""


class SolveError(Error, RuntimeError):
    """Floating point could not give a valid map (BP_ERR_NUMERICAL)."""


class FileError(Error, OSError):
    """A file could not be opened, read or written."""


class ChartsFailedError(Error, RuntimeError):
    """Some charts could not be flattened (each chart's "error" in
    result.report["per_chart"] says why); the others are valid.

    result   the Result: the failed charts' faces are in result.failed_faces,
             and their vertices have NaN uvs."""

    def __init__(self, message, result, **kw):
        super().__init__(message, **kw)
        self.result = result


class BijectivityWarning(UserWarning):
    """The float32 uvs, rounded from the library's float64 map, are not
    bijective (a triangle thinner than float32 can resolve): ask for
    uv_dtype=numpy.float64."""


_VALUE_STATUSES = {
    "BP_ERR_INVALID_ARGUMENT", "BP_ERR_PARSE", "BP_ERR_EMPTY", "BP_ERR_INDEX", "BP_ERR_NONFINITE",
    "BP_ERR_POLYGON", "BP_ERR_DEGENERATE", "BP_ERR_DUPLICATE_FACE", "BP_ERR_NONMANIFOLD",
    "BP_ERR_ORIENTATION", "BP_ERR_TOPOLOGY", "BP_ERR_TOO_LARGE",
}


def _locator(element, index, index2, arrays):
    """Where an element named by the library is in the caller's arrays (the
    library's messages number elements from 1, as a file does)."""
    if not arrays or index < 0:
        return ""
    if element == "triangle":
        return f" [indices[{index}] in the arrays]"
    if element == "vertex":
        return f" [positions[{index}] in the arrays]"
    if element == "edge" and index2 >= 0:
        return f" [vertices {index} and {index2} of the arrays]"
    return ""


def _raise(t, arrays=False, path=None, gltf=None):
    """Raise the exception for a failure tuple of _native (a glTF file's
    elements named as the file numbers them)."""
    _, status, status_text, message, element, index, index2, line = t
    text = message + _locator(element, index, index2, arrays)
    if gltf is not None and element in ("triangle", "vertex", "edge") and index >= 0:
        names = [gltf.name("triangle" if element == "triangle" else "vertex", index)]
        if element == "edge" and index2 >= 0:
            names.append(gltf.name("vertex", index2))
        text += " [" + "; ".join(n for n in names if n) + "]"
    if path is not None:
        text = f"{path}: {text}"
    kw = dict(status=status, element=element, index=index, index2=index2, line=line)
    if status == "BP_ERR_OUT_OF_MEMORY":
        raise MemoryError(text)
    if status == "BP_ERR_IO":
        raise FileError(text, **kw)
    if status in _VALUE_STATUSES:
        raise MeshError(text, **kw)
    raise SolveError(text, **kw)


# ---- arrays in --------------------------------------------------------------

def _float_array(a, name, cols):
    arr = np.asarray(a)
    if arr.dtype.kind not in "fiu":
        raise MeshError(f"{name} must hold real numbers (float32 or float64), not {arr.dtype}",
                        status="BP_ERR_INVALID_ARGUMENT")
    if arr.ndim != 2 or arr.shape[1] != cols:
        raise MeshError(f"{name} must have shape (N, {cols}), not {arr.shape}", status="BP_ERR_INVALID_ARGUMENT")
    if arr.shape[0] > _UINT32_MAX:
        raise MeshError(f"{name} has {arr.shape[0]} rows: at most 2^32 - 1", status="BP_ERR_TOO_LARGE")
    return np.ascontiguousarray(arr, dtype=np.float64)


# bp_atlas_build's limit: the 3 corners of every triangle numbered in 32 bits
MAX_TRIANGLES = 1431655764


def _index_array(a, name, cols=3):
    """Any integer dtype, any layout, into C-contiguous uint32.  Values the
    library cannot see as uint32 (negative, or 2^32 and above) are named
    here; an index past the vertex count is left to the library, which
    names it."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "iu":
        raise MeshError(f"{name} must hold integers, not {arr.dtype}", status="BP_ERR_INVALID_ARGUMENT")
    if arr.ndim != 2 or arr.shape[1] != cols:
        raise MeshError(f"{name} must have shape (M, {cols}), not {arr.shape}", status="BP_ERR_INVALID_ARGUMENT")
    limit = MAX_TRIANGLES if cols == 3 else _UINT32_MAX
    if arr.shape[0] > limit:
        raise MeshError(f"too many triangles ({arr.shape[0]} rows in {name}): at most {limit}"
                        if cols == 3 else f"{name} has {arr.shape[0]} rows: at most {limit}", status="BP_ERR_TOO_LARGE")
    if arr.size and arr.dtype != np.uint32:
        bad = None
        if arr.dtype.kind == "i" and arr.min() < 0:
            bad = np.argmax((arr < 0).any(axis=1))
            why = "is negative"
        elif arr.max() > _UINT32_MAX:
            bad = np.argmax((arr > _UINT32_MAX).any(axis=1))
            why = "is 2^32 or more"
        if bad is not None:
            row = arr[bad].tolist()
            v = next(x for x in row if x < 0 or x > _UINT32_MAX)
            raise MeshError(f"{name}[{bad}] = {row}: index {v} {why}", status="BP_ERR_INDEX",
                            element="triangle", index=int(bad))
    return np.ascontiguousarray(arr, dtype=np.uint32)


# ---- options ------------------------------------------------------------------

_ENERGIES = {"sd": 0, "symmetric_dirichlet": 0, "conformal": 1, "mips": 2, "iso": 3, "isometric": 3,
             "maxiso": 4, "max_isometric": 4}
_INITS = {"auto": 0, "mvc": 1, "mean_value": 1, "input": 2, "tutte": 3, "conformal": 4}
_STARTS = {"auto": 0, "plain": 1, "progressive": 2}
_DIRECTIONS = {"default": 0, "lbfgs": 1, "gd": 2, "gradient": 2, "newton": 3, "precond": 4}
_CUTS = {"auto": 0, "none": 1}
_SEGMENTS = {"auto": 0, "on": 1, "off": -1}
_VIEWS = {None: 0, "none": 0, "uniform": 1, "front": 2, "ring": 3, "side": 4}


def _choice(table, value, name):
    if table is _SEGMENTS and isinstance(value, (bool, np.bool_)):
        value = "on" if value else "off"
    try:
        if not isinstance(value, str) and value is not None:
            raise KeyError(value)
        return table[value.lower() if isinstance(value, str) else value]
    except (KeyError, TypeError):
        names = ", ".join(repr(k) for k in table if isinstance(k, str))
        raise MeshError(f"unknown {name} {value!r} (one of {names})", status="BP_ERR_INVALID_ARGUMENT") from None


def _int(value, name, lo, hi=2**31 - 1):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise MeshError(f"{name} must be an integer, not {value!r}", status="BP_ERR_INVALID_ARGUMENT")
    if not lo <= value <= hi:
        raise MeshError(f"{name} must be in [{lo}, {hi}], not {value}", status="BP_ERR_INVALID_ARGUMENT")
    return int(value)


def _num(value, name, lo=0.0, positive=False):
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise MeshError(f"{name} must be a number, not {value!r}", status="BP_ERR_INVALID_ARGUMENT") from None
    if not np.isfinite(x) or x < lo or (positive and x <= 0):
        raise MeshError(f"{name} must be a finite number {'>' if positive else '>='} {lo}, not {value!r}",
                        status="BP_ERR_INVALID_ARGUMENT")
    return x


def _vec3(value, name):
    try:
        v = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        v = ()
    if len(v) != 3 or not all(np.isfinite(v)) or not any(v):
        raise MeshError(f"{name} must be three finite numbers, not all 0, not {value!r}",
                        status="BP_ERR_INVALID_ARGUMENT")
    return v


def _pins(pins, num_vertices):
    """{vertex: (u, v)} or {(vertex, uv): (u, v)}, or (vertices, targets)
    arrays, into the three arrays of _native (uv side: the uv index + 1, 0
    for every side)."""
    if isinstance(pins, dict):
        vx, side, tg = [], [], []
        for key, target in pins.items():
            if isinstance(key, tuple):
                if len(key) != 2:
                    raise MeshError(f"pin key {key!r}: expected vertex or (vertex, uv)", status="BP_ERR_INVALID_ARGUMENT")
                v, s = key
                s = _int(s, "a pin's uv index", 0, _UINT32_MAX - 1) + 1
            else:
                v, s = key, 0
            vx.append(_int(v, "a pinned vertex", 0, _UINT32_MAX))
            side.append(s)
            tg.append(target)
        vx = np.array(vx, dtype=np.uint32)
        side = np.array(side, dtype=np.uint32)
        targets = _float_array(np.array(tg, dtype=np.float64).reshape(-1, 2) if tg else np.zeros((0, 2)), "pin targets", 2)
    else:
        try:
            verts, targets = pins
        except (TypeError, ValueError):
            raise MeshError("pins must be a dict {vertex: (u, v)} or a pair (vertices, targets)",
                            status="BP_ERR_INVALID_ARGUMENT") from None
        vx = _index_array(np.asarray(verts).reshape(-1, 1), "pin vertices", 1).reshape(-1)
        side = np.zeros(len(vx), dtype=np.uint32)
        targets = _float_array(targets, "pin targets", 2)
        if len(targets) != len(vx):
            raise MeshError(f"pins: {len(vx)} vertices but {len(targets)} targets", status="BP_ERR_INVALID_ARGUMENT")
    return vx, side, targets


def _options(kw, num_faces, has_uvs):
    """The keyword options into the dict _native reads and the extra
    arrays (importance, pins, views)."""
    kw = dict(kw)
    o = {}
    pins = kw.pop("pins", None)
    resolution = kw.pop("resolution", None)
    padding = kw.pop("padding", None)
    if resolution is None:
        resolution = 0 if pins is not None else 1024
    o["atlas_resolution"] = _int(resolution, "resolution", 0, 32768)
    if padding is None:
        padding = 4 if o["atlas_resolution"] else 0
    o["padding"] = _int(padding, "padding", 0)
    if o["padding"] and not o["atlas_resolution"]:
        raise MeshError("padding needs a resolution (texels are what it counts)", status="BP_ERR_INVALID_ARGUMENT")
    if o["atlas_resolution"] and o["padding"] >= o["atlas_resolution"]:
        raise MeshError(f"padding {o['padding']} must be less than the resolution {o['atlas_resolution']}",
                        status="BP_ERR_INVALID_ARGUMENT")
    o["normalize"] = 0 if pins is not None else 1
    o["threads"] = _int(kw.pop("threads", 0), "threads", 0, 256)
    o["energy"] = _choice(_ENERGIES, kw.pop("energy", "sd"), "energy")
    o["max_distortion"] = _num(kw.pop("max_distortion", 0), "max_distortion")
    o["max_charts"] = _int(kw.pop("max_charts", 0), "max_charts", 0, _UINT32_MAX)
    o["cut"] = _choice(_CUTS, kw.pop("cut", "auto"), "cut")
    o["segment"] = _choice(_SEGMENTS, kw.pop("segment", "auto"), "segment")
    o["strict"] = int(bool(kw.pop("strict", False)))
    o["init"] = _choice(_INITS, kw.pop("init", "input" if has_uvs else "auto"), "init")
    if o["init"] == 2 and not has_uvs:
        raise MeshError("init='input' needs uvs", status="BP_ERR_INVALID_ARGUMENT")
    o["start"] = _choice(_STARTS, kw.pop("start", "auto"), "start")
    o["direction"] = _choice(_DIRECTIONS, kw.pop("direction", "default"), "direction")
    o["max_iterations"] = _int(kw.pop("max_iterations", 0), "max_iterations", 0)
    o["tolerance"] = _num(kw.pop("tolerance", 0), "tolerance")
    o["max_seconds"] = _num(kw.pop("max_seconds", 0), "max_seconds")
    o["epsilon"] = _num(kw.pop("epsilon", 0), "epsilon")
    o["history"] = _int(kw.pop("history", 0), "history", 0, 1000)
    o["no_barrier"] = int(not kw.pop("barrier", True))
    o["no_rotation"] = int(not kw.pop("rotate", True))
    o["init_only"] = int(bool(kw.pop("init_only", False)))
    o["memory_limit"] = _int(kw.pop("memory_limit", 0), "memory_limit", 0, 2**63 - 1)
    # visibility (chapter 4 of the dissertation)
    visibility = kw.pop("visibility", None)
    views = kw.pop("views", None)
    view_list = None
    if views is not None:
        view_list = _float_array(views, "views", 4)
        if visibility not in (None, "list"):
            raise MeshError("give visibility or views, not both", status="BP_ERR_INVALID_ARGUMENT")
        o["views_model"] = 5
    else:
        o["views_model"] = _choice(_VIEWS, visibility, "visibility")
    view_dir = kw.pop("view_dir", None)
    if view_dir is not None:
        o["view_dir"] = _vec3(view_dir, "view_dir")
    up = kw.pop("up", None)
    if up is not None:
        o["up"] = _vec3(up, "up")
    o["elevation"] = _num(kw.pop("ring_elevation", 30), "ring_elevation", lo=-90)
    if o["elevation"] > 90:
        raise MeshError("ring_elevation must be in [-90, 90]", status="BP_ERR_INVALID_ARGUMENT")
    o["samples"] = _int(kw.pop("vis_samples", 64), "vis_samples", 1, _UINT32_MAX)
    o["floor"] = _num(kw.pop("vis_floor", 0.05), "vis_floor", positive=True)
    o["seed"] = _int(kw.pop("seed", 0), "seed", 0, 2**63 - 1)
    importance = kw.pop("importance", None)
    if importance is not None:
        importance = np.asarray(importance)
        if importance.dtype.kind not in "fiu" or importance.shape != (num_faces,):
            raise MeshError(f"importance must be {num_faces} numbers (one per face), not {importance.dtype} "
                            f"{importance.shape}", status="BP_ERR_INVALID_ARGUMENT")
        importance = np.ascontiguousarray(importance, dtype=np.float64)
    if kw:
        raise TypeError(f"parametrize() got an unexpected keyword argument {sorted(kw)[0]!r}")
    return o, importance, pins, view_list


# ---- meshes from files -----------------------------------------------------------

class Mesh:
    """A triangle mesh as arrays, as the library's readers give it.

    positions   (N, 3) float64
    indices     (M, 3) uint32 (polygons are split into fans)
    uvs         (T, 2) float64 or None: the file's texture coordinates
    uv_indices  (M, 3) uint32 or None: each corner's uv (seams are where
                they differ between neighbours)
    faces       (M,) uint32 or None: the file's polygon of each triangle
    lines       (M,) uint32 or None: the file's line of each triangle
    path        the file it was read from, or None; format "obj", "off",
                "ply", "gltf", "glb" or None
    info        glTF: meshes, primitives, buffer_files, has_uv
    A glTF file's arrays are read-only views of what the writer keeps.
    """

    def __init__(self, positions, indices, uvs=None, uv_indices=None, *, faces=None, lines=None,
                 num_faces=0, path=None, format=None, read_seconds=0.0, read_cpu_seconds=0.0, gltf=None,
                 info=None):
        self.positions = positions
        self.indices = indices
        self.uvs = uvs
        self.uv_indices = uv_indices
        self.faces = faces
        self.lines = lines
        self.num_faces = num_faces or (len(indices) if indices is not None else 0)
        self.path = path
        self.format = format
        self.read_seconds = read_seconds
        self.read_cpu_seconds = read_cpu_seconds
        self._gltf = gltf
        self.info = info or {}

    def __repr__(self):
        src = f" from {self.path!r}" if self.path else ""
        return (f"<bijparam.Mesh{src}: {len(self.positions)} vertices, {len(self.indices)} triangles"
                f"{', with uvs' if self.uvs is not None else ''}>")


def read_mesh(path, *, threads=0, progress=None, texcoord=0):
    """Read an OBJ, OFF, PLY (the library's readers) or glTF file (.gltf,
    .glb: examples/bp_gltf.h) by its extension: polygons split into fans,
    the file's texture coordinates and seams kept (glTF: TEXCOORD_n, n =
    `texcoord`; vertices welded by position), every error naming the
    file's line or glTF element.  threads: 0 = all cores (a large OBJ file
    is parsed in chunks); progress as in parametrize (stage "read")."""
    path = os.fspath(path)
    _int(threads, "threads", 0, 256)
    _int(texcoord, "texcoord", 0, 2**31 - 1)
    if os.path.isdir(path):
        raise FileError(f"{path}: is a directory, not an .obj, .off, .ply, .gltf or .glb file", status="BP_ERR_IO")
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if ext in ("gltf", "glb"):
        t = _native.read_gltf(path, texcoord)
        if t[0] != "ok":
            _raise(t, path=path)
        _, handle, d = t
        return Mesh(d["positions"], d["indices"], d["uvs"] if d["uv_indices"] is not None else None, d["uv_indices"],
                    faces=d["faces"], num_faces=d["num_faces"], path=path, format="glb" if d["glb"] else "gltf",
                    read_seconds=d["seconds"], read_cpu_seconds=d["cpu_seconds"], gltf=handle,
                    info={k: d[k] for k in ("meshes", "primitives", "buffer_files", "has_uv")})
    t = _native.read_mesh(path, threads, progress)
    if t[0] != "ok":
        _raise(t, path=path)
    d = t[1]
    return Mesh(d["positions"], d["indices"], d["uvs"] if d["uv_indices"] is not None else None, d["uv_indices"],
                faces=d["faces"], lines=d["lines"], num_faces=d["num_faces"], path=path, format=ext,
                read_seconds=d["seconds"], read_cpu_seconds=d["cpu_seconds"])


# ---- the result -------------------------------------------------------------------

def _umask():
    """The process's umask, read without changing it where Linux allows."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except OSError:
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _same_file(a, b):
    try:
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return False
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def _write_atomic(target, write, force_source=None):
    """Write `target` whole or not at all: `write(tmp)` writes a temporary
    file next to it (symlinks followed, so a link keeps pointing at the
    replaced file), which gets the target's mode (a new file: 0666 less the
    umask) and is renamed over the target only when complete."""
    final = os.path.realpath(target)
    folder, name = os.path.split(final)
    try:
        mode = stat.S_IMODE(os.stat(final).st_mode)
    except FileNotFoundError:
        mode = 0o666 & ~_umask()
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".bijparam-tmp", dir=folder or ".")
    except OSError as e:
        raise FileError(f"{target}: cannot create a file next to it: {e.strerror}", status="BP_ERR_IO") from e
    try:
        os.fchmod(fd, mode)
        os.close(fd)
        fd = -1
        write(tmp)
        os.replace(tmp, final)
    except BaseException:
        if fd >= 0:
            os.close(fd)
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


class Result(tuple):
    """What parametrize returns: the tuple (vmapping, indices, uvs), as
    xatlas-python's, which is also an object.

    vmapping      (K,) uint32: the input vertex of each output vertex
    indices       (M, 3) uint32: each input face, in its place and with its
                  corners in their order, as output vertices
    uvs           (K, 2) float32 (or float64, uv_dtype) in [0, 1]
    report        the tool's --json report as a dict: charts, per-chart
                  energies, iterations, stops, start maps, directions,
                  repairs, timings, utilization, threads, memory
    failed_faces  (M,) bool: faces of charts that failed (only in the
                  result a ChartsFailedError carries)
    charts        number of charts; utilization: UV area over [0,1]^2
    write(path)   the mesh with its new uvs as OBJ (the library's writer;
                  an OBJ input keeps every other line of its file)
    """

    def __new__(cls, vmapping, indices, uvs, report, failed_faces=None, handle=None, mesh=None):
        self = super().__new__(cls, (vmapping, indices, uvs))
        self.report = report
        self.failed_faces = failed_faces
        self._handle = handle
        self._mesh = mesh
        return self

    vmapping = property(lambda self: self[0])
    indices = property(lambda self: self[1])
    uvs = property(lambda self: self[2])
    charts = property(lambda self: self.report["charts"])
    utilization = property(lambda self: self.report["utilization"])

    def __reduce__(self):   # pickled without the library's atlas (write needs the original)
        return (_rebuild_result, (tuple(self), self.report, self.failed_faces))

    def __repr__(self):
        return (f"<bijparam.Result: {len(self[0])} vertices, {len(self[1])} faces, {self.report['charts']} "
                f"charts, utilization {self.report['utilization']}, status {self.report['status']!r}>")

    def release(self):
        """Free the library's copy of the mesh and atlas now (write needs them)."""
        if self._handle is not None:
            self._handle.release()
            self._handle = None

    def write(self, path, *, source=None, force=False, threads=0, progress=None):
        """Write the mesh with its new map, whole or not at all (temporary
        files next to `path` renamed over it when complete), with the
        library's writers, as the tool's -o does.

        path    .obj; or .glb / .gltf for a mesh read from a glTF file:
                the file written back with the new TEXCOORD_n and all else
                of it kept (examples/bp_gltf.h; a .gltf whose input kept
                its bytes in files gets them in <name>.bin beside it)
        source  (OBJ) None: the OBJ file the mesh was read from, if any,
                whose every other line (normals, materials, groups,
                comments, spacing) comes back unchanged; a path: that OBJ
                file, whose faces must be the mesh's; False: written from
                the mesh alone (v, vt and f lines).
        force   allow `path` to be an input file.
        """
        if self._handle is None:
            raise ValueError("this result has no atlas to write (released, or unpickled)")
        _int(threads, "threads", 0, 256)
        path = os.fspath(path)
        mesh = self._mesh
        ext = os.path.splitext(path)[1].lower()
        if ext in (".gltf", ".glb"):
            if mesh is None or mesh._gltf is None:
                raise MeshError(f"{path}: a .gltf or .glb is written back from a mesh read from one (write .obj)",
                                status="BP_ERR_INVALID_ARGUMENT")
            return self._write_gltf(path, ext == ".glb", force, threads)
        if source is None:
            src = mesh.path if mesh is not None and mesh.format == "obj" else None
        else:
            src = os.fspath(source) if source is not False else None
        if not force and mesh is not None and mesh.path and _same_file(path, mesh.path):
            raise FileError(f"{path}: is the input file; pass force=True to replace it", status="BP_ERR_INVALID_ARGUMENT")
        if src is not None and not force and _same_file(path, src):
            raise FileError(f"{path}: is the input file; pass force=True to replace it", status="BP_ERR_INVALID_ARGUMENT")
        seconds = []

        def write(tmp):
            t = self._handle.write(tmp, src or "", threads, progress)
            if t[0] != "ok":
                _raise(t, path=path)
            seconds.append(t[1:])

        _write_atomic(path, write)
        self._written(path, *seconds[0])
        return path

    def _written(self, path, wall, cpu):
        self.report["output"] = path
        self.report["timings"]["write"], self.report["cpu_timings"]["write"] = wall, cpu
        flipped = self.report["repairs"]["flipped"]
        flipped["written_reordered"] = flipped["count"]

    def _write_gltf(self, path, glb, force, threads):
        """bpg_encode's bytes into their files, as the tool's -o: a .gltf
        whose input kept its bytes in files (a .glb's BIN chunk, a .bin)
        gets the new bytes in <name>.bin next to it, written and renamed
        first; relative uris are rewritten when the folder changes."""
        mesh = self._mesh
        g = mesh._gltf
        inputs = [mesh.path] + g.external_files()
        if not force and any(_same_file(path, x) for x in inputs):
            raise FileError(f"{path}: is an input file; pass force=True to replace it", status="BP_ERR_INVALID_ARGUMENT")
        bin_uri = bin_path = None
        if not glb and (mesh.format == "glb" or g.external_files()):
            base = os.path.basename(path)
            bin_uri = base[: -len(".gltf")] + ".bin"
            bin_path = os.path.join(os.path.dirname(path), bin_uri)
            if any(_same_file(bin_path, x) for x in inputs):
                raise FileError(f"{path}: its new data would go into {bin_path}, which the input reads; choose "
                                f"another output name", status="BP_ERR_INVALID_ARGUMENT")
            bin_uri = urllib.parse.quote(bin_uri)
        src_dir = os.path.dirname(os.path.realpath(mesh.path))
        out_dir = os.path.dirname(os.path.realpath(path))
        prefix = None
        if src_dir != out_dir:
            prefix = urllib.parse.quote(os.path.relpath(src_dir, out_dir).replace(os.sep, "/")) + "/"
        t = _native.encode_gltf(g, self._handle, glb, bin_uri, prefix, threads)
        if t[0] != "ok":
            _raise(t, path=path, gltf=g)
        _, data, bin_bytes, vin, vout, fixed, wall, cpu, removed = t

        def put(data):
            def write(tmp):
                with open(tmp, "wb") as f:
                    f.write(data)
            return write

        if bin_bytes is not None:
            _write_atomic(bin_path, put(bin_bytes))
        _write_atomic(path, put(data))
        self._written(path, wall, cpu)
        self.report["gltf"] = {"primitives": mesh.info.get("primitives", 0), "vertices_in": vin,
                               "vertices_out": vout, "rounding_fixed": fixed, "accessors_removed": removed[0],
                               "views_removed": removed[1], "bytes_removed": removed[2]}
        return path


def _rebuild_result(arrays, report, failed_faces):
    return Result(arrays[0], arrays[1], arrays[2], report, failed_faces)


# ---- parametrize -------------------------------------------------------------------

def parametrize(positions, indices=None, normals=None, uvs=None, *, uv_indices=None, progress=None,
                uv_dtype=np.float32, **options):
    """Bijective UV atlas of a triangle mesh; xatlas-python's call.

    positions   (N, 3) float32/float64 (any real dtype, any layout), or a
                Mesh (then indices and uvs come from it)
    indices     (M, 3) integers (any dtype, any layout)
    normals     (N, 3): accepted for xatlas-python's call, not used
    uvs         your own texture coordinates, the start map: (N, 2) per
                vertex, or (T, 2) with uv_indices (M, 3) per corner (seams
                are kept where the uv indices differ)
    progress    callable(stage, fraction), called on the calling thread;
                an exception it raises stops the run and propagates
    uv_dtype    numpy.float32 (xatlas-python's) or numpy.float64

    Options (the library's; the README lists them all): resolution=1024
    and padding=4 (texels: charts packed by their outlines into [0,1]^2;
    resolution=0 packs bounding boxes), threads=0 (all cores), energy="sd",
    max_distortion, max_charts, cut="auto", segment="auto", strict=False,
    pins, init, start, direction, visibility, importance, memory_limit, ...

    Returns a Result: the tuple (vmapping, indices, uvs) with .report.
    Raises MeshError (a ValueError) for bad input, naming the face or
    vertex; MemoryError; ChartsFailedError; KeyboardInterrupt (Ctrl-C
    cancels the run within one iteration).
    """
    mesh = positions if isinstance(positions, Mesh) else None
    lines = faces = None
    num_faces = 0
    if mesh is not None:
        if indices is not None:
            raise TypeError("parametrize(mesh): the indices come from the Mesh")
        if uvs is None and uv_indices is None and mesh.uv_indices is not None:
            uvs, uv_indices = mesh.uvs, mesh.uv_indices
            options.setdefault("init", "auto")      # the file's vt: its seams; the start as the tool's
        positions, indices = mesh.positions, mesh.indices
        lines, faces, num_faces = mesh.lines, mesh.faces, mesh.num_faces
    elif indices is None:
        raise TypeError("parametrize() needs positions and indices")
    pos = _float_array(positions, "positions", 3)
    tri = _index_array(indices, "indices")
    if normals is not None:
        _float_array(normals, "normals", 3)
    corner_uv = uv = None
    if uv_indices is not None:
        if uvs is None:
            raise MeshError("uv_indices needs uvs", status="BP_ERR_INVALID_ARGUMENT")
        corner_uv = _index_array(uv_indices, "uv_indices")
        uv = _float_array(uvs, "uvs", 2)
        if len(corner_uv) != len(tri):
            raise MeshError(f"uv_indices has {len(corner_uv)} rows, indices {len(tri)}", status="BP_ERR_INVALID_ARGUMENT")
    elif uvs is not None:
        uv = _float_array(uvs, "uvs", 2)
        if len(uv) != len(pos):
            raise MeshError(f"uvs without uv_indices must have one row per vertex ({len(pos)}), not {len(uv)}",
                            status="BP_ERR_INVALID_ARGUMENT")
        corner_uv = tri
    if np.dtype(uv_dtype) not in (np.float32, np.float64):
        raise MeshError(f"uv_dtype must be float32 or float64, not {uv_dtype!r}", status="BP_ERR_INVALID_ARGUMENT")
    o, importance, pins, view_list = _options(options, len(tri), uv is not None)
    pin_arrays = _pins(pins, len(pos)) if pins is not None else None
    if lines is not None:
        lines = np.ascontiguousarray(lines, dtype=np.uint32)
    if faces is not None:
        faces = np.ascontiguousarray(faces, dtype=np.uint32)
    t = _native.parametrize(pos, tri, corner_uv, uv, lines, faces, int(num_faces), o, importance, pin_arrays,
                            view_list, np.dtype(uv_dtype) == np.float64, progress)
    if t[0] == "error":
        _raise(t, arrays=mesh is None, gltf=mesh._gltf if mesh is not None else None)
    _, handle, vmapping, out_indices, out_uvs, failed, report, round_status, round_message = t
    if mesh is not None:
        report["input"] = mesh.path
        report["format"] = mesh.format
        report["timings"]["read"] = mesh.read_seconds
        report["cpu_timings"]["read"] = mesh.read_cpu_seconds
    report["uvs_check"] = "ok" if round_status == "BP_OK" else round_message
    result = Result(vmapping, out_indices, out_uvs, report, failed, handle, mesh)
    if round_status != "BP_OK":
        warnings.warn(f"the float32 uvs are not bijective ({round_message}); ask for uv_dtype=numpy.float64",
                      BijectivityWarning, stacklevel=2)
    if t[0] == "charts_failed":
        first = next((c for c in report["per_chart"] if c["error"]), None)
        msg = (f"{report['failed_charts']} of {report['charts']} charts failed"
               + (f"; chart {first['index']}: {first['error']}" if first else ""))
        raise ChartsFailedError(msg, result, status="BP_ERR_CHARTS_FAILED")
    return result


# ---- the exact check ------------------------------------------------------------------

class CheckResult:
    """The verdict of check(): true when the map is bijective.

    bijective   every chart bijective and no two overlapping
    charts      the charts the uv indices make; bad_charts: how many fail
    overlap     True when the charts are each fine but overlap each other
    message     the first problem, naming faces, vertices and uvs by their
                0-based rows in the arrays ("" when bijective)
    counts      flipped, degenerate, nonfinite, boundary_intersections,
                loop_orientation, nested, ... of the first failing check
    chart       the first failing chart (-1: all charts together)
    """

    def __init__(self, d):
        self.bijective = d["bijective"]
        self.charts = d["charts"]
        self.bad_charts = d["bad_charts"]
        self.overlap = d["overlap"]
        self.message = d["message"]
        self.counts = d["counts"]
        self.chart = d["chart"]
        self.status = d["status"]

    def __bool__(self):
        return bool(self.bijective)

    def __repr__(self):
        if self.bijective:
            return f"<bijparam.CheckResult: bijective ({self.charts} charts, none overlapping)>"
        return f"<bijparam.CheckResult: NOT bijective: {self.message}>"


def check(positions, indices, uvs, uv_indices=None, *, threads=0):
    """Decide exactly whether a UV map is bijective: every chart (the mesh's
    pieces cut where uv_indices differ between neighbours) has no flipped
    or zero-area triangle and a boundary that does not touch itself, and no
    two charts overlap.  The tool's --check, on arrays.

    For parametrize's output: check(positions, faces, uvs, indices), with
    the input positions and faces and the output uvs and indices.
    uvs (T, 2) with uv_indices (M, 3), or (N, 2) per vertex.
    Returns a CheckResult (true when bijective).
    """
    pos = _float_array(positions, "positions", 3)
    tri = _index_array(indices, "indices")
    uv = _float_array(uvs, "uvs", 2)
    if uv_indices is None:
        if len(uv) != len(pos):
            raise MeshError("uvs without uv_indices must have one row per vertex", status="BP_ERR_INVALID_ARGUMENT")
        corner_uv = tri
    else:
        corner_uv = _index_array(uv_indices, "uv_indices")
    if len(corner_uv) != len(tri):
        raise MeshError(f"uv_indices has {len(corner_uv)} rows, indices {len(tri)}", status="BP_ERR_INVALID_ARGUMENT")
    t = _native.check(pos, tri, corner_uv, uv, _int(threads, "threads", 0, 256))
    if t[0] != "ok":
        _raise(t, arrays=True)
    return CheckResult(t[1])


# ---- xatlas-python's export -----------------------------------------------------------

def export(path, positions, indices=None, uvs=None, normals=None):
    """xatlas-python's export: an OBJ file of v (and vn, vt) lines and f
    lines whose corners use one index for all three, written whole or not
    at all.  For a file that keeps everything of the input, use
    Result.write."""
    def digits(a):      # enough to read back the same float32 or float64
        return 9 if a is not None and np.asarray(a).dtype.itemsize <= 4 else 17
    dp, du, dn = digits(positions), digits(uvs), digits(normals)
    pos = _float_array(positions, "positions", 3)
    tri = _index_array(indices, "indices") if indices is not None else None
    uv = _float_array(uvs, "uvs", 2) if uvs is not None else None
    nrm = _float_array(normals, "normals", 3) if normals is not None else None
    for name, a in (("uvs", uv), ("normals", nrm)):
        if a is not None and len(a) != len(pos):
            raise MeshError(f"{name} must have one row per vertex", status="BP_ERR_INVALID_ARGUMENT")
    if tri is not None and tri.size and int(tri.max()) >= len(pos):
        bad = int(np.argmax((tri >= len(pos)).any(axis=1)))
        raise MeshError(f"indices[{bad}] = {tri[bad].tolist()}: index out of range ({len(pos)} vertices)",
                        status="BP_ERR_INDEX", element="triangle", index=bad)

    def write(tmp):
        with open(tmp, "w", encoding="ascii") as f:
            np.savetxt(f, pos, fmt=f"v %.{dp}g %.{dp}g %.{dp}g")
            if nrm is not None:
                np.savetxt(f, nrm, fmt=f"vn %.{dn}g %.{dn}g %.{dn}g")
            if uv is not None:
                np.savetxt(f, uv, fmt=f"vt %.{du}g %.{du}g")
            if tri is not None:
                one = tri.astype(np.int64) + 1
                corner = "{0}/{0}/{0}" if uv is not None and nrm is not None else \
                         "{0}//{0}" if nrm is not None else "{0}/{0}" if uv is not None else "{0}"
                fmt = "f " + " ".join(corner.replace("0", str(k)) for k in range(3)) + "\n"
                f.writelines(fmt.format(*row) for row in one.tolist())

    _write_atomic(os.fspath(path), write)
