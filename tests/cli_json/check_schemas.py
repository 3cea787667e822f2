#!/usr/bin/python3
"""Every `zhc ... --json` output against its schema in docs/schema/.

Usage: check_schemas.py ZHC SCHEMA_DIR ENVMAP WORK_DIR [GLTF_SCENE]

Runs each verb that prints JSON on small real inputs (one sample environment map, a container
converted from it, a JSON probe list, a glTF with the probes embedded, a 16x16 synthetic SH
lightmap), checks the versioned envelope ("zhc" = `zhc --version`, "command" = the verb) and
validates the object with Debian's python3-jsonschema. Then it shows each schema is strict: every
key of every output, renamed, must make the object invalid (except the keys of maps whose keys are
data, e.g. audit's "representations" keyed by codec name). Exit 0 when all of it holds.
"""
import json
import os
import subprocess
import sys

import jsonschema

ZHC, SCHEMA_DIR, ENVMAP, WORK = sys.argv[1:5]
GLTF_SCENE = sys.argv[5] if len(sys.argv) > 5 else None
os.makedirs(WORK, exist_ok=True)
failures = []
checked = 0
mutations = 0

# Objects whose keys are names (codec table entries), not fields: renaming one stays valid.
FREE_KEY_MAPS = {"representations"}


def run(*args):
    r = subprocess.run([ZHC, *args], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("zhc %s: exit %d\n%s" % (" ".join(args), r.returncode, r.stderr))
    return r.stdout


VERSION = run("--version").strip().split()[-1]


def schema_for(name):
    with open(os.path.join(SCHEMA_DIR, name + ".schema.json")) as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def renamed_copies(value, path=()):
    """Yields (path, copy of the root with one key renamed) for every object key under value."""
    if isinstance(value, dict):
        free = bool(path) and path[-1] in FREE_KEY_MAPS
        for key in list(value):
            if not free:
                yield path + (key,), {(k + "_renamed" if k == key else k): v for k, v in value.items()}
            for sub_path, sub in renamed_copies(value[key], path + (key,)):
                copy = dict(value)
                copy[key] = sub
                yield sub_path, copy
    elif isinstance(value, list):
        for i, item in enumerate(value):
            for sub_path, sub in renamed_copies(item, path + (i,)):
                copy = list(value)
                copy[i] = sub
                yield sub_path, copy


def check(schema_name, command, args):
    global checked, mutations
    label = "zhc " + " ".join(args)
    try:
        doc = json.loads(run(*args))
    except json.JSONDecodeError as e:
        failures.append("%s: not JSON (%s)" % (label, e))
        return
    if doc.get("zhc") != VERSION:
        failures.append('%s: "zhc" is %r, expected %r' % (label, doc.get("zhc"), VERSION))
    if doc.get("command") != command:
        failures.append('%s: "command" is %r, expected %r' % (label, doc.get("command"), command))
    if list(doc)[:2] != ["zhc", "command"]:
        failures.append('%s: the envelope keys are not first: %s' % (label, list(doc)[:3]))
    validator = schema_for(schema_name)
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.path))
    for e in errors[:5]:
        failures.append("%s: %s at %s" % (label, e.message, "/".join(map(str, e.path))))
    checked += 1
    if errors:
        return
    for path, copy in renamed_copies(doc):
        mutations += 1
        if validator.is_valid(copy):
            failures.append("%s: schema %s still accepts the output with key %s renamed"
                            % (label, schema_name, "/".join(map(str, path))))


W = lambda name: os.path.join(WORK, name)
# Inputs: the map, a quantised container, a float container, a JSON probe list, a glTF, a lightmap.
run("convert", ENVMAP, "-o", W("q16.zhp"), "-r", "zh3_q16")
run("convert", ENVMAP, "-o", W("sh3.zhp"), "-r", "sh3", "--zstd", "3")
run("convert", ENVMAP, "-o", W("list.json"))
run("lightmap", "synth", ENVMAP, "--size", "16", "-o", W("lm.exr"))
with open(W("cost.json"), "w") as f:
    json.dump({"device": "schema test", "rows": [
        {"encoding": "sh3", "spirv_instructions": 120, "ns_per_eval": 2.5, "ratio_to_sh3": 1.0}]}, f)

