// runtime/zhc_runtime.h: .zhp header parsing against formats/probes/probe_file (files from zhc's writer,
// every bit flip, every truncation, random mutations with valid checksums; helpers:
// runtime_c_helpers.h). Built with -ffp-contract=off like the codec (tests/runtime_c/CMakeLists.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "formats/probes/probe_file.h"
#include "runtime_c_helpers.h"
#include "support.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace zhc {
namespace {

using namespace runtime_c_test;

// ---- .zhp headers --------------------------------------------------------------------------

// One numbering (codec/status.h): every class the runtime reports has ErrorCode's value.
static_assert(int(ErrorCode::kInvalidArgument) == ZHC_ERR_ARGUMENT && int(ErrorCode::kTruncated) == ZHC_ERR_TRUNCATED &&
              int(ErrorCode::kBadFormat) == ZHC_ERR_BAD_FORMAT && int(ErrorCode::kUnsupported) == ZHC_ERR_UNSUPPORTED &&
              int(ErrorCode::kChecksum) == ZHC_ERR_CHECKSUM && int(ErrorCode::kTooLarge) == ZHC_ERR_TOO_LARGE &&
              int(ErrorCode::kInvalidValue) == ZHC_ERR_INVALID_VALUE && int(ErrorCode::kTrailingBytes) == ZHC_ERR_TRAILING_BYTES,
              "ErrorCode and zhc_error number the same classes alike");
static_assert(int(ErrorCode::kIoError) > ZHC_ERR_NOT_GRID && int(ErrorCode::kInternal) > ZHC_ERR_NOT_GRID,
              "the library-only classes do not reuse a runtime number");

// The classes a .zhp reader can report: the same number in both.
int expected_code(ErrorCode c) {
    switch (c) {
        case ErrorCode::kTruncated:
        case ErrorCode::kBadFormat:
        case ErrorCode::kUnsupported:
        case ErrorCode::kChecksum:
        case ErrorCode::kTooLarge:
        case ErrorCode::kInvalidValue:
        case ErrorCode::kTrailingBytes: return static_cast<int>(c);
        default: return -1;
    }
}

// zhc's reader and the runtime agree on accept/reject and on the error class. A compressed body
// the runtime reports as ZHC_ERR_COMPRESSED once its header (and body CRC) pass.
void expect_agreement(const std::vector<std::uint8_t>& file, const std::string& what) {
    zhc_probe_format f;
    zhc_zhp_info info;
    const int rt = zhc_zhp_open(&f, &info, file.data(), file.size());
    auto ref = parse_probe_set(file, "x");
    if (rt == ZHC_ERR_COMPRESSED) {
        if (!ref) {
            EXPECT_EQ(ref.error().code, ErrorCode::kBadFormat) << what << ": " << ref.error().message;
        }
        return;
    }
    if (ref) {
        ASSERT_EQ(rt, ZHC_OK) << what;
        const CodecOptions& p = ref->params;
        EXPECT_EQ(f.encoding, zhc_encoding_from_name(ref->representation.c_str())) << what;
        EXPECT_EQ(f.bits, p.bits);
        EXPECT_EQ(f.sqrt_encoding, int(p.sqrt_encoding));
        EXPECT_EQ(f.l2_bound, int(p.l2_bound));
        EXPECT_EQ(f.dc_format, int(p.dc_format));
        EXPECT_EQ(f.zonal_mapping, int(p.zonal_mapping));
        EXPECT_EQ(f.axis_mode, int(p.axis_mode));
        EXPECT_EQ(f.kind, int(p.kind));
        EXPECT_EQ(std::memcmp(f.luminance, &p.luminance, 24), 0);
        EXPECT_EQ(info.probe_count, ref->count);
        EXPECT_EQ(info.layout, int(ref->layout.kind));
        ASSERT_LE(info.payload_offset + ref->payload.size(), file.size());
        // (memcmp with an empty payload's null data() is undefined even for 0 bytes.)
        EXPECT_TRUE(ref->payload.empty() ||
                    std::memcmp(file.data() + info.payload_offset, ref->payload.data(), ref->payload.size()) == 0)
            << what;
        EXPECT_EQ(info.payload_offset + ref->payload.size() + ref->validity.size() + ref->visibility.size(), file.size());
        // Version 2 sections: where the runtime says, the bytes zhc's reader returns.
        EXPECT_EQ(info.validity_offset != 0, !ref->validity.empty()) << what;
        EXPECT_EQ(info.visibility_offset != 0, !ref->visibility.empty()) << what;
        if (!ref->validity.empty()) {
            EXPECT_EQ(std::memcmp(file.data() + info.validity_offset, ref->validity.data(), ref->validity.size()), 0);
        }
        if (!ref->visibility.empty()) {
            EXPECT_EQ(std::memcmp(file.data() + info.visibility_offset, ref->visibility.data(), ref->visibility.size()), 0);
        }
        if (ref->layout.kind == ProbeLayoutKind::kGrid)
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(info.grid_counts[c], ref->layout.grid.counts[size_t(c)]);
                EXPECT_EQ(info.grid_origin[c], ref->layout.grid.origin[c]);
                EXPECT_EQ(info.grid_spacing[c], ref->layout.grid.spacing[c]);
            }
    } else {
        EXPECT_EQ(rt, expected_code(ref.error().code)) << what << ": " << ref.error().message;
    }
}

