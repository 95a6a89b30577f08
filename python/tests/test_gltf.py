"""glTF (.glb, .gltf) through the package: read_mesh, parametrize(mesh),
Result.write back as .glb or .gltf -- the tool's -o output byte for byte,
everything else of the file kept (tests/gltf_check.py, an independent
reader), the new TEXCOORD_0 bijective (tests/uvcheck.py)."""
import filecmp
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import bijparam
from conftest import ROOT


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """tests/gltf_make.py's models and a Khronos sample of tests/data/gltf."""
    d = tmp_path_factory.mktemp("gltf")
    subprocess.run([sys.executable, os.path.join(ROOT, "tests", "gltf_make.py"), str(d)], check=True,
                   capture_output=True)
    shutil.copy(os.path.join(ROOT, "tests", "data", "gltf", "BoxTextured.glb"), d / "BoxTextured.glb")
    return d


def checker(*args):
    return subprocess.run([sys.executable, os.path.join(ROOT, "tests", "gltf_check.py"), *args], capture_output=True,
                          text=True)


@pytest.mark.parametrize("name", ["two_meshes.glb", "strips.gltf", "external.gltf", "BoxTextured.glb"])
def test_written_back_as_the_tool_writes_it(models, tool, name, tmp_path):
    src = str(models / name)
    m = bijparam.read_mesh(src)
    assert m.format == ("glb" if name.endswith(".glb") else "gltf") and not m.positions.flags.writeable
    r = bijparam.parametrize(m, threads=2)
    for ext in (".glb", ".gltf"):
        a, b = tmp_path / "tool", tmp_path / "py"
        for x in (a, b):
            shutil.rmtree(x, ignore_errors=True)
            x.mkdir()
        p = subprocess.run([tool, src, "--atlas", "1024", "--padding", "4", "--threads", "2", "--json", "-q", "-o",
                            str(a / ("out" + ext))], capture_output=True, text=True, check=True)
        r.write(str(b / ("out" + ext)))
        assert sorted(os.listdir(a)) == sorted(os.listdir(b))
        for f in os.listdir(a):
            assert filecmp.cmp(a / f, b / f, shallow=False), f"{name} -> {ext}: {f} differs from the tool's"
        assert r.report["gltf"] == json.loads(p.stdout)["gltf"]
        out = str(b / ("out" + ext))
        c = checker("compare", src, out)
        assert c.returncode == 0, c.stdout[-2000:]
        c = checker("obj", out, str(tmp_path / "map.obj"))
        assert c.returncode == 0, c.stdout[-2000:]
        u = subprocess.run([sys.executable, os.path.join(ROOT, "tests", "uvcheck.py"), str(tmp_path / "map.obj")],
                           capture_output=True, text=True)
        assert u.returncode == 0, u.stdout[-2000:]
        back = bijparam.read_mesh(out)                  # and as the library reads it
        assert bijparam.check(back.positions, back.indices, back.uvs, back.uv_indices)


def test_gltf_refusals(models, data, tmp_path):
    m = bijparam.read_mesh(str(models / "two_meshes.glb"))
    r = bijparam.parametrize(m, resolution=256)
    with pytest.raises(bijparam.FileError):                          # onto the input
        r.write(str(models / "two_meshes.glb"))
    obj = bijparam.read_mesh(data("spot.obj"))
    with pytest.raises(bijparam.MeshError, match="written back from a mesh read from one"):
        bijparam.parametrize(obj, resolution=256).write(str(tmp_path / "x.glb"))
    r.write(str(tmp_path / "as.obj"))                                # a glTF mesh as OBJ
    back = bijparam.read_mesh(str(tmp_path / "as.obj"))
    assert len(back.indices) == len(m.indices) and bijparam.check(back.positions, back.indices, back.uvs, back.uv_indices)
    bad = tmp_path / "bad.glb"
    bad.write_bytes(b"glTF\x02\x00\x00\x00\x10\x00\x00\x00garbage!")
    with pytest.raises(bijparam.MeshError) as e:
        bijparam.read_mesh(str(bad))
    assert e.value.status == "BP_ERR_PARSE"
    with pytest.raises(bijparam.FileError):
        bijparam.read_mesh(str(tmp_path / "missing.glb"))
    assert sorted(os.listdir(tmp_path)) == ["as.obj", "bad.glb"]     # no temporary left


def test_gltf_errors_name_the_files_elements(models, tmp_path):
    """A defect the library refuses (strict: a flipped triangle) is named as
    the glTF file numbers it: mesh, primitive, triangle."""
    m = bijparam.read_mesh(str(models / "strips.gltf"))
    with pytest.raises(bijparam.MeshError) as e:
        bijparam.parametrize(m, strict=True, resolution=256)
    assert "primitive" in str(e.value) and "mesh" in str(e.value), str(e.value)
