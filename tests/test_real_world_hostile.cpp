// Real-world inputs, hostile variants (the companion of test_real_world.cpp): trailing bytes
// after every kind of EXR and .hdr, a huge declared image in a small file (peak memory), deep
// files, Radiance .hdr in every orientation and XYZE (our own writer) and ImageMagick's, and JSON
// nesting in every JSON reader.
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfEnvmap.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>
#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "cli/cli.h"
#include "codec/sh/cubemap.h"
#include "formats/envmap/envmap.h"
#include "formats/io/json_depth.h"
#include "support.h"

#include "real_world_helpers.h"

namespace zhc {
namespace {

using namespace real_world;

// ---- 3. trailing bytes, 4. memory --------------------------------------------------------

std::vector<std::uint8_t> with_tail(std::vector<std::uint8_t> b, size_t n) {
    for (size_t i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(i * 7 + 1));
    return b;
}

TEST(TrailingBytes, AfterEveryKindOfExrAndHdrAreExit4) {
    const std::string dir = test::temp_dir("rw_trailing");
    const Image img = test::render_latlong(64, 32, [](Vec3 d) { return Rgb{float(1 + d.x), 1.0f, float(1 + d.z)}; });
    std::vector<std::string> good;
    ASSERT_TRUE(write_exr(dir + "/scan.exr", img));
    good.push_back(dir + "/scan.exr");
    write_float_exr(dir + "/none.exr", 64, 32, img.rgb, false, Imf::NO_COMPRESSION);
    good.push_back(dir + "/none.exr");
    write_float_exr(dir + "/piz.exr", 64, 32, img.rgb, false, Imf::PIZ_COMPRESSION);
    good.push_back(dir + "/piz.exr");
    ASSERT_TRUE(write_hdr(dir + "/map.hdr", img));
    good.push_back(dir + "/map.hdr");
#ifdef ZHC_TOOL_EXRMAKETILED
    // Tiled in every level mode and rounding (the chunk count depends on all of them); exrmaketiled
    // makes multi-resolution files only from images without an envmap attribute. 64 x 32 with
    // 16 x 8 tiles, and 60 x 30 with 16 x 16 (levels of odd sizes: rounding matters).
    write_float_exr(dir + "/plain.exr", 64, 32, img.rgb, false, Imf::ZIP_COMPRESSION, false);
    for (const std::string opts : {"-o -t 16 8", "-m -d -t 16 8", "-m -u -t 16 8", "-r -d -t 16 8", "-r -u -t 16 8"}) {
        const std::string out = dir + "/tiled" + std::to_string(good.size()) + ".exr";
        ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRMAKETILED) + " " + opts + " " + quote(dir + "/plain.exr") + " " + quote(out)), 0) << opts;
        good.push_back(out);
    }
#endif
#ifdef ZHC_TOOL_EXRMULTIPART
    const std::string mp = dir + "/multi.exr";
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRMULTIPART) + " -combine -i " + quote(dir + "/scan.exr") + " " + quote(dir + "/piz.exr") +
                     " -o " + quote(mp)),
              0);
    good.push_back(mp);
#ifdef ZHC_TOOL_EXRMAKETILED
    // A tiled mip-mapped part (round up) after a scanline part: the multi-part chunk layout with tiles.
    const std::string mp_tiled = dir + "/multi_tiled.exr";
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRMULTIPART) + " -combine -i " + quote(dir + "/scan.exr") + " " + quote(good[6]) + " -o " +
                     quote(mp_tiled)),
              0);
    good.push_back(mp_tiled);
#endif
#endif
    const Sh3Radiance ref = project_latlong(img.rgb.data(), 64, 32, 64 * 3);
    for (const std::string& path : good) {
        SCOPED_TRACE(path);
        const Sh3Radiance s = cli_project(path);
        EXPECT_LT(test::sh_distance(s, ref), 0.01);  // .hdr: RGBE's 8-bit mantissa
        const auto bytes = test::read_bytes(path);
        for (size_t n : {size_t(1), size_t(100)}) {
            const std::string bad = path + ".tail" + std::to_string(n);
            test::write_bytes(bad, with_tail(bytes, n));
            auto r = read_envmap(bad);
            ASSERT_FALSE(r);
            EXPECT_EQ(r.error().code, ErrorCode::kTrailingBytes) << r.error().message;
            expect_one_line_error(test::run_zhc({"project", bad}), cli::kExitInvalidInput, bad);
        }
    }
}

