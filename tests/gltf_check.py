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
    gained one (appended);
  - the accessors and bufferViews only the written primitives referenced
    are gone (worked out here: none when an unknown extension holds a
    whole number), every other one comes first in OUT in its order with
    its JSON and its bytes, and every reference to it is renumbered;
  - the bytes of IN's buffers are a prefix of OUT's, but for a .glb's BIN
    chunk, where the 4-byte units that only removed bufferViews held are
    cut out; OUT's new bytes all lie in its new bufferViews, and every
    accessor and bufferView of OUT is referenced (unless IN already left
    it unreferenced);
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


KNOWN_EXT = ('KHR_texture_transform', 'KHR_lights_punctual', 'KHR_mesh_quantization', 'KHR_texture_basisu',
             'EXT_texture_webp', 'EXT_texture_avif', 'KHR_xmp_json_ld', 'KHR_materials_variants', 'MSFT_texture_dds',
             'EXT_lights_image_based')


def has_int(x):
    if isinstance(x, bool):
        return False
    if isinstance(x, int):
        return True
    if isinstance(x, dict):
        return any(has_int(v) for v in x.values())
    if isinstance(x, list):
        return any(has_int(v) for v in x)
    return False


def extension_dicts(x):
    """every "extensions" object of the document"""
    if isinstance(x, dict):
        for k, v in x.items():
            if k == 'extensions' and isinstance(v, dict):
                yield v
            yield from extension_dicts(v)
    elif isinstance(x, list):
        for v in x:
            yield from extension_dicts(v)


def references(doc, written_of):
    """(kind, container, key, use) for every reference to an accessor
    (kind 0) or bufferView (kind 1): use 1 from a written primitive, 2
    from anything else"""
    refs = []
    for m in doc.get('meshes', []):
        for prim in m['primitives']:
            use = 1 if written_of(prim) else 2
            refs += [(0, prim['attributes'], k, use) for k in prim['attributes']]
            if 'indices' in prim:
                refs.append((0, prim, 'indices', use))
            for t in prim.get('targets', []):
                refs += [(0, t, k, use) for k in t]
    for sk in doc.get('skins', []):
        if 'inverseBindMatrices' in sk:
            refs.append((0, sk, 'inverseBindMatrices', 2))
    for an in doc.get('animations', []):
        for sa in an.get('samplers', []):
            refs += [(0, sa, k, 2) for k in ('input', 'output') if k in sa]
    for im in doc.get('images', []):
        if 'bufferView' in im:
            refs.append((1, im, 'bufferView', 2))
    for ext in extension_dicts(doc):
        inst = ext.get('EXT_mesh_gpu_instancing')
        if isinstance(inst, dict):
            refs += [(0, inst['attributes'], k, 2) for k in inst.get('attributes', {})]
    return refs


def accessor_view_refs(acc):
    out = [(acc, 'bufferView')] if 'bufferView' in acc else []
    sp = acc.get('sparse')
    if sp:
        out += [(sp['indices'], 'bufferView'), (sp['values'], 'bufferView')]
    return out


