"""python -m bijparam.batch IN_DIR OUT_DIR [--scheduler ADDRESS | --workers N]

Every mesh of IN_DIR (.obj, .off, .ply, .gltf, .glb) unwrapped into
OUT_DIR/<name>.obj (a glTF file into OUT_DIR/<name>.glb or .gltf, written
back with a new TEXCOORD_0) by tasks on a Dask distributed cluster: an existing scheduler (ADDRESS,
e.g. tcp://10.0.0.5:8786, whose workers see IN_DIR and OUT_DIR at the same
paths), or by default a LocalCluster of N worker processes on this machine.

  - Each output is written whole or not at all (a temporary file next to
    it, renamed when complete); an OBJ or glTF input keeps everything else
    of its file, as the command-line tool's -o does.
  - A restarted run skips a mesh whose output exists, is this mesh (the
    same vertices and faces) and passes the exact check; any other output
    is made again.
  - A worker that dies mid-run has its tasks run again on another worker
    (the scheduler's own retry), so nothing is lost; what a killed task
    left (its temporary file) is removed at the end.
  - One JSON report per mesh on stdout as it finishes (the tool's --json
    fields, or the error), then one summary line; exit status 0 when every
    mesh was written or skipped, 1 when one failed, 2 for a usage error.
"""
import argparse
import glob
import json
import os
import sys
import time

import numpy as np

import bijparam

EXTENSIONS = (".obj", ".off", ".ply", ".gltf", ".glb")


def outputs_for(inputs):
    """OUT names: <stem>.obj, or <stem>.glb / <stem>.gltf for glTF; stems
    shared by two inputs (a.obj, a.off) get their extension too (a.obj.obj,
    a.off.obj)."""
    stems = {}
    for p in inputs:
        stems.setdefault(os.path.splitext(os.path.basename(p))[0], []).append(p)
    out = {}
    for stem, ps in stems.items():
        for p in ps:
            ext = os.path.splitext(p)[1].lower()
            ext = ext if ext in (".gltf", ".glb") else ".obj"
            out[p] = stem + ext if len(ps) == 1 else os.path.basename(p) + ext
    return out


def finished(src, dst, threads=0):
    """The output exists, holds this input's triangles (the same corner
    positions, in order; a triangle the repair re-oriented with its last
    two corners swapped, as the writers list it), and its uv map passes
    the exact check (bijparam.check)."""
    if not os.path.exists(dst):
        return False
    try:
        a = bijparam.read_mesh(src, threads=threads)
        b = bijparam.read_mesh(dst, threads=threads)
    except (bijparam.Error, MemoryError):
        return False
    if b.uvs is None or a.indices.shape != b.indices.shape:
        return False
    pa, pb = a.positions[a.indices], b.positions[b.indices]          # (M, 3 corners, xyz)
    same = (pa == pb).all(axis=(1, 2))
    swapped = (pa[:, 0] == pb[:, 0]).all(axis=1) & (pa[:, 1] == pb[:, 2]).all(axis=1) & \
        (pa[:, 2] == pb[:, 1]).all(axis=1)
    if not (same | swapped).all():
        return False
    return bool(bijparam.check(b.positions, b.indices, b.uvs, b.uv_indices, threads=threads))


def unwrap_one(src, dst, options):
    """One task: skip a finished output, else read, parameterize, write.
    Returns the report (a dict: the tool's --json fields, or the error)."""
    t0 = time.perf_counter()
    threads = options.get("threads", 0)
    if finished(src, dst, threads):
        return {"input": src, "output": dst, "status": "skipped",
                "reason": "the output exists and passes the exact check"}
    try:
        mesh = bijparam.read_mesh(src, threads=threads)
        result = bijparam.parametrize(mesh, **options)
        result.write(dst)
        report = result.report
    except bijparam.ChartsFailedError as e:
        report = e.result.report
        report.update(input=src, output=None, status="failed", error=str(e))
    except (bijparam.Error, MemoryError) as e:
        report = {"input": src, "output": None, "status": "failed", "error": f"{type(e).__name__}: {e}"}
    report["seconds"] = time.perf_counter() - t0
    report["host"] = os.uname().nodename
    return report


