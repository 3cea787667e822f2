// runtime/zhc_runtime.h against the codec on arbitrary input: byte 0 picks the codec table entry,
// bytes 1-3 the storage parameters (bits, sqrt, bound, DC format, zonal mapping, axis mode, kind,
// luminance weights), the rest (zero-padded) is the stored probe; the runtime's decode and
// irradiance must give the codec's bits (any NaN equals any NaN). The whole input is also parsed as
// a .zhp file by the runtime and by formats/probe_file: same accept/reject and error class, and as a
// probe volume (zhc_volume_from_zhp, sampled when accepted); then once more with both CRC-32s
// recomputed, so that mutated bodies (validity, visibility masks, cell planes: byte 21 bits 0-2)
// reach the section checks and the volume sampling instead of stopping at a checksum. An accepted
// volume has its sections' pointers exactly when byte 21 says so, and is sampled at grid points,
// cell interiors (where a cell plane's side test runs), outside, infinite and NaN positions.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "formats/probes/probe_file.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace {

bool same(float a, float b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
    std::uint32_t ia, ib;
    std::memcpy(&ia, &a, 4);
    std::memcpy(&ib, &b, 4);
    return ia == ib;
}

int code_of(zhc::ErrorCode c) {
    switch (c) {
        case zhc::ErrorCode::kTruncated: return ZHC_ERR_TRUNCATED;
        case zhc::ErrorCode::kBadFormat: return ZHC_ERR_BAD_FORMAT;
        case zhc::ErrorCode::kUnsupported: return ZHC_ERR_UNSUPPORTED;
        case zhc::ErrorCode::kChecksum: return ZHC_ERR_CHECKSUM;
        case zhc::ErrorCode::kTooLarge: return ZHC_ERR_TOO_LARGE;
        case zhc::ErrorCode::kInvalidValue: return ZHC_ERR_INVALID_VALUE;
        case zhc::ErrorCode::kTrailingBytes: return ZHC_ERR_TRAILING_BYTES;
        default: return -1;
    }
}

