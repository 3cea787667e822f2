// zh3_channel_q16 and zh3_solved_channel_q16 (codec/probe/zh3_channel_q16.h): the code search against a
// brute-force twin over the stored code grid (decoded by the real decoder), the byte layout by a
// hand decoder written from docs/quantization.md, golden bytes, the container's axis mode not
// applying, scale invariance, determinism, bad input, and the audit ratios to SH2 on the maps.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "codec/probe/codec.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "codec/probe/zh3.h"
#include "codec/probe/zh3_channel_q16.h"
#include "support.h"

namespace zhc {
namespace {

const Codec& fitted() { return *find_codec("zh3_channel_q16"); }
const Codec& solved() { return *find_codec("zh3_solved_channel_q16"); }

struct Rng {
    std::mt19937_64 g;
    explicit Rng(unsigned seed) : g(seed) {}
    double u() { return std::uniform_real_distribution<double>(0, 1)(g); }
    Vec3 dir() {
        const double u1 = u();
        return test::uniform_direction(u1, u());
    }
    Rgb colour() {
        const float r = float(0.1 + u()), gg = float(0.1 + u());
        return {r, gg, float(0.1 + u())};
    }
};

// Several coloured lights from different directions plus a dim ambient: a non-negative lighting.
Sh3Radiance random_lighting(Rng& rng) {
    const float a = float(0.05 * rng.u()), b = float(0.05 * rng.u()), c = float(0.05 * rng.u());
    Sh3Radiance sh = project_constant({a, b, c});
    const int n = 1 + static_cast<int>(rng.u() * 4);
    for (int i = 0; i < n; ++i) {
        const double kind = rng.u();
        const Vec3 d = rng.dir();
        const Rgb col = rng.colour();
        if (kind < 0.4) sh = sh + project_directional(d, col);
        else sh = sh + project_cone(d, 0.05 + 1.5 * rng.u(), col);
    }
    return sh;
}

std::vector<Sh3Radiance> map_probes() {
    std::vector<Sh3Radiance> out;
    for (const auto& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3, 2));
    }
    return out;
}

// Squared L2 norm over the sphere of the irradiance difference of channel k, bands 1 and 2
// (Parseval with the band scales 2/3, 1/4): the error the search minimises, measured on the
// decoder's output.
double channel_error(const Sh3Radiance& decoded, const Sh3Radiance& target, int k) {
    double e = 0;
    for (int i = 1; i < 9; ++i) {
        const double s = i < 4 ? 2.0 / 3.0 : 0.25;
        const double d = (double(decoded[i][k]) - double(target[i][k])) * s;
        e += d * d;
    }
    return e;
}

std::array<std::uint8_t, 16> encode(const Codec& c, const Sh3Radiance& sh, const CodecOptions& p = CodecOptions{}) {
    std::array<std::uint8_t, 16> b{};
    encode_probe(c, p, sh, b.data(), nullptr);
    return b;
}

// Brute force over channel k's stored codes: every L1 code triple within +-r of `centre`'s and every
// zonal code, each decoded by the real decoder. Returns the lowest channel error found.
double brute_force_channel(const std::array<std::uint8_t, 16>& bytes, const std::array<std::uint8_t, 16>& centre,
                           int k, int r, const Sh3Radiance& target, const CodecOptions& p) {
    const int top = 2 * quant_half_range(p.bits);
    std::array<std::uint8_t, 16> b = bytes;
    double best = INFINITY;
    const int o = 4 + 4 * k;
    for (int d0 = -r; d0 <= r; ++d0)
        for (int d1 = -r; d1 <= r; ++d1)
            for (int d2 = -r; d2 <= r; ++d2) {
                const int c0 = centre[size_t(o)] + d0, c1 = centre[size_t(o + 1)] + d1, c2 = centre[size_t(o + 2)] + d2;
                if (std::min({c0, c1, c2}) < 0 || std::max({c0, c1, c2}) > top) continue;
                b[size_t(o)] = std::uint8_t(c0);
                b[size_t(o + 1)] = std::uint8_t(c1);
                b[size_t(o + 2)] = std::uint8_t(c2);
                for (int z = 0; z <= top; ++z) {
                    b[size_t(o + 3)] = std::uint8_t(z);
                    best = std::min(best, channel_error(decode_probe(solved(), p, b.data()), target, k));
                }
            }
    return best;
}

