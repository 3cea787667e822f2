// KTX2 writer and strict reader (formats/lightmap/ktx2.h).
#include <random>

#include "codec/lightmap/bc6h.h"
#include "formats/lightmap/ktx2.h"
#include "support.h"

namespace zhc {
namespace {

using test::put32;
Ktx2Image sample(std::uint32_t fmt, int w, int h) { return test::sample_block_image(fmt, w, h); }

TEST(Ktx2, RoundTripsAllThreeFormats) {
    for (const auto fmt : {kVkFormatBc4Unorm, kVkFormatBc5Unorm, kVkFormatBc6hUfloat})
        for (auto [w, h] : {std::pair{4, 4}, std::pair{13, 7}, std::pair{64, 32}}) {
            const Ktx2Image img = sample(fmt, w, h);
            auto bytes = encode_ktx2(img);
            ASSERT_TRUE(bytes.ok());
            // Identifier, vkFormat and the level data's alignment.
            EXPECT_EQ((*bytes)[1], 'K');
            EXPECT_EQ((*bytes)[12], fmt);
            auto back = decode_ktx2(*bytes, "mem");
            ASSERT_TRUE(back.ok()) << back.error().message;
            EXPECT_EQ(back->vk_format, fmt);
            EXPECT_EQ(back->width, w);
            EXPECT_EQ(back->height, h);
            EXPECT_EQ(back->blocks, img.blocks);
        }
    const std::string dir = test::temp_dir("ktx2");
    const Ktx2Image img = sample(kVkFormatBc6hUfloat, 8, 8);
    ASSERT_TRUE(write_ktx2(dir + "/a.ktx2", img).ok());
    auto r = read_ktx2(dir + "/a.ktx2");
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->blocks, img.blocks);
}

TEST(Ktx2, StrictReaderGivesDistinctErrors) {
    const auto good = *encode_ktx2(sample(kVkFormatBc5Unorm, 16, 8));
    auto expect = [&](std::vector<std::uint8_t> b, ErrorCode code, const char* what) {
        auto r = decode_ktx2(b, "x.ktx2");
        ASSERT_FALSE(r.ok()) << what;
        EXPECT_EQ(r.error().code, code) << what << ": " << r.error().message;
        EXPECT_NE(r.error().message.find("x.ktx2: "), std::string::npos);
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    };
    auto b = good;
    b[0] = 0;
    expect(b, ErrorCode::kBadFormat, "identifier");
    expect(std::vector<std::uint8_t>(good.begin(), good.begin() + 50), ErrorCode::kTruncated, "short header");
    b = good, put32(b, 12, 37);
    expect(b, ErrorCode::kUnsupported, "vkFormat");
    b = good, put32(b, 20, 1u << 20);
    expect(b, ErrorCode::kTooLarge, "width limit");
    b = good, put32(b, 24, 0);
    expect(b, ErrorCode::kBadFormat, "zero height");
    b = good, put32(b, 40, 3);
    expect(b, ErrorCode::kUnsupported, "mip levels");
    b = good, put32(b, 44, 2);
    expect(b, ErrorCode::kUnsupported, "supercompression");
    b = good, put32(b, 32, 6);
    expect(b, ErrorCode::kUnsupported, "array layers");
    b = good, b[104 + 12] ^= 1;  // colour model
    expect(b, ErrorCode::kBadFormat, "DFD content");
    b = good, put32(b, 88, 16);
    expect(b, ErrorCode::kBadFormat, "level length");
    expect(std::vector<std::uint8_t>(good.begin(), good.end() - 1), ErrorCode::kTruncated, "level data truncated");
    b = good;
    b.resize(good.size() + 1, 0);
    expect(b, ErrorCode::kTrailingBytes, "trailing");
    b = good, put32(b, 80, 161);
    expect(b, ErrorCode::kBadFormat, "misaligned level");
}

TEST(Ktx2, RandomCorruptionNeverCrashes) {
    const auto good = *encode_ktx2(sample(kVkFormatBc6hUfloat, 20, 12));
    const int accepted =
        test::decode_corrupted_copies(good, 5, 20000, [](std::span<const std::uint8_t> b) { return decode_ktx2(b, "fuzz"); });
    EXPECT_GT(accepted, 0);  // flips inside the block data are still valid files
}

}  // namespace
}  // namespace zhc