def plan(din, bufs_in, written_of):
    """What the writer must remove (bp_gltf.h, "what the rewrite leaves
    unused"), worked out here on the parsed JSON: (accessor map, view map,
    expected BIN chunk or None, refused); a map gives each input index its
    output index or None when removed."""
    na, nv = len(din.get('accessors', [])), len(din.get('bufferViews', []))
    refused = any(k != 'EXT_mesh_gpu_instancing' and not k.startswith('KHR_materials_') and k not in KNOWN_EXT and
                  has_int(v) for ext in extension_dicts(din) for k, v in ext.items())
    acc_use, view_use = [0] * na, [0] * nv
    for kind, obj, key, use in references(din, written_of):
        i, lim, u = obj[key], (na, nv)[kind], (acc_use, view_use)[kind]
        if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < lim:
            refused = True
            continue
        u[i] = max(u[i], use)
    for i, acc in enumerate(din.get('accessors', [])):
        for obj, key in accessor_view_refs(acc):
            view_use[obj[key]] = max(view_use[obj[key]], 1 if acc_use[i] == 1 else 2)
    if refused:
        return list(range(na)), list(range(nv)), None, True
    amap, vmap, k = [], [], 0
    for u in acc_use:
        amap.append(None if u == 1 else k)
        k += u != 1
    k = 0
    for u in view_use:
        vmap.append(None if u == 1 else k)
        k += u != 1
    binc = None
    bufs = din.get('buffers', [])
    if bufs and 'uri' not in bufs[0]:
        # buffer 0 is the BIN chunk: a 4-byte unit goes when a removed view
        # covers it whole and no kept view touches it
        data = bufs_in[0]
        units = (len(data) + 3) // 4
        dropped, kept = bytearray(units), bytearray(units)
        for j, bv in enumerate(din.get('bufferViews', [])):
            if bv['buffer'] != 0:
                continue
            a, b = bv.get('byteOffset', 0), bv.get('byteOffset', 0) + bv['byteLength']
            if vmap[j] is None:
                for q in range((a + 3) // 4, b // 4):
                    dropped[q] = 1
            else:
                for q in range(a // 4, (b + 3) // 4):
                    kept[q] = 1
        binc = b''.join(data[4 * q:4 * q + 4] for q in range(units) if not (dropped[q] and not kept[q]))
    return amap, vmap, binc, False


def translate(x, amap, vmap, written_of):
    """a deep copy of IN's JSON value x with every reference renumbered"""
    x = json.loads(json.dumps(x))
    wrap = {'v': x}
    doc = x if isinstance(x, dict) else {}
    for kind, obj, key, use in references(doc, written_of) if doc else []:
        if use == 2:
            obj[key] = (amap, vmap)[kind][obj[key]]
    return wrap['v']


def valid(doc, bufs):
    """what breaks the glTF 2.0 rules on indices, ranges and alignment"""
    bad = []
    na, nv = len(doc.get('accessors', [])), len(doc.get('bufferViews', []))
    for kind, obj, k, _ in references(doc, lambda p: False):
        if not 0 <= obj[k] < (na, nv)[kind]:
            bad.append('%s %s = %d out of range' % (('accessor', 'bufferView')[kind], k, obj[k]))
    for j, bv in enumerate(doc.get('bufferViews', [])):
        if not 0 <= bv['buffer'] < len(bufs) or bv.get('byteOffset', 0) + bv['byteLength'] > len(bufs[bv['buffer']]):
            bad.append('bufferView %d outside its buffer' % j)
    for i, acc in enumerate(doc.get('accessors', [])):
        for o, k in accessor_view_refs(acc):
            if not 0 <= o[k] < nv:
                bad.append('accessor %d: bufferView %d out of range' % (i, o[k]))
        if 'bufferView' not in acc or not 0 <= acc['bufferView'] < nv:
            continue
        bv = doc['bufferViews'][acc['bufferView']]
        es, cs = esize(acc), CSIZE[acc['componentType']]
        stride = bv.get('byteStride', es)
        off = acc.get('byteOffset', 0)
        if acc['count'] and off + stride * (acc['count'] - 1) + es > bv['byteLength']:
            bad.append('accessor %d overruns bufferView %d' % (i, acc['bufferView']))
        if (bv.get('byteOffset', 0) + off) % cs or stride % cs:
            bad.append('accessor %d is not aligned to its component size' % i)
    return bad


def compare(pin, pout, tex):
    r = Report()
    din, bin_, _ = load(pin)
    dout, bout, _ = load(pout)
    resolve_uris(din, pin)
    resolve_uris(dout, pout)
    key = 'TEXCOORD_%d' % tex
    written_in = lambda prim: written(prim, din, bin_)
    amap, vmap, binc, refused = plan(din, bin_, written_in)
    ain, aout = din.get('accessors', []), dout.get('accessors', [])
    vin, vout = din.get('bufferViews', []), dout.get('bufferViews', [])
    na_kept = sum(m is not None for m in amap)
    nv_kept = sum(m is not None for m in vmap)
    print('ok   %s: %d of %d accessors and %d of %d bufferViews left unreferenced by the rewrite%s'
          % (pout, len(ain) - na_kept, len(ain), len(vin) - nv_kept, len(vin), ' (kept: an extension holds indices)'
             if refused else ''))
    # 1. the JSON: everything of IN in OUT (references renumbered), but what must change
    tin = translate(din, amap, vmap, written_in)
    skip = ('meshes', 'accessors', 'bufferViews', 'buffers')
    same = all(dout.get(k) == v for k, v in tin.items() if k not in skip) and \
        all(k in din or k in skip for k in dout)
    r.check(same, '%s: every top-level value but meshes, accessors, bufferViews, buffers is unchanged, references '
            'renumbered (%d keys)' % (pout, len(din)))
    # the kept accessors and bufferViews, in order, first; their JSON and bytes
    ok_acc = len(aout) >= na_kept
    for i, m in enumerate(amap):
        if m is None or not ok_acc:
            continue
        want = json.loads(json.dumps(ain[i]))
        for obj, k in accessor_view_refs(want):
            obj[k] = vmap[obj[k]]
        ok_acc &= aout[m] == want and elements(din, bin_, i) == elements(dout, bout, m)
    r.check(ok_acc, '%s: the input\'s %d kept accessors come first, their JSON and elements unchanged' % (pout, na_kept))
    ok_view = len(vout) >= nv_kept
    for j, m in enumerate(vmap):
        if m is None or not ok_view:
            continue
        a, b = vin[j], vout[m]
        ok_view &= {k: v for k, v in a.items() if k != 'byteOffset'} == {k: v for k, v in b.items() if k != 'byteOffset'}
        oa, ob = a.get('byteOffset', 0), b.get('byteOffset', 0)
        ok_view &= bin_[a['buffer']][oa:oa + a['byteLength']] == bout[b['buffer']][ob:ob + b['byteLength']]
        ok_view &= oa % 4 == ob % 4
    r.check(ok_view, '%s: the input\'s %d kept bufferViews come first, their JSON (but byteOffset) and bytes unchanged, '
            'offsets aligned as they were' % (pout, nv_kept))
    nb = len(din.get('buffers', []))
    okb = len(dout.get('buffers', [])) in (nb, nb + 1)
    for i, b in enumerate(din.get('buffers', [])):
        bo = dout['buffers'][i] if i < len(dout.get('buffers', [])) else {}
        rest_in = {k: v for k, v in b.items() if k not in ('byteLength', 'uri')}
        rest_out = {k: v for k, v in bo.items() if k not in ('byteLength', 'uri')}
        okb &= rest_in == rest_out
        if 'uri' in b:
            okb &= bo.get('uri') == b['uri'] and bo['byteLength'] == b['byteLength'] and bout[i] == bin_[i]
        else:
            keep = bin_[i] if binc is None else binc
            okb &= bout[i][:len(keep)] == keep
    r.check(okb, '%s: the input\'s %d buffers keep their bytes (a .glb\'s BIN chunk: all but what removed bufferViews '
            'alone held), new bytes appended' % (pout, nb))
    # nothing unreferenced is left behind: every accessor and bufferView of
    # OUT is referenced, unless the input already left it unreferenced
    if not refused:
        inv_a = {m: i for i, m in enumerate(amap) if m is not None}
        inv_v = {m: j for j, m in enumerate(vmap) if m is not None}
        used_a, used_v = set(), set()
        for kind, obj, k, use in references(dout, lambda p: False):
            (used_a, used_v)[kind].add(obj[k])
        for acc in aout:
            used_v.update(o[k] for o, k in accessor_view_refs(acc))
        orphan_a = [i for i in range(len(aout)) if i not in used_a and not (i in inv_a and not any(
            obj[k] == inv_a[i] for kind, obj, k, _ in references(din, written_in) if kind == 0))]
        orphan_v = [j for j in range(len(vout)) if j not in used_v and not (j in inv_v and not any(
            o[k] == inv_v[j] for acc in ain for o, k in accessor_view_refs(acc)) and not any(
            im.get('bufferView') == inv_v[j] for im in din.get('images', [])))]
        r.check(not orphan_a and not orphan_v, '%s: every accessor and bufferView is referenced (unreferenced: accessors '
                '%s, bufferViews %s)' % (pout, orphan_a[:5], orphan_v[:5]))
        if binc is not None and dout.get('buffers') and 'uri' not in din['buffers'][0]:
            b0 = [(bv.get('byteOffset', 0), bv['byteLength']) for bv in vout if bv['buffer'] == 0]
            tail = [(o, n) for o, n in b0 if o >= len(binc)]
            covered = sum(n for o, n in tail)
            extra = len(bout[0]) - (len(binc) + 3) // 4 * 4
            r.check(extra <= covered + 3 * len(tail), '%s: buffer 0 holds %d bytes (the input\'s %d, %d kept) and its new '
                    '%d bytes are all in new bufferViews (%d bytes, %d views)'
                    % (pout, len(bout[0]), len(bin_[0]), len(binc), extra, covered, len(tail)))
    r.check(valid(dout, bout) == [], '%s: valid glTF: every reference in range, every accessor inside its bufferView '
            'and aligned, every bufferView inside its buffer (%s)' % (pout, '; '.join(valid(dout, bout)[:3]) or 'none broken'))
    # 2. meshes: the primitives
    mi, mo = din.get('meshes', []), dout.get('meshes', [])
    mt = tin.get('meshes', [])
    r.check(len(mi) == len(mo), '%s: %d meshes' % (pout, len(mi)))
    nprim = ncorner = nflip = 0
    for m, (a, b) in enumerate(zip(mi, mo)):
        r.check({k: v for k, v in a.items() if k != 'primitives'} == {k: v for k, v in b.items() if k != 'primitives'},
                'mesh %d: its other values (name, weights, extras, extensions) are unchanged' % m)
        r.check(len(a['primitives']) == len(b['primitives']), 'mesh %d: %d primitives' % (m, len(a['primitives'])))
        for p, (pa, pb) in enumerate(zip(a['primitives'], b['primitives'])):
            name = 'mesh %d primitive %d' % (m, p)
            if not written(pa, din, bin_):
                r.check(mt[m]['primitives'][p] == pb, '%s (mode %d) is unchanged, references renumbered'
                        % (name, pa.get('mode', 4)))
                continue
            nprim += 1
            other_a = {k: v for k, v in pa.items() if k not in ('attributes', 'indices', 'mode', 'targets')}
            other_b = {k: v for k, v in pb.items() if k not in ('attributes', 'indices', 'mode', 'targets')}
            r.check(other_a == other_b and pb.get('mode', 4) == 4,
                    '%s: mode 4, material, extras and extensions unchanged' % name)
            names_a = set(pa['attributes']) | {key}
            r.check(set(pb['attributes']) == names_a and
                    all(pb['attributes'][k] >= na_kept for k in pb['attributes']) and pb['indices'] >= na_kept,
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
