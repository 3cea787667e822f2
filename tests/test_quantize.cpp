// Ratio-bound quantisation (codec/probe/quantize.h): bounds re-derived numerically, DC formats against
// brute-force nearest search, the scalar quantiser's error bound, the packed layouts' bit
// positions and golden bytes, totality and determinism. The acceptance tables on the eight real
// maps are in test_quantize_real_maps.cpp (helper: quantize_helpers.h).
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "codec/probe/codec.h"
#include "codec/probe/quantize.h"
#include "codec/probe/zh3.h"
#include "quantize_helpers.h"
#include "support.h"

namespace zhc {
namespace {

using namespace quantize_test;

// ---- bounds ---------------------------------------------------------------------------------

TEST(QuantBounds, IntervalsAreTheExtremesOfDeltaProjectionRatiosOverDenseDirections) {
    // Slow twin of App. A / Wiederien & Sloan Sec. 3.1: the projection of a delta at w has
    // c_i / c_0 = Y_i(w) / Y_0; the extremes over w are the intervals.
    const auto dirs = fibonacci_directions(400000);
    double lo[9], hi[9];
    std::fill(lo, lo + 9, 1e9);
    std::fill(hi, hi + 9, -1e9);
    for (const Vec3 d : dirs) {
        const auto y = sh3_basis(d);
        for (int i = 1; i < 9; ++i) {
            lo[i] = std::min(lo[i], y[i] / y[0]);
            hi[i] = std::max(hi[i], y[i] / y[0]);
        }
    }
    std::printf("\nratio extremes over 400k directions vs the tight intervals\n");
    for (int i = 1; i < 9; ++i) {
        const RatioInterval iv = ratio_interval(i, StoredKind::kRadiance, L2Bound::kTight);
        std::printf("  c%d/c0: [%9.6f, %9.6f]  interval [%9.6f, %9.6f]\n", i, lo[i], hi[i], iv.lo, iv.hi);
        EXPECT_NEAR(lo[i], iv.lo, 1e-4) << i;
        EXPECT_NEAR(hi[i], iv.hi, 1e-4) << i;
        EXPECT_GE(lo[i], iv.lo - 1e-12);  // the numeric extremes never leave the interval
        EXPECT_LE(hi[i], iv.hi + 1e-12);
    }
    // The loose non-zonal bound sqrt(5) is NOT reached (that is the point of the tight one).
    for (int i : {4, 5, 7, 8}) {
        EXPECT_EQ(ratio_interval(i, StoredKind::kRadiance, L2Bound::kLoose).hi, std::sqrt(5.0));
        EXPECT_LT(hi[i], std::sqrt(5.0) - 0.29);
    }
    // Irradiance intervals are the radiance ones times the band scales 2/3 and 1/4 (App. A.1).
    for (int i = 1; i < 9; ++i) {
        const double s = i < 4 ? 2.0 / 3.0 : 1.0 / 4.0;
        const RatioInterval r = ratio_interval(i, StoredKind::kRadiance, L2Bound::kTight);
        const RatioInterval e = ratio_interval(i, StoredKind::kIrradiance, L2Bound::kTight);
        EXPECT_DOUBLE_EQ(e.lo, r.lo * s);
        EXPECT_DOUBLE_EQ(e.hi, r.hi * s);
    }
}

TEST(QuantBounds, RandomNonNegativeFunctionsStayInsideAndZh3ZonalObeysTheZonalBound) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int trial = 0; trial < 300; ++trial) {
        // A positive mix of deltas and cones: a non-negative function.
        Sh3Radiance sh;
        const int n = 1 + trial % 5;
        for (int j = 0; j < n; ++j) {
            const Vec3 a = test::uniform_direction(u(rng), u(rng));
            const Rgb c{float(u(rng)), float(u(rng)), float(u(rng))};
            sh = sh + (j % 2 ? project_cone(a, 0.05 + u(rng), c) : project_directional(a, c));
        }
        for (int k = 0; k < 3; ++k)
            for (int i = 1; i < 9; ++i) {
                const RatioInterval iv = ratio_interval(i, StoredKind::kRadiance, L2Bound::kTight);
                const double r = sh[i][k] / sh[0][k];
                EXPECT_GE(r, iv.lo - 1e-5);
                EXPECT_LE(r, iv.hi + 1e-5);
            }
        // The ZH3 zonal coefficient is an m = 0 coefficient in its axis frame: zonal interval.
        const Zh3 z = zh3_fit(sh, ZonalAxisMode::kLuminance, {});
        for (int k = 0; k < 3; ++k) {
            const RatioInterval iv = zonal_l2_interval(StoredKind::kRadiance);
            EXPECT_GE(z.zonal[k] / sh[0][k], iv.lo - 1e-5);
            EXPECT_LE(z.zonal[k] / sh[0][k], iv.hi + 1e-5);
        }
    }
}

