// The fast scanline EXR decoder (formats/io/exr_scanlines.h) against its slow twin, OpenEXR's own
// Imf::InputFile::readPixels into FLOAT slices, bit for bit: files written by OpenEXR's library
// with ZIP (16-line chunks), ZIPS (1 line) and no compression, HALF and FLOAT channels, channels
// not asked for, odd sizes, a data window away from the origin, incompressible chunks (which the
// writer stores raw), every row range and thread count; corrupt chunks fail with the first bad
// chunk's row whatever the thread count; the files it leaves to readPixels; the lightmap reader
// through it on the sample maps' lightmaps.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

#include <cstring>
#include <random>

#include "codec/lightmap/lightmap.h"
#include "formats/envmap/envmap.h"
#include "formats/io/exr_memory.h"
#include "formats/io/exr_scanlines.h"
#include "formats/lightmap/lightmap_exr.h"
#include "support.h"

namespace zhc {
namespace {

struct Spec {
    int min_x = 0, min_y = 0, width = 0, height = 0;
    Imf::Compression compression = Imf::ZIP_COMPRESSION;
    std::vector<std::pair<std::string, Imf::PixelType>> channels;
    bool noise = false;  // random bits (finite): chunks do not shrink and are stored raw
};

// Writes `spec` with OpenEXR's library; sample values are smooth per channel (compressible) or noise.
void write_exr(const std::string& path, const Spec& s, std::uint32_t seed) {
    Imf::Header h(Imath::Box2i({s.min_x, s.min_y}, {s.min_x + s.width - 1, s.min_y + s.height - 1}),
                  Imath::Box2i({s.min_x, s.min_y}, {s.min_x + s.width - 1, s.min_y + s.height - 1}));
    h.compression() = s.compression;
    for (const auto& [name, type] : s.channels) h.channels().insert(name, Imf::Channel(type));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1000.f, 1000.f);
    const size_t n = static_cast<size_t>(s.width) * static_cast<size_t>(s.height);
    std::vector<std::vector<float>> f(s.channels.size(), std::vector<float>(n));
    std::vector<std::vector<Imath::half>> hv(s.channels.size(), std::vector<Imath::half>(n));
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < s.channels.size(); ++c) {
        for (size_t i = 0; i < n; ++i) {
            const double x = double(i % static_cast<size_t>(s.width)), y = double(i / static_cast<size_t>(s.width));
            f[c][i] = s.noise ? u(rng) : static_cast<float>(std::sin(0.05 * x + 0.3 * double(c)) * std::cos(0.07 * y) * (1 + double(c)));
            hv[c][i] = Imath::half(f[c][i]);
        }
        const bool half = s.channels[c].second == Imf::HALF;
        char* base = half ? reinterpret_cast<char*>(hv[c].data()) : reinterpret_cast<char*>(f[c].data());
        const size_t es = half ? 2 : 4;
        base -= (static_cast<std::ptrdiff_t>(s.min_x) + static_cast<std::ptrdiff_t>(s.min_y) * s.width) * static_cast<std::ptrdiff_t>(es);
        fb.insert(s.channels[c].first, Imf::Slice(s.channels[c].second, base, es, es * static_cast<size_t>(s.width)));
    }
    Imf::OutputFile out(path.c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(s.height);
}

// Rows [y0, y1) of `names` as floats, channel-interleaved: by readPixels (the twin) or the fast path.
std::vector<float> read_rows(const std::string& path, const std::vector<std::string>& names, int y0, int y1, bool fast,
                             int threads, Status* status = nullptr) {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const size_t w = static_cast<size_t>(dw.max.x - dw.min.x + 1), nc = names.size();
    std::vector<float> out(w * static_cast<size_t>(y1 - y0) * nc, -12345.f);
    const size_t xs = nc * sizeof(float), ys = xs * w;
    if (fast) {
        EXPECT_TRUE(exr_scanlines_supported(file)) << path;
        std::vector<ExrFloatSlice> slices;
        for (size_t c = 0; c < nc; ++c) slices.push_back({names[c], reinterpret_cast<char*>(out.data()) + c * sizeof(float), xs, ys});
        const Status st = decode_exr_scanlines(file, path, y0, y1, slices, threads);
        if (status) *status = st;
        else EXPECT_TRUE(st.ok()) << st.error().message;
        return out;
    }
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(out.data()) -
                 (static_cast<std::ptrdiff_t>(dw.min.x) * static_cast<std::ptrdiff_t>(xs) +
                  (static_cast<std::ptrdiff_t>(dw.min.y) + y0) * static_cast<std::ptrdiff_t>(ys));
    for (size_t c = 0; c < nc; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y + y0, dw.min.y + y1 - 1);
    return out;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

std::vector<Spec> specs() {
    using P = Imf::PixelType;
    std::vector<Spec> v;
    const std::vector<std::pair<std::string, P>> mixed = {{"B", P::HALF}, {"G", P::FLOAT}, {"R", P::FLOAT}, {"Z", P::HALF}, {"a", P::FLOAT}};
    for (Imf::Compression c : {Imf::ZIP_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::NO_COMPRESSION}) {
        v.push_back({0, 0, 64, 48, c, mixed, false});
        v.push_back({-3, 17, 37, 41, c, mixed, false});    // odd width, window away from the origin, 41 = 2 x 16 + 9 rows
        v.push_back({5, -20, 29, 35, c, {{"R", P::FLOAT}, {"sh0.G", P::HALF}}, true});  // incompressible
    }
    return v;
}

TEST(ExrScanlines, MatchesReadPixelsForEveryCompressionTypeWindowAndRowRange) {
    const std::string dir = test::fresh_dir("exr_scanlines");
    int k = 0;
    for (const Spec& s : specs()) {
        const std::string path = dir + "/f" + std::to_string(k++) + ".exr";
        write_exr(path, s, static_cast<std::uint32_t>(k));
        std::vector<std::string> all;
        for (const auto& c : s.channels) all.push_back(c.first);
        // Every channel, a subset in a different order, and one channel.
        const std::vector<std::vector<std::string>> picks = {all, {all.back(), all.front()}, {all[1]}};
        for (const auto& names : picks) {
            for (const auto& [y0, y1] : std::vector<std::pair<int, int>>{{0, s.height}, {1, s.height - 2}, {15, 17}, {16, 32}, {s.height - 1, s.height}}) {
                const auto twin = read_rows(path, names, y0, y1, false, 1);
                for (int threads : {1, 3}) {
                    const auto fast = read_rows(path, names, y0, y1, true, threads);
                    EXPECT_TRUE(same_bits(fast, twin)) << path << " rows " << y0 << ".." << y1 << " threads " << threads;
                }
            }
        }
    }
}

TEST(ExrScanlines, IncompressibleChunksAreStoredRawAndStillRead) {
    // The case the noise specs rely on: OpenEXR stored at least one of their chunks uncompressed.
    const std::string dir = test::fresh_dir("exr_scanlines_raw");
    const Spec s = specs()[2];
    ASSERT_TRUE(s.noise);
    write_exr(dir + "/n.exr", s, 7);
    Imf::InputFile file((dir + "/n.exr").c_str());
    const size_t row_bytes = static_cast<size_t>(s.width) * (4 + 2);
    int raw = 0;
    for (int y = 0; y < s.height; y += 16) {
        const char* data = nullptr;
        int size = 0;
        file.rawPixelData(s.min_y + y, data, size);
        raw += static_cast<size_t>(size) == row_bytes * static_cast<size_t>(std::min(16, s.height - y));
    }
    EXPECT_GT(raw, 0);
    EXPECT_TRUE(same_bits(read_rows(dir + "/n.exr", {"R", "sh0.G"}, 0, s.height, true, 2),
                          read_rows(dir + "/n.exr", {"R", "sh0.G"}, 0, s.height, false, 1)));
}

// The byte offset of the chunk for `row` (0 = the data window's top) and its packed size, from the
// offset table after the header.
std::pair<size_t, size_t> chunk_of(const std::vector<std::uint8_t>& b, int chunk) {
    ExrLayout layout;
    const Status st = validate_exr_header(b, "x", [](std::uint64_t, std::uint64_t) { return Status{Ok{}}; }, &layout);
    EXPECT_TRUE(st.ok());
    std::uint64_t off = 0;
    std::memcpy(&off, b.data() + layout.tables_start + 8 * static_cast<size_t>(chunk), 8);
    std::int32_t size = 0;
    std::memcpy(&size, b.data() + off + 4, 4);
    return {static_cast<size_t>(off) + 8, static_cast<size_t>(size)};
}

TEST(ExrScanlines, CorruptChunkFailsWithTheFirstBadChunksRowForAnyThreadCount) {
    const std::string dir = test::fresh_dir("exr_scanlines_corrupt");
    Spec s = specs()[0];
    s.height = 160;  // ten chunks
    write_exr(dir + "/ok.exr", s, 3);
    auto bytes = test::read_bytes(dir + "/ok.exr");
    // Chunks 3 and 7: garbage in the middle of their deflate streams.
    for (int c : {7, 3}) {
        const auto [off, size] = chunk_of(bytes, c);
        ASSERT_GT(size, 64u);
        for (size_t i = size / 3; i < size / 3 + 24; ++i) bytes[off + i] ^= 0x5A;
    }
    test::write_bytes(dir + "/bad.exr", bytes);
    for (int threads : {1, 2, 4}) {
        Status st = Ok{};
        read_rows(dir + "/bad.exr", {"R", "G"}, 0, s.height, true, threads, &st);
        ASSERT_FALSE(st.ok()) << threads;
        EXPECT_EQ(st.error().code, ErrorCode::kBadFormat);
        EXPECT_NE(st.error().message.find("bad.exr: corrupt OpenEXR chunk at row 48 "), std::string::npos) << st.error().message;
    }
    // Rows before the first bad chunk still read.
    EXPECT_TRUE(same_bits(read_rows(dir + "/bad.exr", {"R"}, 0, 48, true, 2), read_rows(dir + "/ok.exr", {"R"}, 0, 48, false, 1)));
    // A truncated deflate stream (the packed size says less than the stream holds): refused too.
    auto cut = test::read_bytes(dir + "/ok.exr");
    const auto [off, size] = chunk_of(cut, 0);
    const std::int32_t smaller = static_cast<std::int32_t>(size / 2);
    std::memcpy(cut.data() + off - 4, &smaller, 4);
    test::write_bytes(dir + "/cut.exr", cut);
    Status st = Ok{};
    read_rows(dir + "/cut.exr", {"R"}, 0, 16, true, 1, &st);
    EXPECT_FALSE(st.ok());
}

TEST(ExrScanlines, OtherFilesAreLeftToReadPixels) {
    const std::string dir = test::fresh_dir("exr_scanlines_other");
    Spec s = specs()[0];
    s.compression = Imf::PIZ_COMPRESSION;
    write_exr(dir + "/piz.exr", s, 1);
    {
        Imf::InputFile f((dir + "/piz.exr").c_str());
        EXPECT_FALSE(exr_scanlines_supported(f));
    }
    s = specs()[0];
    s.channels = {{"R", Imf::UINT}};
    write_exr(dir + "/uint.exr", s, 1);
    {
        Imf::InputFile f((dir + "/uint.exr").c_str());
        EXPECT_FALSE(exr_scanlines_supported(f));
    }
    {
        Imf::Header h(16, 16);
        h.setTileDescription(Imf::TileDescription(8, 8));
        h.compression() = Imf::ZIP_COMPRESSION;
        h.channels().insert("R", Imf::Channel(Imf::FLOAT));
        std::vector<float> px(256, 1.f);
        Imf::FrameBuffer fb;
        fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data()), 4, 64));
        Imf::TiledOutputFile out((dir + "/tiled.exr").c_str(), h);
        out.setFrameBuffer(fb);
        out.writeTiles(0, 1, 0, 1);
    }
    {
        Imf::InputFile f((dir + "/tiled.exr").c_str());
        EXPECT_FALSE(exr_scanlines_supported(f));
    }
    // The sample maps (DWAB, written by oiiotool) take readPixels; the lightmap reader handles both.
    for (const auto& p : test::envmap_paths()) {
        Imf::InputFile f(p.c_str());
        EXPECT_FALSE(exr_scanlines_supported(f)) << p;
    }
}

