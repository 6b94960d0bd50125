#!/usr/bin/env python3
"""Write a copy of a glTF file in which one node turns about its local Y axis once every 4 s
(LINEAR rotation keys every quarter turn), beside the original so that its relative URIs still
resolve. For measuring what animation costs a scene (`hush-cli bench COPY --mode animate`).

usage: animate_node.py SCENE.gltf NODE_INDEX [OUT.gltf]"""
import base64, json, math, os, struct, sys

src, node = sys.argv[1], int(sys.argv[2])
out = sys.argv[3] if len(sys.argv) > 3 else os.path.splitext(src)[0] + f'_node{node}_turning.gltf'
j = json.load(open(src))
if node >= len(j.get('nodes', [])):
    sys.exit(f'{src} has {len(j.get("nodes", []))} nodes')
n = j['nodes'][node]
if 'matrix' in n:
    sys.exit(f'nodes[{node}] has a matrix; pick a node with translation/rotation/scale')
times = [0.0, 1.0, 2.0, 3.0, 4.0]
rest = n.get('rotation', [0.0, 0.0, 0.0, 1.0])
def mul(a, b):  # quaternion product a b, (x, y, z, w)
    ax, ay, az, aw = a; bx, by, bz, bw = b
    return [aw*bx + ax*bw + ay*bz - az*by, aw*by - ax*bz + ay*bw + az*bx,
            aw*bz + ax*by - ay*bx + az*bw, aw*bw - ax*bx - ay*by - az*bz]
keys = [mul(rest, [0.0, math.sin(k * math.pi / 4), 0.0, math.cos(k * math.pi / 4)]) for k in range(5)]
data = struct.pack('<5f', *times) + b''.join(struct.pack('<4f', *q) for q in keys)
j.setdefault('buffers', []).append({'byteLength': len(data), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(data).decode()})
b = len(j['buffers']) - 1
views = j.setdefault('bufferViews', [])
views += [{'buffer': b, 'byteOffset': 0, 'byteLength': 20}, {'buffer': b, 'byteOffset': 20, 'byteLength': 80}]
acc = j.setdefault('accessors', [])
acc += [{'bufferView': len(views) - 2, 'componentType': 5126, 'count': 5, 'type': 'SCALAR', 'min': [0.0], 'max': [4.0]},
        {'bufferView': len(views) - 1, 'componentType': 5126, 'count': 5, 'type': 'VEC4'}]
j.setdefault('animations', []).append({'name': f'node {node} turning',
    'samplers': [{'input': len(acc) - 2, 'output': len(acc) - 1, 'interpolation': 'LINEAR'}],
    'channels': [{'sampler': 0, 'target': {'node': node, 'path': 'rotation'}}]})
json.dump(j, open(out, 'w'))
print(out)
