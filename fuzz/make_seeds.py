#!/usr/bin/env python3
"""Writes the fuzzers' seed corpus: fuzz/corpus/scene (scene archives, see hush_engine::fuzz) and
fuzz/corpus/image. Seeds named ok-* load; bad-* are refused (the corpus replay test checks both).
Needs Pillow (PNG, JPEG) and an EXR written by Hush: `hush-cli render default --spp 1 --width 8
--height 4 --out env.exr`, passed as the first argument."""
import base64, io, json, os, struct, sys
from PIL import Image

here = os.path.dirname(os.path.abspath(__file__))
MARK = b"\n--hush-file:"
exr = open(sys.argv[1], 'rb').read()

def pack(scene, files):
    out = scene if isinstance(scene, bytes) else json.dumps(scene, separators=(',', ':')).encode()
    for name, data in files.items():
        out += MARK + name.encode() + b"\n" + data
    return out

def img(mode, size, fmt, color):
    b = io.BytesIO()
    Image.new(mode, size, color).save(b, fmt)
    return b.getvalue()

PNG = img('RGBA', (4, 4), 'PNG', (200, 100, 50, 255))
JPG = img('RGB', (8, 8), 'JPEG', (20, 200, 50))

# A unit quad: positions, normals, uvs, u32 indices (152 bytes); u16 and u8 index copies after.
QUAD = b''.join(struct.pack('<3f', *p) for p in [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)])
QUAD += struct.pack('<3f', 0, 1, 0) * 4
QUAD += b''.join(struct.pack('<2f', *u) for u in [(0, 0), (1, 0), (1, 1), (0, 1)])
QUAD += struct.pack('<6I', 0, 2, 1, 0, 3, 2)
QUAD += struct.pack('<4H', 0, 1, 2, 3) + struct.pack('<4B', 0, 1, 2, 3)  # strip/fan indices
TIMES = struct.pack('<3f', 0, 0.5, 1)
KEYS3 = struct.pack('<9f', 0, 0, 0, 0, 1, 0, 0, 0, 0)
KEYS4 = struct.pack('<12f', 0, 0, 0, 1, 0, 0.7071, 0, 0.7071, 0, 0, 0, 1)
BIN = QUAD + TIMES + KEYS3 + KEYS4  # 164 + 12 + 36 + 48 = 260

def doc(extra_nodes=(), **kw):
    d = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 3, 0.01], "rotation": [-0.7071068, 0, 0, 0.7071068]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0}, "emissiveFactor": [1, 1, 1]}],
        "buffers": [{"uri": "q.bin", "byteLength": len(BIN)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 152, "byteLength": 8}, {"buffer": 0, "byteOffset": 160, "byteLength": 4},
                        {"buffer": 0, "byteOffset": 164, "byteLength": 12}, {"buffer": 0, "byteOffset": 176, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 212, "byteLength": 48}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                      {"bufferView": 3, "componentType": 5125, "count": 6, "type": "SCALAR"},
                      {"bufferView": 4, "componentType": 5123, "count": 4, "type": "SCALAR"},
                      {"bufferView": 5, "componentType": 5121, "count": 4, "type": "SCALAR"},
                      {"bufferView": 6, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [1]},
                      {"bufferView": 7, "componentType": 5126, "count": 3, "type": "VEC3"},
                      {"bufferView": 8, "componentType": 5126, "count": 3, "type": "VEC4"}],
    }
    d.update(kw)
    return d

