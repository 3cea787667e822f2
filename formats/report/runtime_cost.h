// zhc/formats/report/runtime_cost.h — the GPU cost of each encoding's irradiance evaluation, as measured by
// bench/bench_runtime (zhc.hlsl compiled to SPIR-V, optimised by spirv-opt -O, run on lavapipe) and
// written with `bench_runtime --json FILE`. `zhc bench --runtime-cost FILE` reads it to put runtime
// cost beside accuracy (docs/runtime.md).
#pragma once

#include <map>
#include <string>

#include "codec/status.h"

namespace zhc {

struct RuntimeCost {
    int spirv_instructions = 0;  // instructions of the optimised evaluation shader
    double ns_per_eval = 0;      // lavapipe, one evaluation per invocation
    double ratio_to_sh3 = 0;     // ns_per_eval over the float sh3 evaluation's, same run
};

struct RuntimeCostTable {
    std::string device;                         // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::map<std::string, RuntimeCost> by_name; // encoding name -> cost
};

// Reads bench_runtime's JSON ({"device", "rows": [{"encoding", "spirv_instructions",
// "ns_per_eval", "ratio_to_sh3", ...}]}). Errors name the file and the field.
Result<RuntimeCostTable> read_runtime_cost(const std::string& path);

}  // namespace zhc
