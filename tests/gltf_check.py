#!/usr/bin/env python3
"""gltf_check.py - an independent reader of what the tool wrote as glTF.

    gltf_check.py compare IN OUT [--texcoord N]
        OUT is IN with a new TEXCOORD_N: prints one line per property
        proven, "FAIL ..." for each one broken, exit 1 when any is.
    gltf_check.py obj OUT OBJ [--texcoord N]
        OUT's triangle primitives and TEXCOORD_N as an OBJ for the exact
        checker (bijparam --check): vertices welded by position within a
        vertex set, vt by (position, uv); vt is (u, -v), the glTF map
        mirrored to the OBJ convention and moved by -1, exactly (negation
        rounds nothing), so orientation and overlaps are those of OUT.

Only the Python standard library: JSON, GLB chunks, data: URIs and .bin
files are read here without the project's C code, so a bug shared by its
reader and writer cannot hide.  "compare" proves:
  - every JSON value of IN is in OUT unchanged, except what the new map
    must change: the triangle primitives' attributes, indices and morph
    targets now point at new accessors (appended after IN's), strips and
    fans became mode 4, buffers may have grown (new bytes appended) or
    gained one (appended); IN's accessors and bufferViews come first in
    OUT as they were;
  - the bytes of IN's buffers are a prefix of OUT's;
  - triangle for triangle, each corner of each written primitive has, in
    OUT, exactly the bytes IN had for every attribute but TEXCOORD_N and
    for every morph target attribute (the corners in the same order, or
    with the last two swapped where the repair re-oriented a triangle);
  - every TEXCOORD_N value is finite.
"""
import base64
import json
import math
import os
import struct
import sys
import urllib.parse

CSIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
NCOMP = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4, 'MAT2': 4, 'MAT3': 9, 'MAT4': 16}
FMT = {5120: 'b', 5121: 'B', 5122: 'h', 5123: 'H', 5125: 'I', 5126: 'f'}


def load(path):
    """(json, [bytes of each buffer], raw JSON text)"""
    data = open(path, 'rb').read()
    bin_chunk = None
    if data[:4] == b'glTF':
        length = struct.unpack_from('<I', data, 8)[0]
        assert length == len(data), 'GLB length %d != file %d' % (length, len(data))
        at = 12
        chunks = []
        while at < len(data):
            cl, ct = struct.unpack_from('<II', data, at)
            chunks.append((ct, data[at + 8:at + 8 + cl]))
            at += 8 + cl
        assert chunks[0][0] == 0x4E4F534A
        text = chunks[0][1]
        for ct, cd in chunks[1:]:
            if ct == 0x004E4942:
                bin_chunk = cd
                break
    else:
        text = data
    doc = json.loads(text.decode('utf-8'))
    bufs = []
    folder = os.path.dirname(path)
    for i, b in enumerate(doc.get('buffers', [])):
        uri = b.get('uri')
        if uri is None:
            assert i == 0 and bin_chunk is not None, 'buffer %d has no uri' % i
            raw = bin_chunk
        elif uri.startswith('data:'):
            head, payload = uri.split(',', 1)
            raw = base64.b64decode(payload) if head.endswith(';base64') else urllib.parse.unquote_to_bytes(payload)
        else:
            raw = open(os.path.join(folder, urllib.parse.unquote(uri)), 'rb').read()
        assert len(raw) >= b['byteLength'], 'buffer %d: %d bytes < byteLength %d' % (i, len(raw), b['byteLength'])
        bufs.append(raw[:b['byteLength']])
    return doc, bufs, text


def esize(acc):
    cs, t = CSIZE[acc['componentType']], acc['type']
    if t.startswith('MAT') and cs < 4:
        m = int(t[3])
        return m * ((m * cs + 3) // 4 * 4)
    return NCOMP[t] * cs


def elements(doc, bufs, i):
    """accessor i's elements as bytes, sparse applied"""
    acc = doc['accessors'][i]
    es, n = esize(acc), acc['count']
    if 'bufferView' in acc:
        bv = doc['bufferViews'][acc['bufferView']]
        data = bufs[bv['buffer']]
        base = bv.get('byteOffset', 0) + acc.get('byteOffset', 0)
        stride = bv.get('byteStride', es)
        out = [data[base + k * stride:base + k * stride + es] for k in range(n)]
    else:
        out = [bytes(es)] * n
    sp = acc.get('sparse')
    if sp:
        iv = doc['bufferViews'][sp['indices']['bufferView']]
        vv = doc['bufferViews'][sp['values']['bufferView']]
        ic = sp['indices']['componentType']
        io = iv.get('byteOffset', 0) + sp['indices'].get('byteOffset', 0)
        vo = vv.get('byteOffset', 0) + sp['values'].get('byteOffset', 0)
        for k in range(sp['count']):
            j = struct.unpack_from('<' + FMT[ic], bufs[iv['buffer']], io + k * CSIZE[ic])[0]
            out[j] = bufs[vv['buffer']][vo + k * es:vo + (k + 1) * es]
    return out


def values(doc, bufs, i):
    """accessor i's elements as tuples of numbers (normalized integers scaled)"""
    acc = doc['accessors'][i]
    ct, nc = acc['componentType'], NCOMP[acc['type']]
    scale = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}.get(ct) if acc.get('normalized') else None
    out = []
    for e in elements(doc, bufs, i):
        v = struct.unpack('<%d%s' % (nc, FMT[ct]), e[:nc * CSIZE[ct]])
        out.append(tuple(max(x / scale, -1.0) for x in v) if scale else v)
    return out


