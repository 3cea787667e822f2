#!/usr/bin/env python3
"""zhc's baked probes against Blender Cycles (tests/cycles/README.md).

For each scene: `zhc bake` writes the probes as float SH3 (JSON); Blender renders what each probe
sees with Cycles (render_probes.py: six cube faces, projected to SH3); the point light's direct
term, which a camera does not see, is added to Cycles' SH3 in closed form (I / d^2 towards the
light, where the light is unoccluded). The irradiance of both for the six axis normals is compared:
the mean and the worst relative difference over the (probe, normal) pairs that receive light.

  cycles_compare.py --zhc PATH/TO/zhc --work DIR [--spp N] [--res N] [--max-noise F] [--json OUT]

Exit 0 when every scene is within its bounds (mean 5 %, worst 15 %), 1 otherwise, 77 (CTest's
skip code) when Blender is not installed (scripts/packages-test.txt installs it).
"""
import argparse
import base64
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(os.path.dirname(HERE), "data")

K0 = 0.5 / math.sqrt(math.pi)
K1 = math.sqrt(3.0 / (4.0 * math.pi))
K2 = math.sqrt(15.0 / (4.0 * math.pi))
K20 = math.sqrt(5.0 / (16.0 * math.pi))
K22 = math.sqrt(15.0 / (16.0 * math.pi))
AXES = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
AXIS_NAMES = ["+x", "-x", "+y", "-y", "+z", "-z"]


def basis(x, y, z):
    return [K0, -K1 * y, K1 * z, -K1 * x, K2 * x * y, -K2 * y * z, K20 * (3 * z * z - 1), -K2 * x * z, K22 * (x * x - y * y)]


def irradiance(sh, n):
    """zhc's normalised irradiance (constant radiance 1 -> 1) of SH3 radiance, luminance."""
    y = basis(*n)
    rgb = [0.0, 0.0, 0.0]
    for i in range(9):
        a = 1.0 if i == 0 else (2.0 / 3.0 if i < 4 else 0.25)
        for k in range(3):
            rgb[k] += a * y[i] * sh[i][k]
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


# --- the house: two rooms (5 x 6 x 3 m inside), a solid wall 0.2 m thick, grey walls of albedo 0.8,
# one KHR point light of 8 cd in the west room. zhc axes (z up); glTF = (y, z, x) of zhc.
def box_triangles(lo, hi):
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    corner = lambda i: [hi[a] if (i >> a) & 1 else lo[a] for a in range(3)]
    out = []
    for q in quads:
        for tri in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            for i in tri:
                out.append(corner(i))
    return out


HOUSE_BOXES = [
    ([-5.2, -3.2, -0.2], [5.2, 3.2, 0.0]),   # floor
    ([-5.2, -3.2, 3.0], [5.2, 3.2, 3.2]),    # ceiling
    ([-5.2, -3.2, 0.0], [-5.0, 3.2, 3.0]),   # west wall
    ([5.0, -3.2, 0.0], [5.2, 3.2, 3.0]),     # east wall
    ([-5.0, -3.2, 0.0], [5.0, -3.0, 3.0]),   # south wall
    ([-5.0, 3.0, 0.0], [5.0, 3.2, 3.0]),     # north wall
    ([-0.1, -3.0, 0.0], [0.1, 3.0, 3.0]),    # the dividing wall
]
HOUSE_LIGHT = ([-2.5, 0.0, 2.2], 8.0)  # zhc position, candela


def write_house(path, probes):
    pos = []
    for lo, hi in HOUSE_BOXES:
        for x, y, z in box_triangles(lo, hi):
            pos += [y, z, x]  # zhc -> glTF
    blob = struct.pack("<%df" % len(pos), *pos)
    n = len(pos) // 3
    lx, ly, lz = HOUSE_LIGHT[0]
    doc = {
        "asset": {"version": "2.0", "generator": "zhc tests/cycles/cycles_compare.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": HOUSE_LIGHT[1], "color": [1, 1, 1]}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "walls", "mesh": 0},
                  {"name": "lamp", "translation": [ly, lz, lx], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "meshes": [{"name": "walls", "primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
                       "min": [min(pos[a::3]) for a in range(3)], "max": [max(pos[a::3]) for a in range(3)]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(blob)}],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "extras": {"zhc": {"probes": {"positions": probes}, "occlusion": {"sky_samples": 0}}},
    }
    json.dump(doc, open(path, "w"))


