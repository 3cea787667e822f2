// Environment maps: projection of the real sample maps against slow references, irradiance against
// direct integration, and every error path of reading a map (library and `zhc project`).
#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>

#include "formats/io/file_io.h"
#include "support.h"

namespace zhc {
namespace {

namespace fs = std::filesystem;

double rel_diff(double a, double b, double scale) { return std::fabs(a - b) / scale; }

TEST(RealMaps, FastProjectionMatchesBruteForceReference) {
    for (const std::string& path : test::envmap_paths()) {
        SCOPED_TRACE(path);
        const Image img = test::load_envmap(path);
        ASSERT_EQ(img.width, 1024);
        // Reference: 2x2 sub-sampled midpoint quadrature of every pixel (independent of the
        // separable closed-form integrals of the fast path).
        const Sh3Radiance ref = test::project_latlong_reference(img, 2);
        const Sh3Radiance fast = project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u, 2);
        for (int k = 0; k < 3; ++k) {
            const double dc = ref[0][k];
            ASSERT_GT(dc, 0.0);
            EXPECT_LT(rel_diff(fast[0][k], ref[0][k], dc), 1e-5);
            for (int l = 1; l < 3; ++l)
                EXPECT_LT(rel_diff(band_norm(fast, l)[k], band_norm(ref, l)[k], band_norm(ref, l)[k]), 1e-4)
                    << "band " << l;
            for (int i = 1; i < 9; ++i) EXPECT_LT(rel_diff(fast[i][k], ref[i][k], dc), 2e-5) << "coefficient " << i;
        }
    }
}

// max over t in [-1, 1] of |k(t) - k3(t)|, k the normalised clamped cosine max(0, t)/pi and k3
// its truncation to bands 0..2: the worst-case irradiance error per unit of integrated |radiance|.
double sh3_kernel_truncation_max() {
    double worst = 0;
    for (int i = 0; i <= 20000; ++i) {
        const double t = -1.0 + 2.0 * i / 20000;
        const double k = std::max(0.0, t) / kPi;
        const double k3 = (1.0 + 3.0 * (2.0 / 3.0) * t + 5.0 * 0.25 * 0.5 * (3 * t * t - 1)) / (4 * kPi);
        worst = std::max(worst, std::fabs(k - k3));
    }
    return worst;
}

TEST(RealMaps, Sh3IrradianceAgreesWithDirectIntegrationWithinTruncationBound) {
    const double kmax = sh3_kernel_truncation_max();
    EXPECT_GT(kmax, 0.01);  // sanity: the bound is not vacuous-zero
    for (const std::string& path : test::envmap_paths()) {
        SCOPED_TRACE(path);
        const Image full = test::load_envmap(path);
        const Image img = test::downsample_latlong(full, 4);  // 256 x 128, flux preserved
        const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u);
        double abs_flux[3] = {};
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                for (int k = 0; k < 3; ++k)
                    abs_flux[k] += std::fabs(img.row(y)[x * 3 + k]) * latlong_pixel_solid_angle(y, img.width, img.height);
        double sq3 = 0, sq2 = 0, mean = 0;
        const auto dirs = test::fibonacci_directions(256);
        const Sh2Radiance sh2 = truncate_to_sh2(sh);
        for (const Vec3 n : dirs) {
            const Rgb exact = test::integrate_irradiance(img, n), approx = irradiance(sh, n), lin = irradiance(sh2, n);
            for (int k = 0; k < 3; ++k) {
                // Rigorous: |E - E3| <= max|k - k3| * integral |L| (plus float rounding).
                EXPECT_LE(std::fabs(exact[k] - approx[k]), kmax * abs_flux[k] * 1.0001 + 1e-4);
                sq3 += (exact[k] - approx[k]) * (exact[k] - approx[k]);
                sq2 += (exact[k] - lin[k]) * (exact[k] - lin[k]);
                mean += exact[k];
            }
        }
        // Orthogonality: the SH3 truncation's squared error over the sphere is the energy of bands
        // >= 3, SH2's is that plus band 2, so uniform-direction RMSE must order SH3 <= SH2.
        const double rel3 = std::sqrt(sq3 / (3 * dirs.size())) / (mean / (3 * dirs.size()));
        const double rel2 = std::sqrt(sq2 / (3 * dirs.size())) / (mean / (3 * dirs.size()));
        EXPECT_LT(rel3, rel2);
        std::printf("%-10s SH3 irradiance relative RMSE %.4f (SH2 %.4f)\n", test::envmap_name(path).c_str(), rel3, rel2);
    }
}

