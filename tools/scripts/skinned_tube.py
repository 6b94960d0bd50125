#!/usr/bin/env python3
"""Write a skinned, animated glTF tube of about N triangles (default 50,000): RINGS rings of
SIDES vertices along +Y, bound to a chain of three joints (hip, knee, ankle) that bend it back
and forth over 2 s, each vertex blended between the two joints nearest it. A stand-in for a
game character when measuring what skinning and the BVH cost a frame
(`hush-cli bench tube.gltf --mode animate`); with a floor and a sun so that it renders.

usage: skinned_tube.py OUT.gltf [TRIANGLES]"""
import base64, json, math, struct, sys

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 50_000
sides = 50
rings = max(2, n // (2 * sides) + 1)
height, radius = 2.0, 0.15
pos, nrm, joints, weights = [], [], [], []
for r in range(rings):
    y = height * r / (rings - 1)
    # Joints at y = 0, 0.7, 1.4: weight shared between the two around y.
    seg = min(int(y / 0.7), 1)
    s = min(max((y - 0.7 * seg) / 0.7, 0.0), 1.0)
    for k in range(sides):
        a = 2 * math.pi * k / sides
        pos += [radius * math.cos(a), y, radius * math.sin(a)]
        nrm += [math.cos(a), 0.0, math.sin(a)]
        joints += [seg, seg + 1, 0, 0]
        weights += [1.0 - s, s, 0.0, 0.0]
idx = []
for r in range(rings - 1):
    for k in range(sides):
        a, b = r * sides + k, r * sides + (k + 1) % sides
        idx += [a, b + sides, b, a, a + sides, b + sides]
floor = [-3, 0, -3, 3, 0, -3, 3, 0, 3, -3, 0, 3]
views, accessors, blob = [], [], bytearray()
def add(data, fmt, count, ty, comp, minmax=None, target=None):
    while len(blob) % 4:
        blob.append(0)
    off = len(blob)
    blob.extend(struct.pack('<%d%s' % (len(data), fmt), *data))
    v = {'buffer': 0, 'byteOffset': off, 'byteLength': len(blob) - off}
    if target:
        v['target'] = target
    views.append(v)
    a = {'bufferView': len(views) - 1, 'componentType': comp, 'count': count, 'type': ty}
    if minmax:
        a['min'], a['max'] = minmax
    accessors.append(a)
    return len(accessors) - 1
P = add(pos, 'f', len(pos) // 3, 'VEC3', 5126, ([min(pos[0::3]), min(pos[1::3]), min(pos[2::3])], [max(pos[0::3]), max(pos[1::3]), max(pos[2::3])]), 34962)
N = add(nrm, 'f', len(nrm) // 3, 'VEC3', 5126, None, 34962)
J = add(joints, 'H', len(joints) // 4, 'VEC4', 5123, None, 34962)
W = add(weights, 'f', len(weights) // 4, 'VEC4', 5126, None, 34962)
I = add(idx, 'I', len(idx), 'SCALAR', 5125, None, 34963)
FP = add(floor, 'f', 4, 'VEC3', 5126, ([-3, 0, -3], [3, 0, 3]), 34962)
FI = add([0, 2, 1, 0, 3, 2], 'I', 6, 'SCALAR', 5125, None, 34963)
ibm = []
for y in (0.0, 0.7, 1.4):
    ibm += [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -y, 0, 1]
IBM = add(ibm, 'f', 3, 'MAT4', 5126)
T = add([0.0, 1.0, 2.0], 'f', 3, 'SCALAR', 5126, ([0.0], [2.0]))
def zrot(deg):
    h = math.radians(deg) / 2
    return [0.0, 0.0, math.sin(h), math.cos(h)]
K1 = add(zrot(0) + zrot(30) + zrot(0), 'f', 3, 'VEC4', 5126)
K2 = add(zrot(0) + zrot(-60) + zrot(0), 'f', 3, 'VEC4', 5126)
j = {
    'asset': {'version': '2.0', 'generator': 'Hush tools/scripts/skinned_tube.py'},
    'scene': 0, 'scenes': [{'nodes': [0, 1, 4, 5, 6]}],
    'nodes': [
        {'name': 'tube', 'mesh': 0, 'skin': 0},
        {'name': 'hip', 'children': [2]},
        {'name': 'knee', 'translation': [0, 0.7, 0], 'children': [3]},
        {'name': 'ankle', 'translation': [0, 0.7, 0]},
        {'name': 'floor', 'mesh': 1},
        {'name': 'camera', 'camera': 0, 'translation': [0, 1.2, 4.0]},
        {'name': 'sun', 'extensions': {'KHR_lights_punctual': {'light': 0}}, 'rotation': [-0.5, 0.2, 0.1, 0.84]},
    ],
    'cameras': [{'type': 'perspective', 'perspective': {'yfov': 0.8, 'znear': 0.01}}],
    'extensionsUsed': ['KHR_lights_punctual'],
    'extensions': {'KHR_lights_punctual': {'lights': [{'type': 'directional', 'intensity': 3.0}]}},
    'meshes': [
        {'primitives': [{'attributes': {'POSITION': P, 'NORMAL': N, 'JOINTS_0': J, 'WEIGHTS_0': W}, 'indices': I, 'material': 0}]},
        {'primitives': [{'attributes': {'POSITION': FP}, 'indices': FI, 'material': 1}]},
    ],
    'materials': [{'pbrMetallicRoughness': {'baseColorFactor': [0.8, 0.3, 0.2, 1], 'metallicFactor': 0, 'roughnessFactor': 0.6}},
                  {'pbrMetallicRoughness': {'baseColorFactor': [0.6, 0.6, 0.6, 1], 'metallicFactor': 0}}],
    'skins': [{'joints': [1, 2, 3], 'inverseBindMatrices': IBM}],
    'animations': [{'samplers': [{'input': T, 'output': K1, 'interpolation': 'LINEAR'}, {'input': T, 'output': K2, 'interpolation': 'LINEAR'}],
                    'channels': [{'sampler': 0, 'target': {'node': 2, 'path': 'rotation'}}, {'sampler': 1, 'target': {'node': 3, 'path': 'rotation'}}]}],
    'accessors': accessors, 'bufferViews': views,
    'buffers': [{'byteLength': len(blob), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(bytes(blob)).decode()}],
}
json.dump(j, open(out, 'w'))
print(out, len(idx) // 3, 'tube triangles')
