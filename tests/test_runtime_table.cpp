// codec/probe/runtime_table.h: the runtime description of codec table entries (what the generated
// runtime tables hold). The real entries' rows are checked against the runtimes' decoders by
// test_runtime_c (bit for bit), test_runtime_gl, test_runtime_vk and js.wgsl; here the derivation
// rules themselves, on made-up entries with known answers.
#include <gtest/gtest.h>

#include <string>

#include "codec/probe/codec.h"
#include "codec/probe/quantize.h"
#include "codec/probe/runtime_table.h"

namespace zhc {
namespace {

Codec fake(std::size_t bytes, ZonalAxis axis, ZonalHallucination h, const PackedCodec* packed = nullptr) {
    Codec c = codecs()[0];  // any functions: runtime_entry reads only name, size, traits and packed
    c.name = "trial";
    c.size_bytes = bytes;
    c.traits = CodecTraits{.zonal_axis = axis, .hallucination = h};
    c.packed = packed;
    return c;
}

TEST(RuntimeTable, FloatLayoutsAreNamedBySizeAndTraits) {
    using H = ZonalHallucination;
    const struct {
        std::size_t bytes;
        ZonalAxis axis;
        H h;
        RuntimeLayout layout;
    } cases[] = {{108, ZonalAxis::kNone, H::kNone, RuntimeLayout::kSh3F32},
                 {48, ZonalAxis::kNone, H::kNone, RuntimeLayout::kSh2F32},
                 {48, ZonalAxis::kPerChannel, H::kSphere, RuntimeLayout::kSh2F32},
                 {60, ZonalAxis::kLuminance, H::kNone, RuntimeLayout::kZh3F32}};
    for (const auto& t : cases) {
        const auto e = runtime_entry(fake(t.bytes, t.axis, t.h));
        ASSERT_TRUE(e.ok()) << t.bytes << ": " << e.error().message;
        EXPECT_EQ(e->layout, t.layout) << t.bytes;
        EXPECT_EQ(e->axis, t.axis);
        EXPECT_EQ(e->hallucination, t.h);
        EXPECT_EQ(e->size_bytes, t.bytes);
    }
}

TEST(RuntimeTable, PackedEntriesTakeTheirPackedLayout) {
    for (const Codec& c : codecs()) {
        if (!c.packed) continue;
        const auto e = runtime_entry(c);
        ASSERT_TRUE(e.ok()) << e.error().message;
        EXPECT_EQ(int(e->layout), int(RuntimeLayout::kZh3Q16) + int(c.packed->layout)) << c.name;
    }
}

TEST(RuntimeTable, EntriesNoRuntimeLayoutHoldsAreRefusedByName) {
    using H = ZonalHallucination;
    const Codec bad[] = {
        fake(64, ZonalAxis::kNone, H::kNone),                   // no float layout of 16 floats
        fake(60, ZonalAxis::kNone, H::kNone),                   // 15 floats without a zonal axis
        fake(108, ZonalAxis::kLuminance, H::kNone),             // sh3 floats have no zonal axis
        fake(60, ZonalAxis::kLuminance, H::kCurve),             // hallucination over a stored zonal
        fake(48, ZonalAxis::kLuminance, H::kCurveAdaptive),     // the adaptive curve needs byte 15 of sh2_q
        fake(48, ZonalAxis::kNone, H::kCurve),                  // hallucination without an axis
        fake(48, ZonalAxis::kLuminance, H::kNone),              // linear floats with an axis but no zonal term
        fake(60, ZonalAxis::kFromParams, H::kNone),             // float layouts fix their axis
    };
    for (const Codec& c : bad) {
        const auto e = runtime_entry(c);
        ASSERT_FALSE(e.ok()) << c.size_bytes;
        EXPECT_EQ(e.error().code, ErrorCode::kUnsupported);
        EXPECT_NE(e.error().message.find("'trial'"), std::string::npos) << e.error().message;
    }
}

TEST(RuntimeTable, EveryCodecTableEntryHasARuntimeRow) {
    // Every entry the runtimes read; the engine layouts have none (runtime_entry refuses them:
    // tests/test_engine_layouts.cpp).
    for (const Codec& c : runtime_codecs()) {
        const auto e = runtime_entry(c);
        ASSERT_TRUE(e.ok()) << e.error().message;
        EXPECT_EQ(e->name, c.name);
        EXPECT_EQ(e->size_bytes, c.size_bytes);
    }
}

// ZHC_CODEC_STORAGE_FIELDS: every storage field (and the luminance weights) changes same_storage's
// answer; an encoder control does not.
TEST(RuntimeTable, SameStorageComparesExactlyTheStorageFields) {
    const CodecOptions a;
    EXPECT_TRUE(same_storage(a, a));
    int fields = 0;
#define ZHC_TEST_FIELD(field)                                                              \
    {                                                                                      \
        CodecOptions b;                                                                    \
        b.field = decltype(b.field)(int(b.field) == 1 ? 0 : 1);                            \
        EXPECT_FALSE(same_storage(a, b)) << #field;                                        \
        ++fields;                                                                          \
    }
    ZHC_CODEC_STORAGE_FIELDS(ZHC_TEST_FIELD)
#undef ZHC_TEST_FIELD
    EXPECT_EQ(fields, 7);  // bits, sqrt_encoding, l2_bound, dc_format, kind, zonal_mapping, axis_mode
    CodecOptions lum;
    lum.luminance.g = 0.5;
    EXPECT_FALSE(same_storage(a, lum));
    CodecOptions controls;
    controls.solver_iterations = 3;
    controls.dering_punctual = true;
    controls.hallucinate_a = 0.5;
    EXPECT_TRUE(same_storage(a, controls));
}

// Packed entries whose traits contradict their layout: each refusal of runtime_entry, by its reason.
TEST(RuntimeTable, PackedEntriesWithContradictoryTraitsAreRefused) {
    using H = ZonalHallucination;
    const PackedCodec* by[3] = {};
    for (const Codec& c : codecs())
        if (c.packed) by[static_cast<int>(c.packed->layout)] = c.packed;
    const PackedCodec *zh3q = by[static_cast<int>(PackedLayout::kZh3Q16)], *sh3q = by[static_cast<int>(PackedLayout::kSh3Q28)],
                      *sh2q = by[static_cast<int>(PackedLayout::kSh2Q)];
    ASSERT_TRUE(zh3q && sh3q && sh2q);
    const struct {
        Codec codec;
        const char* reason;
    } bad[] = {
        {fake(20, ZonalAxis::kFromParams, H::kNone, zh3q), "size differs from its packed layout"},
        {fake(16, ZonalAxis::kNone, H::kNone, zh3q), "zh3_q16 layout needs a zonal axis"},
        {fake(28, ZonalAxis::kLuminance, H::kNone, sh3q), "layout without zonal term has no zonal axis"},
        {fake(28, ZonalAxis::kFromParams, H::kCurve, sh3q), "needs linear SH bytes"},
        {fake(16, ZonalAxis::kFromParams, H::kSphere, sh2q), "by the Eq. 21 curve only"},
        {fake(16, ZonalAxis::kFromParams, H::kNone, sh2q), "layout without zonal term has no zonal axis"},
    };
    for (const auto& b : bad) {
        const auto e = runtime_entry(b.codec);
        ASSERT_FALSE(e.ok()) << b.reason;
        EXPECT_EQ(e.error().code, ErrorCode::kUnsupported);
        EXPECT_NE(e.error().message.find(b.reason), std::string::npos) << e.error().message;
    }
}

}  // namespace
}  // namespace zhc
