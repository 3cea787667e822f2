// Uncompressed 2-D / 3-D KTX 2.0 textures (formats/engines/ktx2_volume.h): round trips, the file
// layout against the KTX 2.0 specification read by an independent parser here, a file another
// program wrote (Bevy's example irradiance volume, written by bevy-baked-gi's export-blender-gi),
// and hostile bytes.
//
// No other KTX2 writer is available on this machine: Debian 12 has no libktx tools (`apt-cache
// search ktx` lists only a Quake mod) and PyPI's pyktx cannot be installed offline; the one file
// another program wrote is tests/data/engines/bevy_example.vxgi.ktx2 (its README).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "formats/engines/ktx2_volume.h"

namespace zhc {
namespace {

std::vector<std::uint8_t> read_all(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::string bevy_example_path() { return std::string(ZHC_TEST_DATA_DIR) + "/engines/bevy_example.vxgi.ktx2"; }

// Little-endian reads for the test's own parser.
std::uint32_t u32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::uint32_t(b.at(at)) | std::uint32_t(b.at(at + 1)) << 8 | std::uint32_t(b.at(at + 2)) << 16 |
           std::uint32_t(b.at(at + 3)) << 24;
}
std::uint64_t u64(const std::vector<std::uint8_t>& b, std::size_t at) { return u32(b, at) | std::uint64_t(u32(b, at + 4)) << 32; }
void set32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.at(at + k) = static_cast<std::uint8_t>(v >> (8 * k));
}
void set64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v) {
    set32(b, at, static_cast<std::uint32_t>(v));
    set32(b, at + 4, static_cast<std::uint32_t>(v >> 32));
}

Ktx2Texture random_texture(std::uint32_t vk, std::uint32_t w, std::uint32_t h, std::uint32_t d, unsigned seed) {
    std::mt19937 rng(seed);
    Ktx2Texture t;
    t.vk_format = vk;
    t.width = w, t.height = h, t.depth = d;
    const std::size_t bytes = ktx2_texel_bytes(vk) * w * h * (d ? d : 1);
    t.texels.resize(bytes);
    for (auto& x : t.texels) x = static_cast<std::uint8_t>(rng());
    return t;
}

// The texel size and typeSize of each format from the Vulkan / KTX 2.0 specifications.
struct FormatFacts {
    std::uint32_t vk, texel_bytes, type_size;
};
constexpr FormatFacts kFormats[] = {{97, 8, 2}, {109, 16, 4}, {123, 4, 4}};

// The DFD words the Khronos Data Format 1.3 specification gives an RGBA float format of `bits`
// per channel (section 5 and its RGBA examples): basic block, RGBSDA, BT.709, linear, 1x1x1x1,
// then one sample per channel R, G, B, A (channel ids 0, 1, 2, 15) with float and signed set.
std::vector<std::uint32_t> rgba_float_dfd_words(std::uint32_t bits) {
    std::vector<std::uint32_t> w = {4 + 24 + 64, 0, 2 | (88u << 16), 1 | (1 << 8) | (1 << 16), 0, bits / 2, 0};
    const std::uint32_t ids[4] = {0, 1, 2, 15};
    for (std::uint32_t c = 0; c < 4; ++c) {
        w.push_back(c * bits | ((bits - 1) << 16) | ((ids[c] | 0x80u | 0x40u) << 24));
        w.push_back(0);
        w.push_back(0xBF800000u);  // -1.0f
        w.push_back(0x3F800000u);  // 1.0f
    }
    return w;
}

