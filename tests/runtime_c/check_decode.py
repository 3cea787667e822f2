#!/usr/bin/env python3
""".zhp files written by `zhc convert` decode with runtime/zhc_runtime.h alone
(the strict-C99 tests/runtime_c/zhc_decode_zhp) to what `zhc convert FILE.zhp -o FILE.json` prints,
within 1e-6 relative, for every packed encoding (and every float one) from sample maps and from
JSON probe lists of random probes (layouts none, grid, positions), with default and non-default
quantiser options.

usage: check_decode.py ZHC DECODER ENVMAP_DIR WORK_DIR
"""
import glob
import json
import math
import os
import random
import struct
import subprocess
import sys

PACKED = ["zh3_q16", "zh3_solved_q16", "sh3_q28", "sh2_q", "hall_curve_q"]
OPTION_SETS = [[], ["--bits", "5", "--sqrt", "--dc", "rgb9e5", "--irradiance", "--axis", "channel",
                    "--zonal-map", "zero", "--bound", "loose"],
               ["--bits", "3", "--zonal-map", "symmetric"]]
REL = 1e-6
# The storage options each packed entry's bytes do not depend on: `zhc convert` refuses them (exit 2).
UNUSED = {"zh3_q16": {"--bound"}, "zh3_solved_q16": {"--bound"}, "sh3_q28": {"--axis"},
          "sh2_q": {"--axis", "--zonal-map", "--bound"}, "hall_curve_q": {"--zonal-map", "--bound"}}
TAKES_VALUE = {"--bits", "--dc", "--axis", "--zonal-map", "--bound"}


def options_for(enc, opts):
    """opts without the options `enc` does not use."""
    out, i = [], 0
    while i < len(opts):
        n = 2 if opts[i] in TAKES_VALUE else 1
        if opts[i] not in UNUSED.get(enc, ()):
            out += opts[i:i + n]
        i += n
    return out


def run(args):
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("FAILED (%d): %s\n%s%s" % (r.returncode, " ".join(args), r.stdout, r.stderr))
    return r.stdout


def random_probe(rng):
    """SH3 of an ambient term plus a few coloured directional lights (zhc's basis)."""
    y00 = 1 / (2 * math.sqrt(math.pi))
    y1 = math.sqrt(3 / (4 * math.pi))
    y2 = math.sqrt(15 / (4 * math.pi))
    y20 = math.sqrt(5 / (16 * math.pi))
    y22 = math.sqrt(15 / (16 * math.pi))
    sh = [[0.0] * 3 for _ in range(9)]
    amb = [rng.uniform(0, 0.5) for _ in range(3)]
    for k in range(3):
        sh[0][k] += 2 * math.sqrt(math.pi) * amb[k]
    for _ in range(rng.randint(1, 4)):
        z = rng.uniform(-1, 1)
        phi = rng.uniform(0, 2 * math.pi)
        s = math.sqrt(1 - z * z)
        x, y = s * math.cos(phi), s * math.sin(phi)
        basis = [y00, -y1 * y, y1 * z, -y1 * x, y2 * x * y, -y2 * y * z, y20 * (3 * z * z - 1), -y2 * x * z,
                 y22 * (x * x - y * y)]
        col = [rng.uniform(0, 10) for _ in range(3)]
        for i in range(9):
            for k in range(3):
                sh[i][k] += col[k] * basis[i]
    if rng.random() < 0.2:  # arbitrary SH too (not a non-negative function: ratios get clamped)
        sh = [[rng.uniform(-2, 2) for _ in range(3)] for _ in range(9)]
    return sh