check("project", "project", ["project", ENVMAP, "--json"])
check("info", "info", ["info", ENVMAP, "--json"])
check("info", "info", ["info", W("q16.zhp"), "--json"])
check("info", "info", ["info", W("sh3.zhp"), "--json"])
check("info", "info", ["info", W("list.json"), "--json"])
with open(W("scene.json"), "w") as f:  # info --inputs: a scene and the environment map behind it
    json.dump({"format": "zhc-scene", "version": 1, "probes": {"positions": [[0, 0, 0]]},
               "environment": {"map": os.path.abspath(ENVMAP)}}, f)
check("info", "info", ["info", "--inputs", W("scene.json"), "--json"])
# A baked grid with leak data (validity + cell planes), as a .zhp and as a glTF volume.
LEAK_ROOM = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "leak_room.json")
for name in ("leak.zhp", "leak.glb"):
    run("bake", LEAK_ROOM, "-o", W(name), "--sky-samples", "64", "--quiet")
    check("info", "info", ["info", W(name), "--json"])
# Lightmap files: the SH EXR, its KTX2 / DDS planes, the IrradZ EXR, and a 2-D KTX2 in a format
# zhc does not read (the BC6H plane relabelled BC7_UNORM_BLOCK, vkFormat 145: same block size).
run("lightmap", "encode", W("lm.exr"), "-o", W("lm"), "--quality", "fast", "--quiet")
run("lightmap", "encode", W("lm.exr"), "-o", W("lm"), "--container", "dds", "--quality", "fast", "--quiet")
run("lightmap", "decode", W("lm"), "-o", W("iz.exr"), "--quiet")
with open(W("lm.iz.ktx2"), "rb") as f:
    relabelled = bytearray(f.read())
relabelled[12:16] = (145).to_bytes(4, "little")
with open(W("bc7_2d.ktx2"), "wb") as f:
    f.write(relabelled)
for name in ("lm.exr", "iz.exr", "lm.iz.ktx2", "lm.d.dds", "bc7_2d.ktx2"):
    check("info", "info", ["info", W(name), "--json"])
# ASTC planes: info names the ASTC format and the plane (HDR I_z, LDR I_z with its range key, d + w_a).
run("lightmap", "encode", W("lm.exr"), "-o", W("hdr"), "--target", "astc", "--footprint", "6x6", "--quiet")
run("lightmap", "encode", W("lm.exr"), "-o", W("ldr"), "--target", "astc-ldr", "--quiet")
for name, fmt, plane in (("hdr.iz.ktx2", "ASTC_6x6_SFLOAT", "I_z: linear"), ("ldr.iz.ktx2", "ASTC_4x4_UNORM", "I_z: log2"),
                         ("hdr.dwa.ktx2", "ASTC_6x6_UNORM", "d and w_a")):
    check("info", "info", ["info", W(name), "--json"])
    doc = json.loads(run("info", W(name), "--json"))
    if doc.get("format") != fmt or not doc.get("plane", "").startswith(plane):
        failures.append("zhc info %s: format %r, plane %r (expected %s, %s...)" % (name, doc.get("format"), doc.get("plane"), fmt, plane))
if GLTF_SCENE:
    run("gltf", "embed", GLTF_SCENE, W("q16.zhp"), "-o", W("lit.glb"))
    check("info", "info", ["info", W("lit.glb"), "--json"])
check("audit", "audit", ["audit", ENVMAP, W("q16.zhp"), "--json", "--no-timing", "--directions", "64",
                         "--representations", "sh3,zh3_q16"])
check("bench", "bench", ["bench", ENVMAP, "--json", "--no-plots", "--repeats", "1", "--directions", "16",
                         "--representations", "sh3,zh3_q16", "--runtime-cost", W("cost.json")])
with open(W("volume.json"), "w") as f:
    json.dump({"benchmark": "volume", "device": "schema test", "grids": ["demo", "scene.glb"], "rows": [
        {"layout": "sh3", "bytes_per_probe": 108, "fetches": 8, "spirv_instructions_minus_skeleton": 1610,
         "lavapipe_ns_per_sample": 1371, "demo": {"mean": 0, "p95": 0, "max": 0}, "gltf": {"mean": 0, "p95": 0, "max": 0}},
        {"layout": "sh3_rgb9e5", "bytes_per_probe": 36, "fetches": 9, "spirv_instructions_minus_skeleton": -1,
         "lavapipe_ns_per_sample": -1, "demo": {"mean": 1.5e-3, "p95": 3.3e-3, "max": 0.01},
         "gltf": {"mean": 1.6e-3, "p95": 3.7e-3, "max": 0.02}}]}, f)
