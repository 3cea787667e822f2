#!/usr/bin/env bash
# The target table of docs/lightmap-formats.md ("What each target costs"): for each sample map a
# 256 x 256 sphere lightmap (`zhc lightmap synth`), then `zhc lightmap audit --targets ... --json` on
# one thread at the given quality; prints the per-map hemispherical RMSE and the means over the maps.
# Usage: bash bench/lightmap_targets.sh [ZHC] [ENVMAP_DIR] [QUALITY] [TARGETS] [WORK_DIR]
set -euo pipefail
zhc="${1:-build/cli/zhc}"
maps="${2:-../shared/data/envmaps}"
quality="${3:-default}"
targets="${4:-bc,astc:4x4,astc:5x5,astc:6x6,astc:8x8,astc-ldr:4x4,astc-ldr:6x6,astc-split:4x4,plain-astc:4x4,plain-astc:6x6}"
work="${5:-$(mktemp -d)}"
mkdir -p "$work"
for m in "$maps"/*.exr; do
  n=$(basename "$m" .exr)
  "$zhc" lightmap synth "$m" -o "$work/$n.lm.exr" --size 256 --threads 2 --quiet > /dev/null
  "$zhc" lightmap audit "$work/$n.lm.exr" --threads 1 --json --quality "$quality" --targets "$targets" --quiet > "$work/$n.json"
done
/usr/bin/python3 - "$work" <<'PY'
import glob, json, math, sys
rows, maps = {}, []
for f in sorted(glob.glob(sys.argv[1] + "/*.json")):
    j = json.load(open(f))
    mean, fit = j["mean_irradiance_at_normal"], j["hemi_rmse"]["search"]
    maps.append((f.split("/")[-1][:-5], 100 * fit / mean, {t["target"]: 100 * t["hemi_rmse"] / mean for t in j["targets"]}))
    for t in j["targets"]:
        p = t.get("psnr_db", {})
        rows.setdefault(t["target"], []).append((t["bytes_per_texel"], 100 * t["hemi_rmse"] / mean,
            100 * math.sqrt(max(0.0, t["hemi_rmse"] ** 2 - fit ** 2)) / mean, p.get("iz_log2"), p.get("wa"), p.get("d"),
            t["encode_mtexel_per_s"]))
print("| target | bytes/texel | hemi RMSE / mean E | added by compression | I_z log2 PSNR | w_a PSNR | d PSNR | encode Mtexel/s |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
mean = lambda v: sum(v) / len(v)
for k, r in rows.items():
    c = list(zip(*r))
    f = lambda i, fmt: fmt % mean(c[i]) if c[i][0] is not None else "-"
    print("| %s | %.2f | %.3f %% | %.3f %% | %s | %s | %s | %.3f |" % (k, mean(c[0]), mean(c[1]), mean(c[2]), f(3, "%.2f dB"),
          f(4, "%.2f dB"), f(5, "%.2f dB"), mean(c[6])))
print()
names = list(rows)
print("| map | fit | " + " | ".join(names) + " |")
print("| --- " * (len(names) + 2) + "|")
for n, fit, t in maps:
    print("| %s | %.2f | " % (n, fit) + " | ".join("%.2f" % t[k] for k in names) + " |")
PY