def triangles(doc, bufs, prim):
    """a primitive's triangles as glTF draws them (strip and fan turned
    into triangles, their degenerate joins dropped)"""
    mode = prim.get('mode', 4)
    if 'indices' in prim:
        idx = [v[0] for v in values(doc, bufs, prim['indices'])]
    else:
        idx = list(range(doc['accessors'][prim['attributes']['POSITION']]['count']))
    tris = []
    if mode == 4:
        tris = [tuple(idx[k:k + 3]) for k in range(0, len(idx) - 2, 3)]
    elif mode == 5:
        for i in range(len(idx) - 2):
            t = (idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2])
            if len(set(t)) == 3:
                tris.append(t)
    elif mode == 6:
        for i in range(len(idx) - 2):
            t = (idx[i + 1], idx[i + 2], idx[0])
            if len(set(t)) == 3:
                tris.append(t)
    return tris


class Report:
    def __init__(self):
        self.bad = 0

    def check(self, ok, what):
        if ok:
            print('ok   ' + what)
        else:
            self.bad += 1
            print('FAIL ' + what)


def written(prim, doc_in, bufs_in):
    return prim.get('mode', 4) in (4, 5, 6) and len(triangles(doc_in, bufs_in, prim)) > 0


def resolve_uris(doc, path):
    """relative uris of buffers and images as the paths they name, so that
    a file written in another folder compares equal when it reaches the
    same files"""
    folder = os.path.dirname(os.path.abspath(path))
    for k in ('buffers', 'images'):
        for x in doc.get(k, []):
            u = x.get('uri')
            if u is not None and not u.startswith('data:') and '://' not in u:
                x['uri'] = os.path.normpath(os.path.join(folder, urllib.parse.unquote(u)))


