// EXR colour spaces and windows on files other programs wrote: the chromaticities attribute (set
// on real files by Debian's exrstdattr), luminance/chroma files (OpenEXR's RgbaOutputFile), a data
// window smaller or larger than the display window (OpenEXR's C++ API: no Debian 12 tool in the
// test set-up writes one; oiiotool --crop would, from openimageio-tools and its ~150 dependencies),
// and what `zhc info` says about chromaticities, NaN pixels and channels zhc cannot read.
//
// The slow twin of the colour conversion is written here from the definitions, in double
// precision: RGB -> XYZ from the primaries' xyz columns scaled so that RGB (1, 1, 1) is the white
// point, and the linear Bradford adaptation between white points.
#include <ImfChannelList.h>
#include <ImfChromaticities.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <ImfStandardAttributes.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "cli/cli.h"
#include "formats/envmap/envmap.h"
#include "support.h"

#include "real_world_helpers.h"

namespace zhc {
namespace {

using namespace real_world;

// ---- the twin: 3x3 matrices in double ------------------------------------------------------

struct M3 {
    double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};

M3 mul(const M3& a, const M3& b) {
    M3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = 0;
            for (int k = 0; k < 3; ++k) r.m[i][j] += a.m[i][k] * b.m[k][j];
        }
    return r;
}

// Gauss-Jordan elimination with partial pivoting (a different route than the reader's cofactors).
M3 inverse(const M3& a) {
    double t[3][6];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 6; ++j) t[i][j] = j < 3 ? a.m[i][j] : (j - 3 == i ? 1.0 : 0.0);
    for (int c = 0; c < 3; ++c) {
        int p = c;
        for (int r = c + 1; r < 3; ++r)
            if (std::fabs(t[r][c]) > std::fabs(t[p][c])) p = r;
        std::swap(t[c], t[p]);
        const double d = t[c][c];
        for (int j = 0; j < 6; ++j) t[c][j] /= d;
        for (int r = 0; r < 3; ++r) {
            if (r == c) continue;
            const double f = t[r][c];
            for (int j = 0; j < 6; ++j) t[r][j] -= f * t[c][j];
        }
    }
    M3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] = t[i][j + 3];
    return r;
}

struct Chroma {
    double rx, ry, gx, gy, bx, by, wx, wy;
};
const Chroma kRec709{0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290};
const Chroma kRec2020{0.708, 0.292, 0.170, 0.797, 0.131, 0.046, 0.3127, 0.3290};
const Chroma kXyzE{1, 0, 0, 1, 0, 0, 1.0 / 3.0, 1.0 / 3.0};

// Columns: each primary's xyz scaled by s, with P s = white XYZ (Y = 1).
M3 rgb_to_xyz(const Chroma& c) {
    M3 p;
    const double x[3] = {c.rx, c.gx, c.bx}, y[3] = {c.ry, c.gy, c.by};
    for (int j = 0; j < 3; ++j) p.m[0][j] = x[j], p.m[1][j] = y[j], p.m[2][j] = 1 - x[j] - y[j];
    const double w[3] = {c.wx / c.wy, 1.0, (1 - c.wx - c.wy) / c.wy};
    const M3 pi = inverse(p);
    double s[3];
    for (int i = 0; i < 3; ++i) s[i] = pi.m[i][0] * w[0] + pi.m[i][1] * w[1] + pi.m[i][2] * w[2];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) p.m[i][j] *= s[j];
    return p;
}