// Checks a written file against the KTX 2.0 specification's layout with a parser of its own.
void expect_layout(const std::vector<std::uint8_t>& f, const Ktx2Texture& t) {
    const std::uint8_t id[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
    ASSERT_GE(f.size(), 104u);
    EXPECT_EQ(std::memcmp(f.data(), id, 12), 0);
    const FormatFacts* facts = nullptr;
    for (const auto& x : kFormats)
        if (x.vk == t.vk_format) facts = &x;
    ASSERT_NE(facts, nullptr);
    EXPECT_EQ(u32(f, 12), t.vk_format);
    EXPECT_EQ(u32(f, 16), facts->type_size);
    EXPECT_EQ(u32(f, 20), t.width);
    EXPECT_EQ(u32(f, 24), t.height);
    EXPECT_EQ(u32(f, 28), t.depth);
    EXPECT_EQ(u32(f, 32), 0u);  // layerCount
    EXPECT_EQ(u32(f, 36), 1u);  // faceCount
    EXPECT_EQ(u32(f, 40), 1u);  // levelCount
    EXPECT_EQ(u32(f, 44), 0u);  // supercompression
    const std::uint32_t dfd_off = u32(f, 48), dfd_len = u32(f, 52), kvd_off = u32(f, 56), kvd_len = u32(f, 60);
    EXPECT_EQ(dfd_off, 104u);
    EXPECT_EQ(u32(f, dfd_off), dfd_len);  // dfdTotalSize
    if (t.vk_format != 123) {
        const auto words = rgba_float_dfd_words(t.vk_format == 97 ? 16 : 32);
        ASSERT_EQ(dfd_len, 4 * words.size());
        for (std::size_t i = 0; i < words.size(); ++i) EXPECT_EQ(u32(f, dfd_off + 4 * i), words[i]) << "DFD word " << i;
    }
    EXPECT_EQ(u64(f, 64), 0u);
    EXPECT_EQ(u64(f, 72), 0u);
    std::size_t meta_end = dfd_off + dfd_len;
    if (t.key_values.empty()) {
        EXPECT_EQ(kvd_off, 0u);
        EXPECT_EQ(kvd_len, 0u);
    } else {
        EXPECT_EQ(kvd_off, dfd_off + dfd_len);
        meta_end = kvd_off + kvd_len;
        // Entries sorted by key, each length-prefixed and padded to 4 bytes.
        std::size_t at = kvd_off;
        std::string previous;
        while (at < kvd_off + kvd_len) {
            const std::uint32_t len = u32(f, at);
            const std::string key(reinterpret_cast<const char*>(f.data() + at + 4));
            EXPECT_LT(previous, key);
            previous = key;
            at += 4 + len;
            while (at % 4) EXPECT_EQ(f.at(at++), 0);
        }
        EXPECT_EQ(at, kvd_off + kvd_len);
    }
    const std::uint64_t lvl_off = u64(f, 80), lvl_len = u64(f, 88);
    EXPECT_EQ(lvl_off % std::max<std::uint32_t>(facts->texel_bytes, 4), 0u);  // lcm(texel size, 4)
    EXPECT_GE(lvl_off, meta_end);
    EXPECT_LT(lvl_off, meta_end + facts->texel_bytes);
    EXPECT_EQ(lvl_len, t.texels.size());
    EXPECT_EQ(u64(f, 96), lvl_len);
    ASSERT_EQ(f.size(), lvl_off + lvl_len);
    EXPECT_TRUE(std::equal(t.texels.begin(), t.texels.end(), f.begin() + static_cast<std::ptrdiff_t>(lvl_off)));
}

TEST(EngineFileKtx2, RoundTripsEveryFormat2DAnd3D) {
    unsigned seed = 1;
    for (const auto& fmt : kFormats) {
        for (const std::array<std::uint32_t, 3> dims : {std::array<std::uint32_t, 3>{5, 3, 0}, {4, 6, 9}, {1, 1, 1}, {7, 2, 3}}) {
            Ktx2Texture t = random_texture(fmt.vk, dims[0], dims[1], dims[2], seed++);
            if (seed % 2) t.key_values = {{"zhc.b", {'x', 'y', 'z'}}, {"KTXwriter", {'z', 'h', 'c', 0}}, {"a", {}}};
            auto bytes = encode_ktx2_texture(t);
            ASSERT_TRUE(bytes.ok()) << bytes.error().message;
            expect_layout(*bytes, t);
            auto back = decode_ktx2_texture(*bytes, "t.ktx2");
            ASSERT_TRUE(back.ok()) << back.error().message;
            EXPECT_EQ(back->vk_format, t.vk_format);
            EXPECT_EQ(back->width, t.width);
            EXPECT_EQ(back->height, t.height);
            EXPECT_EQ(back->depth, t.depth);
            EXPECT_EQ(back->texels, t.texels);
            // Read back sorted by key.
            auto sorted = t.key_values;
            std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.key < b.key; });
            ASSERT_EQ(back->key_values.size(), sorted.size());
            for (std::size_t i = 0; i < sorted.size(); ++i) {
                EXPECT_EQ(back->key_values[i].key, sorted[i].key);
                EXPECT_EQ(back->key_values[i].value, sorted[i].value);
            }
            // Deterministic, and independent of the order the keys are given in.
            std::reverse(t.key_values.begin(), t.key_values.end());
            auto again = encode_ktx2_texture(t);
            ASSERT_TRUE(again.ok());
            EXPECT_EQ(*again, *bytes);
        }
    }
}