// Slow twin of the search: brute force over the stored code grid around the result and around
// the fitted codes, for the default parameters and a non-default set (5 bits, sqrt, irradiance
// storage, zero-preserving zonal mapping, RGB9E5 DC).
void check_against_brute_force(const CodecOptions& p, int probes_from_maps, int random_probes, int* better,
                               int* channels) {
    Rng rng(5);
    std::vector<Sh3Radiance> probes;
    const auto maps = map_probes();
    for (size_t i = 0; i < maps.size() && int(probes.size()) < probes_from_maps; i += 2) probes.push_back(maps[i]);
    for (int i = 0; i < random_probes; ++i) probes.push_back(random_lighting(rng));
    for (const Sh3Radiance& sh : probes) {
        const auto s = encode(solved(), sh, p);
        const auto f = encode(fitted(), sh, p);
        const Sh3Radiance ds = decode_probe(solved(), p, s.data()), df = decode_probe(fitted(), p, f.data());
        for (int k = 0; k < 3; ++k) {
            const double es = channel_error(ds, sh, k), ef = channel_error(df, sh, k);
            const double around_solution = brute_force_channel(s, s, k, 3, sh, p);
            const double around_fit = brute_force_channel(s, f, k, 2, sh, p);
            const double tol = 1e-6 * es + 1e-12 * double(sh[0][k]) * double(sh[0][k]);
            EXPECT_LE(es, around_solution + tol) << "channel " << k;
            EXPECT_LE(es, around_fit + tol) << "channel " << k;
            EXPECT_LE(es, ef + tol) << "channel " << k;  // never worse than the fitted entry
            *better += es < ef * (1 - 1e-6);
            ++*channels;
        }
    }
}

TEST(Zh3ChannelQ16, SolvedCodesAreTheBestOfABruteForceSearchAroundThemAndAroundTheFit) {
    int better = 0, channels = 0;
    check_against_brute_force(CodecOptions{}, 4, 6, &better, &channels);
    std::printf("defaults: solved better than fitted on %d of %d channels\n", better, channels);
    EXPECT_GT(better, channels / 2);
    CodecOptions other;
    other.bits = 5;
    other.sqrt_encoding = true;
    other.kind = StoredKind::kIrradiance;
    other.zonal_mapping = ZonalMapping::kZeroPreserving;
    other.dc_format = DcFormat::kRGB9E5;
    better = channels = 0;
    check_against_brute_force(other, 2, 8, &better, &channels);
    std::printf("5 bits, sqrt, irradiance: solved better than fitted on %d of %d channels\n", better, channels);
    EXPECT_GT(better, channels / 3);  // measured 16 of 30
}

TEST(Zh3ChannelQ16, SearchErrorIsTheDecodersError) {
    // channel_code_error (ratio units) times DC^2 is the decoder's irradiance error of bands 1-2.
    Rng rng(9);
    for (int t = 0; t < 200; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        const auto b = encode(solved(), sh);
        const Sh3Radiance d = decode_probe(solved(), {}, b.data());
        const Rgb dc = load_dc(b.data(), DcFormat::kR11G11B10F);
        for (int k = 0; k < 3; ++k) {
            ChannelCodeProblem pr;
            pr.w1 = 4.0 / 9.0;
            pr.w2 = 1.0 / 16.0;
            for (int j = 0; j < 3; ++j) pr.t1[size_t(j)] = sh[j + 1][k] / double(dc[k]);
            for (int m = 0; m < 5; ++m) pr.t2[size_t(m)] = sh[4 + m][k] / double(dc[k]);
            std::uint8_t zonal = 0;
            const double e = channel_code_error(pr, CodecOptions{}, {b[size_t(4 + 4 * k)], b[size_t(5 + 4 * k)], b[size_t(6 + 4 * k)]}, &zonal);
            EXPECT_EQ(zonal, b[size_t(7 + 4 * k)]);
            const double measured = channel_error(d, sh, k);
            EXPECT_NEAR(e * double(dc[k]) * double(dc[k]), measured, 1e-5 * measured + 1e-9 * double(dc[k]) * double(dc[k]));
        }
    }
}