// Peak resident memory (KiB) and exit code of `zhc ARGS` in a child process.
std::pair<long, int> zhc_peak_rss(const std::vector<std::string>& args) {
    std::vector<std::string> all = {ZHC_CLI_PATH};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::FILE* devnull = std::freopen("/dev/null", "w", stderr);
        (void)devnull;
        ::execv(argv[0], argv.data());
        ::_exit(127);
    }
    int status = 0;
    rusage ru{};
    ::wait4(pid, &status, 0, &ru);
    return {ru.ru_maxrss, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)};
}

TEST(Memory, HugeDeclaredImageInASmallFileIsRefusedWithoutAllocatingIt) {
    // An EXR header declaring 8192 x 8191 pixels (ZIP: 512 chunks) whose offset table is all
    // zeros and no pixel data follows: what OpenEXR's OutputFile leaves when no pixel is written.
    // Variants: offsets pointing past the end; a .hdr declaring the same size in 4 KB.
    const std::string dir = test::temp_dir("rw_memory");
    const std::string empty = dir + "/huge_empty.exr";
    {
        Imf::Header header(8192, 8191);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::HALF));
        Imf::OutputFile out(empty.c_str(), header);
    }
    auto bytes = test::read_bytes(empty);
    std::printf("huge-declared EXR: %zu bytes\n", bytes.size());
    ASSERT_LT(bytes.size(), 8000u);
    std::vector<std::pair<std::string, int>> cases = {{empty, cli::kExitInvalidInput}};
    {
        // Offset table entries pointing far beyond the end.
        auto far = bytes;
        const size_t table = far.size() - 512 * 8;
        for (size_t k = 0; k < 512; ++k) {
            const std::uint64_t off = 1'000'000'000ull + k * 1000;
            std::memcpy(&far[table + 8 * k], &off, 8);
        }
        test::write_bytes(dir + "/huge_far.exr", far);
        cases.push_back({dir + "/huge_far.exr", cli::kExitInvalidInput});
        // Offsets inside the file, each chunk claiming 1 MB of data.
        auto claims = bytes;
        std::vector<std::uint8_t> chunk(8, 0);
        const std::int32_t big = 1 << 20;
        std::memcpy(&chunk[4], &big, 4);
        for (size_t k = 0; k < 512; ++k) {
            const std::uint64_t off = claims.size();
            std::memcpy(&claims[table + 8 * k], &off, 8);
            const std::int32_t y = static_cast<std::int32_t>(16 * k);
            std::memcpy(&chunk[0], &y, 4);
            claims.insert(claims.end(), chunk.begin(), chunk.end());
        }
        test::write_bytes(dir + "/huge_claims.exr", claims);
        cases.push_back({dir + "/huge_claims.exr", cli::kExitInvalidInput});
    }
    {
        std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8191 +X 8192\n";
        hdr.append(4096, '\x01');
        test::write_bytes(dir + "/huge.hdr", {hdr.begin(), hdr.end()});
        cases.push_back({dir + "/huge.hdr", cli::kExitInvalidInput});
    }
    for (const auto& [path, code] : cases) {
        const auto [kib, rc] = zhc_peak_rss({"project", path});
        const double mb = kib / 1024.0, file_mb = static_cast<double>(test::read_bytes(path).size()) / (1 << 20);
        std::printf("%-16s peak RSS %.1f MB (file %.3f MB), exit %d\n", path.substr(dir.size() + 1).c_str(), mb, file_mb, rc);
        EXPECT_EQ(rc, code) << path;
        EXPECT_LT(mb, 64.0 + file_mb) << path;
        expect_one_line_error(test::run_zhc({"project", path}), code, path);
    }
}