// Linear Bradford: XYZ seen under white (sx, sy) -> under white (dx, dy).
M3 bradford(double sx, double sy, double dx, double dy) {
    M3 b;
    const double k[3][3] = {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b.m[i][j] = k[i][j];
    const double s[3] = {sx / sy, 1, (1 - sx - sy) / sy}, d[3] = {dx / dy, 1, (1 - dx - dy) / dy};
    M3 scale;
    for (int i = 0; i < 3; ++i) {
        double cs = 0, cd = 0;
        for (int j = 0; j < 3; ++j) cs += k[i][j] * s[j], cd += k[i][j] * d[j];
        scale.m[i][i] = cd / cs;
    }
    return mul(inverse(b), mul(scale, b));
}

// Rec. 709 / D65 RGB -> RGB in the space c (adapting D65 to c's white with Bradford).
M3 from_709(const Chroma& c) {
    return mul(inverse(rgb_to_xyz(c)), mul(bradford(kRec709.wx, kRec709.wy, c.wx, c.wy), rgb_to_xyz(kRec709)));
}

std::vector<float> transform(const std::vector<float>& rgb, const M3& m) {
    std::vector<float> out(rgb.size());
    for (size_t p = 0; p < rgb.size(); p += 3)
        for (int i = 0; i < 3; ++i)
            out[p + size_t(i)] = float(m.m[i][0] * rgb[p] + m.m[i][1] * rgb[p + 1] + m.m[i][2] * rgb[p + 2]);
    return out;
}

std::string chroma_args(const Chroma& c) {
    char buf[256];
    std::snprintf(buf, sizeof buf, " -chromaticities %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g ", c.rx, c.ry, c.gx, c.gy,
                  c.bx, c.by, c.wx, c.wy);
    return buf;
}

TEST(ExrColourTwin, MatricesMatchPublishedValues) {
    // The twin against published numbers: the sRGB / Rec. 709 RGB -> XYZ matrix (IEC 61966-2-1, 4
    // decimals) and ITU-R BT.2087-0's Rec. 2020 -> Rec. 709 matrix (4 decimals).
    const double srgb[3][3] = {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};
    const M3 a = rgb_to_xyz(kRec709);
    const double bt2087[3][3] = {{1.6605, -0.5876, -0.0728}, {-0.1246, 1.1329, -0.0083}, {-0.0182, -0.1006, 1.1187}};
    const M3 b = inverse(from_709(kRec2020));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            EXPECT_NEAR(a.m[i][j], srgb[i][j], 1.5e-4) << i << j;
            EXPECT_NEAR(b.m[i][j], bt2087[i][j], 1e-4) << i << j;
        }
    // Bradford keeps white: the XYZ-E space's (1, 1, 1) is Rec. 709's (1, 1, 1).
    const M3 e = from_709(kXyzE);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(e.m[i][0] + e.m[i][1] + e.m[i][2], 1.0, 1e-12);
}

// ---- files ---------------------------------------------------------------------------------

// Writes float RGB pixels with an optional chromaticities attribute (OpenEXR's API).
void write_exr(const std::string& path, int w, int h, const std::vector<float>& rgb, const Chroma* c = nullptr) {
    Imf::Header header(w, h);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
    if (c)
        Imf::addChromaticities(header, Imf::Chromaticities({float(c->rx), float(c->ry)}, {float(c->gx), float(c->gy)},
                                                           {float(c->bx), float(c->by)}, {float(c->wx), float(c->wy)}));
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
    const size_t xs = 3 * sizeof(float), ys = size_t(w) * xs;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + 4, xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 8, xs, ys));
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

const std::string& sample(const char* name) {
    static std::map<std::string, std::string> paths;
    auto& p = paths[name];
    if (p.empty())
        for (const std::string& s : test::envmap_paths())
            if (test::envmap_name(s) == name) p = s;
    return p;
}

nlohmann::json info_json(const std::string& path) {
    const auto r = test::run_zhc({"info", path, "--json"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
}

TEST(ExrColour, Rec2020PrimariesGiveBt2087Values) {
    // Analytic: a constant map of Rec. 2020 red, green, blue (1 in one channel) tagged Rec. 2020
    // projects to L00 = 2 sqrt(pi) x that column of BT.2087's matrix; Rec. 2020 white to white.
    const std::string dir = test::temp_dir("exr_colour_bt2087");
    const double bt2087[3][3] = {{1.6605, -0.5876, -0.0728}, {-0.1246, 1.1329, -0.0083}, {-0.0182, -0.1006, 1.1187}};
    for (int col = 0; col < 4; ++col) {
        std::vector<float> rgb(64 * 32 * 3);
        for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = (col == 3 || int(i % 3) == col) ? 1.0f : 0.0f;
        const std::string path = dir + "/c" + std::to_string(col) + ".exr";
        write_exr(path, 64, 32, rgb, &kRec2020);
        const Sh3Radiance s = cli_project(path);
        for (int k = 0; k < 3; ++k) {
            const double want = col == 3 ? 1.0 : bt2087[k][col];
            EXPECT_NEAR(s[0][k] / (2 * std::sqrt(kPi)), want, col == 3 ? 1e-5 : 1e-4) << col << " " << k;
        }
    }
}

#ifdef ZHC_TOOL_EXRSTDATTR
TEST(ExrColour, SampleMapsTaggedRec2020ProjectLikeTheirRec709Originals) {
    // Real maps converted pixel-wise to Rec. 2020 by the twin and tagged Rec. 2020 by exrstdattr
    // project like the Rec. 709 originals; the same pixels without the tag do not.
    const std::string dir = test::temp_dir("exr_colour_2020");
    const M3 to2020 = from_709(kRec2020);
    for (const char* name : {"forest", "sunset", "courtyard"}) {
        SCOPED_TRACE(name);
        const Image img = test::load_envmap(sample(name));
        const std::string raw = dir + "/" + name + "_2020_untagged.exr", tagged = dir + "/" + name + "_2020.exr";
        write_exr(raw, img.width, img.height, transform(img.rgb, to2020));
        ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + chroma_args(kRec2020) + quote(raw) + " " + quote(tagged)), 0);
        const Sh3Radiance ref = cli_project(sample(name));
        const double d = test::sh_distance(cli_project(tagged), ref), wrong = test::sh_distance(cli_project(raw), ref);
        double dc_wrong = 0;
        const Sh3Radiance w = cli_project(raw);
        for (int k = 0; k < 3; ++k) dc_wrong = std::max(dc_wrong, std::fabs(double(w[0][k]) - ref[0][k]) / std::fabs(ref[0][k]));
        std::printf("%-10s Rec. 2020 tagged vs Rec. 709 original: %.2e of |L00|; untagged: %.3f (DC worst channel %.3f)\n",
                    name, d, wrong, dc_wrong);
        EXPECT_LT(d, 2e-6);        // measured 2.9e-7 to 3.6e-7
        EXPECT_GT(wrong, 0.02);    // measured 0.041 to 0.140
    }
}

