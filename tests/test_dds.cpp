// DDS writer and strict reader (formats/lightmap/dds.h) and `zhc lightmap encode/decode --container dds`.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <random>

#include "codec/lightmap/lightmap.h"
#include "formats/lightmap/dds.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/ktx2.h"
#include "support.h"

// The largest single allocation while g_watch_allocations is set (global operator new is replaced
// in this test executable only): shows that a header declaring a huge image is refused before the
// reader allocates anything of that size.
namespace {
bool g_watch_allocations = false;
std::size_t g_largest_allocation = 0;
}  // namespace

// noinline: GCC would otherwise see free() applied to operator new's result and warn.
[[gnu::noinline]] void* operator new(std::size_t n) {
    if (g_watch_allocations && n > g_largest_allocation) g_largest_allocation = n;
    if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
    throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept { std::free(p); }
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace zhc {
namespace {

using test::fresh_dir;
using test::get32;
using test::put32;
Ktx2Image sample(std::uint32_t fmt, int w, int h) { return test::sample_block_image(fmt, w, h); }

void put_fourcc(std::vector<std::uint8_t>& b, size_t off, const char* s) {
    for (int k = 0; k < 4; ++k) b[off + k] = static_cast<std::uint8_t>(s[k]);
}

// A legacy (no DX10 header) file: the DX10 file with its extension header cut out and the FourCC
// replaced, data at byte 128.
std::vector<std::uint8_t> legacy(const std::vector<std::uint8_t>& dx10, const char* four) {
    std::vector<std::uint8_t> b = dx10;
    b.erase(b.begin() + 128, b.begin() + 148);
    put_fourcc(b, 84, four);
    return b;
}

TEST(Dds, HeaderFieldsAsDocumented) {
    // The header of a 5x3 BC6H file, field by field, against the values docs/lightmap-formats.md
    // lists (Microsoft's DDS_HEADER / DDS_PIXELFORMAT / DDS_HEADER_DXT10 layout).
    const auto b = *encode_dds(sample(kVkFormatBc6hUfloat, 5, 3));
    ASSERT_EQ(b.size(), 148u + 2 * 1 * 16);
    EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "DDS ");
    const std::pair<size_t, std::uint32_t> fields[] = {
        {4, 124},                                  // dwSize
        {8, 0x1 | 0x2 | 0x4 | 0x1000 | 0x80000},   // CAPS | HEIGHT | WIDTH | PIXELFORMAT | LINEARSIZE
        {12, 3},                                   // dwHeight
        {16, 5},                                   // dwWidth
        {20, 2 * 16},                              // dwPitchOrLinearSize: 2 blocks x 16 bytes
        {24, 0},                                   // dwDepth
        {28, 1},                                   // dwMipMapCount
        {76, 32},                                  // ddspf.dwSize
        {80, 0x4},                                 // DDPF_FOURCC
        {84, 0x30315844},                          // 'DX10'
        {108, 0x1000},                             // DDSCAPS_TEXTURE
        {112, 0},                                  // dwCaps2
        {128, 95},                                 // DXGI_FORMAT_BC6H_UF16
        {132, 3},                                  // D3D10_RESOURCE_DIMENSION_TEXTURE2D
        {136, 0},                                  // miscFlag
        {140, 1},                                  // arraySize
        {144, 3},                                  // DDS_ALPHA_MODE_OPAQUE
    };
    for (const auto& [off, v] : fields) EXPECT_EQ(get32(b, off), v) << "byte " << off;
    for (size_t off = 32; off < 76; off += 4) EXPECT_EQ(get32(b, off), 0u) << "dwReserved1 at " << off;
    for (size_t off = 88; off < 108; off += 4) EXPECT_EQ(get32(b, off), 0u) << "RGB fields at " << off;
    for (size_t off = 116; off < 128; off += 4) EXPECT_EQ(get32(b, off), 0u) << "caps3/4, reserved2 at " << off;
    EXPECT_EQ(get32(*encode_dds(sample(kVkFormatBc5Unorm, 5, 3)), 128), 83u);
    EXPECT_EQ(get32(*encode_dds(sample(kVkFormatBc4Unorm, 5, 3)), 128), 80u);
    EXPECT_EQ(get32(*encode_dds(sample(kVkFormatBc4Unorm, 5, 3)), 20), 2u * 8u);
}

TEST(Dds, RoundTripsAllThreeFormatsAtOddSizes) {
    const std::string dir = fresh_dir("dds");
    for (const auto fmt : {kVkFormatBc4Unorm, kVkFormatBc5Unorm, kVkFormatBc6hUfloat})
        for (auto [w, h] : {std::pair{5, 3}, std::pair{1, 1}, std::pair{17, 9}, std::pair{4, 4}, std::pair{64, 32}}) {
            const Ktx2Image img = sample(fmt, w, h);
            auto bytes = encode_dds(img);
            ASSERT_TRUE(bytes.ok());
            EXPECT_EQ(bytes->size(), kDdsDataOffset + img.blocks.size());
            EXPECT_TRUE(std::equal(img.blocks.begin(), img.blocks.end(), bytes->begin() + kDdsDataOffset));
            auto back = decode_dds(*bytes, "mem");
            ASSERT_TRUE(back.ok()) << back.error().message;
            EXPECT_EQ(back->vk_format, fmt);
            EXPECT_EQ(back->width, w);
            EXPECT_EQ(back->height, h);
            EXPECT_EQ(back->blocks, img.blocks);
            const std::string path = dir + "/t" + std::to_string(fmt) + "_" + std::to_string(w) + "x" + std::to_string(h) + ".dds";
            ASSERT_TRUE(write_dds(path, img).ok());
            EXPECT_EQ(test::read_bytes(path), *bytes);
            auto r = read_dds(path);
            ASSERT_TRUE(r.ok()) << r.error().message;
            EXPECT_EQ(r->blocks, img.blocks);
        }
    // The format mapping both ways, and nothing else maps.
    for (std::uint32_t v = 0; v < 256; ++v) {
        const std::uint32_t d = dxgi_format_for_vk(v);
        if (v == kVkFormatBc4Unorm || v == kVkFormatBc5Unorm || v == kVkFormatBc6hUfloat) {
            EXPECT_NE(d, 0u);
            EXPECT_EQ(vk_format_for_dxgi(d), v);
        } else {
            EXPECT_EQ(d, 0u);
        }
    }
    EXPECT_EQ(vk_format_for_dxgi(96), 0u);  // BC6H_SF16
    EXPECT_EQ(vk_format_for_dxgi(81), 0u);  // BC4_SNORM
    // The writer refuses what it cannot describe.
    EXPECT_EQ(encode_dds(sample(37, 4, 4)).error().code, ErrorCode::kInvalidArgument);
    Ktx2Image bad = sample(kVkFormatBc4Unorm, 8, 8);
    bad.blocks.pop_back();
    EXPECT_EQ(encode_dds(bad).error().code, ErrorCode::kInvalidArgument);
    bad = sample(kVkFormatBc4Unorm, 8, 8);
    bad.width = 0;
    EXPECT_EQ(encode_dds(bad).error().code, ErrorCode::kInvalidArgument);
    EXPECT_FALSE(write_dds(dir + "/bad.dds", bad).ok());
    EXPECT_FALSE(std::filesystem::exists(dir + "/bad.dds"));
    EXPECT_EQ(read_dds(dir + "/missing.dds").error().code, ErrorCode::kIoError);
}

TEST(Dds, LegacyFourCcsAreReadAsBc4AndBc5) {
    const auto bc4 = *encode_dds(sample(kVkFormatBc4Unorm, 17, 9));
    const auto bc5 = *encode_dds(sample(kVkFormatBc5Unorm, 17, 9));
    for (const char* four : {"ATI1", "BC4U"}) {
        auto r = decode_dds(legacy(bc4, four), "l.dds");
        ASSERT_TRUE(r.ok()) << four << ": " << r.error().message;
        EXPECT_EQ(r->vk_format, kVkFormatBc4Unorm);
        EXPECT_EQ(r->blocks, sample(kVkFormatBc4Unorm, 17, 9).blocks);
    }
    for (const char* four : {"ATI2", "BC5U"}) {
        auto r = decode_dds(legacy(bc5, four), "l.dds");
        ASSERT_TRUE(r.ok()) << four << ": " << r.error().message;
        EXPECT_EQ(r->vk_format, kVkFormatBc5Unorm);
        EXPECT_EQ(r->blocks, sample(kVkFormatBc5Unorm, 17, 9).blocks);
    }
    // A legacy BC5 file is 20 bytes shorter than its DX10 twin; read with the DX10 layout's size
    // check it would be short: the data offset really depends on the FourCC.
    auto b = legacy(bc5, "ATI2");
    b.pop_back();
    EXPECT_EQ(decode_dds(b, "l.dds").error().code, ErrorCode::kTruncated);
    EXPECT_EQ(decode_dds(legacy(bc5, "BC5S"), "l.dds").error().code, ErrorCode::kUnsupported);  // signed: not read
    EXPECT_EQ(decode_dds(legacy(bc5, "DXT1"), "l.dds").error().code, ErrorCode::kUnsupported);
}

TEST(Dds, StrictReaderGivesDistinctErrors) {
    const auto good = *encode_dds(sample(kVkFormatBc5Unorm, 17, 9));  // 5 x 3 blocks, 240 bytes of data
    ASSERT_TRUE(decode_dds(good, "x.dds").ok());
    auto expect = [&](const std::vector<std::uint8_t>& b, ErrorCode code, const char* what, const char* where) {
        auto r = decode_dds(b, "x.dds");
        ASSERT_FALSE(r.ok()) << what;
        EXPECT_EQ(r.error().code, code) << what << ": " << r.error().message;
        EXPECT_EQ(r.error().message.rfind("x.dds: ", 0), 0u) << r.error().message;
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
        EXPECT_NE(r.error().message.find(where), std::string::npos) << what << ": " << r.error().message;
    };
    auto b = good;
    b[0] = 'X';
    expect(b, ErrorCode::kBadFormat, "magic", "byte 0");
    expect({'D', 'D', 'S'}, ErrorCode::kBadFormat, "3 bytes", "byte 0");
    expect({}, ErrorCode::kBadFormat, "empty", "byte 0");
    // Truncated at (inside or at the start of) every header field: the message names that field.
    const std::pair<size_t, const char*> cuts[] = {
        {4, "dwSize at byte 4"},          {9, "dwFlags at byte 8"},           {12, "dwHeight at byte 12"},
        {18, "dwWidth at byte 16"},       {20, "dwPitchOrLinearSize at byte 20"}, {27, "dwDepth at byte 24"},
        {28, "dwMipMapCount at byte 28"}, {50, "dwReserved1 at byte 32"},     {77, "ddspf.dwSize at byte 76"},
        {80, "ddspf.dwFlags at byte 80"}, {86, "ddspf.dwFourCC at byte 84"},  {90, "ddspf.dwRGBBitCount at byte 88"},
        {104, "ddspf.dwABitMask at byte 104"}, {108, "dwCaps at byte 108"},   {113, "dwCaps2 at byte 112"},
        {127, "dwReserved2 at byte 124"}, {128, "dxgiFormat at byte 128"},    {133, "resourceDimension at byte 132"},
        {136, "miscFlag at byte 136"},    {143, "arraySize at byte 140"},     {147, "miscFlags2 at byte 144"},
    };
    for (const auto& [n, field] : cuts)
        expect(std::vector<std::uint8_t>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n)), ErrorCode::kTruncated,
               "truncated header", field);
    for (size_t n = 4; n < kDdsDataOffset; ++n) {
        auto r = decode_dds(std::vector<std::uint8_t>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n)), "x.dds");
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::kTruncated) << n;
    }
    b = good, put32(b, 4, 123);
    expect(b, ErrorCode::kBadFormat, "dwSize", "byte 4");
    b = good, put32(b, 76, 24);
    expect(b, ErrorCode::kBadFormat, "ddspf.dwSize", "byte 76");
    b = good, put32(b, 80, 0x40);  // DDPF_RGB: uncompressed
    expect(b, ErrorCode::kUnsupported, "no FourCC", "byte 80");
    b = good, put_fourcc(b, 84, "DXT5");
    expect(b, ErrorCode::kUnsupported, "FourCC", "'DXT5'");
    b = good, put32(b, 84, 0x71);  // a D3DFMT number (A16B16G16R16F) in the FourCC field
    expect(b, ErrorCode::kUnsupported, "numeric FourCC", "0x00000071");
    for (const std::uint32_t dxgi : {0u, 71u, 79u, 81u, 82u, 84u, 94u, 96u, 98u, 1000u}) {
        b = good, put32(b, 128, dxgi);
        expect(b, ErrorCode::kUnsupported, "dxgiFormat", "byte 128");
    }
    b = good, put32(b, 132, 4);
    expect(b, ErrorCode::kUnsupported, "3-D", "byte 132");
    b = good, put32(b, 132, 2);
    expect(b, ErrorCode::kUnsupported, "1-D", "byte 132");
    b = good, put32(b, 132, 7);
    expect(b, ErrorCode::kBadFormat, "resourceDimension", "byte 132");
    b = good, put32(b, 136, 4);
    expect(b, ErrorCode::kUnsupported, "DX10 cube", "byte 136");
    b = good, put32(b, 136, 1);
    expect(b, ErrorCode::kBadFormat, "miscFlag", "byte 136");
    b = good, put32(b, 140, 2);
    expect(b, ErrorCode::kUnsupported, "array size 2", "byte 140");
    b = good, put32(b, 140, 0);
    expect(b, ErrorCode::kBadFormat, "array size 0", "byte 140");
    b = good, put32(b, 144, 5);
    expect(b, ErrorCode::kBadFormat, "alpha mode", "byte 144");
    b = good, put32(b, 112, 0x200 | 0xFC00);  // DDSCAPS2_CUBEMAP_ALLFACES
    expect(b, ErrorCode::kUnsupported, "cube flag", "byte 112");
    b = good, put32(b, 112, 0x200000);
    expect(b, ErrorCode::kUnsupported, "volume flag", "byte 112");
    b = good, put32(b, 24, 2);
    expect(b, ErrorCode::kUnsupported, "depth 2", "byte 24");
    b = good, put32(b, 28, 5);
    expect(b, ErrorCode::kUnsupported, "mip levels", "byte 28");
    b = good, put32(b, 12, 0);
    expect(b, ErrorCode::kBadFormat, "zero height", "bytes 12-19");
    b = good, put32(b, 16, 16385);
    expect(b, ErrorCode::kTooLarge, "width limit", "bytes 12-19");
    b = good, put32(b, 12, 0xFFFFFFFFu);
    expect(b, ErrorCode::kTooLarge, "height limit", "bytes 12-19");
    b = good, put32(b, 20, 241);
    expect(b, ErrorCode::kBadFormat, "linear size", "byte 20");
    b = good, put32(b, 16, 21);  // 6 x 3 blocks: the declared linear size no longer matches
    expect(b, ErrorCode::kBadFormat, "size vs linear size", "byte 20");
    b = good, put32(b, 16, 21), put32(b, 20, 0);  // ... without it, the data is short
    expect(b, ErrorCode::kTruncated, "size vs data", "needs 436 bytes, has 388");
    expect(std::vector<std::uint8_t>(good.begin(), good.end() - 1), ErrorCode::kTruncated, "short data", "needs 388 bytes");
    expect(std::vector<std::uint8_t>(good.begin(), good.begin() + 148), ErrorCode::kTruncated, "no data", "has 148");
    b = good;
    b.push_back(0);
    expect(b, ErrorCode::kTrailingBytes, "trailing", "1 bytes after the block data (byte 388)");
    b.resize(good.size() + 240, 0);  // a second mip level's worth would be trailing too
    expect(b, ErrorCode::kTrailingBytes, "trailing level", "byte 388");
    // Accepted variants: what other writers put in fields zhc does not rely on.
    for (auto [off, v] : {std::pair<size_t, std::uint32_t>{28, 0}, {20, 0}, {8, 0}, {108, 0}, {144, 0}, {144, 4}, {24, 1},
                          {40, 0xDEADBEEF}, {88, 32}, {80, 0x4 | 0x1}}) {
        b = good, put32(b, off, v);
        auto r = decode_dds(b, "x.dds");
        EXPECT_TRUE(r.ok()) << "byte " << off << " = " << v << ": " << r.error().message;
    }
}