// The layout by hand, from docs/quantization.md (8 bits, affine zonal mapping, radiance):
// ratio(code) = (code - 127) / 127 * sqrt(3) for L1; zonal t = (code - 127) / 127,
// r = (t (hi - lo) + hi + lo) / 2 with [lo, hi] = [-sqrt(5)/2, sqrt(5)]; channel k's axis is
// normalize(-L11, -L1-1, L10) of its decoded L1; L2_m = r DC sqrt(4 pi / 5) Y2m(axis).
Sh3Radiance hand_decode(const std::uint8_t* b) {
    const Rgb dc = unpack_r11g11b10f(std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
                                     std::uint32_t(b[3]) << 24);
    Sh3Radiance out;
    const double lo = -std::sqrt(5.0) / 2, hi = std::sqrt(5.0);
    for (int k = 0; k < 3; ++k) {
        out[0][k] = dc[k];
        double l[3];
        for (int j = 0; j < 3; ++j) {
            l[j] = (b[4 + 4 * k + j] - 127.0) / 127.0 * std::sqrt(3.0) * dc[k];
            out[j + 1][k] = float(l[j]);
        }
        const double t = (b[4 + 4 * k + 3] - 127.0) / 127.0;
        const double z = (t * (hi - lo) + hi + lo) / 2 * dc[k];
        const double len = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
        const Vec3 a = len > 0 ? Vec3{-l[2] / len, -l[0] / len, l[1] / len} : Vec3{0, 0, 1};
        const auto y = sh3_basis(a);
        for (int m = 0; m < 5; ++m) out[4 + m][k] = float(z * std::sqrt(4 * kPi / 5) * y[size_t(4 + m)]);
    }
    return out;
}

TEST(Zh3ChannelQ16, BytesDecodeAsTheDocumentedLayout) {
    Rng rng(21);
    for (int t = 0; t < 300; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        for (const Codec* c : {&fitted(), &solved()}) {
            const auto b = encode(*c, sh);
            const Sh3Radiance want = hand_decode(b.data()), got = c->decode(b.data(), {});
            EXPECT_LE(test::max_abs_diff(want, got), 2e-6 * test::max_abs(want)) << c->name;
        }
    }
}

TEST(Zh3ChannelQ16, ContainerAxisModeDoesNotApplyButMattersForZh3Q16) {
    Rng rng(4);
    int differs = 0;
    for (int t = 0; t < 50; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        CodecOptions lum, chan;
        chan.axis_mode = ZonalAxisMode::kPerChannel;
        const auto b = encode(solved(), sh, lum);
        EXPECT_EQ(b, encode(solved(), sh, chan));
        EXPECT_EQ(encode(fitted(), sh, lum), encode(fitted(), sh, chan));
        const Sh3Radiance a = decode_probe(solved(), lum, b.data()), c = decode_probe(solved(), chan, b.data());
        EXPECT_EQ(test::max_abs_diff(a, c), 0.0);
        // The same bytes read as zh3_q16 with the luminance axis are a different probe.
        differs += test::max_abs_diff(a, decode_probe(*find_codec("zh3_q16"), lum, b.data())) > 1e-4 * test::max_abs(a);
    }
    EXPECT_GT(differs, 40);
}