TEST(TrailingBytes, DeepFilesAreWalkedToTheirEnd) {
    // Deep scanline files (OpenEXR's API; chunk = y, three 64-bit sizes, offset table + samples):
    // the chunk walk must find their true end, so the file is refused as unsupported (exit 5: deep
    // images are not environment maps), and only with a byte appended as trailing data (exit 4).
    const std::string dir = test::temp_dir("rw_deep");
    for (const Imf::Compression c : {Imf::NO_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::RLE_COMPRESSION}) {
        const std::string path = dir + "/deep" + std::to_string(int(c)) + ".exr";
        const int w = 16, h = 8;
        {
            Imf::Header header(w, h);
            header.setType(Imf::DEEPSCANLINE);
            header.compression() = c;
            for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
            Imf::DeepScanLineOutputFile out(path.c_str(), header);
            std::vector<unsigned> counts(w * h);
            std::vector<float> values;
            for (int i = 0; i < w * h; ++i) counts[static_cast<size_t>(i)] = static_cast<unsigned>(i % 3);
            values.assign(w * h * 2, 0.5f);
            std::vector<float*> ptrs(w * h);
            for (int i = 0; i < w * h; ++i) ptrs[static_cast<size_t>(i)] = values.data() + 2 * i;
            Imf::DeepFrameBuffer fb;
            fb.insertSampleCountSlice(Imf::Slice(Imf::UINT, reinterpret_cast<char*>(counts.data()), sizeof(unsigned),
                                                 sizeof(unsigned) * w));
            for (const char* ch : {"R", "G", "B"})
                fb.insert(ch, Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(ptrs.data()), sizeof(float*), sizeof(float*) * w,
                                             sizeof(float)));
            out.setFrameBuffer(fb);
            out.writePixels(h);
        }
        expect_one_line_error(test::run_zhc({"project", path}), cli::kExitUnsupported, path);
        test::write_bytes(path + ".tail", with_tail(test::read_bytes(path), 1));
        expect_one_line_error(test::run_zhc({"project", path + ".tail"}), cli::kExitInvalidInput, path + ".tail");
    }
}


// ---- 6. Radiance .hdr --------------------------------------------------------------------

// RGBE of a value triple (Radiance's setcolr: truncating mantissas of the largest component).
std::array<std::uint8_t, 4> rgbe(float r, float g, float b) {
    const float m = std::max({r, g, b});
    if (m < 1e-32f) return {0, 0, 0, 0};
    int e;
    const float scale = std::frexp(m, &e) * 256.0f / m;
    return {static_cast<std::uint8_t>(r * scale), static_cast<std::uint8_t>(g * scale), static_cast<std::uint8_t>(b * scale),
            static_cast<std::uint8_t>(e + 128)};
}
float from_rgbe(std::uint8_t v, std::uint8_t e) { return e ? std::ldexp(float(v), int(e) - 136) : 0.0f; }

