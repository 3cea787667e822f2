#!/usr/bin/env python3
"""Regenerates the measured numbers in README.md and docs/*.md from the benchmarks and zhc itself.

Usage (from anywhere; needs a Release build in build/, or --build DIR):
  python3 scripts/docs_numbers.py                 # run every generator, rewrite every marked block
  python3 scripts/docs_numbers.py --only bench_bake   # the blocks whose command contains this text
  python3 scripts/docs_numbers.py --check         # run nothing: every marker is well formed, names a
                                                  # known command, and each table names its command and machine

A generated block sits between two HTML comments (invisible in rendered Markdown):

  <!-- BEGIN numbers: COMMAND -->
  ...generated...
  <!-- END numbers -->

COMMAND is the command that produces the numbers, exactly as in GENERATORS below. A block on lines
of its own is a table that starts with the line "Measured by `scripts/docs_numbers.py`: `COMMAND`
on MACHINE, DATE." (CPU model, cores, load average); a marker inside a line of prose (both
comments on the same line) is a single value. The numbers are what this machine measured in one
run: times on a shared machine are noisy, which the machine line lets a reader judge. Standard-
library Python only.
"""
import datetime
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# A marker quoted in backticks (as in the README's description of this script) is not a marker.
BEGIN = re.compile(r"(?<!`)<!-- BEGIN numbers: (.+?) -->")
END = re.compile(r"(?<!`)<!-- END numbers -->")


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return "%s, %d cores, load average %.1f" % (model, os.cpu_count() or 0, load)


def header(command):
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")
    return "Measured by `scripts/docs_numbers.py`: `%s` on %s, %s." % (command, machine(), date)


def run_json(program, args, tmp):
    out = os.path.join(tmp, os.path.basename(program) + ".json")
    subprocess.run([program] + args + ["--json", out], check=True, stdout=subprocess.DEVNULL, cwd=tmp)
    with open(out) as f:
        return json.load(f)


def sig(x, digits=2):
    """x in the docs' style: 9.7e6 / 1.5e2 / 42 (two significant digits)."""
    if x < 100:
        return "%.*g" % (digits, x)
    mantissa, exponent = ("%.*e" % (digits - 1, x)).split("e")
    return "%se%d" % (mantissa, int(exponent))