// ---- DC formats -------------------------------------------------------------------------------

// Slow twin: the nearest decodable value by scanning every code (ties: the even code).
template <class Decode>
std::uint32_t nearest_code(double v, std::uint32_t codes, Decode decode) {
    std::uint32_t best = 0;
    double best_err = INFINITY;
    for (std::uint32_t c = 0; c < codes; ++c) {
        const double d = decode(c);
        if (!std::isfinite(d)) continue;
        const double e = std::fabs(d - v);
        if (e < best_err || (e == best_err && (c % 2 == 0))) best = c, best_err = e;
    }
    return best;
}

TEST(DcFormats, R11G11B10FIsRoundToNearestEvenAgainstExhaustiveSearch) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> e(-20, 17);
    for (int trial = 0; trial < 400; ++trial) {
        const double v = std::exp2(e(rng));
        const std::uint32_t packed = pack_r11g11b10f(v, v, v);
        const std::uint32_t r = packed & 0x7FF, g = (packed >> 11) & 0x7FF, b = packed >> 22;
        auto dec11 = [](std::uint32_t c) { return static_cast<double>(unpack_r11g11b10f(c).r); };
        auto dec10 = [](std::uint32_t c) { return static_cast<double>(unpack_r11g11b10f(c << 22).b); };
        if (v <= 65024.0) { EXPECT_EQ(r, nearest_code(v, 2048, dec11)) << v; }
        if (v <= 64512.0) { EXPECT_EQ(b, nearest_code(v, 1024, dec10)) << v; }
        EXPECT_EQ(r, g);
    }
    // Bit positions (DXGI): 1.0 is exponent 15, mantissa 0 in each field.
    EXPECT_EQ(pack_r11g11b10f(1, 1, 1), (0x3C0u) | (0x3C0u << 11) | (0x1E0u << 22));
    EXPECT_EQ(pack_r11g11b10f(1, 0, 0), 0x3C0u);
    EXPECT_EQ(pack_r11g11b10f(0, 0, 2), 0x200u << 22);  // 2.0: exponent 16 -> 16 << 5
    // Negative and NaN store 0; overflow stores the largest finite (never Inf).
    EXPECT_EQ(pack_r11g11b10f(-1, NAN, -0.0), 0u);
    const Rgb big = unpack_r11g11b10f(pack_r11g11b10f(1e30, INFINITY, 1e9));
    EXPECT_EQ(big.r, 65024.0f);
    EXPECT_EQ(big.g, 65024.0f);
    EXPECT_EQ(big.b, 64512.0f);
    // Relative error of normal values: half an ulp, 2^-7 (R, G) and 2^-6 (B).
    for (double v = 1e-4; v < 6e4; v *= 1.37) {
        const Rgb d = unpack_r11g11b10f(pack_r11g11b10f(v, v, v));
        EXPECT_LE(std::fabs(d.r - v), v * std::exp2(-7) * (1 + 1e-12));
        EXPECT_LE(std::fabs(d.b - v), v * std::exp2(-6) * (1 + 1e-12));
    }
}