// Our own writer: any orientation "S1A1 N1 S2A2 N2", flat or new-style RLE scanlines.
std::string write_radiance(const Image& img, const std::string& orientation, bool rle, bool xyz) {
    std::string out = "#?RADIANCE\n# test writer\nFORMAT=" + std::string(xyz ? "32-bit_rle_xyze" : "32-bit_rle_rgbe") + "\n\n";
    const char s1 = orientation[0], a1 = orientation[1], s2 = orientation[2], a2 = orientation[3];
    const int n1 = a1 == 'Y' ? img.height : img.width, n2 = a2 == 'Y' ? img.height : img.width;
    out += std::string{s1, a1, ' '} + std::to_string(n1) + " " + std::string{s2, a2, ' '} + std::to_string(n2) + "\n";
    for (int i = 0; i < n1; ++i) {
        std::vector<std::array<std::uint8_t, 4>> line;
        for (int j = 0; j < n2; ++j) {
            const int c1 = s1 == '+' ? i : n1 - 1 - i, c2 = s2 == '+' ? j : n2 - 1 - j;
            const int x = a1 == 'X' ? c1 : c2, y = a1 == 'Y' ? c1 : c2;  // Radiance coordinates, y up
            const float* p = img.row(img.height - 1 - y) + 3 * x;
            line.push_back(rgbe(p[0], p[1], p[2]));
        }
        if (rle) {
            out += std::string{'\x02', '\x02', char(n2 >> 8), char(n2 & 255)};
            for (int c = 0; c < 4; ++c) {
                int j = 0;
                while (j < n2) {  // a run when >= 3 equal bytes, else a literal of up to 128
                    int run = 1;
                    while (j + run < n2 && run < 127 && line[j + run][c] == line[j][c]) ++run;
                    if (run >= 3) {
                        out += char(128 + run);
                        out += char(line[j][c]);
                        j += run;
                    } else {
                        int lit = 0;
                        std::string bytes;
                        while (j + lit < n2 && lit < 128) {
                            bytes += char(line[j + lit][c]);
                            ++lit;
                            if (j + lit + 2 < n2 && line[j + lit][c] == line[j + lit + 1][c] && line[j + lit][c] == line[j + lit + 2][c])
                                break;
                        }
                        out += char(lit);
                        out += bytes;
                        j += lit;
                    }
                }
            }
        } else {
            for (const auto& q : line) out.append(reinterpret_cast<const char*>(q.data()), 4);
        }
    }
    return out;
}

TEST(Radiance, EveryOrientationAndXyzeReads) {
    const std::string dir = test::temp_dir("rw_hdr");
    // A 24 x 10 image whose values survive RGBE exactly (checked below): asymmetric in x and y.
    Image img;
    img.width = 24;
    img.height = 10;
    img.rgb.resize(24 * 10 * 3);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 24; ++x) {
            float* p = img.row(y) + 3 * x;
            p[0] = float(1 + x) / 32.0f, p[1] = float(1 + y) / 16.0f, p[2] = float((x * 7 + y * 3) % 11 + 1) / 8.0f;
        }
    Image exact = img;  // what RGBE stores
    for (size_t i = 0; i < img.rgb.size(); i += 3) {
        const auto q = rgbe(img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]);
        for (int c = 0; c < 3; ++c) exact.rgb[i + static_cast<size_t>(c)] = from_rgbe(q[static_cast<size_t>(c)], q[3]);
    }
    int files = 0;
    for (const char* o : {"-Y+X", "+Y+X", "-Y-X", "+Y-X", "+X-Y", "-X-Y", "+X+Y", "-X+Y"})
        for (bool rle : {false, true}) {
            const std::string text = write_radiance(exact, o, rle, false);
            const std::string path = dir + "/o" + std::to_string(files++) + ".hdr";
            test::write_bytes(path, {text.begin(), text.end()});
            auto r = read_envmap(path);
            ASSERT_TRUE(r) << o << " " << r.error().message;
            EXPECT_EQ(r->width, 24) << o;
            EXPECT_EQ(r->rgb, exact.rgb) << o << (rle ? " rle" : " flat");
            EXPECT_EQ(test::run_zhc({"project", path}).exit_code, 0) << o;
        }
    // XYZE: the decoded XYZ through the published XYZ -> linear sRGB/Rec. 709 (D65) matrix of IEC
    // 61966-2-1; the values are D65 white's XYZ (0.9505, 1, 1.089), RGB (1, 1, 1) up to RGBE's
    // quantisation (which the matrix amplifies to ~1.5%).
    Image white;
    white.width = 8, white.height = 2;
    white.rgb.assign(8 * 2 * 3, 0.0f);
    for (size_t i = 0; i < white.rgb.size(); i += 3) white.rgb[i] = 0.95047f, white.rgb[i + 1] = 1.0f, white.rgb[i + 2] = 1.08883f;
    const std::string text = write_radiance(white, "-Y+X", true, true);
    test::write_bytes(dir + "/xyz.hdr", {text.begin(), text.end()});
    EnvmapInfo info;
    auto r = read_envmap(dir + "/xyz.hdr", {}, &info);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(info.channels, "XYZE");
    const auto q = rgbe(0.95047f, 1.0f, 1.08883f);
    const double X = from_rgbe(q[0], q[3]), Y = from_rgbe(q[1], q[3]), Z = from_rgbe(q[2], q[3]);
    const double expect[3] = {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
                              0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
    for (size_t i = 0; i < r->rgb.size(); ++i) {
        EXPECT_NEAR(r->rgb[i], expect[i % 3], 1e-5);
        EXPECT_NEAR(r->rgb[i], 1.0f, 0.03f);
    }
    // Malformed resolution lines: exit 4; too large: exit 6.
    const std::pair<std::string, int> bad[] = {
        {"-Y -5 +X 3", cli::kExitInvalidInput}, {"-Y 5 +X -3", cli::kExitInvalidInput}, {"-Y 0 +X 3", cli::kExitInvalidInput},
        {"-Y 5 -Y 3", cli::kExitInvalidInput},  {"-Z 5 +X 3", cli::kExitInvalidInput},  {"-Y 5 +X", cli::kExitInvalidInput},
        {"-Y 99999 +X 99999", cli::kExitTooLarge}, {"+X 99999999999 -Y 99999", cli::kExitTooLarge}};
    for (const auto& [res, code] : bad) {
        const std::string t = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + res + "\n" + std::string(60, '\x10');
        const std::string path = dir + "/bad" + std::to_string(files++) + ".hdr";
        test::write_bytes(path, {t.begin(), t.end()});
        expect_one_line_error(test::run_zhc({"project", path}), code, res);
    }
}