TEST(ExrColour, XyzPrimariesFileProjectsLikeItsRec709Original) {
    // An XYZ file (primaries (1,0), (0,1), (0,0), white E = (1/3, 1/3)) made from a real map: the
    // twin takes Rec. 709 / D65 to XYZ and adapts D65 to E (Bradford); zhc reads it back.
    const std::string dir = test::temp_dir("exr_colour_xyz");
    const Image img = test::load_envmap(sample("sunset"));
    const std::string raw = dir + "/xyz_untagged.exr", tagged = dir + "/xyz.exr";
    write_exr(raw, img.width, img.height, transform(img.rgb, from_709(kXyzE)));
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + " -chromaticities 1 0 0 1 0 0 0.333333333 0.333333333 " + quote(raw) +
                     " " + quote(tagged)),
              0);
    const Sh3Radiance ref = cli_project(sample("sunset"));
    const double d = test::sh_distance(cli_project(tagged), ref), wrong = test::sh_distance(cli_project(raw), ref);
    std::printf("sunset as XYZ (white E): %.2e of |L00|; read as Rec. 709: %.3f\n", d, wrong);
    EXPECT_LT(d, 2e-6);
    EXPECT_GT(wrong, 0.05);
    const auto j = info_json(tagged);
    EXPECT_EQ(j["chromaticities"]["red"], nlohmann::json({1.0, 0.0}));
    EXPECT_NE(j["colour_conversion"].get<std::string>().find("Bradford adaptation from white (0.3333, 0.3333)"),
              std::string::npos)
        << j.dump();
}

TEST(ExrColour, Rec709TagAndD50AdaptedSrgbLeaveTheOutputBitIdentical) {
    // forest has no chromaticities; tagged Rec. 709 / D65 by exrstdattr it must give the same bytes.
    // city.exr (as shipped) is tagged with Rec. 709 primaries Bradford-adapted to D50 (ICC-managed
    // tools write this): its conversion is the identity within 1.6e-4, below half's precision, so
    // it is not transformed either: retagged Rec. 709 it gives the same bytes too.
    const std::string dir = test::temp_dir("exr_colour_709");
    for (const char* name : {"forest", "city"}) {
        SCOPED_TRACE(name);
        const std::string tagged = dir + "/" + name + "_709.exr";
        ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + chroma_args(kRec709) + quote(sample(name)) + " " + quote(tagged)), 0);
        for (const std::string& in : {sample(name), tagged}) {
            const auto r = test::run_zhc({"convert", in, "-o", in == tagged ? dir + "/b.zhp" : dir + "/a.zhp", "-r", "sh3"});
            ASSERT_EQ(r.exit_code, 0) << r.err;
        }
        const auto a = test::read_bytes(dir + "/a.zhp"), b = test::read_bytes(dir + "/b.zhp");
        EXPECT_FALSE(a.empty());
        EXPECT_EQ(a, b);
        const auto ja = info_json(sample(name)), jb = info_json(tagged);
        EXPECT_EQ(ja["mean_radiance_luminance"], jb["mean_radiance_luminance"]);
        EXPECT_EQ(jb["chromaticities"]["white"], nlohmann::json({0.3127, 0.329}));
        EXPECT_EQ(jb["colour_conversion"].get<std::string>().rfind("none", 0), 0u) << jb.dump();
    }
    const auto city = info_json(sample("city"));
    EXPECT_NE(city["colour_conversion"].get<std::string>().find("identity"), std::string::npos) << city.dump();
    EXPECT_EQ(city["chromaticities"]["white"], nlohmann::json({0.3457084, 0.3585413}));
    // The D50 white alone (Rec. 709 primaries, not adapted) is a real difference: converted.
    Chroma d50 = kRec709;
    d50.wx = 0.3457084, d50.wy = 0.3585413;
    const std::string warm = dir + "/forest_709_d50white.exr";
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + chroma_args(d50) + quote(sample("forest")) + " " + quote(warm)), 0);
    EXPECT_NE(info_json(warm)["colour_conversion"].get<std::string>().find("Bradford"), std::string::npos);
    EXPECT_GT(test::sh_distance(cli_project(warm), cli_project(sample("forest"))), 1e-3);
}