TEST(DcFormats, HalfIsRoundToNearestEvenAgainstExhaustiveSearch) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> e(-26, 15.9);
    for (int trial = 0; trial < 200; ++trial) {
        const double v = (trial % 2 ? -1 : 1) * std::exp2(e(rng));
        const std::uint16_t h = pack_half(v);
        const auto want = nearest_code(v, 65536, [](std::uint32_t c) { return double(unpack_half(std::uint16_t(c))); });
        // +0 and -0 are equally near; the packer emits +0.
        if (unpack_half(static_cast<std::uint16_t>(want)) == 0.0f) EXPECT_EQ(unpack_half(h), 0.0f);
        else EXPECT_EQ(h, want) << v;
    }
    EXPECT_EQ(pack_half(1.0), 0x3C00);
    EXPECT_EQ(pack_half(-2.0), 0xC000);
    EXPECT_EQ(pack_half(1e9), 0x7BFF);
    EXPECT_EQ(pack_half(NAN), 0);
}

TEST(DcFormats, Rgb9e5FollowsTheSharedExponentSpec) {
    EXPECT_EQ(pack_rgb9e5(1, 1, 1), (256u) | (256u << 9) | (256u << 18) | (16u << 27));
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> e(-12, 15.9), u(0, 1);
    for (int trial = 0; trial < 2000; ++trial) {
        const double m = std::exp2(e(rng));
        const double c[3] = {m, m * u(rng), m * u(rng) * u(rng)};
        const Rgb d = unpack_rgb9e5(pack_rgb9e5(c[0], c[1], c[2]));
        // Each channel within half a step of the shared exponent, the step <= 2^-8 of the max.
        for (int k = 0; k < 3; ++k) EXPECT_LE(std::fabs(d[k] - c[k]), m * std::exp2(-9) * (1 + 1e-9)) << m;
    }
    for (std::uint32_t bits : {0u, 0xFFFFFFFFu, 0x12345678u}) {
        const Rgb d = unpack_rgb9e5(bits);
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(d[k]));
    }
}

// ---- scalar quantiser -------------------------------------------------------------------------



TEST(QuantScalar, EveryCodeRoundTripsAndErrorIsWithinHalfAStep) {
    std::mt19937 rng(2);
    for (int bits : {2, 4, 6, 8})
        for (bool sq : {false, true})
            for (ZonalMapping zm : {ZonalMapping::kAffine, ZonalMapping::kZeroPreserving, ZonalMapping::kSymmetric})
                for (int i = 1; i < 9; ++i) {
                    CodecOptions p;
                    p.bits = bits;
                    p.sqrt_encoding = sq;
                    p.zonal_mapping = zm;
                    const RatioCoder c = ratio_coder(i, p);
                    const int bv = quant_half_range(bits);
                    // (The symmetric zonal mapping has codes below the interval, never produced.)
                    for (int code = 0; code <= 2 * bv; ++code)
                        if (c.decode(static_cast<std::uint8_t>(code)) >= c.interval.lo) {
                            EXPECT_EQ(c.encode(c.decode(static_cast<std::uint8_t>(code)), nullptr), code);
                        }
                    EXPECT_DOUBLE_EQ(c.decode(255), c.decode(static_cast<std::uint8_t>(2 * bv)));  // total
                    std::uniform_real_distribution<double> r(c.interval.lo, c.interval.hi);
                    for (int trial = 0; trial < 200; ++trial) {
                        const double x = r(rng);
                        bool clamped = true;
                        const double y = c.decode(c.encode(x, &clamped));
                        EXPECT_FALSE(clamped);
                        EXPECT_LE(std::fabs(y - x), max_ratio_error(c, x)) << bits << sq << i << " " << x;
                    }
                    // Endpoints are exact; zero is exact when the mapping keeps it at t = 0.
                    if (!c.zonal || zm != ZonalMapping::kSymmetric) {
                        EXPECT_NEAR(c.decode(c.encode(c.interval.lo, nullptr)), c.interval.lo, 1e-12);
                    }
                    EXPECT_NEAR(c.decode(c.encode(c.interval.hi, nullptr)), c.interval.hi, 1e-12);
                    if (i != 6 || zm != ZonalMapping::kAffine) { EXPECT_EQ(c.decode(c.encode(0.0, nullptr)), 0.0); }
                }
}