#ifdef ZHC_TOOL_CONVERT
TEST(Radiance, ImageMagickHdrReadsLikeItsSource) {
    // ImageMagick writes .hdr (RGBE, -Y +X, run-length coded) from a PFM we write: the decoded
    // pixels must equal the source within RGBE's 8-bit mantissa (2^-8 of the pixel's largest
    // component, relative; 2^-7 allowing for ImageMagick's rounding), plus ImageMagick's own
    // 16-bit quantum (2^-15 absolute): Debian's ImageMagick is a Q16 build without HDRI (it
    // clamps to [0, 1] and keeps 16 bits), so the map is scaled to a maximum of 0.9.
    const std::string dir = test::temp_dir("rw_magick");
    Image src = test::downsample_latlong(test::load_envmap(test::envmap_paths()[0]), 8);
    const float peak = *std::max_element(src.rgb.begin(), src.rgb.end());
    for (float& v : src.rgb) v = std::max(v, 0.0f) * 0.9f / peak;
    {
        std::ofstream pfm(dir + "/src.pfm", std::ios::binary);
        pfm << "PF\n" << src.width << " " << src.height << "\n-1.0\n";
        for (int y = src.height - 1; y >= 0; --y) pfm.write(reinterpret_cast<const char*>(src.row(y)), src.width * 12);
    }
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_CONVERT) + " " + quote(dir + "/src.pfm") + " " + quote(dir + "/magick.hdr")), 0);
    auto r = read_envmap(dir + "/magick.hdr");
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->width, src.width);
    ASSERT_EQ(r->height, src.height);
    double worst = 0;  // error over its allowance
    for (size_t i = 0; i < src.rgb.size(); i += 3) {
        const double m = std::max({src.rgb[i], src.rgb[i + 1], src.rgb[i + 2]});
        for (size_t c = 0; c < 3; ++c)
            worst = std::max(worst, std::fabs(double(r->rgb[i + c]) - src.rgb[i + c]) / (m / 128 + 1.0 / 32768));
    }
    std::printf("ImageMagick .hdr: worst pixel error %.2f of its allowance (2^-7 relative + 2^-15)\n", worst);
    EXPECT_LT(worst, 1.0);
    const Sh3Radiance ref = project_latlong(src.rgb.data(), src.width, src.height, src.width * 3u);
    EXPECT_LT(test::sh_distance(cli_project(dir + "/magick.hdr"), ref), 1.0 / 128);
}
#endif

// ---- 7. JSON nesting ---------------------------------------------------------------------