std::vector<std::vector<std::uint8_t>> sample_files() {
    std::mt19937_64 rng(184);
    std::vector<std::vector<std::uint8_t>> files;
    for (const Codec& c : runtime_codecs()) {  // the engine layouts are no .zhp the runtime opens
        for (int variant = 0; variant < 3; ++variant) {
            const CodecOptions p = variant == 0 ? CodecOptions{} : random_params(rng, c.name);
            std::vector<Sh3Radiance> hub;
            ProbeLayout layout;
            const int n = variant == 2 ? 0 : 6;
            for (int i = 0; i < n; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
            if (variant == 1) {
                layout.kind = ProbeLayoutKind::kGrid;
                layout.grid.counts = {3, 2, 1};
                layout.grid.origin = {1, -2, 0.5};
                layout.grid.spacing = {0.25, 1, 2};
            } else if (variant == 0) {
                layout.kind = ProbeLayoutKind::kPositions;
                for (int i = 0; i < n; ++i) layout.positions.push_back({float(i), -1.5f, 2.0f});
            }
            auto set = encode_probe_set(hub, c.name, p, layout);
            EXPECT_TRUE(bool(set)) << c.name;
            if (!set) continue;
            auto bytes = serialize_probe_set(*set);
            EXPECT_TRUE(bool(bytes));
            if (bytes) files.push_back(*bytes);
        }
    }
    // Version 2 files (validity and/or visibility sections): grid with both, grid with
    // visibility only, positions with validity only.
    for (int variant = 0; variant < 3; ++variant) {
        std::vector<Sh3Radiance> hub;
        for (int i = 0; i < 6; ++i) hub.push_back(random_probe(rng, std::uint64_t(i)));
        ProbeLayout layout;
        if (variant < 2) {
            layout.kind = ProbeLayoutKind::kGrid;
            layout.grid.counts = {3, 2, 1};
            layout.grid.spacing = {1, 1, 1};
        } else {
            layout.kind = ProbeLayoutKind::kPositions;
            for (int i = 0; i < 6; ++i) layout.positions.push_back({float(i), 0.0f, 1.0f});
        }
        auto set = encode_probe_set(hub, "zh3_q16", CodecOptions{}, layout);
        EXPECT_TRUE(bool(set));
        if (!set) continue;
        if (variant != 1) set->validity = {1, 0, 1, 1, 0, 1};
        if (variant != 2) set->visibility = {0xFF, 0x0F, 0x80, 0x01, 0x00, 0x5A};
        auto bytes = serialize_probe_set(*set);
        EXPECT_TRUE(bool(bytes));
        if (bytes) files.push_back(*bytes);
    }
    return files;
}

TEST(RuntimeC, ZhpFilesFromZhcsWriterParseToTheSameParamsAndPayload) {
    const auto files = sample_files();
    ASSERT_EQ(files.size(), size_t(3 * ZHC_ENC_COUNT + 3));
    for (size_t i = 0; i < files.size(); ++i) {
        zhc_probe_format f;
        ASSERT_EQ(zhc_probe_format_from_zhp(&f, files[i].data(), files[i].size()), ZHC_OK) << i;
        ASSERT_EQ(zhc_probe_format_from_zhp(&f, files[i].data(), ZHC_ZHP_HEADER_BYTES), ZHC_OK) << i;
        expect_agreement(files[i], "file " + std::to_string(i));
        // Decoding through the runtime gives decode_probe_set's hub.
        auto set = parse_probe_set(files[i], "x");
        ASSERT_TRUE(bool(set));
        auto hub = decode_probe_set(*set);
        ASSERT_TRUE(bool(hub));
        zhc_zhp_info info;
        ASSERT_EQ(zhc_zhp_open(&f, &info, files[i].data(), files[i].size()), ZHC_OK);
        for (std::uint64_t p = 0; p < info.probe_count; ++p) {
            float sh[27];
            ASSERT_EQ(zhc_decode_probe(&f, files[i].data() + info.payload_offset + p * info.probe_size, sh), ZHC_OK);
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) ASSERT_EQ(ulp_distance(sh[c * 3 + k], (*hub)[p][c][k]), 0u);
        }
    }
    // zstd bodies: the header parses, the body is out of scope (distinct error).
    std::vector<Sh3Radiance> hub(5, project_constant({1, 2, 3}));
    auto set = encode_probe_set(hub, "zh3_q16", CodecOptions{}, ProbeLayout{});
    ASSERT_TRUE(bool(set));
    ProbeFileWriteOptions wo;
    wo.zstd_level = 3;
    auto packed = serialize_probe_set(*set, wo);
    ASSERT_TRUE(bool(packed));
    zhc_probe_format f;
    zhc_zhp_info info;
    EXPECT_EQ(zhc_probe_format_from_zhp(&f, packed->data(), packed->size()), ZHC_OK);
    EXPECT_EQ(zhc_zhp_open(&f, &info, packed->data(), packed->size()), ZHC_ERR_COMPRESSED);
    EXPECT_EQ(info.compressed, 1);
    EXPECT_TRUE(bool(parse_probe_set(*packed, "x")));
    // CRC-32 check value.
    EXPECT_EQ(zhc_crc32(0, "123456789", 9), 0xCBF43926u);
    EXPECT_EQ(zhc_crc32(zhc_crc32(0, "1234", 4), "56789", 5), 0xCBF43926u);
}