TEST(Dds, HugeDeclaredSizesAreRefusedBeforeAllocating) {
    // A 148-byte header declaring 4 GB of BC6H blocks (16384 x 16384 is within the default limit,
    // 16385 is not): the reader must refuse both without allocating anything of that size.
    auto b = *encode_dds(sample(kVkFormatBc6hUfloat, 4, 4));
    b.resize(kDdsDataOffset);
    for (const std::uint32_t dim : {16384u, 16385u, 0x7FFFFFFFu, 0xFFFFFFFFu}) {
        put32(b, 12, dim), put32(b, 16, dim), put32(b, 20, 0);
        g_largest_allocation = 0;
        g_watch_allocations = true;
        auto r = decode_dds(b, "huge.dds");
        g_watch_allocations = false;
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, dim == 16384u ? ErrorCode::kTruncated : ErrorCode::kTooLarge) << r.error().message;
        EXPECT_LT(g_largest_allocation, 4096u) << dim;
    }
    // A smaller limit is honoured the same way.
    DdsLimits small;
    small.max_dimension = 16;
    EXPECT_EQ(decode_dds(*encode_dds(sample(kVkFormatBc4Unorm, 17, 9)), "x.dds", small).error().code, ErrorCode::kTooLarge);
    EXPECT_TRUE(decode_dds(*encode_dds(sample(kVkFormatBc4Unorm, 16, 9)), "x.dds", small).ok());
}