TEST(QuantScalar, OutOfRangeAndNonFiniteRatiosAreClampedAndCounted) {
    CodecOptions p;
    const RatioCoder c = ratio_coder(1, p);
    bool clamped = false;
    EXPECT_EQ(c.decode(c.encode(5.0, &clamped)), std::sqrt(3.0));
    EXPECT_TRUE(clamped);
    EXPECT_EQ(c.decode(c.encode(-INFINITY, &clamped)), -std::sqrt(3.0));
    EXPECT_TRUE(clamped);
    EXPECT_EQ(c.decode(c.encode(NAN, &clamped)), 0.0);
    EXPECT_TRUE(clamped);
    c.encode(1.0, &clamped);
    EXPECT_FALSE(clamped);
}

// ---- packed layouts ---------------------------------------------------------------------------

// A probe with hand-picked ratios (DC 2 per channel so the DC is exact in every format).
Sh3Radiance probe_with_ratios(const double ratios[9]) {
    Sh3Radiance sh;
    for (int k = 0; k < 3; ++k) {
        sh[0][k] = 2.0f;
        for (int i = 1; i < 9; ++i) sh[i][k] = static_cast<float>(2.0 * ratios[i] * (1.0 - 0.25 * k));
    }
    return sh;
}

TEST(PackedLayouts, BytesAreWhereTheSpecSaysSh3Q28) {
    const double ratios[9] = {0, std::sqrt(3.0), 0, -std::sqrt(3.0), std::sqrt(15.0) / 2, 0, std::sqrt(5.0), -std::sqrt(15.0) / 2, 0};
    std::uint8_t b[28];
    encode_packed(PackedLayout::kSh3Q28, probe_with_ratios(ratios), {}, b, nullptr);
    EXPECT_EQ(b[0] | (b[1] << 8) | (b[2] << 16) | (std::uint32_t(b[3]) << 24), pack_r11g11b10f(2, 2, 2));
    // Channel 0 (red), ratios at full scale: codes 254 (=+1), 127 (0), 0 (-1). Affine zonal: hi -> 254.
    const std::uint8_t red[8] = {254, 127, 0, 254, 127, 254, 0, 127};
    for (int i = 0; i < 8; ++i) EXPECT_EQ(b[4 + i], red[i]) << i;
    // Green is 3/4 of red: +-sqrt(3) * 0.75 -> 127 +- round(0.75 * 127) = 127 +- 95.
    EXPECT_EQ(b[12 + 0], 127 + 95);
    EXPECT_EQ(b[12 + 2], 127 - 95);
}

TEST(PackedLayouts, BytesAreWhereTheSpecSaysZh3Q16AndSh2Q) {
    // A zonal probe along +Z (axis from L1 = +Z): L1 index 2 (Y10) and L2 index 6 (Y20) only.
    double ratios[9] = {0, 0, 1.0, 0, 0, 0, 1.0, 0, 0};
    std::uint8_t z[16], s[16];
    encode_packed(PackedLayout::kZh3Q16, probe_with_ratios(ratios), {}, z, nullptr);
    encode_packed(PackedLayout::kSh2Q, probe_with_ratios(ratios), {}, s, nullptr);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(z[4 + 4 * k + 0], 127);
        EXPECT_EQ(z[4 + 4 * k + 2], 127);
        const double r = 1.0 - 0.25 * k;
        EXPECT_EQ(z[4 + 4 * k + 1], 127 + std::lround(r / std::sqrt(3.0) * 127));
        // Zonal affine: t = (2 r - sqrt(5)/2) / (3 sqrt(5)/2).
        EXPECT_EQ(z[4 + 4 * k + 3], std::lround(127 + 127 * (2 * r - std::sqrt(5.0) / 2) / (1.5 * std::sqrt(5.0))));
        // sh2_q: 6-byte DC slot (4 bytes + 2 zero), then 3 bytes per channel, byte 15 zero.
        for (int j = 0; j < 3; ++j) EXPECT_EQ(s[6 + 3 * k + j], z[4 + 4 * k + j]);
    }
    EXPECT_EQ(s[4], 0);
    EXPECT_EQ(s[5], 0);
    EXPECT_EQ(s[15], 0);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(s[i], z[i]);
    // The zonal probe decodes to itself within the 8-bit steps.
    const Sh3Radiance d = decode_packed(PackedLayout::kZh3Q16, z, {});
    const Sh3Radiance want = probe_with_ratios(ratios);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(d[i][k], want[i][k], 2.0 * 1.5 * std::sqrt(5.0) / 254 + 1e-6) << i;
}

