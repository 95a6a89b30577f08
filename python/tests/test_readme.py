"""python/README.md's examples run as written: its ```python blocks, in
order, in one namespace, with the names they assume (a trimesh-like `mesh`,
`positions`, `faces`, a "scan.obj") given spot's data."""
import os
import re
import shutil

import numpy as np

from conftest import ROOT


def test_readme_examples_run(data, tmp_path, monkeypatch):
    text = open(os.path.join(ROOT, "python", "README.md"), encoding="utf-8").read()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 3
    import bijparam
    spot = bijparam.read_mesh(data("spot.obj"))

    class TrimeshLike:
        vertices = spot.positions.astype(np.float32)
        faces = spot.indices.astype(np.int64)

    shutil.copy(data("spot.obj"), tmp_path / "scan.obj")
    monkeypatch.chdir(tmp_path)
    ns = {"mesh": TrimeshLike(), "positions": spot.positions, "faces": spot.indices.astype(np.int64)}
    for code in blocks:
        exec(compile(code, "python/README.md", "exec"), ns)
    assert os.path.exists(tmp_path / "scan_uv.obj")
    out = bijparam.read_mesh(str(tmp_path / "scan_uv.obj"))
    assert bijparam.check(out.positions, out.indices, out.uvs, out.uv_indices)
