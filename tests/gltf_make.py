#!/usr/bin/env python3
"""gltf_make.py DIR - the glTF test models, made the same way every time.

  two_meshes.glb   the issue's model: two meshes with normals, materials
                   and extras, and what a real asset carries besides: a
                   terrain (an open surface) split into two primitives
                   sharing their vertex accessors (NORMAL, TANGENT, COLOR_0
                   of 3-byte normalized colours, a morph target with a
                   sparse POSITION and a NORMAL without bufferView), and a
                   closed cube-sphere with flat normals (so its vertices
                   are split at every cube edge) in one interleaved
                   bufferView, skinned (JOINTS_0, WEIGHTS_0, a skin, an
                   animation), with a points primitive sharing its
                   POSITION; a texture whose image sits in a bufferView, an
                   unknown extension, numbers and strings whose text must
                   come back as written (1.50e0, -0.0e+0, \\u00e9, \\/).
  strips.gltf      data: URIs only: a triangle strip with byte indices and
                   a degenerate join, a fan without indices, int16
                   normalized positions (KHR_mesh_quantization), a
                   TEXCOORD_0 of normalized uint16 on the strip, a
                   non-indexed triangle list whose two triangles are wound
                   opposite ways, a line strip.
  external.gltf    its bytes in "external data.bin" (a uri with %20), an
                   image file next to it, TEXCOORD_0 given (float, v downward
                   as glTF has it: a map that is not mirrored).
"""
import json
import math
import os
import struct
import sys


class Builder:
    """buffer bytes, bufferViews and accessors of one glTF file"""

    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def view(self, raw, target=None, stride=None):
        while len(self.data) % 4:
            self.data.append(0)
        v = {'buffer': 0, 'byteOffset': len(self.data), 'byteLength': len(raw)}
        if stride:
            v['byteStride'] = stride
        if target:
            v['target'] = target
        self.data += raw
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, **kw):
        self.accessors.append(kw)
        return len(self.accessors) - 1

    def floats(self, rows, typ, target=34962, minmax=False, **extra):
        n = len(rows[0])
        raw = b''.join(struct.pack('<%df' % n, *r) for r in rows)
        a = dict(bufferView=self.view(raw, target), componentType=5126, count=len(rows), type=typ, **extra)
        if minmax:
            a['min'] = [min(struct.unpack('<f', struct.pack('<f', r[k]))[0] for r in rows) for k in range(n)]
            a['max'] = [max(struct.unpack('<f', struct.pack('<f', r[k]))[0] for r in rows) for k in range(n)]
        return self.accessor(**a)

    def indices(self, idx, ctype):
        fmt = {5121: 'B', 5123: 'H', 5125: 'I'}[ctype]
        return self.accessor(bufferView=self.view(struct.pack('<%d%s' % (len(idx), fmt), *idx), 34963),
                             componentType=ctype, count=len(idx), type='SCALAR')