TEST(ExrColour, ChromaticitiesThatDefineNoSpaceAreMalformed) {
    const std::string dir = test::temp_dir("exr_colour_bad");
    const std::string bad = dir + "/collinear.exr";
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + " -chromaticities 0.2 0.2 0.3 0.3 0.4 0.4 0.3127 0.329 " +
                     quote(sample("studio")) + " " + quote(bad)),
              0);
    const auto r = test::run_zhc({"project", bad});
    expect_one_line_error(r, cli::kExitInvalidInput, "collinear");
    EXPECT_NE(r.err.find("chromaticities: the red, green and blue primaries are collinear"), std::string::npos) << r.err;
    const std::string dark = dir + "/white_y0.exr";
    ASSERT_EQ(sh_run(quote(ZHC_TOOL_EXRSTDATTR) + " -chromaticities 0.64 0.33 0.3 0.6 0.15 0.06 0.3 0 " +
                     quote(sample("studio")) + " " + quote(dark)),
              0);
    const auto w = test::run_zhc({"info", dark});
    expect_one_line_error(w, cli::kExitInvalidInput, "white y 0");
    EXPECT_NE(w.err.find("white point y 0 is not positive"), std::string::npos) << w.err;
}
#endif

TEST(ExrColour, LuminanceChromaFileInRec2020) {
    // A Rec. 2020 map written as Y RY BY by OpenEXR's RgbaOutputFile (WRITE_YC; its luminance
    // weights come from the header's chromaticities): zhc must equal OpenEXR's own decoding
    // (RgbaInputFile) taken to Rec. 709 by the twin, and match the Rec. 709 original within YC's
    // chroma loss. No Debian tool writes YC (exrenvmap writes RGB(A)).
    const std::string dir = test::temp_dir("exr_colour_yc");
    const Image img = test::downsample_latlong(test::load_envmap(sample("sunset")), 2);
    const int w = img.width, h = img.height;
    const std::vector<float> v2020 = transform(img.rgb, from_709(kRec2020));
    std::vector<Imf::Rgba> px(size_t(w) * size_t(h));
    for (size_t i = 0; i < px.size(); ++i) px[i] = Imf::Rgba(v2020[3 * i], v2020[3 * i + 1], v2020[3 * i + 2], 1.0f);
    const std::string path = dir + "/yc2020.exr";
    {
        Imf::Header header(w, h);
        Imf::addChromaticities(header, Imf::Chromaticities({0.708f, 0.292f}, {0.170f, 0.797f}, {0.131f, 0.046f},
                                                           {0.3127f, 0.3290f}));
        Imf::RgbaOutputFile out(path.c_str(), header, Imf::WRITE_YC);
        out.setFrameBuffer(px.data(), 1, size_t(w));
        out.writePixels(h);
    }
    std::vector<Imf::Rgba> back(px.size());
    {
        Imf::RgbaInputFile in(path.c_str());
        ASSERT_EQ(int(in.channels()) & int(Imf::WRITE_Y), int(Imf::WRITE_Y));
        in.setFrameBuffer(back.data(), 1, size_t(w));
        in.readPixels(0, h - 1);
    }
    std::vector<float> decoded(px.size() * 3);
    for (size_t i = 0; i < back.size(); ++i) decoded[3 * i] = back[i].r, decoded[3 * i + 1] = back[i].g, decoded[3 * i + 2] = back[i].b;
    const std::vector<float> twin = transform(decoded, inverse(from_709(kRec2020)));
    const Sh3Radiance want = project_latlong(twin.data(), w, h, size_t(w) * 3);
    const Sh3Radiance got = cli_project(path);
    const Sh3Radiance unconverted = project_latlong(decoded.data(), w, h, size_t(w) * 3);
    const Sh3Radiance original = project_latlong(img.rgb.data(), w, h, size_t(w) * 3);
    const double d = test::sh_distance(got, want), loss = test::sh_distance(got, original),
                 wrong = test::sh_distance(unconverted, want);
    std::printf("YC Rec. 2020: vs OpenEXR's decoding + twin %.2e, vs Rec. 709 original %.2e, unconverted %.3f of |L00|\n",
                d, loss, wrong);
    EXPECT_LT(d, 2e-6);
    EXPECT_LT(loss, 1e-2);  // measured 4.9e-3
    EXPECT_GT(wrong, 0.02);
    EXPECT_EQ(info_json(path)["channels"], "YC half");
}

