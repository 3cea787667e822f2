// zhc/formats/report/volume_cost.h — the GPU volume layouts as measured by bench/bench_volume (bytes
// per probe, texture fetches, SPIR-V instructions and lavapipe ns of one trilinear sample, and its
// error against the exact trilinear SH3 volume on two grids), written with `bench_volume --json FILE`.
// `zhc bench --volume-cost FILE` reads it to show the layouts beside the per-probe table
// (docs/runtime.md "GPU volume layouts").
#pragma once

#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

struct VolumeGridError {
    double mean = 0, p95 = 0, max = 0;  // |E - E_ref| / mean |E_ref| over the grid's samples
};

struct VolumeLayoutCost {
    std::string layout;    // e.g. "sh3_rgb9e5"
    std::string kind;      // how the shader samples it (free text; may be empty)
    std::string textures;  // what the GPU holds (free text; may be empty)
    double bytes_per_probe = 0;
    int fetches = 0;             // texture samples or probe decodes per sample
    int spirv_instructions = -1; // of one sample after spirv-opt -O, minus a skeleton kernel's; -1: not measured
    double lavapipe_ns = -1;     // per sample on lavapipe; -1: not measured
    VolumeGridError demo, gltf;  // the demo grid and the baked glTF scene
    // The larger of the two grids' mean errors: what "best per byte" ranks by.
    double worst_mean() const { return demo.mean > gltf.mean ? demo.mean : gltf.mean; }
};

struct VolumeCostTable {
    std::string device;
    std::string gltf_grid;  // the glTF scene's name ("grids"[1]); may be empty
    std::vector<VolumeLayoutCost> rows;  // file order; layout names are unique
};

// Reads bench_volume's JSON ({"device", "grids", "rows": [{"layout", "kind", "textures",
// "bytes_per_probe", "fetches", "spirv_instructions_minus_skeleton", "lavapipe_ns_per_sample",
// "demo": {"mean", "p95", "max"}, "gltf": {...}}]}). Errors name the file and the field (also for
// text that is not JSON, such as a NaN: the field being read where the parser stopped); kIo when
// unreadable, kBadFormat otherwise.
Result<VolumeCostTable> read_volume_cost(const std::string& path);

// A row's lavapipe time over the packed "sh3" row's in the same table; < 0 when either is not
// measured or the table has no "sh3" row.
double volume_ratio_to_sh3(const VolumeCostTable& table, const VolumeLayoutCost& row);

// Best layout per GPU byte: for each byte budget B, the layout with the lowest worst_mean() among
// the layouts of at most B bytes per probe (ties: lower lavapipe time, then file order). Returned
// are the budgets where that best layout changes (strictly lower error), by increasing B: the
// Pareto frontier of error against bytes. Indices into table.rows.
std::vector<std::size_t> volume_best_per_byte(const VolumeCostTable& table);

}  // namespace zhc