// Golden bytes (tests/golden/zh3_*channel_q16*.bin): the four probes of test_quantize's golden set
// plus a sample map, default params and one non-default set. ZHC_UPDATE_GOLDEN=1 rewrites them.
std::vector<Sh3Radiance> golden_probes() {
    const float p[2][9][3] = {
        {{3.5f, 3.25f, 2.75f}, {0.5f, 0.375f, 0.25f}, {1.25f, 1.0f, 0.75f}, {-0.625f, -0.5f, -0.375f},
         {0.125f, 0.1f, 0.05f}, {-0.25f, -0.2f, -0.15f}, {0.75f, 0.6f, 0.45f}, {0.3f, 0.2f, 0.1f},
         {-0.0625f, -0.05f, -0.04f}},
        {{1.0f, 1.0f, 1.0f}, {3.0f, 0.0f, -3.0f}, {0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 1.0f},
         {2.5f, -2.5f, 0.0f}, {0.0f, 0.0f, 0.0f}, {-1.5f, 2.5f, 0.0f}, {0.0f, 0.0f, 0.0f},
         {0.0f, 0.0f, 0.0f}},
    };
    std::vector<Sh3Radiance> out(2);
    for (int n = 0; n < 2; ++n)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) out[size_t(n)][i][k] = p[n][i][k];
    Rng rng(77);
    for (int i = 0; i < 4; ++i) out.push_back(random_lighting(rng));
    return out;
}

TEST(Zh3ChannelQ16, GoldenBytes) {
    const std::string dir = std::string(ZHC_GOLDEN_DIR);
    CodecOptions other;
    other.bits = 6;
    other.sqrt_encoding = true;
    other.dc_format = DcFormat::kRGB9E5;
    other.kind = StoredKind::kIrradiance;
    other.zonal_mapping = ZonalMapping::kZeroPreserving;
    for (const Codec* c : {&fitted(), &solved()})
        for (const auto& [suffix, params] : {std::pair{std::string(""), CodecOptions{}}, {std::string("_6bit_sqrt_rgb9e5_irradiance_zero"), other}}) {
            std::vector<std::uint8_t> all;
            for (const Sh3Radiance& sh : golden_probes()) {
                const auto b = encode(*c, sh, params);
                all.insert(all.end(), b.begin(), b.end());
            }
            const std::string path = dir + "/" + std::string(c->name) + suffix + ".bin";
            if (const char* u = std::getenv("ZHC_UPDATE_GOLDEN"); u && std::string(u) == "1") {
                test::write_bytes(path, all);
                continue;
            }
            ASSERT_TRUE(std::filesystem::exists(path)) << path << " missing (run with ZHC_UPDATE_GOLDEN=1)";
            EXPECT_EQ(test::read_bytes(path), all) << path;
        }
}