TEST(RealMaps, HdrInputProjectsLikeItsPixels) {
    // Round-trip each map through .hdr (RGBE) and check that the .hdr path projects its own
    // decoded pixels correctly and stays close to the EXR projection (RGBE keeps 8 mantissa bits).
    const std::string dir = test::temp_dir("hdr_maps");
    for (const std::string& path : test::envmap_paths()) {
        SCOPED_TRACE(path);
        Image img = test::load_envmap(path);
        for (float& v : img.rgb) v = std::max(v, 0.0f);  // RGBE cannot store negatives
        const std::string hdr = dir + "/" + test::envmap_name(path) + ".hdr";
        ASSERT_TRUE(write_hdr(hdr, img));
        auto back = read_envmap(hdr);
        ASSERT_TRUE(back) << back.error().message;
        EXPECT_EQ(back->width, img.width);
        const Sh3Radiance a = project_latlong(back->rgb.data(), back->width, back->height, back->width * 3u);
        const Sh3Radiance ref = test::project_latlong_reference(*back, 1);
        const Sh3Radiance exr = project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u);
        for (int k = 0; k < 3; ++k) {
            EXPECT_LT(rel_diff(a[0][k], ref[0][k], ref[0][k]), 1e-4);
            EXPECT_LT(rel_diff(a[0][k], exr[0][k], exr[0][k]), 1e-2);
            for (int l = 1; l < 3; ++l) EXPECT_LT(rel_diff(band_norm(a, l)[k], band_norm(ref, l)[k], ref[0][k]), 1e-4);
        }
    }
}

TEST(Envmap, ExrWriteReadRoundTripIsExactAndOrientationIsOpenExrLatLong) {
    // A map bright only near +Z (top rows) must project with positive L10; near +X (centre
    // column) with negative L11 (Y11 = -sqrt(3/4pi) x).
    const Image top = test::render_latlong(64, 32, [](Vec3 d) { return d.z > 0.9 ? Rgb{1, 1, 1} : Rgb{}; });
    const std::string dir = test::temp_dir("exr_rt");
    ASSERT_TRUE(write_exr(dir + "/top.exr", top));
    auto back = read_envmap(dir + "/top.exr");
    ASSERT_TRUE(back);
    EXPECT_EQ(back->rgb, top.rgb);
    EXPECT_GT(back->row(0)[0], 0.5f);                   // row 0 is the top (+Z)
    const Image centre = test::render_latlong(64, 32, [](Vec3 d) { return d.x > 0.9 ? Rgb{1, 1, 1} : Rgb{}; });
    EXPECT_GT(centre.row(16)[32 * 3], 0.5f);             // centre column looks along +X
    const Image left = test::render_latlong(64, 32, [](Vec3 d) { return d.y > 0.9 ? Rgb{1, 1, 1} : Rgb{}; });
    EXPECT_GT(left.row(16)[16 * 3], 0.5f);               // longitude decreases to the right: +Y at u = 1/4
    const Sh3Radiance s = project_latlong(centre.rgb.data(), 64, 32, 64 * 3);
    EXPECT_LT(s[3].r, 0.0f);
}

TEST(Envmap, AcceptsAnyAspectRatioAndYOnlyFiles) {
    const Image odd = test::render_latlong(37, 29, [](Vec3 d) { return Rgb{float(d.z + 2), 1, 1}; });
    const std::string dir = test::temp_dir("odd");
    ASSERT_TRUE(write_exr(dir + "/odd.exr", odd));
    auto back = read_envmap(dir + "/odd.exr");
    ASSERT_TRUE(back);
    EXPECT_EQ(back->width, 37);
    EXPECT_EQ(back->height, 29);
}

// ---- error paths -----------------------------------------------------------------------------

struct BadFileCase {
    std::string name;
    std::vector<std::uint8_t> bytes;
    ErrorCode code;
};

std::vector<std::uint8_t> small_exr_bytes(const Image& img, const std::string& dir, const std::string& name) {
    const std::string p = dir + "/" + name;
    EXPECT_TRUE(write_exr(p, img));
    return test::read_bytes(p);
}