check("bench", "bench", ["bench", ENVMAP, "--json", "--no-plots", "--repeats", "1", "--directions", "16",
                         "--representations", "sh3", "--volume-cost", W("volume.json")])
check("lightmap-audit", "lightmap audit", ["lightmap", "audit", W("lm.exr"), "--json", "--stride", "5"])
check("lightmap-audit", "lightmap audit", ["lightmap", "audit", W("lm.exr"), "--json", "--stride", "5",
                                          "--targets", "bc,astc:6x6,astc-ldr,plain-astc"])

# The choice section with every constraint: a budget below the smallest size, one above the largest,
# --require nonnegative, --max-instructions against a cost table that lists only sh3.
check("audit", "audit", ["audit", ENVMAP, "--json", "--no-timing", "--directions", "64", "--budget", "8",
                         "--budget", "200", "--require", "nonnegative", "--max-instructions", "200",
                         "--runtime-cost", W("cost.json")])
check("audit", "audit", ["audit", ENVMAP, "--json", "--directions", "32", "--representations", "sh3,sh2,zh3_q16",
                         "--max-encode-us", "1000000"])

# Acceptance on the sample maps: with --require nonnegative every chosen representation (and
# runner-up) has negative_fraction 0 on every input; a budget below the smallest size has no choice.
MAPS = os.path.dirname(ENVMAP)
doc = json.loads(run("audit", MAPS, "--json", "--no-timing", "--directions", "128", "--require", "nonnegative",
                     "--budget", "8"))
checked += 1
if not schema_for("audit").is_valid(doc):
    failures.append("audit %s --require nonnegative: the JSON does not validate" % MAPS)
budgets = doc["choice"]["budgets"]
if [b["budget_bytes"] for b in budgets] != [8, 16, 28, 48, 60, 108]:
    failures.append("audit --budget 8: budgets %s" % [b["budget_bytes"] for b in budgets])
if budgets[0]["choice"] is not None or budgets[0]["fitting"] != 0:
    failures.append("audit --budget 8: a choice below the smallest size: %s" % budgets[0])
if len(doc["files"]) < 2:
    failures.append("audit %s: %d files, expected the sample maps" % (MAPS, len(doc["files"])))
for b in budgets[1:]:
    if b["choice"] is None:
        failures.append("audit --require nonnegative: no choice at %d bytes (%s)" % (b["budget_bytes"], b["reason"]))
    for role in ("choice", "runner_up"):
        if b[role] is None:
            continue
        name = b[role]["representation"]
        for f in doc["files"]:
            nf = f["representations"][name]["negative_fraction"]
            if nf != 0:
                failures.append("audit --require nonnegative: %s %s at %d bytes has negative_fraction %g on %s"
                                % (role, name, b["budget_bytes"], nf, f["path"]))

# A failing gate still prints its JSON (exit 8): the gates object lists the failure.
r = subprocess.run([ZHC, "audit", ENVMAP, "--json", "--no-timing", "--directions", "32", "--representations", "sh2",
                    "--max-rmse", "0"], capture_output=True, text=True)
if r.returncode != 8:
    failures.append("audit --max-rmse 0: exit %d, expected 8" % r.returncode)
else:
    doc = json.loads(r.stdout)
    if not schema_for("audit").is_valid(doc) or doc["gates"]["passed"] or not doc["gates"]["failures"]:
        failures.append("audit --max-rmse 0: the JSON does not validate or does not report the failed gate")
    checked += 1

# Every schema in the folder named after a verb was used (a new verb's schema is tested here).
verb_schemas = {"project", "info", "audit", "bench", "lightmap-audit"}
on_disk = {n[:-len(".schema.json")] for n in os.listdir(SCHEMA_DIR) if n.endswith(".schema.json")}
untested = on_disk - verb_schemas - {"ZHC_light_probes", "scene"}
if untested:
    failures.append("schemas without a case here: %s" % sorted(untested))

for f in failures:
    print("FAIL:", f)
print("%d outputs validated, %d renamed-key copies rejected%s" % (checked, mutations - sum("renamed" in f for f in failures),
                                                                 "" if not failures else ", %d failures" % len(failures)))
sys.exit(1 if failures else 0)