def write_lists(work):
    rng = random.Random(15)
    lists = []
    n = 1500
    probes = [{"sh3": random_probe(rng)} for _ in range(n)]
    path = os.path.join(work, "random_none.json")
    with open(path, "w") as f:
        json.dump({"format": "zhc-probes", "version": 1, "kind": "radiance", "layout": {"type": "none"},
                   "probes": probes}, f)
    lists.append(path)
    probes = [{"sh3": random_probe(rng)} for _ in range(4 * 5 * 6)]
    path = os.path.join(work, "random_grid.json")
    with open(path, "w") as f:
        json.dump({"format": "zhc-probes", "version": 1, "layout": {"type": "grid", "origin": [1, 2, 3],
                   "spacing": [0.5, 0.5, 2], "counts": [4, 5, 6]}, "probes": probes}, f)
    lists.append(path)
    probes = [{"position": [rng.uniform(-9, 9) for _ in range(3)], "sh3": random_probe(rng)} for _ in range(333)]
    path = os.path.join(work, "random_positions.json")
    with open(path, "w") as f:
        json.dump({"format": "zhc-probes", "version": 1, "layout": {"type": "positions"}, "probes": probes}, f)
    lists.append(path)
    return lists


def f32(x):
    """The float32 a decimal number reads back as (both sides print floats; Python parses doubles)."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return x


def close(a, b):
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return a == b or abs(a - b) <= REL * max(abs(a), abs(b))


def sample_scale():
    """ZHC_TEST_SAMPLE_SCALE as tests/support.cpp reads it: a number in (0, 1], else 1."""
    try:
        s = float(os.environ.get("ZHC_TEST_SAMPLE_SCALE", "1"))
    except ValueError:
        return 1.0
    return s if 0 < s <= 1 else 1.0


def main():
    zhc, decoder, envmaps, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    maps = sorted(glob.glob(os.path.join(envmaps, "*.exr")))
    if sample_scale() < 1 and len(maps) >= 8:
        # The sanitizer pass (scripts/sanitize.sh) converts two of the eight maps (one probe each,
        # through the same code paths; every encoding, option set and random list is kept); the
        # Release pass converts all eight.
        maps = maps[:2]
    inputs = write_lists(work) + maps
    if len(inputs) < 4:
        sys.exit("FAILED: no sample maps in %s" % envmaps)
    all_names = PACKED + ["sh3", "sh2", "zh3_lum", "zh3_channel", "hall_curve", "hall_sphere_channel",
                          "zh3_lum_axis_clamp", "sh3_dering"]
    checked = probes_total = inexact = 0
    worst = 0.0
    for inp in inputs:
        base = os.path.splitext(os.path.basename(inp))[0]
        for enc in all_names:
            option_sets = OPTION_SETS if enc in PACKED else [[], ["--irradiance"]]
            for oi, opts in enumerate(option_sets):
                zhp = os.path.join(work, "%s.%s.%d.zhp" % (base, enc, oi))
                js = zhp + ".json"
                run([zhc, "convert", inp, "--to", enc, "-o", zhp] + options_for(enc, opts))
                run([zhc, "convert", zhp, "-o", js])
                lines = run([decoder, zhp]).splitlines()
                with open(js) as f:
                    ref = json.load(f)["probes"]
                if len(lines) != len(ref):
                    sys.exit("FAILED: %s: %d probes decoded, zhc has %d" % (zhp, len(lines), len(ref)))
                for p, (line, probe) in enumerate(zip(lines, ref)):
                    got = [f32(float(v)) for v in line.split()]
                    want = [f32(float(v)) for row in probe["sh3"] for v in row]
                    if len(got) != 27:
                        sys.exit("FAILED: %s probe %d: %d numbers" % (zhp, p, len(got)))
                    for i, (a, b) in enumerate(zip(got, want)):
                        if not close(a, b):
                            sys.exit("FAILED: %s probe %d coefficient %d: C %r, zhc %r" % (zhp, p, i, a, b))
                        if a != b and not (math.isnan(a) and math.isnan(b)):
                            worst = max(worst, abs(a - b) / max(abs(a), abs(b)))
                            inexact += 1
                checked += 1
                probes_total += len(lines)
    print("OK: %d files, %d probes; %d of %d floats differ as float32, largest relative difference %.3g (limit %g)"
          % (checked, probes_total, inexact, 27 * probes_total, worst, REL))


if __name__ == "__main__":
    main()