def direct_sh(probe, light, intensity, visible):
    """SH3 of a point light's delta: (I / d^2) Y(w) (the closed form zhc bakes), if unoccluded."""
    sh = [[0.0, 0.0, 0.0] for _ in range(9)]
    if not visible:
        return sh
    v = [light[a] - probe[a] for a in range(3)]
    d2 = sum(c * c for c in v)
    d = math.sqrt(d2)
    y = basis(v[0] / d, v[1] / d, v[2] / d)
    for i in range(9):
        for k in range(3):
            sh[i][k] = intensity / d2 * y[i]
    return sh


def run(cmd, **kw):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise SystemExit("cycles_compare: %s failed with exit %d" % (cmd[0], r.returncode))
    return r.stdout


def scene_cases(work):
    cases = []
    # 1. An asset nobody here built: CesiumGS/gltf-pipeline specs/data/2.0/multiple-boxes (four
    # 2 m cubes exported from Blender, grey 0.8, metallic 0; Apache-2.0), unmodified; the test adds a
    # point light and the probes through extras.zhc in a copy (zhc axes) and the same light in
    # Blender.
    src = os.path.join(DATA, "gltf", "gltf-pipeline", "multiple-boxes", "multiple-boxes.gltf")
    doc = json.load(open(src))
    light, intensity = [0.0, 0.0, 0.5], 20.0
    probes = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [1.5, 1.5, 0.5], [0.5, -2.0, -0.5], [-2.2, 0.3, 0.0]]
    doc.setdefault("extras", {})["zhc"] = {
        "probes": {"positions": probes}, "occlusion": {"sky_samples": 0},
        "lights": [{"type": "point", "position": light, "intensity": intensity, "shadows": True}]}
    path = os.path.join(work, "multiple-boxes.gltf")
    json.dump(doc, open(path, "w"))
    cases.append({"name": "multiple-boxes (gltf-pipeline)", "gltf": path, "render_gltf": src, "probes": probes,
                  "light": light, "intensity": intensity, "visible": [True] * len(probes),
                  "extra_light": "%g,%g,%g,%g" % (light[0], light[1], light[2], intensity)})
    # 2. The house.
    probes = [[-2.5, 0.0, 1.2], [-4.0, 2.0, 0.5], [-1.0, -1.5, 2.0], [-0.5, 1.0, 1.5], [-3.0, -2.0, 2.6],
              [1.0, 0.0, 1.5], [3.0, 1.0, 1.0]]
    path = os.path.join(work, "house.gltf")
    write_house(path, probes)
    cases.append({"name": "house (two rooms, 8 cd lamp)", "gltf": path, "render_gltf": path, "probes": probes,
                  "light": HOUSE_LIGHT[0], "intensity": HOUSE_LIGHT[1], "visible": [p[0] < -0.1 for p in probes],
                  "extra_light": None})
    # 3. Textures: CesiumGS/gltf-pipeline specs/data/2.0/box-textured-embedded (COLLADA2GLTF's unit
    # box, a 128 x 128 PNG base colour texture tiled up to 6 times, metallic 0; Apache-2.0),
    # unmodified; a point light and probes near the +x face (zhc axes) through extras.zhc in a copy.
    # The normals facing the box see only the light the textured face reflects.
    src = os.path.join(DATA, "gltf", "gltf-pipeline", "box-textured-embedded", "box-textured-embedded.gltf")
    doc = json.load(open(src))
    light, intensity = [1.6, 0.2, 0.3], 10.0
    probes = [[0.8, 0.0, 0.0], [0.9, 0.3, -0.2], [0.75, -0.3, 0.35], [1.1, 0.1, 0.4]]
    doc.setdefault("extras", {})["zhc"] = {
        "probes": {"positions": probes}, "occlusion": {"sky_samples": 0},
        "lights": [{"type": "point", "position": light, "intensity": intensity, "shadows": True}]}
    path = os.path.join(work, "box-textured-embedded.gltf")
    json.dump(doc, open(path, "w"))
    cases.append({"name": "box-textured-embedded (gltf-pipeline, base colour texture)", "gltf": path, "render_gltf": src,
                  "probes": probes, "light": light, "intensity": intensity, "visible": [True] * len(probes),
                  "extra_light": "%g,%g,%g,%g" % (light[0], light[1], light[2], intensity)})
    return cases


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--zhc", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=32)
    ap.add_argument("--max-noise", default="0.005")
    ap.add_argument("--json")
    args = ap.parse_args()
    blender = shutil.which("blender")
    if not blender:
        print("cycles_compare: skipped: Blender is not installed (scripts/packages-test.txt installs it)")
        return 77
    os.makedirs(args.work, exist_ok=True)
    report = {"scenes": []}
    ok = True
    for case in scene_cases(args.work):
        out = os.path.join(args.work, os.path.basename(case["gltf"]) + ".probes.json")
        t0 = time.time()
        bake_log = run([args.zhc, "bake", case["gltf"], "-o", out, "--max-noise", args.max_noise, "--threads", "0"])
        zhc_s = time.time() - t0
        zhc = [p["sh3"] for p in json.load(open(out))["probes"]]
        probes_json = os.path.join(args.work, "positions.json")
        json.dump({"positions": case["probes"]}, open(probes_json, "w"))
        cyc_json = os.path.join(args.work, os.path.basename(case["gltf"]) + ".cycles.json")
        cmd = [blender, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1", "--python", os.path.join(HERE, "render_probes.py"), "--",
               case["render_gltf"], probes_json, cyc_json, "--res", str(args.res), "--spp", str(args.spp)]
        if case["extra_light"]:
            cmd += ["--light", case["extra_light"]]
        # Blender's embedded Python must find Debian's modules (NumPy for its glTF importer): the
        # system directories first on PATH, whatever Python runs this script.
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYENV") and not k.startswith("PYTHON")}
        env["PATH"] = "/usr/bin:/bin:" + env.get("PATH", "")
        run(cmd, env=env)
        cyc = json.load(open(cyc_json))
        rows, errs = [], []
        lit_values = []
        for pi, p in enumerate(case["probes"]):
            d = direct_sh(p, case["light"], case["intensity"], case["visible"][pi])
            total = [[cyc["sh3"][pi][i][k] + d[i][k] for k in range(3)] for i in range(9)]
            for ai, n in enumerate(AXES):
                ez, ec = irradiance(zhc[pi], n), irradiance(total, n)
                lit_values.append(ec)
                rows.append((pi, AXIS_NAMES[ai], ez, ec))
        scale = max(lit_values)
        dark = []
        for pi, axis, ez, ec in rows:
            if ec > 0.02 * scale:  # a (probe, normal) that receives light
                errs.append(abs(ez - ec) / ec)
            else:
                dark.append(max(abs(ez), abs(ec)) / scale)
        mean, worst = sum(errs) / len(errs), max(errs)
        scene_ok = mean <= 0.05 and worst <= 0.15 and all(x <= 0.02 for x in dark)
        ok = ok and scene_ok
        print("%s: zhc bake %.1f s, Cycles %.1f s (%d spp, %dx%d per face, 6 faces per probe)" %
              (case["name"], zhc_s, cyc["seconds"], cyc["spp"], cyc["res"], cyc["res"]))
        print("  probe  normal        zhc     Cycles   diff")
        for pi, axis, ez, ec in rows:
            print("  %5d  %6s  %9.4f  %9.4f  %+6.1f %%" % (pi, axis, ez, ec, 100 * (ez - ec) / ec if ec > 0.02 * scale else 0.0))
        print("  mean %.2f %%, worst %.2f %% over %d lit pairs; %d dark pairs below %.3f of the brightest: %s" %
              (100 * mean, 100 * worst, len(errs), len(dark), max(dark) if dark else 0.0, "ok" if scene_ok else "FAILED"))
        for line in bake_log.splitlines():
            if "reflected light" in line:
                print("  zhc " + line.strip())
        report["scenes"].append({"name": case["name"], "mean": mean, "worst": worst, "zhc_seconds": zhc_s,
                                 "cycles_seconds": cyc["seconds"], "rows": rows})
    if args.json:
        json.dump(report, open(args.json, "w"), indent=1)
    print("cycles_compare: %s" % ("every scene within its bounds" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