// One .zhp input: the runtime and zhc's reader agree, and an accepted grid samples without a crash.
void check_zhp(const std::uint8_t* data, std::size_t size) {
    using namespace zhc;
    zhc_probe_format f;
    zhc_zhp_info info{};
    const int rt = zhc_zhp_open(&f, &info, data, size);
    const auto ref = parse_probe_set({data, size}, "fuzz");
    if (rt == ZHC_ERR_COMPRESSED) {
        // The header can't see inside a zstd body; zhc's reader can: a bad frame (kBadFormat) or
        // values the body holds (kInvalidValue: a non-finite position, a validity byte, a plane or
        // tetrahedron out of place).
        if (!ref && ref.error().code != ErrorCode::kBadFormat && ref.error().code != ErrorCode::kInvalidValue) std::abort();
    } else if (ref ? rt != ZHC_OK : rt != code_of(ref.error().code)) {
        std::abort();
    }
    // The payload ends where the per-probe sections and the tetrahedra section (count, then 4
    // indices and 4 neighbours per tetrahedron) begin.
    const std::size_t tetra_bytes = ref && !ref->tetrahedra.empty() ? 4 + 32 * ref->tetrahedra.size() : 0;
    if (rt == ZHC_OK && info.payload_offset + ref->payload.size() !=
                            size - (ref->validity.size() + ref->visibility.size() + ref->planes.size() + tetra_bytes))
        std::abort();
    // Probe volumes: zhc_zhp_open's code, then NOT_GRID for a valid file that is not a volume; an
    // accepted volume samples anywhere (inside, outside, infinite and NaN positions) without crashing.
    zhc_volume v;
    const int vr = zhc_volume_from_zhp(&v, data, size);
    // A grid, or scattered probes with their tetrahedra, is a volume (or refused by
    // zhc_volume_init's own checks, e.g. a spacing <= 0 the container allows); other valid files
    // are NOT_GRID.
    const bool volume = rt == ZHC_OK && (ref->layout.kind == ProbeLayoutKind::kGrid ||
                                         (ref->layout.kind == ProbeLayoutKind::kPositions && !ref->tetrahedra.empty()));
    if (rt != ZHC_OK ? vr != rt : (!volume) != (vr == ZHC_ERR_NOT_GRID)) std::abort();
    if (vr != ZHC_OK) return;
    const int sections = data[8] == 2 ? data[21] : 0;
    if ((v.validity != nullptr) != bool(sections & 1) || (v.visibility != nullptr) != bool(sections & 2) ||
        (v.planes != nullptr) != bool(sections & 4))
        std::abort();
    if (v.planes && std::memcmp(v.planes, ref->planes.data(), ref->planes.size()) != 0) std::abort();
    const double n[3] = {0.6, -0.48, 0.64};
    double e[3];
    const double points[4][3] = {{0, 0, 0}, {1e30, -1e30, 3}, {INFINITY, -INFINITY, 0}, {NAN, 1, NAN}};
    for (const auto& pt : points) zhc_volume_irradiance_d(&v, pt, n, e);
    // Inside the grid's box: fractions of it, and the centre of every cell of the first few.
    for (const double t : {0.13, 0.5, 0.87}) {
        double p[3];
        for (int c = 0; c < 3; ++c) p[c] = v.origin[c] + t * double(v.counts[c] - 1) * v.spacing[c];
        zhc_volume_irradiance_d(&v, p, n, e);
    }
    for (std::uint32_t i = 0; i < 8 && i < v.counts[0]; ++i) {
        const double p[3] = {v.origin[0] + (i + 0.25) * v.spacing[0], v.origin[1] + 0.6 * v.spacing[1], v.origin[2] + 0.3 * v.spacing[2]};
        zhc_volume_irradiance_d(&v, p, n, e);
        const float pf[3] = {float(p[0]), float(p[1]), float(p[2])}, nf[3] = {0.0f, 0.0f, 1.0f};
        float ef[3];
        zhc_volume_irradiance(&v, pf, nf, ef);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace zhc;
    // .zhp parsing: must never crash and must agree with zhc's reader; then the same input with
    // its header and body CRC-32s made right.
    check_zhp(data, size);
    if (size >= ZHC_ZHP_HEADER_BYTES) {
        std::vector<std::uint8_t> sealed(data, data + size);
        const std::uint32_t body = zhc_crc32(0, sealed.data() + ZHC_ZHP_HEADER_BYTES, size - ZHC_ZHP_HEADER_BYTES);
        for (int b = 0; b < 4; ++b) sealed[176 + std::size_t(b)] = std::uint8_t(body >> (8 * b));
        const std::uint32_t head = zhc_crc32(0, sealed.data(), 180);
        for (int b = 0; b < 4; ++b) sealed[180 + std::size_t(b)] = std::uint8_t(head >> (8 * b));
        check_zhp(sealed.data(), sealed.size());
    }
    // runtime_codecs(): the table without the engine layouts, which no zhc runtime reads (codec.h).
    const auto table = runtime_codecs();
    if (size < 4 || table.empty()) return 0;
    const Codec& c = table[data[0] % table.size()];
    CodecOptions p;
    p.bits = 2 + data[1] % 7;
    p.sqrt_encoding = (data[1] >> 3) & 1;
    p.l2_bound = L2Bound((data[1] >> 4) & 1);
    p.kind = StoredKind((data[1] >> 5) & 1);
    p.axis_mode = ZonalAxisMode((data[1] >> 6) & 1);
    p.dc_format = DcFormat(data[2] % 3);
    p.zonal_mapping = ZonalMapping((data[2] / 3) % 3);
    if (data[3] & 1) p.luminance = {data[3] / 255.0, 0.5, -0.25};
    const bool valid = bool(validate_quant_params(p, c.name));
    zhc_probe_format f;
    if (!runtime_format(c.name, p, &f)) std::abort();
    if ((zhc_probe_format_validate(&f) == ZHC_OK) != valid) std::abort();
    std::vector<std::uint8_t> stored(c.size_bytes, 0);
    std::memcpy(stored.data(), data + 4, std::min(size - 4, stored.size()));
    float sh[27], e[3];
    if (!valid) {
        if (zhc_decode_probe(&f, stored.data(), sh) != ZHC_ERR_ARGUMENT) std::abort();
        return 0;
    }
    if (zhc_decode_probe(&f, stored.data(), sh) != ZHC_OK) std::abort();
    const Sh3Radiance ref = decode_probe(c, p, stored.data());
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k)
            if (!same(sh[i * 3 + k], ref[i][k])) std::abort();
    const float n[3] = {0.6f, -0.48f, 0.64f};
    zhc_probe_irradiance(&f, stored.data(), n, e);
    const Vec3 nd{n[0], n[1], n[2]};
    PackedLayout layout;
    const Rgb ref_e = (p.kind == StoredKind::kRadiance && !packed_layout_from_name(c.name, &layout))
                          ? c.irradiance(stored.data(), p, nd)
                          : irradiance(decode_probe(c, p, stored.data()), nd);
    for (int k = 0; k < 3; ++k)
        if (!same(e[k], ref_e[k])) std::abort();
    return 0;
}