def remove_leftovers(out_dir):
    """The temporary files of tasks whose worker died."""
    for p in glob.glob(os.path.join(out_dir, ".*.bijparam-tmp")):
        try:
            os.unlink(p)
        except OSError:
            pass


def parse(argv):
    ap = argparse.ArgumentParser(prog="python -m bijparam.batch", description=__doc__.split("\n\n")[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("in_dir")
    ap.add_argument("out_dir")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running dask scheduler (dask-scheduler)")
    where.add_argument("--workers", type=int, metavar="N", help="a LocalCluster of N worker processes "
                       "(default: one per two cores, at least 1)")
    ap.add_argument("--threads", type=int, default=None,
                    help="library threads per mesh (default: the cores over the local workers; 0 on a scheduler)")
    ap.add_argument("--resolution", type=int, default=1024, help="atlas texels per side (default 1024; 0: no grid)")
    ap.add_argument("--padding", type=int, default=None, help="texels between charts (default 4)")
    ap.add_argument("--energy", default="sd")
    ap.add_argument("--max-distortion", type=float, default=0)
    ap.add_argument("--max-charts", type=int, default=0)
    ap.add_argument("--cut", default="auto")
    ap.add_argument("--segment", default="auto")
    ap.add_argument("--strict", action="store_true")
    ap.add_argument("--max-seconds", type=float, default=0, help="per chart optimization")
    a = ap.parse_args(argv)
    if a.workers is not None and a.workers < 1:
        ap.error("--workers needs 1 or more")
    if not os.path.isdir(a.in_dir):
        ap.error(f"{a.in_dir}: not a folder")
    return a


def main(argv=None):
    a = parse(sys.argv[1:] if argv is None else argv)
    inputs = sorted(p for p in glob.glob(os.path.join(os.path.abspath(a.in_dir), "*"))
                    if p.lower().endswith(EXTENSIONS) and os.path.isfile(p))
    out_dir = os.path.abspath(a.out_dir)
    os.makedirs(out_dir, exist_ok=True)
    names = outputs_for(inputs)
    cores = os.cpu_count() or 1
    workers = a.workers or max(1, cores // 2)
    threads = a.threads if a.threads is not None else (0 if a.scheduler else max(1, cores // workers))
    options = dict(resolution=a.resolution, threads=threads, energy=a.energy, max_distortion=a.max_distortion,
                   max_charts=a.max_charts, cut=a.cut, segment=a.segment, strict=a.strict, max_seconds=a.max_seconds)
    if a.padding is not None:
        options["padding"] = a.padding
    try:                                   # the options are checked once, here, not by every task
        bijparam._options(options, 1, False)
    except (bijparam.MeshError, TypeError) as e:
        print(f"bijparam.batch: {e}", file=sys.stderr)
        return 2

    import logging
    import dask
    from distributed import Client, LocalCluster, as_completed
    for name in ("distributed", "distributed.nanny", "distributed.scheduler", "distributed.worker"):
        logging.getLogger(name).setLevel(logging.ERROR)

    t0 = time.perf_counter()
    cluster = None
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
        client = Client(cluster)
    counts = {"written": 0, "skipped": 0, "failed": 0}
    library_seconds = 0.0
    try:
        futures = [client.submit(unwrap_one, p, os.path.join(out_dir, names[p]), options, pure=False,
                                 key=f"bijparam-{k}-{os.path.basename(p)}") for k, p in enumerate(inputs)]
        for fut in as_completed(futures):
            try:
                report = fut.result()
            except Exception as e:            # a task lost more workers than the scheduler allows
                report = {"input": None, "output": None, "status": "failed", "error": f"{type(e).__name__}: {e}"}
            status = report.get("status")
            kind = "skipped" if status == "skipped" else "failed" if report.get("output") is None else "written"
            counts[kind] += 1
            library_seconds += report.get("seconds", 0.0)
            print(json.dumps(report), flush=True)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    remove_leftovers(out_dir)
    wall = time.perf_counter() - t0
    where = f"scheduler {a.scheduler}" if a.scheduler else f"{workers} local workers x {threads} threads"
    print(f"bijparam.batch: {len(inputs)} meshes: {counts['written']} written, {counts['skipped']} skipped "
          f"(done before), {counts['failed']} failed; {wall:.1f} s wall, {library_seconds:.1f} s in tasks; "
          f"{where}", flush=True)
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