TEST(Zh3ChannelQ16, CodeSearchIsScaleInvariant) {
    // The search works on ratios to the decoded DC: the same problem at any magnitude gives the same
    // codes and the same error (ratio units). Scales 1e-8 .. 1e8.
    Rng rng(13);
    for (int t = 0; t < 100; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        const int k = t % 3;
        ChannelCodes ref;
        double ref_e = 0;
        for (int e10 = -8; e10 <= 8; ++e10) {
            const double s = std::pow(10.0, e10);
            const double dc = double(sh[0][k]) * s;
            ChannelCodeProblem pr;
            pr.w1 = 4.0 / 9.0;
            pr.w2 = 1.0 / 16.0;
            for (int j = 0; j < 3; ++j) pr.t1[size_t(j)] = double(sh[j + 1][k]) * s / dc;
            for (int m = 0; m < 5; ++m) pr.t2[size_t(m)] = double(sh[4 + m][k]) * s / dc;
            bool clamped = false;
            std::array<std::uint8_t, 3> start;
            for (int j = 0; j < 3; ++j) start[size_t(j)] = ratio_coder(j + 1, CodecOptions{}).encode(pr.t1[size_t(j)], &clamped);
            int evals = 0;
            const ChannelCodes c = solve_channel_codes(pr, CodecOptions{}, &start, 1, &evals);
            const double e = channel_code_error(pr, CodecOptions{}, c.l1, nullptr);
            if (e10 == -8) {
                ref = c;
                ref_e = e;
                continue;
            }
            EXPECT_EQ(c.l1, ref.l1) << "scale " << s;
            EXPECT_EQ(c.zonal, ref.zonal) << "scale " << s;
            EXPECT_NEAR(e, ref_e, 1e-6 * ref_e + 1e-300) << "scale " << s;
        }
    }
    // The entry: powers of two that keep the DC among R11G11B10F's normal numbers scale it exactly
    // and keep every code.
    for (int t = 0; t < 50; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        const auto b = encode(solved(), sh);
        for (int e2 = -6; e2 <= 12; e2 += 3) {
            const auto bs = encode(solved(), scale(sh, std::ldexp(1.0, e2)));
            EXPECT_TRUE(std::equal(b.begin() + 4, b.end(), bs.begin() + 4)) << "2^" << e2;
            const Rgb d = load_dc(b.data(), DcFormat::kR11G11B10F), ds = load_dc(bs.data(), DcFormat::kR11G11B10F);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(double(ds[k]), std::ldexp(double(d[k]), e2));
        }
    }
}

TEST(Zh3ChannelQ16, DeterministicAndTotalOnBadInput) {
    Rng rng(31);
    for (int t = 0; t < 100; ++t) {
        const Sh3Radiance sh = random_lighting(rng);
        EXPECT_EQ(encode(solved(), sh), encode(solved(), sh));
    }
    // Non-finite, negative-DC, zero and huge input: 16 bytes, decodes to finite-or-NaN without traps.
    const float bad[] = {NAN, INFINITY, -INFINITY, 0.0f, -1.0f, 1e38f, -1e38f, 1e-40f};
    for (int t = 0; t < 400; ++t) {
        Sh3Radiance sh;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) sh[i][k] = rng.u() < 0.3 ? bad[size_t(rng.u() * 8)] : float(rng.u() * 2 - 0.5);
        for (const Codec* c : {&fitted(), &solved()}) {
            const auto b = encode(*c, sh);
            const Sh3Radiance d = c->decode(b.data(), {});
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_FALSE(std::isinf(d[i][k])) << c->name;
        }
    }
}

// The acceptance numbers, from `zhc audit` itself: mean and worst ratio of irradiance RMSE to SH2's
// over the eight sample maps (target: mean <= 0.50 with 16 bytes).
TEST(Zh3ChannelQ16, AuditRatiosToSh2OnTheSampleMaps) {
    const auto paths = test::envmap_paths();
    ASSERT_EQ(paths.size(), 8u);
    const auto r = test::run_zhc({"audit", std::filesystem::path(paths[0]).parent_path().string(), "--representations",
                                  "sh2,zh3_channel_q16,zh3_solved_channel_q16", "--no-timing", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["files"].size(), 8u);
    for (const char* name : {"zh3_channel_q16", "zh3_solved_channel_q16"}) {
        double sum = 0, worst = 0;
        for (const auto& f : j["files"]) {
            const double ratio = f["representations"][name]["rmse"].get<double>() /
                                 f["representations"]["sh2"]["rmse"].get<double>();
            sum += ratio;
            worst = std::max(worst, ratio);
        }
        const double mean = sum / 8;
        std::printf("%-24s mean %.4f worst %.4f of SH2\n", name, mean, worst);
        if (std::string(name) == "zh3_channel_q16") {
            EXPECT_LE(mean, 0.535);
            EXPECT_LE(worst, 0.845);
        } else {
            EXPECT_LE(mean, 0.48);
            EXPECT_LE(worst, 0.80);
        }
    }
}

}  // namespace
}  // namespace zhc