def gen_bench_bake(ctx):
    d = run_json(os.path.join(ctx["build"], "bench", "bench_bake"), [], ctx["tmp"])
    n = d["probes_per_axis"] // 2
    rows = ["| occluder | BVH build | BVH rays/s (query) | rays/s (whole bake) | brute force rays/s | BVH / brute force | rays blocked "
            "| BVH bytes/triangle | bake peak bytes/triangle |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for m in d["meshes"]:
        rows.append("| %s triangles | %.0f ms | %s | %s | %s | ~%s x | %.1f%% | %.0f | %.0f |" % (
            format(m["triangles"], ","), m["bvh_build_ms"], sig(m["query_rays_per_s"]), sig(m["bake_rays_per_s"]),
            sig(m["brute_force_rays_per_s"]), format(int(float("%.2g" % (m["query_rays_per_s"] / m["brute_force_rays_per_s"]))), ","),
            100 * m["blocked_fraction"], m["bvh_bytes_per_triangle"], m["bake_peak_bytes_per_triangle"]))
    rays = d["meshes"][0]["rays"] if d["meshes"] else 0
    return "\n".join([header("build/bench/bench_bake --json FILE"),
                      "One thread, %dx%dx%d probes, a sun with 64 samples over a tessellated sphere (%s rays), "
                      "median of %d runs in thread CPU time; brute force on a subset of the same rays. Memory: the tree's bytes per triangle, "
                      "and the peak resident memory of making the scene and baking it given up (`bake_scene(Scene&&)`, as `zhc bake` does) "
                      "in a fresh process, per triangle." % (n, n, max(1, n // 4), format(rays, ","), d["repeats"]),
                      ""] + rows)


def gen_bench_runtime(ctx):
    d = run_json(os.path.join(ctx["build"], "bench", "bench_runtime"), [], ctx["tmp"])
    rows = ["| encoding | bytes | SPIR-V instr. | minus skeleton | ns/eval | vs sh3 | cached ns/eval | vs sh3 |",
            "|---|---:|---:|---:|---:|---:|---:|---:|"]

    def num(v, fmt):
        return "—" if v is None or v < 0 else fmt % v

    for r in d["rows"]:
        rows.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["encoding"], "%g" % r["bytes"], num(r["spirv_instructions"], "%d"), num(r["spirv_instructions_minus_skeleton"], "%d"),
            num(r["ns_per_eval"], "%.0f"), num(r["ratio_to_sh3"], "%.2f"), num(r["ns_per_eval_cached"], "%.0f"),
            num(r["ratio_to_sh3_cached"], "%.2f")))
    return "\n".join([header("build/bench/bench_runtime --json FILE"),
                      "Device: %s; %s evaluations per dispatch, median of %s repeats. \"SPIR-V instr.\" is the whole kernel, "
                      "the number `zhc bench --runtime-cost` and `zhc audit --runtime-cost` show; \"minus skeleton\" subtracts the "
                      "kernel that only reads and writes the normal." % (d.get("device", "?"), d.get("evaluations", "?"), d.get("repeats", "?")),
                      ""] + rows)


def peak_rss_mb(argv, cwd):
    """Runs argv; its own peak resident set (MB) and wall time (s)."""
    t0 = datetime.datetime.now()
    p = subprocess.Popen(argv, cwd=cwd, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise subprocess.CalledProcessError(p.returncode, argv)
    return usage.ru_maxrss / 1024.0, (datetime.datetime.now() - t0).total_seconds()


def gen_lightmap_encode(ctx):
    zhc, tmp = ctx["zhc"], ctx["tmp"]
    synth = [zhc, "lightmap", "synth", os.path.join(ctx["maps"], "sunset.exr"), "-o", "big.exr", "--size", "2048", "--quiet"]
    synth_mb, synth_s = peak_rss_mb(synth, tmp)
    enc_mb, enc_s = peak_rss_mb([zhc, "lightmap", "encode", "big.exr", "-o", "big", "--threads", "2", "--quiet"], tmp)
    blocks = sum(os.path.getsize(os.path.join(tmp, "big.%s.ktx2" % k)) for k in ("iz", "d", "wa"))
    rows = ["| step | input | output | wall | peak memory (RSS) |", "|---|---:|---:|---:|---:|",
            "| `zhc lightmap synth ... --size 2048` | | %.0f MB EXR | %.1f s | %.0f MB |" % (
                os.path.getsize(os.path.join(tmp, "big.exr")) / 1e6, synth_s, synth_mb),
            "| `zhc lightmap encode big.exr -o big --threads 2` | %.0f MB EXR | %s bytes KTX2 | %.1f s | %.0f MB |" % (
                os.path.getsize(os.path.join(tmp, "big.exr")) / 1e6, format(blocks, ","), enc_s, enc_mb)]
    return "\n".join([header("zhc lightmap synth examples/maps/sunset.exr -o big.exr --size 2048 && "
                             "zhc lightmap encode big.exr -o big --threads 2"), ""] + rows)


def big_lightmap(ctx):
    """The 2048 x 2048 SH lightmap of sunset.exr (big.exr in the work folder), made once per run."""
    if not os.path.isfile(os.path.join(ctx["tmp"], "big.exr")):
        subprocess.run([ctx["zhc"], "lightmap", "synth", os.path.join(ctx["maps"], "sunset.exr"), "-o", "big.exr", "--size", "2048",
                        "--quiet"], cwd=ctx["tmp"], check=True, stdout=subprocess.DEVNULL)
    return "big.exr"


def gen_lightmap_audit(ctx):
    args = ["--stride", "16", "--threads", "2", "--json"]
    out = subprocess.run([ctx["zhc"], "lightmap", "audit", big_lightmap(ctx)] + args + ["--quiet"], cwd=ctx["tmp"], check=True,
                         stdout=subprocess.PIPE).stdout
    d = json.loads(out)
    h, mean = d["hemi_rmse"], d["mean_irradiance_at_normal"]
    rows = ["| | hemispherical RMSE | / mean I_z (%.3f) |" % mean, "| --- | ---: | ---: |"]
    for label, key in (("talk's baseline (optimal linear direction, spherical Gram)", "old_way"),
                       ("fit (hemispherical Gram, Newton on d: the encoder's default)", "search"),
                       ("fit, after BC6H + BC5 + BC4 (`--quality %s`)" % d["quality"], "search_after_bc")):
        rows.append("| %s | %.4f | %.1f %% |" % (label, h[key], 100 * h[key] / mean))
    p, a = d["psnr_db"], d["d_error_deg"]
    return "\n".join([header("zhc lightmap audit big.exr " + " ".join(args)),
                      "big.exr: `zhc lightmap synth examples/maps/sunset.exr -o big.exr --size 2048`; %s texels audited (every 16th). "
                      "The fit lowers the baseline's error by %.0f %%; block compression changes it by %+.2g. PSNR per texture after "
                      "compression: I_z %.1f dB (log2), w_a %.1f dB, d %.1f dB (angle error mean %.3f deg, max %.1f deg)." % (
                          format(d["texels_audited"], ","), 100 * (1 - h["search"] / h["old_way"]), h["search_after_bc"] - h["search"],
                          p["iz_bc6h_log2"], p["wa_bc4"], p["d_bc5"], a["mean"], a["max"]),
                      ""] + rows)


def gen_demo_report(ctx):
    subprocess.run([ctx["zhc"], "demo", "-o", "demo"], cwd=ctx["tmp"], check=True, stdout=subprocess.DEVNULL)
    return "%.1f MB" % (os.path.getsize(os.path.join(ctx["tmp"], "demo", "report.html")) / 1e6)


AUDIT_ZH3_Q16 = ["zh3_q16", "zh3_solved_q16", "zh3_channel_q16", "zh3_solved_channel_q16", "zh3_solved_channel"]


def gen_audit_zh3_q16(ctx):
    reprs = ["sh2"] + AUDIT_ZH3_Q16
    args = ["--json", "--threads", "1", "-r", ",".join(reprs)]
    out = subprocess.run([ctx["zhc"], "audit", ctx["maps"]] + args, check=True, stdout=subprocess.PIPE, cwd=ctx["tmp"]).stdout
    d = json.loads(out)
    rows = ["| representation | bytes | mean ratio to sh2 | worst ratio | encode us/probe (median over maps) |",
            "| --- | --- | --- | --- | --- |"]
    for name in AUDIT_ZH3_Q16:
        ratios = [f["representations"][name]["rmse"] / f["representations"]["sh2"]["rmse"] for f in d["files"]]
        enc = sorted(f["representations"][name]["encode_ns"] for f in d["files"])
        bytes_ = d["files"][0]["representations"][name]["bytes_per_probe"]
        label = "`%s`%s" % (name, "" if bytes_ == 16 else " (float, for reference)")
        us = enc[len(enc) // 2] / 1e3
        rows.append("| %s | %d | %.4f | %.3f | %s |" % (label, bytes_, sum(ratios) / len(ratios), max(ratios),
                                                   "%.2f" % us if us < 1 else "%.1f" % us if us < 10 else "%.0f" % us))
    return "\n".join([header("zhc audit examples/maps " + " ".join(args)),
                      "Irradiance RMSE against each map's true irradiance (%d directions), as a ratio to `sh2`'s RMSE "
                      "on the same map, over the %d sample maps; encode time from the same run, one thread." % (d["directions"], len(d["files"])),
                      ""] + rows)


def engine_rows(d):
    """The engine_layouts of a `zhc audit --json` object as a Markdown table."""
    rows = ["| engine layout | engine | bytes | rel. rmse | neg. frac | zhc's best at <= its bytes | bytes | rel. rmse | neg. frac "
            "| lower error |",
            "|---|---|---:|---:|---:|---|---:|---:|---:|---|"]
    for e in d["engine_layouts"]:
        z = e["zhc_best"]
        if z is None:
            rows.append("| `%s` | %s | %d | %.4f | %.3f | none | - | - | - | - |" % (
                e["representation"], e["engine"], e["bytes_per_probe"], e["relative_rmse"], e["max_negative_fraction"]))
            continue
        a, b = e["relative_rmse"], z["relative_rmse"]
        # Within 0.5 % of each other, or both below 1e-5: equal (as zhc audit's lower_error column,
        # codec/audit/choice.cpp).
        if max(a, b) < 1e-5 or max(a, b) <= 1.005 * min(a, b):
            lead = "equal"
        elif b < a:
            lead = "zhc %.2fx" % (a / b) if b > 0 else "zhc"
        else:
            lead = "engine %.2fx" % (b / a) if a > 0 else "engine"
        rows.append("| `%s` | %s | %d | %.4f | %.3f | `%s` | %d | %.4f | %.3f | %s |" % (
            e["representation"], e["engine"], e["bytes_per_probe"], a, e["max_negative_fraction"], z["representation"],
            z["bytes_per_probe"], b, z["max_negative_fraction"], lead))
    return rows


def gen_engine_maps(ctx):
    args = ["--no-timing", "--json", "--threads", "2"]
    out = subprocess.run([ctx["zhc"], "audit", ctx["maps"]] + args, check=True, stdout=subprocess.PIPE, cwd=ctx["tmp"]).stdout
    d = json.loads(out)
    return "\n".join([header("zhc audit ../shared/data/envmaps " + " ".join(args)),
                      "Relative irradiance rmse against each map's true irradiance (%d directions), the mean over the %d sample "
                      "maps; neg. frac: the largest fraction of directions below 0 on a map." % (d["directions"], len(d["files"])),
                      ""] + engine_rows(d))


def gen_engine_demo(ctx):
    subprocess.run([ctx["zhc"], "demo", "-o", "engine-demo"], cwd=ctx["tmp"], check=True, stdout=subprocess.DEVNULL)
    args = ["--no-timing", "--json", "--threads", "2"]
    out = subprocess.run([ctx["zhc"], "audit", os.path.join("engine-demo", "probes_sh3.zhp")] + args, check=True,
                         stdout=subprocess.PIPE, cwd=ctx["tmp"]).stdout
    d = json.loads(out)
    return "\n".join([header("zhc audit zhc-demo/probes_sh3.zhp " + " ".join(args)),
                      "The demo scene's %d baked probes (`zhc demo`); the reference is each probe's SH3, so the float L2 "
                      "layouts are exact up to float rounding (and three.js's and Unreal's clamp at 0)." % d["files"][0]["probes"],
                      ""] + engine_rows(d))


def gen_bench_volume_engines(ctx):
    d = run_json(os.path.join(ctx["build"], "bench", "bench_volume"), [], ctx["tmp"])
    rows = ["| engine layout | bytes (entry) | GPU bytes | file bytes | fetches | leak data | demo mean | demo p95 | glTF mean "
            "| glTF p95 | CPU model ns |",
            "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|"]
    for r in d["engine_rows"]:
        rows.append("| `%s` | %d | %s | %s | %d | %s | %s | %s | %s | %s | %.0f |" % (
            r["layout"], r["bytes_per_probe"], r["gpu_bytes_per_probe"] or "-", r["file_bytes_per_probe"] or "-", r["fetches"],
            "yes" if r["carries_leak_data"] else "no", sig(r["demo"]["mean"]), sig(r["demo"]["p95"]), sig(r["gltf"]["mean"]),
            sig(r["gltf"]["p95"]), r["cpu_model_ns_per_sample"]))
    return "\n".join([header("bench_volume --json"),
                      "Error of one sample against the exact trilinear SH3 volume of the baked probes, |dE| / mean |E|, over %d "
                      "random points and normals per grid (the demo's 8x8x4 and the glTF scene's 8x8x8). GPU / file bytes: - "
                      "where the engine keeps none per probe (Godot and RealityKit blend per object on the CPU; three.js bakes at "
                      "load and writes no file)." %
                      d["samples"], ""] + rows)


# command (as written in the marker) -> generator
GENERATORS = {
    "bench_bake --json": gen_bench_bake,
    "bench_runtime --json": gen_bench_runtime,
    "zhc lightmap encode (2048 x 2048)": gen_lightmap_encode,
    "zhc lightmap audit (2048 x 2048)": gen_lightmap_audit,
    "zhc demo (size of report.html)": gen_demo_report,
    "zhc audit --json (16-byte ZH3 entries)": gen_audit_zh3_q16,
    "zhc audit --json (engine layouts, sample maps)": gen_engine_maps,
    "zhc audit --json (engine layouts, demo volume)": gen_engine_demo,
    "bench_volume --json (engine layouts)": gen_bench_volume_engines,
}


def markdown_files(root):
    return [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))


def blocks(text, path):
    """[(command, start, end, inline)] of the marked blocks: text[start:end] is the generated part."""
    out, problems = [], []
    pos = 0
    while True:
        m = BEGIN.search(text, pos)
        if not m:
            break
        em = END.search(text, m.end())
        e = em.start() if em else -1
        nxt = BEGIN.search(text, m.end())
        line = text.count("\n", 0, m.start()) + 1
        if e < 0 or (nxt and nxt.start() < e):
            problems.append("%s:%d: BEGIN numbers without its END" % (path, line))
            pos = m.end()
            continue
        inline = "\n" not in text[m.end():e]
        out.append((m.group(1), m.end(), e, inline, line))
        pos = em.end()
    if len(END.findall(text)) != len(BEGIN.findall(text)):
        problems.append("%s: %d BEGIN numbers and %d END numbers" % (path, len(BEGIN.findall(text)), len(END.findall(text))))
    return out, problems


def check(root):
    problems, count = [], 0
    for md in markdown_files(root):
        rel = os.path.relpath(md, root)
        with open(md, encoding="utf-8") as f:
            text = f.read()
        bl, pr = blocks(text, rel)
        problems += pr
        for command, s, e, inline, line in bl:
            count += 1
            if command not in GENERATORS:
                problems.append("%s:%d: no generator for '%s' (known: %s)" % (rel, line, command, ", ".join(GENERATORS)))
            body = text[s:e]
            if inline:
                if not body.strip():
                    problems.append("%s:%d: empty value for '%s'" % (rel, line, command))
                continue
            first = body.strip().splitlines()[0] if body.strip() else ""
            if not re.match(r"Measured by `scripts/docs_numbers\.py`: `[^`]+` on .+ cores.*\.$", first):
                problems.append("%s:%d: the table does not start with the line naming its command and machine "
                                "(Measured by `scripts/docs_numbers.py`: `COMMAND` on CPU, N cores, ...): %r" % (rel, line, first[:120]))
            elif command.split()[0] not in first:
                problems.append("%s:%d: the table's first line does not name '%s'" % (rel, line, command.split()[0]))
            if "|" not in body:
                problems.append("%s:%d: no table in the block for '%s'" % (rel, line, command))
    for p in problems:
        print(p)
    print("%d marked blocks, %d problems" % (count, len(problems)))
    return 1 if problems else 0


def regenerate(root, build, only):
    ctx = {"build": build, "zhc": os.path.join(build, "cli", "zhc"), "maps": None}
    maps = os.environ.get("ZHC_ENVMAP_DIR") or os.path.join(root, "..", "shared", "data", "envmaps")
    if not os.path.isfile(os.path.join(maps, "city.exr")):
        maps = os.path.join(root, ".cache", "envmaps")
    ctx["maps"] = os.path.abspath(maps)
    results = {}
    with tempfile.TemporaryDirectory(prefix="zhc-docs-numbers-") as tmp:
        ctx["tmp"] = tmp
        for md in markdown_files(root):
            with open(md, encoding="utf-8") as f:
                text = f.read()
            bl, pr = blocks(text, md)
            if pr:
                print("\n".join(pr))
                return 1
            new, last = [], 0
            for command, s, e, inline, _ in bl:
                if only and only not in command or command not in GENERATORS:
                    continue
                if command not in results:
                    print("running: %s" % command, flush=True)
                    results[command] = GENERATORS[command](ctx)
                value = results[command]
                new.append(text[last:s])
                new.append(value if inline else "\n" + value + "\n")
                last = e
            new.append(text[last:])
            out = "".join(new)
            if out != text:
                with open(md, "w", encoding="utf-8") as f:
                    f.write(out)
                print("updated %s" % os.path.relpath(md, root))
    return 0


def main(argv):
    args = argv[1:]
    if args == ["--check"]:
        return check(ROOT)
    build, only = os.path.join(ROOT, "build"), None
    while args:
        if args[0] == "--build" and len(args) > 1:
            build, args = os.path.abspath(args[1]), args[2:]
        elif args[0] == "--only" and len(args) > 1:
            only, args = args[1], args[2:]
        else:
            print(__doc__)
            return 2
    return regenerate(ROOT, build, only)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