// ---- windows -------------------------------------------------------------------------------

// Writes the part of a full-size image that lies in `data` (pixels outside the image are a
// constant), with display window `display` (OpenEXR's API).
void write_windowed(const std::string& path, const Image& full, const Imath::Box2i& display, const Imath::Box2i& data) {
    Imf::Header header(display, data);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
    const int w = data.max.x - data.min.x + 1, h = data.max.y - data.min.y + 1;
    std::vector<float> rgb(size_t(w) * size_t(h) * 3, 7.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int fx = x + data.min.x - display.min.x, fy = y + data.min.y - display.min.y;
            if (fx < 0 || fy < 0 || fx >= full.width || fy >= full.height) continue;
            for (int c = 0; c < 3; ++c) rgb[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)] = full.row(fy)[3 * fx + c];
        }
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    // Base such that base + x*xs + y*ys is pixel (x, y) of the data window (an integer: a pointer
    // outside the buffer would be UB; OpenEXR only adds offsets that land inside it).
    const std::int64_t origin = -(std::int64_t(data.min.x) + std::int64_t(data.min.y) * w) * 3 * std::int64_t(sizeof(float));
    char* base = reinterpret_cast<char*>(reinterpret_cast<std::uintptr_t>(rgb.data()) + static_cast<std::uintptr_t>(origin));
    const size_t xs = 3 * sizeof(float), ys = size_t(w) * xs;
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xs, ys));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + 4, xs, ys));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 8, xs, ys));
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