TEST(PackedLayouts, HalfDcOnlyInSh2QAndEveryCodecEntryIsPresent) {
    CodecOptions p;
    p.dc_format = DcFormat::kHalf;
    EXPECT_TRUE(validate_quant_params(p, "sh2_q").ok());
    EXPECT_FALSE(validate_quant_params(p, "zh3_q16").ok());
    EXPECT_FALSE(validate_quant_params(p, "sh3_q28").ok());
    p.dc_format = DcFormat::kR11G11B10F;
    p.bits = 9;
    EXPECT_FALSE(validate_quant_params(p, "sh3_q28").ok());
    for (auto [name, size] :
         {std::pair{"zh3_q16", 16}, {"zh3_solved_q16", 16}, {"sh3_q28", 28}, {"sh2_q", 16}, {"hall_curve_q", 16}}) {
        const Codec* c = find_codec(name);
        ASSERT_NE(c, nullptr) << name;
        EXPECT_EQ(c->size_bytes, static_cast<size_t>(size));
    }
    // Half DC in sh2_q keeps a negative DC and more mantissa.
    Sh3Radiance sh;
    sh[0] = {-1.5f, 3.001953125f, 0.125f};  // 3 + 2^-9: one half ulp at [2, 4)
    p.dc_format = DcFormat::kHalf;
    std::uint8_t b[16];
    encode_packed(PackedLayout::kSh2Q, sh, p, b, nullptr);
    const Sh3Radiance d = decode_packed(PackedLayout::kSh2Q, b, p);
    EXPECT_EQ(d[0].r, -1.5f);
    EXPECT_EQ(d[0].g, 3.001953125f);
    EXPECT_EQ(d[0].b, 0.125f);
}

TEST(PackedLayouts, ZonalRefitAfterL1QuantisationUsesTheDecodersAxis) {
    // The decoded L2 band is exactly zonal about the axis derived from the decoded L1.
    const auto maps = test::envmap_paths();
    const Image img = test::load_envmap(maps[0]);
    const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3);
    std::uint8_t b[16];
    encode_packed(PackedLayout::kZh3Q16, sh, {}, b, nullptr);
    const Sh3Radiance d = decode_packed(PackedLayout::kZh3Q16, b, {});
    const Vec3 axis = zh3_axis(truncate_to_sh2(d), ZonalAxisMode::kLuminance, 0, {});
    const auto y = sh3_basis(axis);
    for (int k = 0; k < 3; ++k) {
        const double f20 = d[6][k] / (std::sqrt(4 * kPi / 5) * y[6]);
        for (int m = 4; m < 9; ++m) EXPECT_NEAR(d[m][k], f20 * std::sqrt(4 * kPi / 5) * y[m], 1e-5);
    }
    // Bytes from the codec table entry equal encode_packed's.
    std::uint8_t t[16];
    find_codec("zh3_q16")->encode(sh, {}, t, nullptr);
    EXPECT_EQ(0, std::memcmp(b, t, 16));
}

TEST(PackedLayouts, DegenerateInputGivesFiniteOutputAndCountsClamps) {
    for (PackedLayout L : {PackedLayout::kZh3Q16, PackedLayout::kSh3Q28, PackedLayout::kSh2Q}) {
        std::uint8_t b[28];
        // Zero probe: all zero, nothing clamped.
        EncodeStats st;
        encode_packed(L, Sh3Radiance{}, {}, b, &st);
        EXPECT_EQ(st.clamped_ratios, 0);
        Sh3Radiance d = decode_packed(L, b, {});
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) EXPECT_EQ(d[i][k], 0.0f);
        // Negative DC with L1, tiny DC with L1, NaN and Inf coefficients: finite and counted.
        for (float dc : {-1.0f, 1e-30f, 0.0f, NAN, INFINITY}) {
            Sh3Radiance sh;
            for (int k = 0; k < 3; ++k) {
                sh[0][k] = dc;
                sh[1][k] = 0.5f;
                sh[4][k] = NAN;
                sh[6][k] = -INFINITY;
            }
            EncodeStats s2;
            encode_packed(L, sh, {}, b, &s2);
            // (sh2_q stores no L2, and with an infinite DC stored as the largest finite its L1 ratio is fine.)
            if (!(L == PackedLayout::kSh2Q && std::isinf(dc))) {
                EXPECT_GT(s2.clamped_ratios, 0) << dc;
            }
            d = decode_packed(L, b, {});
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(d[i][k])) << dc << " " << i;
        }
    }
}