std::vector<BadFileCase> bad_files() {
    const std::string dir = test::temp_dir("bad_inputs");
    std::vector<BadFileCase> cases;
    const Image good = test::render_latlong(32, 16, [](Vec3 d) { return Rgb{float(d.z + 1), 1, 1}; });
    const auto exr = small_exr_bytes(good, dir, "good.exr");
    cases.push_back({"empty", {}, ErrorCode::kTruncated});
    const std::string text = "hello, this is not an image\n";
    cases.push_back({"text", {text.begin(), text.end()}, ErrorCode::kBadFormat});
    cases.push_back({"exr_magic_only", {exr.begin(), exr.begin() + 4}, ErrorCode::kTruncated});
    for (size_t cut : {size_t(10), exr.size() / 3, exr.size() / 2, exr.size() - 3})
        cases.push_back({"exr_truncated_" + std::to_string(cut), {exr.begin(), exr.begin() + static_cast<long>(cut)},
                         ErrorCode::kTruncated});
    Image nan = good;
    nan.row(3)[5 * 3 + 1] = std::nanf("");
    cases.push_back({"exr_nan", small_exr_bytes(nan, dir, "nan.exr"), ErrorCode::kInvalidValue});
    Image inf = good;
    inf.row(0)[0] = std::numeric_limits<float>::infinity();
    cases.push_back({"exr_inf", small_exr_bytes(inf, dir, "inf.exr"), ErrorCode::kInvalidValue});
    // An EXR whose dataWindow claims 100000 x 100000 pixels.
    {
        auto huge = exr;
        const char key[] = "dataWindow\0box2i";
        auto it = std::search(huge.begin(), huge.end(), key, key + sizeof key);
        EXPECT_NE(it, huge.end());
        const size_t at = static_cast<size_t>(it - huge.begin()) + sizeof key + 4;  // skip size field
        const std::int32_t big = 99999;
        std::memcpy(&huge[at + 8], &big, 4);
        std::memcpy(&huge[at + 12], &big, 4);
        cases.push_back({"exr_huge_window", huge, ErrorCode::kTooLarge});
    }
    // Declared attribute sizes that disagree with the value's own length (OpenEXR's typed readers
    // ignore the declared size, so it would continue parsing from the wrong byte; a fuzzer turned
    // that into a 1.7 GB allocation from a 263-byte file).
    auto patch_size = [&](const char* key, size_t key_len, std::int32_t delta) {
        auto bytes = exr;
        auto it = std::search(bytes.begin(), bytes.end(), key, key + key_len);
        EXPECT_NE(it, bytes.end());
        const size_t at = static_cast<size_t>(it - bytes.begin()) + key_len;
        std::int32_t size;
        std::memcpy(&size, &bytes[at], 4);
        size += delta;
        std::memcpy(&bytes[at], &size, 4);
        return bytes;
    };
    {
        const char chlist[] = "channels\0chlist";
        cases.push_back({"exr_chlist_size_short", patch_size(chlist, sizeof chlist, -1), ErrorCode::kBadFormat});
        const char aspect[] = "pixelAspectRatio\0float";
        cases.push_back({"exr_float_size_long", patch_size(aspect, sizeof aspect, 4), ErrorCode::kBadFormat});
    }
    {
        // An idmanifest attribute: OpenEXR 3.1 reads 4 bytes past its declared end (a fuzzer turned
        // that into a 1.9 GB allocation), so zhc refuses the type.
        auto with_manifest = exr;
        const char attr[] = "manifest\0idmanifest\0\x08\0\0\0\0\0\0\0\0\0\0\0";
        with_manifest.insert(with_manifest.begin() + 8, attr, attr + sizeof attr - 1);
        cases.push_back({"exr_idmanifest", with_manifest, ErrorCode::kUnsupported});
        // Self-delimiting values that disagree with their declared size.
        auto with_attribute = [&](const std::string& bytes) {
            auto out = exr;
            out.insert(out.begin() + 8, bytes.begin(), bytes.end());
            return out;
        };
        using namespace std::string_literals;
        // preview: 2 x 2 RGBA needs 8 + 16 bytes, 12 declared
        cases.push_back({"exr_preview_size", with_attribute("thumb\0preview\0\x0c\0\0\0\x02\0\0\0\x02\0\0\0\0\0\0\0"s),
                         ErrorCode::kBadFormat});
        // stringvector: an entry of 100 bytes in an 8-byte value
        cases.push_back({"exr_stringvector_entry", with_attribute("names\0stringvector\0\x08\0\0\0\x64\0\0\0abcd"s),
                         ErrorCode::kBadFormat});
        // floatvector: 6 bytes is not a whole number of floats
        cases.push_back({"exr_floatvector_size", with_attribute("weights\0floatvector\0\x06\0\0\0\0\0\0\0\0\0"s),
                         ErrorCode::kBadFormat});
    }
    const std::string hdr_huge = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n";
    cases.push_back({"hdr_huge", {hdr_huge.begin(), hdr_huge.end()}, ErrorCode::kTooLarge});
    {
        EXPECT_TRUE(write_hdr(dir + "/good.hdr", good));
        const auto hdr = test::read_bytes(dir + "/good.hdr");
        for (size_t cut : {hdr.size() / 2, hdr.size() - 1})
            cases.push_back({"hdr_truncated_" + std::to_string(cut), {hdr.begin(), hdr.begin() + static_cast<long>(cut)},
                             ErrorCode::kTruncated});
        const std::string garbage = "#?RADIANCE\nFORMAT=banana\n\n-Y 4 +X 4\n";
        cases.push_back({"hdr_bad_header", {garbage.begin(), garbage.end()}, ErrorCode::kBadFormat});
    }
    return cases;
}