TEST(ExrWindows, CroppedDataWindowIsReadAgainstTheDisplayWindow) {
    const std::string dir = test::temp_dir("exr_windows_crop");
    const Image full = test::load_envmap(sample("studio"));
    const Imath::Box2i display({0, 0}, {full.width - 1, full.height - 1}), data({100, 64}, {923, 383});
    const std::string cropped = dir + "/cropped.exr";
    write_windowed(cropped, full, display, data);
    // Twin: the full-size map with the pixels outside the data window set to 0 by hand.
    Image zeroed = full;
    for (int y = 0; y < full.height; ++y)
        for (int x = 0; x < full.width; ++x)
            if (x < data.min.x || x > data.max.x || y < data.min.y || y > data.max.y)
                for (int c = 0; c < 3; ++c) zeroed.row(y)[3 * x + c] = 0.0f;
    const std::string twin = dir + "/zeroed.exr";
    write_float_exr(twin, full.width, full.height, zeroed.rgb, false);
    const auto r = test::run_zhc({"project", cropped, "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Sh3Radiance got = parse_sh(r.out), want = cli_project(twin);
    // The library hands the warning to EnvmapReadOptions::warn when one is set.
    EnvmapReadOptions ro;
    std::vector<std::string> warnings;
    ro.warn = [&](const std::string& line) { warnings.push_back(line); };
    auto img = read_envmap(cropped, ro);
    ASSERT_TRUE(img) << img.error().message;
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(r.err, "zhc: warning: " + warnings[0] + "\n");
    // The whole sphere from the data window alone (what a reader ignoring the display window does).
    EXPECT_EQ(img->width, full.width);
    EXPECT_EQ(img->height, full.height);
    std::vector<float> inside;
    for (int y = data.min.y; y <= data.max.y; ++y)
        inside.insert(inside.end(), full.row(y) + 3 * data.min.x, full.row(y) + 3 * (data.max.x + 1));
    const Sh3Radiance stretched = project_latlong(inside.data(), 824, 320, 824 * 3);
    const double d = test::sh_distance(got, want), wrong = test::sh_distance(stretched, want);
    std::printf("cropped studio: vs zeroed full-size twin %.2e; data window as the whole sphere %.3f of |L00|\n", d, wrong);
    EXPECT_EQ(d, 0.0);
    EXPECT_GT(wrong, 0.1);
    // One warning line naming the file and both windows.
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("zhc: warning: " + cropped + ": data window (100 64) - (923 383) differs from the display "
                                                       "window (0 0) - (1023 511)",
                          0),
              0u)
        << r.err;
    EXPECT_NE(r.err.find("outside the data window are 0"), std::string::npos) << r.err;
    // Every verb reading lat-long EXRs goes through the same reader.
    const auto conv = test::run_zhc({"convert", cropped, "-o", dir + "/c.json"});
    EXPECT_EQ(conv.exit_code, 0) << conv.err;
    EXPECT_NE(conv.err.find("(100 64) - (923 383)"), std::string::npos) << conv.err;
    const auto conv_twin = test::run_zhc({"convert", twin, "-o", dir + "/t.json"});
    EXPECT_EQ(conv_twin.exit_code, 0) << conv_twin.err;
    EXPECT_TRUE(conv_twin.err.empty()) << conv_twin.err;
    EXPECT_EQ(test::read_bytes(dir + "/c.json"), test::read_bytes(dir + "/t.json"));
    // dering, lightmap synth and audit: the same output as the zeroed twin's, and the warning.
    const std::vector<std::vector<std::string>> verbs = {
        {"dering", "IN", "-o", "OUT.json"}, {"lightmap", "synth", "IN", "-o", "OUT.exr", "--size", "16"}};
    for (const auto& v : verbs) {
        std::vector<std::string> out_paths;
        for (const std::string& in : {cropped, twin}) {
            std::vector<std::string> args;
            for (const std::string& a : v) {
                if (a == "IN") args.push_back(in);
                else if (a.rfind("OUT", 0) == 0) args.push_back(out_paths.emplace_back(in + "." + v[0] + a.substr(3)));
                else args.push_back(a);
            }
            const auto vr = test::run_zhc(args);
            EXPECT_EQ(vr.exit_code, 0) << v[0] << ": " << vr.err;
            EXPECT_EQ(vr.err.find("zhc: warning: " + cropped + ": data window") != std::string::npos, in == cropped)
                << v[0] << ": " << vr.err;
        }
        if (v[0] == "dering") {  // the JSON names its input: compare the rest
            auto a = nlohmann::json::parse(test::read_bytes(out_paths[0])), b = nlohmann::json::parse(test::read_bytes(out_paths[1]));
            ASSERT_TRUE(a.contains("input") && b.contains("input"));
            a.erase("input"), b.erase("input");
            EXPECT_EQ(a, b);
        } else {
            EXPECT_EQ(test::read_bytes(out_paths[0]), test::read_bytes(out_paths[1])) << v[0];
        }
    }
    double audit_rmse[2] = {-1, -2};
    for (int k = 0; k < 2; ++k) {
        const auto ar = test::run_zhc({"audit", k ? twin : cropped, "--representations", "sh3", "--json"});
        ASSERT_EQ(ar.exit_code, 0) << ar.err;
        EXPECT_EQ(ar.err.find("(100 64) - (923 383)") != std::string::npos, k == 0) << ar.err;
        audit_rmse[k] = nlohmann::json::parse(ar.out)["files"][0]["representations"]["sh3"]["relative_rmse"].get<double>();
    }
    EXPECT_EQ(audit_rmse[0], audit_rmse[1]);
    const auto j = info_json(cropped);
    EXPECT_EQ(j["data_window"], "(100 64) - (923 383)");
    EXPECT_EQ(j["display_window"], "(0 0) - (1023 511)");
    EXPECT_EQ(j["width"], 1024);
}

TEST(ExrWindows, DataWindowBeyondTheDisplayWindowIsCropped) {
    // A data window larger than, and offset past, the display window: the display window's pixels
    // are the map; the rest (set to 7 here) is dropped, with a warning.
    const std::string dir = test::temp_dir("exr_windows_large");
    const Image full = test::downsample_latlong(test::load_envmap(sample("forest")), 4);
    const Imath::Box2i display({10, 20}, {10 + full.width - 1, 20 + full.height - 1});
    const Imath::Box2i larger({-6, 0}, {10 + full.width + 30, 20 + full.height + 3});
    write_windowed(dir + "/larger.exr", full, display, larger);
    write_float_exr(dir + "/plain.exr", full.width, full.height, full.rgb, false);
    const auto r = test::run_zhc({"project", dir + "/larger.exr", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(test::sh_distance(parse_sh(r.out), cli_project(dir + "/plain.exr")), 0.0);
    EXPECT_NE(r.err.find("data outside the display window is dropped"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("are 0"), std::string::npos) << r.err;  // it covers the display window
    // Offset so that it covers part of the display window and reaches past it: both clauses.
    const Imath::Box2i shifted({10 + full.width / 2, 20}, {10 + full.width + 40, 20 + full.height - 1});
    write_windowed(dir + "/shifted.exr", full, display, shifted);
    const auto s = test::run_zhc({"project", dir + "/shifted.exr"});
    EXPECT_EQ(s.exit_code, 0) << s.err;
    EXPECT_NE(s.err.find("are 0, data outside the display window is dropped"), std::string::npos) << s.err;
}

TEST(ExrWindows, CubeMapWithAPartialDataWindow) {
    // A cube map (envmap attribute cube) whose data window holds only faces +X, -X, +Y: the
    // display window (N x 6N) is the cube, the other three faces are 0.
    const std::string dir = test::temp_dir("exr_windows_cube");
    const int n = 16;
    Image cube;
    cube.width = n;
    cube.height = 6 * n;
    cube.rgb = render_cube(n, [](Vec3 d) { return Rgb{float(2 + d.x), float(2 + d.y), float(2 + d.z)}; });
    Image zeroed = cube;
    std::fill(zeroed.rgb.begin() + 3 * n * 3 * n, zeroed.rgb.end(), 0.0f);
    {
        Imf::Header header(Imath::Box2i({0, 0}, {n - 1, 6 * n - 1}), Imath::Box2i({0, 0}, {n - 1, 3 * n - 1}));
        for (const char* ch : {"R", "G", "B"}) header.channels().insert(ch, Imf::Channel(Imf::FLOAT));
        Imf::addEnvmap(header, Imf::ENVMAP_CUBE);
        Imf::OutputFile out((dir + "/half_cube.exr").c_str(), header);
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(cube.rgb.data());
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, 12, size_t(n) * 12));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + 4, 12, size_t(n) * 12));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 8, 12, size_t(n) * 12));
        out.setFrameBuffer(fb);
        out.writePixels(3 * n);
    }
    write_float_exr(dir + "/zeroed_cube.exr", n, 6 * n, zeroed.rgb, true);
    const auto r = test::run_zhc({"project", dir + "/half_cube.exr", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("data window (0 0) - (15 47) differs from the display window (0 0) - (15 95)"), std::string::npos)
        << r.err;
    const Sh3Radiance got = parse_sh(r.out), want = cli_project(dir + "/zeroed_cube.exr");
    EXPECT_EQ(test::sh_distance(got, want), 0.0);
    write_float_exr(dir + "/full_cube.exr", n, 6 * n, cube.rgb, true);
    EXPECT_GT(test::sh_distance(got, cli_project(dir + "/full_cube.exr")), 0.1);  // the zeros count
    EXPECT_EQ(info_json(dir + "/half_cube.exr")["type"], "environment map (cube)");
}