// Bevy's example volume (export-blender-gi, DFD from the vk2dfd crate, a port of libktx's): zhc
// reads it, and writing what it read gives the same bytes (the same DFD, offsets and padding).
TEST(EngineFileKtx2, ReadsAndRewritesBevysExampleByteForByte) {
    const auto file = read_all(bevy_example_path());
    ASSERT_EQ(file.size(), 4836u) << bevy_example_path();
    auto t = decode_ktx2_texture(file, "Example.vxgi.ktx2");
    ASSERT_TRUE(t.ok()) << t.error().message;
    EXPECT_EQ(t->vk_format, 123u);
    EXPECT_EQ(t->width, 8u);
    EXPECT_EQ(t->height, 16u);
    EXPECT_EQ(t->depth, 9u);
    EXPECT_TRUE(t->key_values.empty());
    ASSERT_EQ(t->texels.size(), 8u * 16 * 9 * 4);
    EXPECT_TRUE(std::equal(t->texels.begin(), t->texels.end(), file.end() - 4608));
    auto again = encode_ktx2_texture(*t);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(*again, file);
}

Ktx2Texture small_3d() {
    Ktx2Texture t = random_texture(97, 3, 4, 5, 7);
    t.key_values = {{"zhc.volume", {'{', '}'}}};
    return t;
}