// Each error code's exit code, one line on stderr and no output: tests/conformance (exr_*, hdr_*).
TEST(EnvmapErrors, EveryBadFileGivesItsErrorCodeWithOneLine) {
    const std::string dir = test::temp_dir("bad_inputs");
    for (const BadFileCase& c : bad_files()) {
        SCOPED_TRACE(c.name);
        const std::string path = dir + "/" + c.name + ".bin";
        test::write_bytes(path, c.bytes);
        auto r = read_envmap(path);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, c.code) << r.error().message;
        EXPECT_NE(r.error().message.find(path), std::string::npos) << "message names the file";
        EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << "one line";
    }
}

TEST(EnvmapErrors, MissingFileAndDirectoryAreUnreadable) {
    const std::string dir = test::temp_dir("missing");
    for (const std::string& p : {dir + "/does_not_exist.exr", dir}) {
        auto r = read_envmap(p);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kIoError);  // exit 3: conformance exr_missing, exr_directory
    }
}

TEST(EnvmapErrors, NonFiniteValuesCanBeReplacedOnRequest) {
    const std::string dir = test::temp_dir("nan_replace");
    Image nan = test::render_latlong(16, 8, [](Vec3) { return Rgb{1, 1, 1}; });
    nan.row(2)[3] = std::nanf("");
    ASSERT_TRUE(write_exr(dir + "/nan.exr", nan));
    EnvmapReadOptions o;
    o.non_finite = NonFinitePolicy::kReplaceZero;
    EnvmapInfo info;
    auto r = read_envmap(dir + "/nan.exr", o, &info);
    ASSERT_TRUE(r);
    EXPECT_EQ(info.replaced_non_finite, 1u);
    EXPECT_EQ(r->row(2)[3], 0.0f);  // the CLI: conformance ok_project_nan_replaced
}

TEST(EnvmapErrors, PixelLimitIsCheckedBeforeAllocating) {
    const std::string dir = test::temp_dir("limit");
    const Image img = test::render_latlong(64, 32, [](Vec3) { return Rgb{1, 1, 1}; });
    ASSERT_TRUE(write_exr(dir + "/m.exr", img));
    EnvmapReadOptions o;
    o.max_pixels = 64 * 32 - 1;
    auto r = read_envmap(dir + "/m.exr", o);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kTooLarge);
}

TEST(Cli, ProjectJsonHasNineRgbRowsMatchingTheLibrary) {
    const std::string path = test::envmap_paths()[0];
    const auto run = test::run_zhc({"project", path, "--json"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    ASSERT_EQ(j["sh3"].size(), 9u);
    const Image img = test::load_envmap(path);
    const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(j["sh3"][i][k].get<float>(), sh[i][k]);
}

TEST(Cli, DemoRunsThePipelineAndListsItsOutputs) {
    const std::string dir = test::temp_dir("demo_out");
    auto d = test::run_zhc({"demo", "-o", dir});
    EXPECT_EQ(d.exit_code, 0) << d.err;
    for (const char* f : {"probes_sh3.zhp", "probes_zh3_q16.zhp", "probes.glb", "audit.md", "scene.json"}) {
        EXPECT_NE(d.out.find(f), std::string::npos) << f;
        EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
    }
}

}  // namespace
}  // namespace zhc