TEST(ExrWindows, HugeDisplayWindowIsTooLargeBeforeAllocating) {
    // A 16 x 8 data window in a 20001 x 20001 display window (4e8 pixels > 2^26): exit 6 naming
    // the display window.
    const std::string dir = test::temp_dir("exr_windows_huge");
    const Image small = test::render_latlong(16, 8, [](Vec3 d) { return Rgb{float(1 + d.z), 1.0f, 1.0f}; });
    write_windowed(dir + "/huge.exr", small, Imath::Box2i({0, 0}, {20000, 20000}), Imath::Box2i({0, 0}, {15, 7}));
    const auto r = test::run_zhc({"project", dir + "/huge.exr"});
    expect_one_line_error(r, cli::kExitTooLarge, "huge display window");
    EXPECT_NE(r.err.find("display window"), std::string::npos) << r.err;
}

// ---- info and channel messages ---------------------------------------------------------------

void write_channels(const std::string& path, int w, int h, const std::vector<std::string>& names,
                    const std::vector<float>& value_of_channel) {
    Imf::Header header(w, h);
    for (const std::string& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
    std::vector<std::vector<float>> planes;
    for (size_t c = 0; c < names.size(); ++c) planes.emplace_back(size_t(w) * size_t(h), value_of_channel[c]);
    Imf::OutputFile out(path.c_str(), header);
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < names.size(); ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes[c].data()), sizeof(float), size_t(w) * sizeof(float)));
    out.setFrameBuffer(fb);
    out.writePixels(h);
}