TEST(RuntimeC, EveryHeaderBitFlipAndEveryTruncationIsRejectedLikeZhcsReader) {
    const auto files = sample_files();
    std::uint64_t flips = 0, truncations = 0;
    for (size_t i = 0; i < files.size(); ++i) {
        const auto& good = files[i];
        for (size_t byte = 0; byte < ZHC_ZHP_HEADER_BYTES; ++byte)
            for (int bit = 0; bit < 8; ++bit) {
                auto bad = good;
                bad[byte] ^= std::uint8_t(1u << bit);
                zhc_probe_format f;
                ASSERT_NE(zhc_probe_format_from_zhp(&f, bad.data(), bad.size()), ZHC_OK) << i << " " << byte << " " << bit;
                expect_agreement(bad, "flip " + std::to_string(byte) + "." + std::to_string(bit));
                ++flips;
            }
        for (size_t len = 0; len < good.size(); ++len) {
            zhc_probe_format f;
            zhc_zhp_info info;
            ASSERT_NE(zhc_zhp_open(&f, &info, good.data(), len), ZHC_OK) << i << " " << len;
            if (len < ZHC_ZHP_HEADER_BYTES) {
                ASSERT_NE(zhc_probe_format_from_zhp(&f, good.data(), len), ZHC_OK);
            }
            expect_agreement(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(len)),
                             "truncated to " + std::to_string(len));
            ++truncations;
        }
        auto longer = good;
        longer.push_back(0);
        expect_agreement(longer, "appended byte");
        // Body bit flips: checksum.
        for (size_t byte = ZHC_ZHP_HEADER_BYTES; byte < good.size(); byte += 3) {
            auto bad = good;
            bad[byte] ^= 0x10;
            expect_agreement(bad, "body flip");
        }
    }
    std::printf("zhp: %llu header bit flips, %llu truncations rejected\n", (unsigned long long)flips,
                (unsigned long long)truncations);
}

TEST(RuntimeC, MutatedHeadersWithValidChecksumsAgreeWithZhcsReader) {
    // Field-level mutations with the header CRC recomputed, so the field checks themselves are
    // compared (enum ranges, reserved bytes, names, sizes, grid, limits, luminance).
    const auto files = sample_files();
    std::mt19937_64 rng(4242);
    std::uint64_t accepted = 0, rejected = 0;
    for (int it = 0; it < 60000; ++it) {
        auto bad = files[rng() % files.size()];
        const int edits = 1 + int(rng() % 3);
        for (int e = 0; e < edits; ++e) {
            const size_t at = size_t(rng() % 180);
            switch (rng() % 4) {
                case 0: bad[at] = std::uint8_t(rng()); break;
                case 1: bad[at] = std::uint8_t(rng() % 4); break;
                case 2: bad[at] ^= std::uint8_t(1u << (rng() % 8)); break;
                default: bad[at] = 0; break;
            }
        }
        if (rng() % 8 != 0) test::put32(bad, 180, crc32({bad.data(), 180}));
        expect_agreement(bad, "mutation " + std::to_string(it));
        if (HasFailure()) return;
        zhc_probe_format f;
        (zhc_zhp_open(&f, nullptr, bad.data(), bad.size()) == ZHC_OK ? accepted : rejected) += 1;
    }
    std::printf("zhp mutations: %llu accepted, %llu rejected (all agreeing with zhc's reader)\n",
                (unsigned long long)accepted, (unsigned long long)rejected);
    EXPECT_GT(accepted, 100u);
    EXPECT_GT(rejected, 1000u);
}

}  // namespace
}  // namespace zhc