F = {"q.bin": BIN}
scenes = {}
scenes['ok-quad'] = pack(doc(), F)
d = doc(); del d['buffers'][0]['uri']
j = json.dumps(d).encode(); j += b' ' * (-len(j) % 4); b = BIN + b'\0' * (-len(BIN) % 4)
scenes['ok-quad-glb'] = b'glTF' + struct.pack('<II', 2, 28 + len(j) + len(b)) + struct.pack('<I', len(j)) + b'JSON' + j + struct.pack('<I', len(b)) + b'BIN\0' + b
d = doc(); d['buffers'][0]['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(BIN).decode()
scenes['ok-data-uri'] = pack(d, {})
d = doc(images=[{"uri": "c.png"}, {"uri": "n.jpg"}, {"bufferView": 9, "mimeType": "image/png"}],
        textures=[{"source": 0, "sampler": 0}, {"source": 1}, {"source": 2}, {"source": 0}],
        samplers=[{"wrapS": 33071, "wrapT": 33648}])
d['bufferViews'].append({"buffer": 1, "byteLength": len(PNG)}); d['buffers'].append({"uri": "img.bin", "byteLength": len(PNG)})
m = d['materials'][0]; m['pbrMetallicRoughness'].update({"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 2}})
m['normalTexture'] = {"index": 1, "scale": 0.5}; m['emissiveTexture'] = {"index": 3}
scenes['ok-textured'] = pack(d, {**F, "c.png": PNG, "n.jpg": JPG, "img.bin": PNG})
d = doc(); d['scenes'][0]['extras'] = {"environment": {"map": "sky.exr", "intensity": 2, "rotation_y_degrees": 90}, "resolution": [8, 4], "max_depth": 3}
scenes['ok-env-map'] = pack(d, {**F, "sky.exr": exr})
d = doc(); d['scenes'][0]['extras'] = {"environment": {"radiance": [0.5, 0.5, 1]}}; d['materials'][0] = {"pbrMetallicRoughness": {"metallicFactor": 1, "roughnessFactor": 0.2}}
scenes['ok-env-constant-metal'] = pack(d, F)
d = doc(extensionsUsed=["KHR_lights_punctual", "KHR_materials_specular", "KHR_materials_emissive_strength"])
d['extensions'] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 10}, {"type": "spot", "intensity": 5, "color": [1, 0.5, 0.2], "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}, {"type": "directional", "intensity": 3}]}}
d['nodes'] += [{"extensions": {"KHR_lights_punctual": {"light": i}}, "translation": [0, 2, 0], "rotation": [-0.7071068, 0, 0, 0.7071068]} for i in range(3)]
d['scenes'][0]['nodes'] += [2, 3, 4]
d['materials'][0] = {"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {"KHR_materials_specular": {"specularFactor": 0.5}, "KHR_materials_emissive_strength": {"emissiveStrength": 4}}, "emissiveFactor": [1, 0.2, 0]}
scenes['ok-lights-specular'] = pack(d, F)
d = doc(animations=[{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}, {"sampler": 1, "target": {"node": 0, "path": "rotation"}}, {"sampler": 2, "target": {"node": 0, "path": "scale"}}],
                     "samplers": [{"input": 6, "output": 7}, {"input": 6, "output": 8, "interpolation": "STEP"}, {"input": 6, "output": 7}]}])
scenes['ok-animated'] = pack(d, F)
d = doc(); d['accessors'][0] = {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 1, 1],
                                "sparse": {"count": 1, "indices": {"bufferView": 5, "componentType": 5121}, "values": {"bufferView": 1}}}
scenes['ok-sparse'] = pack(d, F)
d = doc(); d['meshes'][0]['primitives'] = [{"attributes": {"POSITION": 0}, "indices": 4, "mode": 5}, {"attributes": {"POSITION": 0}, "indices": 5, "mode": 6}, {"attributes": {"POSITION": 0}, "mode": 1}]
scenes['ok-strip-fan'] = pack(d, F)
d = doc(); d['cameras'][0] = {"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 2, "znear": 0.01, "zfar": 100}}
scenes['ok-ortho-camera'] = pack(d, F)
d = doc(); d['nodes'] = [{"children": [2], "matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 0, 0, 1]}, d['nodes'][1], {"mesh": 0, "scale": [-1, 1, 1], "children": [3]}, {"mesh": 0, "translation": [0, 0.5, 0]}]
scenes['ok-hierarchy'] = pack(d, F)
d = doc(); d['materials'][0].update({"alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": True}); d['materials'].append({"alphaMode": "BLEND"})
d['meshes'][0]['primitives'].append({"attributes": {"POSITION": 0}, "material": 1})
scenes['ok-alpha'] = pack(d, F)
scenes['ok-empty'] = pack({"asset": {"version": "2.0"}, "scenes": [{}]}, {})
# Texture coordinates and materials: TEXCOORD_1 through KHR_texture_transform's override, COLOR_0,
# a NEAREST sampler, alpha blend and KHR_materials_ior.
d = doc(images=[{"uri": "c.png"}], textures=[{"source": 0, "sampler": 0}], samplers=[{"magFilter": 9728, "wrapS": 33648}],
        extensionsUsed=["KHR_texture_transform", "KHR_materials_ior"])
d['meshes'][0]['primitives'][0]['attributes'].update({"TEXCOORD_1": 2, "COLOR_0": 1})
m = d['materials'][0]; m.update({"alphaMode": "BLEND", "extensions": {"KHR_materials_ior": {"ior": 1.33}}})
m['pbrMetallicRoughness']['baseColorTexture'] = {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 0.3, "scale": [2, 2], "texCoord": 1}}}
scenes['ok-texcoords'] = pack(d, {**F, "c.png": PNG})
# Glass: KHR_materials_transmission + KHR_materials_volume on the quad, and a second material
# whose values are all out of range (clamped, with warnings).
d = doc(extensionsUsed=["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_ior"])
d['materials'][0]['extensions'] = {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.33},
                                   "KHR_materials_volume": {"thicknessFactor": 0.5, "attenuationColor": [0.9, 0.5, 0.2], "attenuationDistance": 2.0}}
d['materials'].append({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 7, "transmissionTexture": {"index": 9}},
                                      "KHR_materials_volume": {"thicknessFactor": -1, "attenuationColor": [2, "x"], "attenuationDistance": -1}}})
