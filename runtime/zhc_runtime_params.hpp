// zhc/runtime/zhc_runtime_params.hpp — C++ bridge for code that has zhc's own CodecOptions
// (codec/probe/probe_set.h) and wants the matching zhc_probe_format of the C runtime (tests, fuzzers,
// tools built with zhc's libraries). Not needed by engines, which fill the format from a .zhp
// header or a glTF volume.
#pragma once

#include <string>
#include <string_view>

#include "codec/probe/probe_set.h"
#include "zhc_runtime.h"

namespace zhc {

// The runtime format of `codec` stored with `params`; false when the runtime does not know the name.
inline bool runtime_format(std::string_view codec, const CodecOptions& params, zhc_probe_format* f) {
    if (zhc_probe_format_init(f, std::string(codec).c_str()) != ZHC_OK) return false;
    // zhc_probe_format's fields carry the names of CodecOptions' storage fields (codec.h).
#define ZHC_COPY_STORAGE_FIELD(field) f->field = int(params.field);
    ZHC_CODEC_STORAGE_FIELDS(ZHC_COPY_STORAGE_FIELD)
#undef ZHC_COPY_STORAGE_FIELD
    f->luminance[0] = params.luminance.r;
    f->luminance[1] = params.luminance.g;
    f->luminance[2] = params.luminance.b;
    return true;
}

}  // namespace zhc