TEST(PackedLayouts, DecodersAreTotalAndEncodingIsDeterministic) {
    std::mt19937 rng(4);
    for (const Codec& c : quantized_codecs()) {
        std::vector<std::uint8_t> b(c.size_bytes);
        for (int trial = 0; trial < 2000; ++trial) {
            for (auto& x : b) x = static_cast<std::uint8_t>(rng());
            const Sh3Radiance d = c.decode(b.data(), {});  // must not trap (NaN allowed for exp-31 DC)
            (void)c.irradiance(b.data(), {}, {0, 0, 1});
            // Whatever decoded finitely re-encodes without clamping beyond float rounding.
            bool finite = true;
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(d[i][k]);
            if (finite) {
                std::vector<std::uint8_t> again(c.size_bytes), again2(c.size_bytes);
                c.encode(d, {}, again.data(), nullptr);
                c.encode(d, {}, again2.data(), nullptr);
                EXPECT_EQ(again, again2);
            }
        }
    }
}

// ---- golden bytes -----------------------------------------------------------------------------

std::string golden_dir() { return std::string(ZHC_GOLDEN_DIR); }

// Compares with tests/golden/NAME; ZHC_UPDATE_GOLDEN=1 rewrites it instead (docs/quantization.md).
void expect_golden(const std::string& name, const std::vector<std::uint8_t>& bytes) {
    const std::string path = golden_dir() + "/" + name;
    if (const char* u = std::getenv("ZHC_UPDATE_GOLDEN"); u && std::string(u) == "1") {
        std::filesystem::create_directories(golden_dir());
        test::write_bytes(path, bytes);
        std::printf("rewrote %s\n", path.c_str());
        return;
    }
    ASSERT_TRUE(std::filesystem::exists(path)) << path << " missing (run with ZHC_UPDATE_GOLDEN=1)";
    EXPECT_EQ(test::read_bytes(path), bytes) << name << " differs from the committed golden bytes";
}

TEST(PackedLayouts, GoldenBytes) {
    struct Variant {
        const char* suffix;
        CodecOptions params;
    };
    std::vector<Variant> variants;
    variants.push_back({"", CodecOptions{}});
    CodecOptions sq;
    sq.sqrt_encoding = true;
    variants.push_back({"_sqrt", sq});
    CodecOptions loose;
    loose.l2_bound = L2Bound::kLoose;
    loose.dc_format = DcFormat::kRGB9E5;
    loose.bits = 6;
    variants.push_back({"_loose_rgb9e5_6bit", loose});
    CodecOptions irr;
    irr.kind = StoredKind::kIrradiance;
    irr.zonal_mapping = ZonalMapping::kZeroPreserving;
    irr.axis_mode = ZonalAxisMode::kPerChannel;
    variants.push_back({"_irradiance_zero_channel", irr});
    for (const auto& [name, layout] : {std::pair{"zh3_q16", PackedLayout::kZh3Q16}, {"sh3_q28", PackedLayout::kSh3Q28},
                                       {"sh2_q", PackedLayout::kSh2Q}})
        for (const Variant& v : variants) {
            std::vector<std::uint8_t> all;
            for (const Sh3Radiance& sh : test::golden_probes()) {
                std::uint8_t b[28];
                encode_packed(layout, sh, v.params, b, nullptr);
                all.insert(all.end(), b, b + packed_size_bytes(layout));
            }
            expect_golden(std::string(name) + v.suffix + ".bin", all);
        }
}

}  // namespace
}  // namespace zhc
