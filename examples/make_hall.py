#!/usr/bin/env python3
"""Writes examples/hall.gltf: a small glTF 2.0 hall (floor, two pillars, a roof slab) lit by
KHR_lights_punctual lights (a sun, a point light, a spot), with its probe grid and sky in the root
extras.zhc object (docs/scene.md). Standard-library Python; the output is checked in, this script
documents how it was made. glTF axes: +Y up, metres.

Usage: python3 examples/make_hall.py [OUT.gltf]   (default: hall.gltf beside this script)
"""
import base64
import json
import os
import struct
import sys


def box(lo, hi):
    """The 8 corners and 12 triangles of an axis-aligned box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [a, b, c, a, c, d]
    return v, tris


meshes = [
    ("floor", box((-6, -0.1, -4), (6, 0, 4))),
    ("pillar west", box((-2.2, 0, -0.3), (-1.6, 4, 0.3))),
    ("pillar east", box((1.6, 0, -0.3), (2.2, 4, 0.3))),
    ("roof", box((-6, 4, -4), (1, 4.2, 4))),
]

blob = b""
views, accessors, gltf_meshes, nodes = [], [], [], []
for name, (verts, tris) in meshes:
    pos = b"".join(struct.pack("<3f", *p) for p in verts)
    idx = b"".join(struct.pack("<H", i) for i in tris)
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(pos), "target": 34962})
    blob += pos
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(idx), "target": 34963})
    blob += idx + b"\0" * (-len(idx) % 4)
    lo = [min(p[k] for p in verts) for k in range(3)]
    hi = [max(p[k] for p in verts) for k in range(3)]
    accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": len(verts), "type": "VEC3",
                      "min": lo, "max": hi})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(tris), "type": "SCALAR"})
    gltf_meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                      "indices": len(accessors) - 1}]})
    nodes.append({"name": name, "mesh": len(gltf_meshes) - 1})

# Lights: the sun points down and to the east (-Z of its node); node rotations are unit quaternions.
lights = [
    {"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 3.0},
    {"name": "lamp", "type": "point", "color": [1.0, 0.7, 0.4], "intensity": 60.0},
    {"name": "spot", "type": "spot", "color": [0.8, 0.9, 1.0], "intensity": 120.0,
     "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}},
]
nodes += [
    {"name": "sun", "rotation": [-0.3535534, 0.3535534, 0.1464466, 0.8535534],
     "extensions": {"KHR_lights_punctual": {"light": 0}}},
    {"name": "lamp", "translation": [3.5, 1.5, 1.0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
    {"name": "spot", "translation": [-3.0, 3.9, 0.0], "rotation": [-0.7071068, 0, 0, 0.7071068],
     "extensions": {"KHR_lights_punctual": {"light": 2}}},
]

gltf = {
    "asset": {"version": "2.0", "generator": "zhc examples/make_hall.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": lights}},
    "scene": 0,
    "scenes": [{"name": "hall", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": gltf_meshes,
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    # zhc axes (Z-up) inside extras.zhc, as in a zhc JSON scene.
    "extras": {"zhc": {
        "probes": {"grid": {"min": [-3, -5, 0.5], "max": [3, 5, 3.5], "counts": [3, 4, 2]}},
        "sky": {"type": "gradient", "zenith": [0.25, 0.45, 0.9], "horizon": [0.7, 0.75, 0.85],
                "ground": [0.15, 0.13, 0.1], "up": [0, 0, 1]},
    }},
}

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "hall.gltf")
with open(out, "w", encoding="utf-8") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