TEST(ExrInfo, NanPixelsAreCountedNotRefused) {
    const std::string dir = test::temp_dir("exr_info_nan");
    std::vector<float> rgb(32 * 16 * 3, 0.5f);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    // 5 pixels, 8 values: pixel 3 has three, pixel 40 two, pixels 100, 200, 511 one each.
    rgb[9] = rgb[10] = rgb[11] = nan;
    rgb[120] = inf, rgb[122] = -inf;
    rgb[301] = nan, rgb[602] = inf, rgb[1533] = nan;
    write_exr(dir + "/nan.exr", 32, 16, rgb);
    const auto r = test::run_zhc({"info", dir + "/nan.exr", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["non_finite_pixels"], 5);
    EXPECT_EQ(j["non_finite_values"], 8);
    EXPECT_EQ(j["width"], 32);
    EXPECT_EQ(r.out.find("replace-non-finite"), std::string::npos);
    // 507 of 512 pixels are 0.5, the rest read as 0: the mean luminance is below 0.5.
    EXPECT_LT(j["mean_radiance_luminance"][0].get<double>(), 0.5);
    const auto text = test::run_zhc({"info", dir + "/nan.exr"});
    EXPECT_EQ(text.exit_code, 0) << text.err;
    EXPECT_NE(text.out.find("non_finite_pixels        5"), std::string::npos) << text.out;
    // project still refuses it (exit 4), pointing at its option.
    const auto p = test::run_zhc({"project", dir + "/nan.exr"});
    expect_one_line_error(p, cli::kExitInvalidInput, "nan project");
    EXPECT_NE(p.err.find("--replace-non-finite"), std::string::npos);
}

TEST(ExrInfo, FilesWithoutRgbListTheirChannels) {
    const std::string dir = test::temp_dir("exr_info_channels");
    write_channels(dir + "/r.exr", 8, 4, {"R"}, {1.0f});
    write_channels(dir + "/rg.exr", 8, 4, {"R", "G"}, {1.0f, 2.0f});
    write_channels(dir + "/other.exr", 8, 4, {"Z", "diffuse.R", "A"}, {1.0f, 2.0f, 3.0f});
    struct Case {
        const char* file;
        const char* listed;
    } cases[] = {{"r.exr", "(part #0: R)"}, {"rg.exr", "(part #0: G, R)"}, {"other.exr", "(part #0: A, Z, diffuse.R)"}};
    for (const Case& c : cases)
        for (const char* verb : {"project", "info"}) {
            const auto r = test::run_zhc({verb, dir + "/" + c.file});
            expect_one_line_error(r, cli::kExitUnsupported, c.file);
            EXPECT_NE(r.err.find(c.listed), std::string::npos) << r.err;
        }
    const auto part = test::run_zhc({"project", dir + "/rg.exr", "--part", "0"});
    expect_one_line_error(part, cli::kExitUnsupported, "--part 0");
    EXPECT_NE(part.err.find("(it has: G, R)"), std::string::npos) << part.err;
}

TEST(ExrInfo, ShowsChromaticitiesAndConversion) {
    const std::string dir = test::temp_dir("exr_info_chroma");
    std::vector<float> rgb(16 * 8 * 3, 1.0f);
    write_exr(dir + "/plain.exr", 16, 8, rgb);
    write_exr(dir + "/p2020.exr", 16, 8, rgb, &kRec2020);
    const auto a = info_json(dir + "/plain.exr"), b = info_json(dir + "/p2020.exr");
    EXPECT_EQ(a["chromaticities"], "none (Rec. 709 / D65)");
    EXPECT_EQ(a["colour_conversion"].get<std::string>().rfind("none", 0), 0u);
    EXPECT_EQ(b["chromaticities"]["red"], nlohmann::json({0.708, 0.292}));
    EXPECT_EQ(b["chromaticities"]["green"], nlohmann::json({0.17, 0.797}));
    EXPECT_EQ(b["chromaticities"]["blue"], nlohmann::json({0.131, 0.046}));
    EXPECT_EQ(b["colour_conversion"], "to Rec. 709 / D65");
    // Same white: a white map stays white (to float precision).
    EXPECT_NEAR(b["mean_radiance_luminance"][0].get<double>(), 1.0, 1e-5);
}

}  // namespace
}  // namespace zhc