TEST(ExrScanlines, LightmapReaderGivesTheSameTexelsThroughEitherPath) {
    // A lightmap of a sample map written as ZIP (zhc's writer, the fast path) and the same texels as
    // PIZ (readPixels): read_sh_lightmap_exr gives the same floats, and the streaming source's bands
    // at any split equal the whole image.
    const std::string dir = test::fresh_dir("exr_scanlines_lightmap");
    auto env = read_envmap(test::envmap_paths().back());
    ASSERT_TRUE(env.ok());
    const lightmap::ShLightmap lm = lightmap::synthesize_sphere(project_envmap(*env, 1), 45, 38, 1);
    ASSERT_TRUE(write_sh_lightmap_exr(dir + "/zip.exr", lm).ok());
    {
        Imf::InputFile in((dir + "/zip.exr").c_str());
        ASSERT_EQ(in.header().compression(), Imf::ZIP_COMPRESSION);
        ASSERT_TRUE(exr_scanlines_supported(in));
        Imf::Header h = in.header();
        h.compression() = Imf::PIZ_COMPRESSION;
        const auto names = sh_lightmap_channel_names();
        const auto all = read_rows(dir + "/zip.exr", names, 0, lm.height, false, 1);
        Imf::FrameBuffer fb;
        const size_t xs = names.size() * 4, ys = xs * static_cast<size_t>(lm.width);
        for (size_t c = 0; c < names.size(); ++c)
            fb.insert(names[c], Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(all.data())) + 4 * c, xs, ys));
        Imf::OutputFile out((dir + "/piz.exr").c_str(), h);
        out.setFrameBuffer(fb);
        out.writePixels(lm.height);
    }
    auto a = read_sh_lightmap_exr(dir + "/zip.exr");
    auto b = read_sh_lightmap_exr(dir + "/piz.exr");
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a->texels.size(), lm.texels.size());
    EXPECT_EQ(std::memcmp(a->texels.data(), lm.texels.data(), lm.texels.size() * sizeof(Sh3Radiance)), 0);
    EXPECT_EQ(std::memcmp(a->texels.data(), b->texels.data(), lm.texels.size() * sizeof(Sh3Radiance)), 0);
    for (int threads : {1, 3}) {
        LightmapStreamOptions o;
        o.threads = threads;
        auto src = ShLightmapSource::open({dir + "/zip.exr"}, o);
        ASSERT_TRUE(src.ok());
        for (int y = 0; y < lm.height; y += 7) {
            lightmap::ShLightmap band;
            const int y1 = std::min(lm.height, y + 7);
            ASSERT_TRUE((*src)->read_rows(y, y1, band).ok());
            EXPECT_EQ(std::memcmp(band.texels.data(), lm.texels.data() + static_cast<size_t>(y) * static_cast<size_t>(lm.width),
                                  band.texels.size() * sizeof(Sh3Radiance)),
                      0)
                << y;
        }
    }
}

}  // namespace
}  // namespace zhc