def terrain(n=16):
    pos, nrm, tan, col = [], [], [], []
    for j in range(n):
        for i in range(n):
            x, y = i / (n - 1), j / (n - 1)
            z = 0.15 * math.sin(3 * x) * math.cos(2 * y)
            dzx, dzy = 0.45 * math.cos(3 * x) * math.cos(2 * y), -0.3 * math.sin(3 * x) * math.sin(2 * y)
            l = math.sqrt(dzx * dzx + dzy * dzy + 1)
            pos.append((x, y, z))
            nrm.append((-dzx / l, -dzy / l, 1 / l))
            t = math.sqrt(1 + dzx * dzx)
            tan.append((1 / t, 0.0, dzx / t, 1.0))
            col.append((i * 255 // (n - 1), j * 255 // (n - 1), (i * j) % 256))
    left, right = [], []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            (left if i < (n - 1) // 2 else right).extend([a, b, c, a, c, d])
    return pos, nrm, tan, col, left, right


def cube_sphere(k=4):
    """six faces of k x k quads each, on a sphere of radius 0.5; each face
    its own vertices with the face's flat normal"""
    pos, nrm, idx = [], [], []
    axes = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)), ((0, 1, 0), (0, 0, 1), (1, 0, 0)),
            ((0, -1, 0), (1, 0, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    for nvec, u, v in axes:
        base = len(pos)
        for j in range(k + 1):
            for i in range(k + 1):
                s, t = 2 * i / k - 1, 2 * j / k - 1
                p = [nvec[c] + s * u[c] + t * v[c] for c in range(3)]
                l = math.sqrt(sum(x * x for x in p))
                pos.append(tuple(0.5 * x / l + (1.5 if c == 0 else 0) for c, x in enumerate(p)))
                nrm.append(tuple(float(x) for x in nvec))
        # orient each face outward: u x v must point along nvec
        cr = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        flip = sum(cr[c] * nvec[c] for c in range(3)) < 0
        for j in range(k):
            for i in range(k):
                a, b = base + j * (k + 1) + i, base + j * (k + 1) + i + 1
                c, d = base + (j + 1) * (k + 1) + i + 1, base + (j + 1) * (k + 1) + i
                idx.extend([a, c, b, a, d, c] if flip else [a, b, c, a, c, d])
    return pos, nrm, idx


# raw text put in place of markers after json.dumps: numbers and strings
# whose exact spelling the writer must keep
RAW = {'"@NUM1@"': '1.50e0', '"@NUM2@"': '-0.0e+0', '"@STR1@"': '"\\u00e9t\\u00e9 \\/ \\"q\\""'}


INDENT = [1]


def dump(doc):
    text = json.dumps(doc, indent=INDENT[0], separators=(',', ':') if INDENT[0] is None else None)
    for k, v in RAW.items():
        text = text.replace(k, v)
    return text.encode('utf-8')


def glb(path, doc, data):
    js = dump(doc)
    js += b' ' * (-len(js) % 4)
    data = bytes(data) + b'\0' * (-len(data) % 4)
    total = 12 + 8 + len(js) + 8 + len(data)
    with open(path, 'wb') as f:
        f.write(struct.pack('<4sII', b'glTF', 2, total))
        f.write(struct.pack('<II', len(js), 0x4E4F534A) + js)
        f.write(struct.pack('<II', len(data), 0x004E4942) + data)


def two_meshes(path, n=16, k=4):
    B = Builder()
    pos, nrm, tan, col, left, right = terrain(n)
    P = B.floats(pos, 'VEC3', minmax=True, name='terrain positions')
    N = B.floats(nrm, 'VEC3')
    T = B.floats(tan, 'VEC4')
    # 3-byte colours: vertex attributes start on 4-byte boundaries, so a strided view
    raw = b''.join(struct.pack('<3B', *c) + b'\0' for c in col)
    C = B.accessor(bufferView=B.view(raw, 34962, stride=4), componentType=5121, normalized=True,
                   count=len(col), type='VEC3')
    IL = B.indices(left, 5123)
    IR = B.indices(right, 5125)
    # morph target: a sparse POSITION (lift 20 vertices), a zero NORMAL
    lift = list(range(n * n // 6, n * n // 6 + n))
    si = B.view(struct.pack('<%dH' % len(lift), *lift))
    sv = B.view(b''.join(struct.pack('<3f', 0.0, 0.0, 0.1) for _ in lift))
    MP = B.accessor(componentType=5126, count=len(pos), type='VEC3', min=[0.0, 0.0, 0.0], max=[0.0, 0.0, 0.1],
                    sparse={'count': len(lift), 'indices': {'bufferView': si, 'componentType': 5123},
                            'values': {'bufferView': sv}})
    MN = B.accessor(componentType=5126, count=len(pos), type='VEC3')
    # the sphere: POSITION, NORMAL interleaved; JOINTS_0, WEIGHTS_0
    spos, snrm, sidx = cube_sphere(k)
    inter = b''.join(struct.pack('<6f', *(p + n)) for p, n in zip(spos, snrm))
    iv = B.view(inter, 34962, stride=24)
    SP = B.accessor(bufferView=iv, byteOffset=0, componentType=5126, count=len(spos), type='VEC3',
                    min=[min(p[c] for p in spos) for c in range(3)], max=[max(p[c] for p in spos) for c in range(3)])
    SN = B.accessor(bufferView=iv, byteOffset=12, componentType=5126, count=len(spos), type='VEC3')
    J = B.accessor(bufferView=B.view(b''.join(struct.pack('<4B', 0, 1, 0, 0) for _ in spos), 34962),
                   componentType=5121, count=len(spos), type='VEC4')
    W = B.floats([(1 - (p[1] + 0.5), p[1] + 0.5, 0.0, 0.0) for p in spos], 'VEC4')
    SI = B.indices(sidx, 5123)
    PI = B.indices(list(range(0, len(spos), 7)), 5123)
    IBM = B.floats([(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1.5, 0, 0, 1), (1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1.5, -0.5, 0, 1)],
                   'MAT4', target=None)
    AT = B.floats([(0.0,), (1.0,), (2.0,)], 'SCALAR', target=None, minmax=True)
    AR = B.floats([(0, 0, 0, 1), (0, 0, 0.3826834, 0.9238795), (0, 0, 0, 1)], 'VEC4', target=None)
    img = B.view(b'\x89PNG\r\n\x1a\n' + bytes(range(40)))
    doc = {
        'asset': {'version': '2.0', 'generator': 'tests/gltf_make.py', 'extras': {'note': '@STR1@', 'scale': '@NUM1@'}},
        'extensionsUsed': ['EXT_example_unknown'],
        'scene': 0,
        'scenes': [{'nodes': [0], 'name': 'scene'}],
        'nodes': [{'name': 'root', 'children': [1, 2, 3], 'rotation': [0, 0, 0.258819, 0.9659258],
                   'scale': [2, 2, '@NUM2@'], 'extras': {'id': 7}},
                  {'name': 'terrain', 'mesh': 0, 'translation': [-1, 0, 0]},
                  {'name': 'sphere', 'mesh': 1, 'skin': 0},
                  {'name': 'bone0', 'translation': [1.5, 0, 0], 'children': [4]},
                  {'name': 'bone1', 'translation': [0, 0.5, 0]}],
        'meshes': [
            {'name': 'terrain', 'weights': [0.5], 'extras': {'targetNames': ['lift']},
             'primitives': [
                 {'attributes': {'POSITION': P, 'NORMAL': N, 'TANGENT': T, 'COLOR_0': C}, 'indices': IL,
                  'material': 0, 'targets': [{'POSITION': MP, 'NORMAL': MN}], 'extras': {'half': 'left'}},
                 {'attributes': {'NORMAL': N, 'POSITION': P, 'COLOR_0': C, 'TANGENT': T}, 'indices': IR,
                  'material': 1, 'targets': [{'POSITION': MP, 'NORMAL': MN}]}]},
            {'name': 'sphere', 'primitives': [
                {'attributes': {'POSITION': SP, 'NORMAL': SN, 'JOINTS_0': J, 'WEIGHTS_0': W}, 'indices': SI,
                 'material': 1, 'mode': 4},
                {'attributes': {'POSITION': SP}, 'indices': PI, 'mode': 0}]}],
        'materials': [
            {'name': 'grass', 'pbrMetallicRoughness': {'baseColorTexture': {'index': 0}, 'metallicFactor': 0},
             'extras': {'wet': False, 'layers': [1, 2, 3]}},
            {'name': 'stone', 'doubleSided': True,
             'extensions': {'EXT_example_unknown': {'strength': '@NUM1@', 'mode': 'x'}}}],
        'textures': [{'source': 0, 'sampler': 0}],
        'samplers': [{'magFilter': 9729, 'wrapS': 33071}],
        'images': [{'bufferView': img, 'mimeType': 'image/png', 'name': 'not really a png'}],
        'skins': [{'inverseBindMatrices': IBM, 'joints': [3, 4], 'skeleton': 3}],
        'animations': [{'name': 'wave', 'samplers': [{'input': AT, 'output': AR, 'interpolation': 'LINEAR'}],
                        'channels': [{'sampler': 0, 'target': {'node': 4, 'path': 'rotation'}}]}],
        'accessors': B.accessors,
        'bufferViews': B.views,
        'buffers': [{'byteLength': len(B.data), 'name': 'bin'}],
        'extras': {'top': True},
    }
    glb(path, doc, B.data)


def strips(path):
    import base64
    B = Builder()
    # a ribbon of 2 x 9 vertices as one strip, then a second strip joined by
    # repeating two indices (degenerate triangles)
    pos, uv = [], []
    for i in range(9):
        for r in range(2):
            x, y = i / 8, r * 0.25
            pos.append((x, y, 0.05 * math.sin(4 * x)))
            uv.append((x, 1 - y * 4))
    for i in range(9):
        for r in range(2):
            x, y = i / 8, 0.5 + r * 0.25
            pos.append((x, y, 0.05 * math.cos(4 * x)))
            uv.append((x, 0.5 - r * 0.5))
    s1 = [2 * i + r for i in range(9) for r in range(2)]
    s2 = [18 + 2 * i + r for i in range(9) for r in range(2)]
    strip = s1 + [s1[-1], s2[0]] + s2
    P = B.floats(pos, 'VEC3', minmax=True)
    UV = B.accessor(bufferView=B.view(b''.join(struct.pack('<2H', int(u * 65535), int(v * 65535)) for u, v in uv), 34962),
                    componentType=5123, normalized=True, count=len(uv), type='VEC2')
    S = B.indices(strip, 5121)
    # a fan (no indices): centre, then 13 rim points; positions as int16 normalized
    fan = [(0.0, 0.0, 0.2)] + [(0.5 * math.cos(2 * math.pi * k / 12), 0.5 * math.sin(2 * math.pi * k / 12), 0.0)
                               for k in range(13)]
    Q = B.accessor(bufferView=B.view(b''.join(struct.pack('<3h', *(int(round(c * 32767)) for c in p)) + b'\0\0'
                                             for p in fan), 34962, stride=8),
                   componentType=5122, normalized=True, count=len(fan), type='VEC3',
                   min=[-1, -1, 0], max=[1, 1, 1])
    # a triangle list without indices (two triangles of a quad), and a line strip
    # (the second triangle wound the other way: the repair turns it, the writer writes it turned)
    quad = [(2, 0, 0), (3, 0, 0), (3, 1, 0.1), (2, 0, 0), (2, 1, 0), (3, 1, 0.1)]
    Qd = B.floats(quad, 'VEC3', minmax=True)
    doc = {
        'asset': {'version': '2.0', 'generator': 'tests/gltf_make.py'},
        'extensionsUsed': ['KHR_mesh_quantization'],
        'extensionsRequired': ['KHR_mesh_quantization'],
        'scene': 0,
        'scenes': [{'nodes': [0, 1]}],
        'nodes': [{'mesh': 0}, {'mesh': 1, 'scale': [1, 1, 1]}],
        'meshes': [
            {'primitives': [{'attributes': {'POSITION': P, 'TEXCOORD_0': UV}, 'indices': S, 'mode': 5},
                            {'attributes': {'POSITION': Q}, 'mode': 6}]},
            {'primitives': [{'attributes': {'POSITION': Qd}},
                            {'attributes': {'POSITION': P}, 'indices': S, 'mode': 3}]}],
        'accessors': B.accessors,
        'bufferViews': B.views,
        'buffers': [{'byteLength': len(B.data),
                     'uri': 'data:application/octet-stream;base64,' + base64.b64encode(bytes(B.data)).decode()}],
    }
    with open(path, 'wb') as f:
        f.write(dump(doc))


def external(path):
    B = Builder()
    pos, nrm, tan, col, left, right = terrain(12)
    P = B.floats(pos, 'VEC3', minmax=True)
    N = B.floats(nrm, 'VEC3')
    UV = B.floats([(p[0] * 2, 1 - p[1]) for p in pos], 'VEC2')   # v runs downward in glTF
    I = B.indices(left + right, 5123)
    folder = os.path.dirname(path)
    with open(os.path.join(folder, 'external data.bin'), 'wb') as f:
        f.write(bytes(B.data))
    with open(os.path.join(folder, 'checker.png'), 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + bytes(24))
    doc = {
        'asset': {'version': '2.0', 'generator': 'tests/gltf_make.py'},
        'scene': 0, 'scenes': [{'nodes': [0]}], 'nodes': [{'mesh': 0}],
        'meshes': [{'primitives': [{'attributes': {'POSITION': P, 'NORMAL': N, 'TEXCOORD_0': UV}, 'indices': I,
                                    'material': 0}]}],
        'materials': [{'pbrMetallicRoughness': {'baseColorTexture': {'index': 0}}}],
        'textures': [{'source': 0}],
        'images': [{'uri': 'checker.png'}],
        'accessors': B.accessors,
        'bufferViews': B.views,
        'buffers': [{'byteLength': len(B.data), 'uri': 'external%20data.bin'}],
    }
    with open(path, 'wb') as f:
        f.write(dump(doc))


def instanced(path):
    """two meshes drawing one cube-sphere from the same accessors (POSITION,
    NORMAL, indices), each placed by its own node: a common glTF pattern"""
    B = Builder()
    pos, nrm, idx = cube_sphere(3)
    ap = B.floats(pos, 'VEC3', minmax=True)
    an = B.floats(nrm, 'VEC3')
    ai = B.indices(idx, 5123)
    prim = {'attributes': {'POSITION': ap, 'NORMAL': an}, 'indices': ai}
    doc = {
        'asset': {'version': '2.0'},
        'scene': 0, 'scenes': [{'nodes': [0, 1]}],
        'nodes': [{'mesh': 0}, {'mesh': 1, 'translation': [0, 2, 0]}],
        'meshes': [{'name': 'a', 'primitives': [dict(prim)]}, {'name': 'b', 'primitives': [dict(prim)]}],
        'accessors': B.accessors,
        'bufferViews': B.views,
        'buffers': [{'byteLength': len(B.data)}],
    }
    glb(path, doc, B.data)


def triangle(path):
    """one triangle, no indices, a data: URI: the smallest file read"""
    import base64
    raw = struct.pack('<9f', 0, 0, 0, 1, 0, 0, 0, 1, 0)
    doc = {'asset': {'version': '2.0'}, 'meshes': [{'primitives': [{'attributes': {'POSITION': 0}}]}],
           'accessors': [{'bufferView': 0, 'componentType': 5126, 'count': 3, 'type': 'VEC3'}],
           'bufferViews': [{'buffer': 0, 'byteLength': 36}],
           'buffers': [{'byteLength': 36, 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(raw).decode()}]}
    with open(path, 'w') as f:
        json.dump(doc, f, separators=(',', ':'))


def main():
    if len(sys.argv) == 3 and sys.argv[1] == '--seeds':
        # small versions for the fuzzer's corpus (each under 4 KiB)
        d = sys.argv[2]
        os.makedirs(d, exist_ok=True)
        INDENT[0] = None
        two_meshes(os.path.join(d, 'two_meshes_small.glb'), 3, 1)
        strips(os.path.join(d, 'strips.gltf'))
        triangle(os.path.join(d, 'triangle.gltf'))
        return 0
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    d = sys.argv[1]
    os.makedirs(d, exist_ok=True)
    two_meshes(os.path.join(d, 'two_meshes.glb'))
    strips(os.path.join(d, 'strips.gltf'))
    external(os.path.join(d, 'external.gltf'))
    instanced(os.path.join(d, 'instanced.glb'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