d['meshes'][0]['primitives'].append({"attributes": {"POSITION": 0}, "material": 1})
scenes['ok-glass'] = pack(d, F)
# KHR_mesh_quantization: the quad's positions as SHORT (padded to 8 bytes), normals as normalized BYTE.
QQ = b''.join(struct.pack('<4h', x, y, z, 0) for x, y, z in [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]) + struct.pack('<4b', 0, 127, 0, 0) * 4
d = doc(extensionsUsed=["KHR_mesh_quantization"], extensionsRequired=["KHR_mesh_quantization"])
d['buffers'].append({"uri": "qq.bin", "byteLength": len(QQ)})
d['bufferViews'] += [{"buffer": 1, "byteOffset": 0, "byteLength": 32, "byteStride": 8}, {"buffer": 1, "byteOffset": 32, "byteLength": 16, "byteStride": 4}]
d['accessors'][0] = {"bufferView": 9, "componentType": 5122, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]}
d['accessors'][1] = {"bufferView": 10, "componentType": 5120, "normalized": True, "count": 4, "type": "VEC3"}
scenes['ok-quantized'] = pack(d, {**F, "qq.bin": QQ})
# EXT_meshopt_compression: the positions' view decoded from bytes that are no meshopt stream, and
# a fallback buffer past the decoded-bytes budget.
def meshopt(fallback_length):
    d = doc(extensionsUsed=["EXT_meshopt_compression"], extensionsRequired=["EXT_meshopt_compression"])
    d['buffers'].append({"byteLength": fallback_length, "extensions": {"EXT_meshopt_compression": {"fallback": True}}})
    d['bufferViews'][0] = {"buffer": 1, "byteOffset": 0, "byteLength": 48, "byteStride": 12, "extensions": {"EXT_meshopt_compression": {
        "buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 12, "count": 4, "mode": "ATTRIBUTES"}}}
    return d
scenes['bad-meshopt-not-a-stream'] = pack(meshopt(48), F)
scenes['bad-meshopt-huge-fallback'] = pack(meshopt(1 << 40), F)
# EXT_meshopt_compression's INDICES mode: the strip's u16 indices (view 4) as an index sequence
# (header 0xd1, one varint a delta from baseline 0, a 4-byte tail), and the same cut short.
def sequence(indices):
    out, last = bytearray([0xd1]), 0
    for i in indices:
        d = i - last; last = i
        v = (((d << 1) ^ (d >> 31)) & 0xffffffff) << 1
        while v >= 0x80:
            out.append(v & 0x7f | 0x80); v >>= 7
        out.append(v)
    return bytes(out) + bytes(4)
SEQ = sequence([0, 1, 2, 3])
def meshopt_strip(stream):
    d = doc(extensionsUsed=["EXT_meshopt_compression"], extensionsRequired=["EXT_meshopt_compression"])
    d['buffers'] += [{"uri": "seq.bin", "byteLength": len(stream)}, {"byteLength": 8, "extensions": {"EXT_meshopt_compression": {"fallback": True}}}]
    d['bufferViews'][4] = {"buffer": 2, "byteOffset": 0, "byteLength": 8, "extensions": {"EXT_meshopt_compression": {
        "buffer": 1, "byteOffset": 0, "byteLength": len(stream), "byteStride": 2, "count": 4, "mode": "INDICES"}}}
    d['meshes'][0]['primitives'] = [{"attributes": {"POSITION": 0}, "indices": 4, "mode": 5}]
    return pack(d, {**F, "seq.bin": stream})
scenes['ok-meshopt-strip'] = meshopt_strip(SEQ)
scenes['bad-meshopt-strip-cut'] = meshopt_strip(SEQ[:6])
# Skins and morph targets: the quad bound to one joint (node 2) whose rotation is animated,
# and one morph target lifting its corners, driven by a weights channel; a vertex bound to a
# joint the skin lacks and a NaN inverse bind matrix are refused.
def skinned(joint=0, bind_nan=False):
    SK = struct.pack('<16B', *([joint, 0, 0, 0] * 4)) + struct.pack('<16f', *([1, 0, 0, 0] * 4))
    ibm = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    if bind_nan:
        ibm[12] = float('nan')
    SK += struct.pack('<16f', *ibm) + struct.pack('<12f', *([0, 0.5, 0] * 4)) + struct.pack('<3f', 0, 1, 0)
    d = doc()
    d['buffers'].append({"uri": "sk.bin", "byteLength": len(SK)})
    d['bufferViews'] += [{"buffer": 1, "byteOffset": 0, "byteLength": 16}, {"buffer": 1, "byteOffset": 16, "byteLength": 64},
                         {"buffer": 1, "byteOffset": 80, "byteLength": 64}, {"buffer": 1, "byteOffset": 144, "byteLength": 48},
                         {"buffer": 1, "byteOffset": 192, "byteLength": 12}]
    d['accessors'] += [{"bufferView": 9, "componentType": 5121, "count": 4, "type": "VEC4"},
                       {"bufferView": 10, "componentType": 5126, "count": 4, "type": "VEC4"},
                       {"bufferView": 11, "componentType": 5126, "count": 1, "type": "MAT4"},
                       {"bufferView": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
                       {"bufferView": 13, "componentType": 5126, "count": 3, "type": "SCALAR"}]
    prim = d['meshes'][0]['primitives'][0]
    prim['attributes'].update(JOINTS_0=9, WEIGHTS_0=10)
    prim['targets'] = [{"POSITION": 12}]
    d['meshes'][0]['weights'] = [0.0]
    d['nodes'][0]['skin'] = 0
    d['nodes'].append({"name": "joint"})
    d['scenes'][0]['nodes'].append(2)
    d['skins'] = [{"joints": [2], "inverseBindMatrices": 11}]
    d['animations'] = [{"samplers": [{"input": 6, "output": 8}, {"input": 6, "output": 13, "interpolation": "STEP"}],
                        "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}},
                                     {"sampler": 1, "target": {"node": 0, "path": "weights"}}]}]
    return pack(d, {**F, "sk.bin": SK})
scenes['ok-skinned-morphed'] = skinned()
scenes['bad-skin-missing-joint'] = skinned(joint=3)
scenes['bad-skin-nan-bind'] = skinned(bind_nan=True)
# One mesh drawn by five nodes (stored once, as instances): turned, mirrored, squashed flat
# and scaled past f32's determinant; the material does not emit (emitters are not instanced).
d = doc()
d['materials'][0]['emissiveFactor'] = [0, 0, 0]
d['nodes'] += [{"mesh": 0, "translation": [3, 0, 0], "rotation": [0, 0.7071068, 0, 0.7071068]},
               {"mesh": 0, "translation": [-3, 0, 0], "scale": [-1, 1, 1]},
               {"mesh": 0, "scale": [1, 0, 1]},
               {"mesh": 0, "scale": [1e30, 1e30, 1e30]}]
d['scenes'][0]['nodes'] += [2, 3, 4, 5]
scenes['ok-instanced-nodes'] = pack(d, F)
# Refused
def bad(name, mutate, files=F):
    d = doc(); mutate(d); scenes['bad-' + name] = pack(d, files)
bad('float-indices', lambda d: d['accessors'][3].update(componentType=5126))
bad('camera-type-mismatch', lambda d: d['cameras'].__setitem__(0, {"type": "orthographic", "perspective": {"yfov": 1, "znear": 0.1}}))
bad('node-cycle', lambda d: d['nodes'][0].update(children=[0]))
bad('shared-child', lambda d: (d['nodes'].append({"mesh": 0}), d['nodes'][0].update(children=[2]), d['nodes'][1].update(children=[2])))
bad('image-both', lambda d: (d.update(images=[{"uri": "c.png", "bufferView": 0, "mimeType": "image/png"}], textures=[{"source": 0}]), d['materials'][0]['pbrMetallicRoughness'].update(baseColorTexture={"index": 0})))
bad('accessor-past-view', lambda d: d['accessors'][0].update(byteOffset=40))
bad('view-past-buffer', lambda d: d['bufferViews'][3].update(byteOffset=250))
bad('position-vec2', lambda d: d['accessors'][0].update(type="VEC2"))
bad('short-texcoords', lambda d: d['accessors'][2].update(count=2))
bad('yfov-zero', lambda d: d['cameras'][0]['perspective'].update(yfov=0))
bad('env-intensity-string', lambda d: d['scenes'][0].update(extras={"environment": {"map": "sky.exr", "intensity": "bright"}}), {**F, "sky.exr": exr})
bad('escaping-uri', lambda d: d['buffers'][0].update(uri="../q.bin"))
bad('missing-buffer', lambda d: d['buffers'][0].update(uri="nothere.bin"))
bad('sparse-not-increasing', lambda d: d['accessors'].__setitem__(0, {"componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1],
                                                                         "sparse": {"count": 2, "indices": {"bufferView": 4, "byteOffset": 4, "componentType": 5121}, "values": {"bufferView": 1}}}))
scenes['bad-not-json'] = b'{"asset": '
scenes['bad-glb-truncated'] = scenes['ok-quad-glb'][:40]

images = {
    'ok-rgba.png': PNG,
    'ok-gray16.png': (lambda: (lambda b: (Image.new('I;16', (5, 3), 300).save(b, 'PNG'), b.getvalue())[1])(io.BytesIO()))(),
    'ok-palette.png': img('P', (6, 2), 'PNG', 3),
    'ok-gray.jpg': img('L', (9, 7), 'JPEG', 128),
    'ok-rgb.jpg': JPG,
    'ok-env.exr': exr,
    'bad-truncated.png': PNG[:30],
    'bad-huge-header.exr': exr[:exr.index(b'dataWindow')] + b'dataWindow\0box2i\0' + struct.pack('<iiiii', 16, 0, 0, 99999, 49999) + exr[exr.index(b'dataWindow') + 37:],
    'bad-empty': b'',
}
for d in ['corpus/scene', 'corpus/image']:
    os.makedirs(os.path.join(here, d), exist_ok=True)
for name, data in scenes.items():
    open(os.path.join(here, 'corpus/scene', name), 'wb').write(data)
for name, data in images.items():
    open(os.path.join(here, 'corpus/image', name), 'wb').write(data)
print(len(scenes), 'scene seeds,', len(images), 'image seeds,', sum(map(len, scenes.values())) + sum(map(len, images.values())), 'bytes')
