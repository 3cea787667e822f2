// The instruction count of a SPIR-V disassembly (spirv-dis --no-header output): the instructions
// inside function bodies, less OpFunctionParameter and OpLabel. bench_runtime and bench_volume
// report it as the cost of one shader evaluation.
#pragma once

#include <cstring>
#include <fstream>
#include <string>

namespace zhc::bench {

inline int spirv_function_instructions(const std::string& disassembly_path) {
    std::ifstream in(disassembly_path);
    std::string line;
    bool inside = false;
    int count = 0;
    while (std::getline(in, line)) {
        auto has = [&](const char* op) {
            const std::size_t p = line.find(op);
            if (p == std::string::npos) return false;
            const std::size_t e = p + std::strlen(op);
            return e == line.size() || line[e] == ' ';
        };
        if (has("OpFunction")) {
            inside = true;
            continue;
        }
        if (has("OpFunctionEnd")) {
            inside = false;
            continue;
        }
        if (!inside || has("OpFunctionParameter") || has("OpLabel")) continue;
        if (line.find_first_not_of(' ') != std::string::npos) ++count;
    }
    return count;
}

}  // namespace zhc::bench