TEST(Dds, RandomCorruptionNeverCrashes) {
    const auto good = *encode_dds(sample(kVkFormatBc6hUfloat, 20, 12));
    const int accepted =
        test::decode_corrupted_copies(good, 7, 20000, [](std::span<const std::uint8_t> b) { return decode_dds(b, "fuzz"); });
    EXPECT_GT(accepted, 0);  // flips inside the block data are still valid files
}

// The same blocks in both containers: the payloads are byte-identical, and both decode to the same
// image. Real data: a sphere lightmap lit by each of the eight sample maps, odd size (partial blocks).
TEST(Dds, SamePayloadAsKtx2OnRealLightmaps) {
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
        const auto lm = lightmap::synthesize_sphere(world, 13, 7, 2);
        const auto c = lightmap::compress(lightmap::encode_planes(lm, {}, 2), bc6h::Quality::kFast, bc45::Quality::kFast, 2);
        const std::pair<std::uint32_t, const std::vector<std::uint8_t>*> planes[] = {
            {kVkFormatBc6hUfloat, &c.bc6h}, {kVkFormatBc5Unorm, &c.bc5}, {kVkFormatBc4Unorm, &c.bc4}};
        for (const auto& [fmt, blocks] : planes) {
            Ktx2Image k;
            k.vk_format = fmt;
            k.width = c.width;
            k.height = c.height;
            k.blocks = *blocks;
            const auto dds = *encode_dds(k);
            const auto ktx = *encode_ktx2(k);
            const std::size_t ktx_offset = get32(ktx, 80);  // level 0 byteOffset (low 32 bits of the u64)
            ASSERT_EQ(dds.size() - kDdsDataOffset, ktx.size() - ktx_offset);
            EXPECT_TRUE(std::equal(dds.begin() + kDdsDataOffset, dds.end(), ktx.begin() + static_cast<std::ptrdiff_t>(ktx_offset)))
                << test::envmap_name(path) << " format " << fmt;
            const auto a = decode_dds(dds, "a.dds");
            const auto b = decode_ktx2(ktx, "a.ktx2");
            ASSERT_TRUE(a.ok() && b.ok());
            EXPECT_EQ(a->blocks, b->blocks);
            EXPECT_EQ(a->blocks, *blocks);
            EXPECT_EQ(a->vk_format, b->vk_format);
            EXPECT_EQ(a->width, b->width);
            EXPECT_EQ(a->height, b->height);
        }
    }
}