Error decode_error(const std::vector<std::uint8_t>& b) {
    auto r = decode_ktx2_texture(b, "bad.ktx2");
    EXPECT_FALSE(r.ok());
    if (r.ok()) return {};
    EXPECT_EQ(r.error().message.rfind("bad.ktx2: ", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
    return r.error();
}

TEST(EngineFileKtx2, EveryTruncationIsRefused) {
    for (const auto& base : {*encode_ktx2_texture(small_3d()), read_all(bevy_example_path())}) {
        for (std::size_t n = 0; n < base.size(); ++n) {
            const std::vector<std::uint8_t> cut(base.begin(), base.begin() + static_cast<std::ptrdiff_t>(n));
            const Error e = decode_error(cut);
            EXPECT_TRUE(e.code == ErrorCode::kTruncated || e.code == ErrorCode::kBadFormat) << n << ": " << e.message;
        }
        auto longer = base;
        longer.push_back(0);
        EXPECT_EQ(decode_error(longer).code, ErrorCode::kTrailingBytes);
    }
}

// Every single-byte change before the texels is either refused or lands in a field the reader
// documents it does not check (the sample bounds, the primaries and flags, padding, key/value
// bytes after the key's NUL); never a crash, and an accepted file has the same texture layout.
TEST(EngineFileKtx2, EveryHeaderByteFlipIsRefusedOrHarmless) {
    const Ktx2Texture t = small_3d();
    const auto base = *encode_ktx2_texture(t);
    const std::size_t lvl_off = static_cast<std::size_t>(u64(base, 80));
    for (std::size_t i = 0; i < lvl_off; ++i) {
        for (const std::uint8_t x : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
            auto b = base;
            b[i] ^= x;
            auto r = decode_ktx2_texture(b, "flip.ktx2");
            if (!r.ok()) continue;
            EXPECT_EQ(r->vk_format, t.vk_format) << i;
            EXPECT_EQ(r->width, t.width) << i;
            EXPECT_EQ(r->height, t.height) << i;
            EXPECT_EQ(r->depth, t.depth) << i;
            EXPECT_EQ(r->texels, t.texels) << i;
            const bool dfd_unchecked = i == 104 + 13 || i == 104 + 15 ||  // primaries, flags (not model, transfer)
                                       (i >= 104 + 28 && (i - 104 - 28) % 16 >= 8 && i < 104 + 92);  // sample bounds
            // The key/value entry's key, value and padding (after its length): a changed key is
            // read as that key.
            const bool kvd_entry = i >= 104 + 92 + 4;
            EXPECT_TRUE(dfd_unchecked || kvd_entry) << "byte " << i << " ^ " << int(x) << " accepted";
            if (kvd_entry && i < 104 + 92 + 4 + 10) {
                ASSERT_EQ(r->key_values.size(), 1u);
                EXPECT_NE(r->key_values[0].key, "zhc.volume") << i;
            }
        }
    }
}

TEST(EngineFileKtx2, UnsupportedFeaturesNamedInOneError) {
    const auto base = *encode_ktx2_texture(small_3d());
    struct Case {
        std::size_t at;
        std::uint32_t value;
        const char* named;
    };
    const Case cases[] = {{40, 4, "4 mip levels"},         {40, 0, "levelCount 0"},   {44, 2, "Zstandard supercompression"},
                          {44, 1, "BasisLZ"},              {32, 6, "array of 6 layers"}, {36, 6, "cube map"},
                          {12, 37, "R8G8B8A8_UNORM"},       {12, 143, "BC6H_UFLOAT_BLOCK"}};
    for (const auto& c : cases) {
        auto b = base;
        set32(b, c.at, c.value);
        const Error e = decode_error(b);
        EXPECT_EQ(e.code, ErrorCode::kUnsupported) << c.named;
        EXPECT_NE(e.message.find(c.named), std::string::npos) << e.message;
    }
    // All at once: one message names each.
    auto b = base;
    set32(b, 40, 3);
    set32(b, 44, 2);
    set32(b, 32, 2);
    set32(b, 36, 6);
    const Error e = decode_error(b);
    EXPECT_EQ(e.code, ErrorCode::kUnsupported);
    for (const char* what : {"3 mip levels", "Zstandard", "array of 2 layers", "cube map"})
        EXPECT_NE(e.message.find(what), std::string::npos) << e.message;
}

TEST(EngineFileKtx2, MalformedFieldsRefused) {
    const auto base = *encode_ktx2_texture(small_3d());
    const std::uint32_t kvd_off = u32(base, 56);
    auto expect = [&](auto edit, ErrorCode code, const char* says) {
        auto b = base;
        edit(b);
        const Error e = decode_error(b);
        EXPECT_EQ(e.code, code) << e.message;
        EXPECT_NE(e.message.find(says), std::string::npos) << e.message;
    };
    expect([](auto& b) { set32(b, 16, 4); }, ErrorCode::kBadFormat, "typeSize 4");
    expect([](auto& b) { set32(b, 20, 0); }, ErrorCode::kBadFormat, "pixelWidth 0");
    expect([](auto& b) { set32(b, 24, 0); }, ErrorCode::kUnsupported, "1-D texture");
    expect([](auto& b) { set32(b, 36, 2); }, ErrorCode::kBadFormat, "faceCount 2");
    expect([](auto& b) { set32(b, 28, 6); }, ErrorCode::kBadFormat, "byteLength");
    expect([](auto& b) { set64(b, 64, 8); }, ErrorCode::kBadFormat, "global data");
    expect([](auto& b) { set32(b, 48, 108); }, ErrorCode::kBadFormat, "dfdByteOffset 108");
    expect([](auto& b) { set32(b, 104, 96); }, ErrorCode::kBadFormat, "dfdTotalSize");
    expect([](auto& b) { set32(b, 104 + 12, 1 | (1 << 8) | (2 << 16)); }, ErrorCode::kBadFormat, "transferFunction 2");
    expect([](auto& b) { set32(b, 104 + 12, 2 | (1 << 8) | (1 << 16)); }, ErrorCode::kBadFormat, "colorModel 2");
    expect([](auto& b) { set32(b, 104 + 20, 4); }, ErrorCode::kBadFormat, "bytesPlane0 4");
    expect([](auto& b) { b[104 + 28 + 16 + 3] = 0xC2; }, ErrorCode::kBadFormat, "sample 1");  // G sample says blue
    expect([&](auto& b) { set32(b, 56, 0); }, ErrorCode::kBadFormat, "overlaps");
    expect([&](auto& b) { set32(b, 60, 0); }, ErrorCode::kBadFormat, "without kvdByteLength");
    expect([&](auto& b) { set32(b, 60, 1u << 20); }, ErrorCode::kTooLarge, "key/value data");
    expect([&](auto& b) { set32(b, kvd_off, 200); }, ErrorCode::kBadFormat, "longer than");
    expect([&](auto& b) { b[kvd_off + 4 + 10] = 'x'; }, ErrorCode::kBadFormat, "NUL-terminated");
    expect([&](auto& b) { b[kvd_off + 4] = 0; }, ErrorCode::kBadFormat, "NUL-terminated");
    expect([](auto& b) { set64(b, 80, u64(b, 80) + 4); }, ErrorCode::kBadFormat, "not a multiple of 8");
    expect([](auto& b) { set64(b, 80, 104); }, ErrorCode::kBadFormat, "overlaps");
    expect([](auto& b) { set64(b, 96, 0); }, ErrorCode::kBadFormat, "uncompressedByteLength 0");
    expect([](auto& b) { b[5] = '1'; }, ErrorCode::kBadFormat, "not a KTX2 file");
}

TEST(EngineFileKtx2, DuplicateKeysRefusedOnReadAndWrite) {
    Ktx2Texture t = small_3d();
    t.key_values = {{"k", {'a'}}, {"k", {'b'}}};
    auto w = encode_ktx2_texture(t);
    ASSERT_FALSE(w.ok());
    EXPECT_EQ(w.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(w.error().message.find("'k' given twice"), std::string::npos);
    // Two entries "k\0a" and "j\0b", then the second key renamed to "k".
    t.key_values = {{"k", {'a'}}, {"j", {'b'}}};
    auto b = *encode_ktx2_texture(t);
    const std::uint32_t kvd_off = u32(b, 56);
    ASSERT_EQ(b.at(kvd_off + 4), 'j');
    b[kvd_off + 4] = 'k';
    const Error e = decode_error(b);
    EXPECT_EQ(e.code, ErrorCode::kBadFormat);
    EXPECT_NE(e.message.find("'k' appears twice"), std::string::npos) << e.message;
}

TEST(EngineFileKtx2, HugeSizesRefusedBeforeAllocating) {
    auto b = *encode_ktx2_texture(small_3d());
    set32(b, 20, 0xFFFFFFFFu);
    set32(b, 24, 0xFFFFFFFFu);
    set32(b, 28, 0xFFFFFFFFu);
    Error e = decode_error(b);
    EXPECT_EQ(e.code, ErrorCode::kTooLarge);
    EXPECT_NE(e.message.find("exceed the limit of 268435456"), std::string::npos) << e.message;
    // Within the default limit but beyond a caller's.
    const auto ok = *encode_ktx2_texture(small_3d());
    auto r = decode_ktx2_texture(ok, "small.ktx2", 59);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
    EXPECT_TRUE(decode_ktx2_texture(ok, "small.ktx2", 60).ok());
}

TEST(EngineFileKtx2, WriterRefusesWhatItCannotWrite) {
    Ktx2Texture t = small_3d();
    t.vk_format = 143;
    EXPECT_FALSE(encode_ktx2_texture(t).ok());
    t = small_3d();
    t.texels.pop_back();
    EXPECT_FALSE(encode_ktx2_texture(t).ok());
    t = small_3d();
    t.width = 0;
    EXPECT_FALSE(encode_ktx2_texture(t).ok());
    t = small_3d();
    t.key_values = {{"", {}}};
    EXPECT_FALSE(encode_ktx2_texture(t).ok());
    t.key_values = {{std::string("a\0b", 3), {}}};
    EXPECT_FALSE(encode_ktx2_texture(t).ok());
    t.key_values = {{"big", std::vector<std::uint8_t>(70000)}};
    auto r = encode_ktx2_texture(t);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace zhc
