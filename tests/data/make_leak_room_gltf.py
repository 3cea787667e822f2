#!/usr/bin/env python3
"""Writes tests/data/leak_room.gltf: the room of tests/data/leak_room.json as glTF meshes.

Every box occluder of the JSON scene becomes a closed 12-triangle box mesh, counter-clockwise seen
from outside (glTF front faces), in glTF axes ((x, y, z)_glTF = (y, z, x)_zhc, docs/scene.md
"glTF input"). The probes, the sky, the occlusion settings and the sphere lamp (glTF has no sphere
lights) go into extras.zhc, in zhc axes. Usage: python3 make_leak_room_gltf.py (next to the JSON).
"""
import base64
import json
import os
import struct

here = os.path.dirname(os.path.abspath(__file__))
scene = json.load(open(os.path.join(here, "leak_room.json")))

# Box corners: bit 0 -> x, bit 1 -> y, bit 2 -> z; faces counter-clockwise from outside.
QUADS = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
positions = []
for occ in scene["occluders"]:
    assert occ["type"] == "box"
    lo, hi = occ["min"], occ["max"]
    corner = lambda i: [hi[a] if (i >> a) & 1 else lo[a] for a in range(3)]
    for q in QUADS:
        for tri in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            for i in tri:
                x, y, z = corner(i)
                positions += [y, z, x]  # zhc -> glTF axes
blob = struct.pack("<%df" % len(positions), *positions)
count = len(positions) // 3
lo = [min(positions[a::3]) for a in range(3)]
hi = [max(positions[a::3]) for a in range(3)]
extras = {k: scene[k] for k in ("probes", "sky", "occlusion", "lights")}
doc = {
    "asset": {"version": "2.0", "generator": "zhc tests/data/make_leak_room_gltf.py"},
    "scene": 0,
    "scenes": [{"name": "leak room", "nodes": [0]}],
    "nodes": [{"name": "walls", "mesh": 0}],
    "meshes": [{"name": "walls", "primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3", "min": lo, "max": hi}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(blob)}],
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "extras": {"zhc": extras},
}
with open(os.path.join(here, "leak_room.gltf"), "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