// An independent DDS reader: Pillow (Debian's python3-pil, scripts/packages-test.txt) opens the
// files zhc writes and decodes their blocks with its own BCn decoder; every 8-bit value it returns
// must be exactly what zhc's decoder predicts under Pillow's documented conversions (BC4/BC5:
// integer palette (6 a0 + a1) / 7 etc. truncated, i.e. floor(255 v); BC6H: the same half bits,
// then (uint8)(min(v, 1) * 255), truncated). Pillow 9.4 reads BC4 only as legacy 'ATI1', so the
// BC4 plane is also written that way; the DX10 BC4 file is checked when the Pillow at hand reads it.
constexpr const char* kPillowScript = R"PY(
import struct, sys
from PIL import Image
failures = 0
for spec in sys.argv[1:]:
    kind, dds, ref = spec.split(",")
    try:
        im = Image.open(dds)
        im.load()
    except NotImplementedError as e:
        if kind == "bc4_optional":
            print("%s: not read by this Pillow (%s)" % (dds, e))
            continue
        raise
    w, h = im.size
    data = open(ref, "rb").read()
    bad = below = 0
    for i in range(w * h):
        p = im.getpixel((i % w, i // w))
        if kind == "bc6h":
            bits = struct.unpack_from("<3H", data, 6 * i)
            f = lambda b: 255 if struct.unpack("<e", struct.pack("<H", b))[0] > 1 else int(struct.unpack("<e", struct.pack("<H", b))[0] * 255)
            want = [f(b) for b in bits]
            got = list(p[:3])
            # Pillow interpolates BC6H endpoints as (a (64 - w) + b w) >> 6, without the format's
            # + 32 rounding (zhc and Mesa round), so its half can be one unit below zhc's.
            if got != want and all(g == x or (b > 0 and g == f(b - 1)) for g, x, b in zip(got, want, bits)):
                below += 1
                continue
        elif kind == "bc5":
            zhc = struct.unpack_from("<2f", data, 8 * i)
            want = [int(255 * v + 1e-3) for v in zhc]
            got = list(p[:2])
        else:
            zhc = struct.unpack_from("<f", data, 4 * i)
            want = [int(255 * zhc[0] + 1e-3)]
            got = [p if isinstance(p, int) else p[0]]
        if got != want:
            bad += 1
            if bad <= 3:
                print("%s texel %d: pillow %s, zhc predicts %s" % (dds, i, got, want))
    print("%s: %dx%d %s, %d of %d texels differ%s" % (dds, w, h, im.mode, bad, w * h,
          ", %d one half-float unit below (Pillow's unrounded interpolation)" % below if kind == "bc6h" else ""))
    failures += bad
sys.exit(1 if failures else 0)
)PY";

TEST(Dds, PillowReadsWhatZhcWrites) {
    const std::string python = "/usr/bin/python3";
    if (std::system((python + " -c 'import PIL.DdsImagePlugin' > /dev/null 2>&1").c_str()) != 0)
        GTEST_SKIP() << "Debian's python3-pil is not installed (scripts/packages-test.txt)";
    const std::string dir = fresh_dir("dds_pillow");
    const Image img = test::load_envmap(test::envmap_paths().front());
    const Sh3Radiance world = project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2);
    const auto c = lightmap::compress(lightmap::encode_planes(lightmap::synthesize_sphere(world, 37, 23, 2), {}, 2),
                                      bc6h::Quality::kFast, bc45::Quality::kFast, 2);
    auto write = [&](const std::string& name, std::uint32_t fmt, const std::vector<std::uint8_t>& blocks) {
        Ktx2Image k;
        k.vk_format = fmt;
        k.width = c.width;
        k.height = c.height;
        k.blocks = blocks;
        EXPECT_TRUE(write_dds(dir + "/" + name, k).ok());
    };
    write("iz.dds", kVkFormatBc6hUfloat, c.bc6h);
    write("d.dds", kVkFormatBc5Unorm, c.bc5);
    write("wa.dds", kVkFormatBc4Unorm, c.bc4);
    test::write_bytes(dir + "/wa_ati1.dds", legacy(test::read_bytes(dir + "/wa.dds"), "ATI1"));
    // zhc's decoded values, little-endian: BC6H as half bits, BC4/BC5 as floats.
    const auto halfs = bc6h::decode_image(c.bc6h.data(), c.bc6h.size(), c.width, c.height);
    std::vector<std::uint8_t> ref(halfs.size() * 2);
    for (size_t i = 0; i < halfs.size(); ++i) ref[2 * i] = halfs[i] & 0xFF, ref[2 * i + 1] = halfs[i] >> 8;
    test::write_bytes(dir + "/iz.ref", ref);
    for (int ch : {1, 2}) {
        const auto& blocks = ch == 1 ? c.bc4 : c.bc5;
        const auto v = bc45::decode_image(blocks.data(), blocks.size(), ch, c.width, c.height);
        std::vector<std::uint8_t> bytes(v.size() * 4);
        std::memcpy(bytes.data(), v.data(), bytes.size());  // x86-64 and every Debian target zhc builds on: little-endian
        test::write_bytes(dir + (ch == 1 ? "/wa.ref" : "/d.ref"), bytes);
    }
    {
        std::FILE* f = std::fopen((dir + "/check.py").c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs(kPillowScript, f);
        std::fclose(f);
    }
    const std::string cmd = python + " " + dir + "/check.py bc6h," + dir + "/iz.dds," + dir + "/iz.ref bc5," + dir + "/d.dds," +
                            dir + "/d.ref bc4," + dir + "/wa_ati1.dds," + dir + "/wa.ref bc4_optional," + dir + "/wa.dds," +
                            dir + "/wa.ref > " + dir + "/out.txt 2>&1";
    const int rc = std::system(cmd.c_str());
    const auto out = test::read_bytes(dir + "/out.txt");
    std::printf("%s", std::string(out.begin(), out.end()).c_str());
    EXPECT_EQ(rc, 0);
}

TEST(WriteFilesAtomic, AllOrNothing) {
    const std::string dir = fresh_dir("write_files_atomic");
    const std::vector<std::uint8_t> x{1, 2, 3}, y{4, 5};
    ASSERT_TRUE(write_files_atomic({{dir + "/a", x}, {dir + "/b", y}}).ok());
    EXPECT_EQ(test::read_bytes(dir + "/a"), x);
    EXPECT_EQ(test::read_bytes(dir + "/b"), y);
    // The third name is a directory: nothing is written, the old files keep their content, no
    // temporary file is left.
    std::filesystem::create_directory(dir + "/c");
    auto s = write_files_atomic({{dir + "/a", y}, {dir + "/b", x}, {dir + "/c", x}});
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kIoError);
    EXPECT_NE(s.error().message.find(dir + "/c"), std::string::npos);
    EXPECT_EQ(test::read_bytes(dir + "/a"), x);
    EXPECT_EQ(test::read_bytes(dir + "/b"), y);
    // A missing folder: fails at the first temporary file.
    EXPECT_FALSE(write_files_atomic({{dir + "/d", x}, {dir + "/nope/e", y}}).ok());
    EXPECT_FALSE(std::filesystem::exists(dir + "/d"));
    int entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) entries += e.path().filename().string().find(".tmp-") == std::string::npos ? 1 : 100;
    EXPECT_EQ(entries, 3);  // a, b, c and no temporaries
}