std::string nested(int depth, const std::string& inner = "0") {
    std::string s;
    for (int i = 0; i < depth; ++i) s += (i % 2 ? "{\"k\":" : "[");
    s += inner;
    for (int i = depth - 1; i >= 0; --i) s += (i % 2 ? "}" : "]");
    return s;
}

TEST(JsonDepth, PreScanCountsOnlyStructure) {
    EXPECT_TRUE(check_json_depth(std::string_view(nested(kMaxJsonDepth)), "x"));
    EXPECT_FALSE(check_json_depth(std::string_view(nested(kMaxJsonDepth + 1)), "x"));
    // Brackets inside strings, escaped quotes and backslashes do not count.
    const std::string str = "[\"" + std::string(2000, '[') + "\\\"" + std::string(2000, '{') + "\\\\\"]";
    EXPECT_TRUE(check_json_depth(std::string_view(str), "x"));
    const std::string after = "[\"\\\\\"" + std::string(kMaxJsonDepth + 5, '[');  // the string ended: these count
    EXPECT_FALSE(check_json_depth(std::string_view(after), "x"));
}

TEST(JsonDepth, EveryJsonReaderRefusesDeepNestingWithOneLine) {
    const std::string dir = test::temp_dir("rw_json_depth");
    for (int depth : {30000, 100000}) {
        const std::string deep = nested(depth);
        const std::string probe = "{\"format\":\"zhc-probes\",\"probes\":" + deep + "}";
        const std::string scene = "{\"lights\":" + deep + "}";
        const std::string gltf = "{\"asset\":{\"version\":\"2.0\",\"extras\":" + deep + "}}";
        std::string glb = "glTF";
        {
            std::string chunk = gltf;
            while (chunk.size() % 4) chunk += ' ';
            auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
            glb += u32(2) + u32(static_cast<std::uint32_t>(12 + 8 + chunk.size())) + u32(static_cast<std::uint32_t>(chunk.size())) +
                   "JSON" + chunk;
        }
        const std::string tag = std::to_string(depth);
        auto put = [&](const std::string& name, const std::string& text) {
            const std::string p = dir + "/" + name;
            test::write_bytes(p, {text.begin(), text.end()});
            return p;
        };
        const std::string probe_path = put("probes" + tag + ".json", probe), scene_path = put("scene" + tag + ".json", scene);
        const std::string gltf_path = put("asset" + tag + ".gltf", gltf), glb_path = put("asset" + tag + ".glb", glb);
        const std::vector<std::vector<std::string>> runs = {
            {"convert", probe_path, "-o", dir + "/o.zhp"}, {"audit", probe_path},          {"dering", probe_path, "-o", dir + "/d.json"},
            {"info", probe_path},                          {"bake", scene_path, "-o", dir + "/o.json"},
            {"info", gltf_path},                           {"info", glb_path},
            {"gltf", "extract", gltf_path, "-o", dir + "/o.zhp"},
            {"bake", gltf_path, "-o", dir + "/o.json"}};
        for (const auto& args : runs) {
            std::string what;
            for (const auto& a : args) what += a + " ";
            const auto r = test::run_zhc(args);
            expect_one_line_error(r, cli::kExitInvalidInput, what);
            EXPECT_NE(r.err.find("nests deeper than"), std::string::npos) << what << r.err;
        }
    }
    // At the limit minus one level of nesting inside a valid asset: read (the extras are kept).
    const std::string ok = "{\"asset\":{\"version\":\"2.0\",\"extras\":" + nested(kMaxJsonDepth - 3) +
                           "},\"scenes\":[{\"nodes\":[]}],\"scene\":0}";
    ASSERT_TRUE(check_json_depth(std::string_view(ok), "ok"));
    ASSERT_FALSE(check_json_depth(std::string_view(ok), "ok", kMaxJsonDepth - 2));  // it is at the limit minus one
    test::write_bytes(dir + "/ok.gltf", {ok.begin(), ok.end()});
    const auto r = test::run_zhc({"info", dir + "/ok.gltf"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
}

// ---- 8. usage errors: tests/conformance cli_usage_* ----------------------------------------------

}  // namespace
}  // namespace zhc