def compare(pin, pout, tex):
    r = Report()
    din, bin_, _ = load(pin)
    dout, bout, _ = load(pout)
    resolve_uris(din, pin)
    resolve_uris(dout, pout)
    key = 'TEXCOORD_%d' % tex
    na, nv, nb = len(din.get('accessors', [])), len(din.get('bufferViews', [])), len(din.get('buffers', []))
    # 1. the JSON: everything of IN in OUT, but what must change
    skip = ('meshes', 'accessors', 'bufferViews', 'buffers')
    same = all(dout.get(k) == v for k, v in din.items() if k not in skip) and \
        all(k in din or k in skip for k in dout)
    r.check(same, '%s: every top-level value but meshes, accessors, bufferViews, buffers is unchanged (%d keys)'
            % (pout, len(din)))
    r.check(dout.get('accessors', [])[:na] == din.get('accessors', []),
            '%s: the input\'s %d accessors come first, unchanged' % (pout, na))
    r.check(dout.get('bufferViews', [])[:nv] == din.get('bufferViews', []),
            '%s: the input\'s %d bufferViews come first, unchanged' % (pout, nv))
    okb = len(dout.get('buffers', [])) in (nb, nb + 1)
    for i, b in enumerate(din.get('buffers', [])):
        bo = dout['buffers'][i] if i < len(dout.get('buffers', [])) else {}
        rest_in = {k: v for k, v in b.items() if k not in ('byteLength', 'uri')}
        rest_out = {k: v for k, v in bo.items() if k not in ('byteLength', 'uri')}
        okb &= rest_in == rest_out and bo.get('byteLength', -1) >= b['byteLength']
        okb &= 'uri' not in b or (bo.get('uri') == b['uri'] and bo['byteLength'] == b['byteLength'])
        okb &= bout[i][:b['byteLength']] == bin_[i]
    r.check(okb, '%s: the bytes of the input\'s %d buffers are unchanged (new ones appended)' % (pout, nb))
    # 2. meshes: the primitives
    mi, mo = din.get('meshes', []), dout.get('meshes', [])
    r.check(len(mi) == len(mo), '%s: %d meshes' % (pout, len(mi)))
    nprim = ncorner = nflip = 0
    for m, (a, b) in enumerate(zip(mi, mo)):
        r.check({k: v for k, v in a.items() if k != 'primitives'} == {k: v for k, v in b.items() if k != 'primitives'},
                'mesh %d: its other values (name, weights, extras, extensions) are unchanged' % m)
        r.check(len(a['primitives']) == len(b['primitives']), 'mesh %d: %d primitives' % (m, len(a['primitives'])))
        for p, (pa, pb) in enumerate(zip(a['primitives'], b['primitives'])):
            name = 'mesh %d primitive %d' % (m, p)
            if not written(pa, din, bin_):
                r.check(pa == pb, '%s (mode %d) is unchanged' % (name, pa.get('mode', 4)))
                continue
            nprim += 1
            other_a = {k: v for k, v in pa.items() if k not in ('attributes', 'indices', 'mode', 'targets')}
            other_b = {k: v for k, v in pb.items() if k not in ('attributes', 'indices', 'mode', 'targets')}
            r.check(other_a == other_b and pb.get('mode', 4) == 4,
                    '%s: mode 4, material, extras and extensions unchanged' % name)
            names_a = set(pa['attributes']) | {key}
            r.check(set(pb['attributes']) == names_a and
                    all(pb['attributes'][k] >= na for k in pb['attributes']) and pb['indices'] >= na,
                    '%s: attributes %s, each a new accessor' % (name, ','.join(sorted(names_a))))
            ta, tb = pa.get('targets', []), pb.get('targets', [])
            r.check(len(ta) == len(tb) and all(set(x) == set(y) for x, y in zip(ta, tb)),
                    '%s: %d morph targets with the same attributes' % (name, len(ta)))
            tri_a, tri_b = triangles(din, bin_, pa), triangles(dout, bout, pb)
            r.check(len(tri_a) == len(tri_b), '%s: %d triangles in, %d out' % (name, len(tri_a), len(tri_b)))
            # every attribute and target attribute of every corner, byte for byte
            maps = [(pa['attributes'][k], pb['attributes'][k], k) for k in pa['attributes'] if k != key]
            for t, (x, y) in enumerate(zip(ta, tb)):
                maps += [(x[k], y[k], 'target %d %s' % (t, k)) for k in x]
            el = [(elements(din, bin_, i), elements(dout, bout, o), k) for i, o, k in maps]
            bad = []
            for ti, (ca, cb) in enumerate(zip(tri_a, tri_b)):
                for order in ((0, 1, 2), (0, 2, 1)):
                    if all(ea[ca[order[k]]] == eb[cb[k]] for ea, eb, _ in el for k in range(3)):
                        nflip += order != (0, 1, 2)
                        break
                else:
                    bad.append(ti)
                ncorner += 3
            r.check(not bad, '%s: every corner keeps the bytes of its %d attributes and target attributes%s'
                    % (name, len(el), ' (bad triangles %s)' % bad[:5] if bad else ''))
            uv = values(dout, bout, pb['attributes'][key])
            r.check(all(math.isfinite(c) for v in uv for c in v) and
                    dout['accessors'][pb['attributes'][key]]['componentType'] == 5126,
                    '%s: %s is float and finite (%d vertices)' % (name, key, len(uv)))
    r.check(nprim > 0, '%s: %d triangle primitives written, %d corners compared, %d triangles re-oriented'
            % (pout, nprim, ncorner, nflip))
    return r.bad


def to_obj(pout, pobj, tex):
    d, b, _ = load(pout)
    key = 'TEXCOORD_%d' % tex
    vs, vts, faces = {}, {}, []
    for m, mesh in enumerate(d.get('meshes', [])):
        for prim in mesh['primitives']:
            if prim.get('mode', 4) not in (4, 5, 6):
                continue
            group = tuple(sorted(prim['attributes'].items())) + (json.dumps(prim.get('targets', [])),)
            pos = values(d, b, prim['attributes']['POSITION'])
            uv = values(d, b, prim['attributes'][key])
            for t in triangles(d, b, prim):
                f = []
                for c in t:
                    p = (group, pos[c])
                    vi = vs.setdefault(p, len(vs) + 1)
                    ti = vts.setdefault((p, uv[c]), len(vts) + 1)
                    f.append('%d/%d' % (vi, ti))
                faces.append('f ' + ' '.join(f))
    with open(pobj, 'w') as o:
        for (_, p), _i in sorted(vs.items(), key=lambda kv: kv[1]):
            o.write('v %r %r %r\n' % tuple(float(x) for x in p))
        for ((_, _p), (u, v)), _i in sorted(vts.items(), key=lambda kv: kv[1]):
            o.write('vt %r %r\n' % (float(u), -float(v)))
        o.write('\n'.join(faces) + '\n')
    print('%s: %d vertices, %d vt, %d faces' % (pobj, len(vs), len(vts), len(faces)))
    return 0


def main():
    args = sys.argv[1:]
    tex = 0
    if '--texcoord' in args:
        i = args.index('--texcoord')
        tex = int(args[i + 1])
        del args[i:i + 2]
    if len(args) == 3 and args[0] == 'compare':
        return 1 if compare(args[1], args[2], tex) else 0
    if len(args) == 3 and args[0] == 'obj':
        return to_obj(args[1], args[2], tex)
    print(__doc__)
    return 2


if __name__ == '__main__':
    sys.exit(main())