TEST(LightmapCliDds, EncodeDecodeMatchesKtx2OnRealData) {
    const std::string dir = fresh_dir("lightmap_cli_dds");
    const std::string map = test::envmap_paths().back();
    // 37 x 37: partial blocks at the right and bottom edges.
    auto r = test::run_zhc({"lightmap", "synth", map, "-o", dir + "/lm.exr", "--size", "37"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/d", "--container", "dds", "--quality", "fast"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(".{iz,d,wa}.dds"), std::string::npos) << r.out;
    r = test::run_zhc({"lightmap", "encode", dir + "/lm.exr", "-o", dir + "/k", "--quality", "fast", "--threads", "2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::pair<const char*, std::uint32_t> planes[] = {{".iz", 95}, {".d", 83}, {".wa", 80}};
    for (const auto& [s, dxgi] : planes) {
        EXPECT_FALSE(std::filesystem::exists(dir + "/d" + s + ".ktx2"));
        EXPECT_FALSE(std::filesystem::exists(dir + "/k" + s + ".dds"));
        auto dds = read_dds(dir + "/d" + s + ".dds");
        auto ktx = read_ktx2(dir + "/k" + s + ".ktx2");
        ASSERT_TRUE(dds.ok()) << dds.error().message;
        ASSERT_TRUE(ktx.ok()) << ktx.error().message;
        EXPECT_EQ(dds->width, 37);
        EXPECT_EQ(dds->height, 37);
        EXPECT_EQ(dxgi_format_for_vk(dds->vk_format), dxgi);
        EXPECT_EQ(dds->blocks, ktx->blocks) << s;  // same encode, same blocks, any thread count
    }
    // Decoding either container gives the same EXR, byte for byte. The DDS prefix has no KTX2
    // files, so auto picks DDS there.
    r = test::run_zhc({"lightmap", "decode", dir + "/d", "-o", dir + "/from_dds.exr"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(".dds"), std::string::npos);
    r = test::run_zhc({"lightmap", "decode", dir + "/k", "-o", dir + "/from_ktx2.exr"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto from_dds = test::read_bytes(dir + "/from_dds.exr");
    ASSERT_FALSE(from_dds.empty());
    EXPECT_EQ(from_dds, test::read_bytes(dir + "/from_ktx2.exr"));

    // Both sets under one prefix: auto reads KTX2, --container dds reads the DDS files.
    for (const char* s : {".iz", ".d", ".wa"})
        std::filesystem::copy_file(dir + "/k" + s + ".ktx2", dir + "/d" + s + ".ktx2");
    r = test::run_zhc({"lightmap", "decode", dir + "/d", "-o", dir + "/both.exr"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(".ktx2"), std::string::npos) << r.out;
    r = test::run_zhc({"lightmap", "decode", dir + "/d", "-o", dir + "/both_dds.exr", "--container", "dds"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(".dds"), std::string::npos) << r.out;
    EXPECT_EQ(test::read_bytes(dir + "/both_dds.exr"), from_dds);

    // Errors (a missing DDS set, a cut .d.dds, BC6H_SF16 or a BC6H file in the wrong slot, an
    // unwritable output leaving none of the three files, --container png): tests/conformance
    // lmdds_*, lmktx2_*, cli_usage_lm_*container.
}

}  // namespace
}  // namespace zhc
