// Ratio-bound quantisation (codec/probe/quantize.h): the acceptance tables on the eight real maps
// (irradiance RMSE, tight vs loose bound, sqrt, zonal mapping, DC vs ratio budget; helper:
// quantize_helpers.h).
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

// ---- acceptance tables on the real maps ---------------------------------------------------------

std::vector<Sh3Radiance> real_map_probes() {
    std::vector<Sh3Radiance> out;
    for (const auto& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3, 2));
    }
    return out;
}

// Uniform random rotation (Shoemake's quaternion from three uniforms).
Mat3 random_rotation(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const double u1 = u(rng), u2 = 2 * kPi * u(rng), u3 = 2 * kPi * u(rng);
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    const double w = a * std::sin(u2), x = a * std::cos(u2), y = b * std::sin(u3), z = b * std::cos(u3);
    Mat3 r;
    r.m = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
           2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
           2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
    return r;
}

// Squared L2 norm over the sphere of the irradiance of an SH3 radiance function (Parseval: the
// basis is orthonormal, irradiance band scales 1, 2/3, 1/4), summed over channels.
double irradiance_energy(const Sh3Radiance& sh) {
    double s = 0;
    for (int i = 0; i < 9; ++i) {
        const double b = kIrradianceBandScale[i == 0 ? 0 : (i < 4 ? 1 : 2)];
        for (int k = 0; k < 3; ++k) s += (b * sh[i][k]) * (b * sh[i][k]);
    }
    return s;
}
Sh3Radiance difference(const Sh3Radiance& a, const Sh3Radiance& b) { return a + scale(b, -1.0); }

TEST(QuantRealMaps, ParsevalErrorMatchesDenseDirectionSampling) {
    // Slow twin of the closed-form RMSE used by the tables.
    const auto probes = real_map_probes();
    const auto dirs = fibonacci_directions(20000);
    for (const Sh3Radiance& sh : probes) {
        const Sh3Radiance q = quantize_roundtrip(PackedLayout::kSh3Q28, sh, {}, nullptr);
        double sampled = 0;
        for (const Vec3 n : dirs) {
            const Rgb a = irradiance(q, n), b = irradiance(sh, n);
            for (int k = 0; k < 3; ++k) sampled += (double(a[k]) - b[k]) * (double(a[k]) - b[k]);
        }
        sampled *= 4 * kPi / dirs.size();
        EXPECT_NEAR(sampled, irradiance_energy(difference(q, sh)), 1e-3 * sampled + 1e-12);
    }
}

TEST(QuantRealMaps, EveryCoefficientIsWithinHalfAStepOfItsIntervalTimesDc) {
    // For rotated real maps, every stored coefficient decodes within (half a quantisation step of
    // its interval, sqrt-adjusted) x (decoded DC) of the input, unless its ratio was clamped; the
    // DC within half an R11G11B10F ulp (relative 2^-7 R/G, 2^-6 B).
    const auto maps = real_map_probes();
    std::mt19937 rng(77);
    int checked = 0, clamped_skipped = 0;
    for (const Sh3Radiance& base : maps)
        for (int r = 0; r < 6; ++r) {
            const Sh3Radiance sh = rotate(base, random_rotation(rng));
            for (int bits : {8, 5})
                for (bool sq : {false, true})
                    for (PackedLayout L : {PackedLayout::kSh3Q28, PackedLayout::kSh2Q, PackedLayout::kZh3Q16}) {
                        CodecOptions p;
                        p.bits = bits;
                        p.sqrt_encoding = sq;
                        std::uint8_t b[28];
                        encode_packed(L, sh, p, b, nullptr);
                        const Sh3Radiance d = decode_packed(L, b, p);
                        const int last = L == PackedLayout::kSh3Q28 ? 8 : 3;
                        for (int k = 0; k < 3; ++k) {
                            const double dc = d[0][k];
                            EXPECT_LE(std::fabs(dc - sh[0][k]), std::fabs(sh[0][k]) * std::exp2(k == 2 ? -6 : -7) * (1 + 1e-6));
                            for (int i = 1; i <= last; ++i) {
                                const RatioCoder c = ratio_coder(i, p);
                                const double ratio = sh[i][k] / dc;
                                if (ratio < c.interval.lo || ratio > c.interval.hi) {
                                    ++clamped_skipped;
                                    continue;
                                }
                                EXPECT_LE(std::fabs(d[i][k] - sh[i][k]), max_ratio_error(c, ratio) * dc + 1e-6 * dc)
                                    << "layout " << int(L) << " bits " << bits << " sqrt " << sq << " i " << i;
                                ++checked;
                            }
                        }
                    }
        }
    std::printf("checked %d coefficients (%d out-of-range ratios skipped)\n", checked, clamped_skipped);
    EXPECT_GT(checked, 5000);
}

struct Config {
    std::string name;
    CodecOptions params;
    QuantEncodeControls controls;
};

TEST(QuantRealMaps, QuantisationErrorTableOverRotatedMaps) {
    // 8 maps x 32 random rotations = 256 probes; relative RMSE of quantised vs float irradiance,
    // sqrt(sum |E_q - E|^2 / sum |E|^2) over the sphere (Parseval) and all probes.
    const auto maps = real_map_probes();
    std::vector<Sh3Radiance> probes;
    std::mt19937 rng(2024);
    for (const Sh3Radiance& sh : maps)
        for (int r = 0; r < 32; ++r) probes.push_back(rotate(sh, random_rotation(rng)));
    auto rel_rmse = [&](PackedLayout L, const CodecOptions& p, const QuantEncodeControls& c, int* clamps) {
        double num = 0, den = 0;
        EncodeStats st;
        for (const Sh3Radiance& sh : probes) {
            num += irradiance_energy(difference(quantize_roundtrip(L, sh, p, &st, c), sh));
            den += irradiance_energy(sh);
        }
        if (clamps) *clamps = st.clamped_ratios;
        return std::sqrt(num / den);
    };
    std::printf("\nsh3_q28 quantisation error, relative irradiance RMSE over %zu probes (8 maps x 32 rotations)\n",
                probes.size());
    std::printf("%-10s %-6s %-10s | %-12s %-12s %-12s %-12s | clamped\n", "bound", "sqrt", "zonal", "exact DC",
                "R11G11B10F", "RGB9E5", "half");
    std::map<std::string, double> table;  // key: bound/sqrt/zonal/dc
    const char* dc_names[4] = {"exact", "r11", "rgb9e5", "half"};
    for (L2Bound bound : {L2Bound::kTight, L2Bound::kLoose})
        for (bool sq : {false, true})
            for (ZonalMapping zm : {ZonalMapping::kAffine, ZonalMapping::kZeroPreserving, ZonalMapping::kSymmetric}) {
                const char* zname = zm == ZonalMapping::kAffine ? "affine" : (zm == ZonalMapping::kZeroPreserving ? "zero" : "symmetric");
                std::printf("%-10s %-6s %-10s |", bound == L2Bound::kTight ? "tight" : "loose", sq ? "yes" : "no", zname);
                int clamps = 0;
                for (int dc = 0; dc < 4; ++dc) {
                    CodecOptions p;
                    p.l2_bound = bound;
                    p.sqrt_encoding = sq;
                    p.zonal_mapping = zm;
                    QuantEncodeControls c;
                    c.exact_dc = dc == 0;
                    // half DC exists only in sh2_q's slot; for the budget study the quantiser
                    // applies it to sh3_q28 through quantize_roundtrip (no bytes are stored).
                    p.dc_format = dc == 2 ? DcFormat::kRGB9E5 : DcFormat::kR11G11B10F;
                    double e;
                    if (dc == 3) {
                        // Emulate a half DC: quantise DC as half, ratios against it (sh2_q slot logic).
                        double num = 0, den = 0;
                        for (const Sh3Radiance& sh : probes) {
                            Sh3Radiance h = sh;
                            for (int k = 0; k < 3; ++k) h[0][k] = unpack_half(pack_half(sh[0][k]));
                            QuantEncodeControls exact;
                            exact.exact_dc = true;
                            Sh3Radiance q = quantize_roundtrip(PackedLayout::kSh3Q28, h, p, nullptr, exact);
                            num += irradiance_energy(difference(q, sh));
                            den += irradiance_energy(sh);
                        }
                        e = std::sqrt(num / den);
                    } else {
                        e = rel_rmse(PackedLayout::kSh3Q28, p, c, dc == 1 ? &clamps : nullptr);
                    }
                    table[std::string(bound == L2Bound::kTight ? "tight" : "loose") + (sq ? "/sqrt/" : "/lin/") + zname + "/" + dc_names[dc]] = e;
                    std::printf(" %11.4f%%", 100 * e);
                }
                std::printf(" | %d\n", clamps);
            }
    // Acceptance: the tight non-zonal bound beats the loose one, with and without sqrt, whatever
    // the DC format and zonal mapping.
    for (const char* sq : {"/lin/", "/sqrt/"})
        for (const char* zm : {"affine", "zero", "symmetric"})
            for (const char* dc : dc_names)
                EXPECT_LT(table[std::string("tight") + sq + zm + "/" + dc], table[std::string("loose") + sq + zm + "/" + dc])
                    << sq << zm << dc;
    // zh3_q16: quantisation error against the float ZH3 fit (zh3_lum) it approximates, with the
    // zonal coefficient refitted on the decoder's axis vs fitted first on the float axis (naive).
    std::printf("\nzh3_q16 relative irradiance RMSE vs SH3 (same probes); float zh3_lum: %.4f%%\n%-6s %-5s %12s %12s %12s\n",
                100 * [&] {
                    double n = 0, d = 0;
                    for (const Sh3Radiance& sh : probes) {
                        n += irradiance_energy(difference(zh3_expand(zh3_fit(sh, ZonalAxisMode::kLuminance, {}), ZonalAxisMode::kLuminance, {}), sh));
                        d += irradiance_energy(sh);
                    }
                    return std::sqrt(n / d);
                }(),
                "bits", "sqrt", "naive", "refit", "refit/naive");
    for (int bits : {8, 6, 5, 4})
        for (bool sq : {false, true}) {
            double num[2] = {0, 0}, den = 0;
            CodecOptions p;
            p.bits = bits;
            p.sqrt_encoding = sq;
            for (const Sh3Radiance& sh : probes) {
                const Sh3Radiance& ref = sh;
                for (int refit = 0; refit < 2; ++refit) {
                    QuantEncodeControls c;
                    c.refit_zonal_after_l1 = refit == 1;
                    num[refit] += irradiance_energy(difference(quantize_roundtrip(PackedLayout::kZh3Q16, sh, p, nullptr, c), ref));
                }
                den += irradiance_energy(ref);
            }
            const double naive = std::sqrt(num[0] / den), refit = std::sqrt(num[1] / den);
            std::printf("%-6d %-5s %11.4f%% %11.4f%% %12.4f\n", bits, sq ? "yes" : "no", 100 * naive, 100 * refit, refit / naive);
            EXPECT_LE(refit, naive * (1 + 1e-9)) << bits << sq;
        }
    // The same errors relative to the directional (non-DC) part of the irradiance instead of all of it.
    {
        double dir = 0, all = 0;
        for (const Sh3Radiance& sh : probes) {
            Sh3Radiance no_dc = sh;
            no_dc[0] = {};
            dir += irradiance_energy(no_dc);
            all += irradiance_energy(sh);
        }
        const double f = std::sqrt(all / dir);
        std::printf("\nrelative to the directional (non-DC) irradiance instead (x%.3f): tight/lin/r11 %.3f%%, "
                    "tight/sqrt/r11 %.3f%%, loose/lin/r11 %.3f%%, loose/sqrt/r11 %.3f%%\n",
                    f, 100 * f * table["tight/lin/affine/r11"], 100 * f * table["tight/sqrt/affine/r11"],
                    100 * f * table["loose/lin/affine/r11"], 100 * f * table["loose/sqrt/affine/r11"]);
    }
    // Other normalisations, for comparing with numbers measured elsewhere: mean over probes of the
    // per-probe relative RMSE, and the RMS over directions of the pointwise relative error
    // |E_q - E| / |E| (directions with luminance E below 1% of the probe's mean excluded).
    {
        const auto dirs = fibonacci_directions(2000);
        std::printf("\nother normalisations (sh3_q28, R11G11B10F DC, affine zonal): per-probe mean | pointwise relative\n");
        for (L2Bound bound : {L2Bound::kTight, L2Bound::kLoose})
            for (bool sq : {false, true}) {
                CodecOptions p;
                p.l2_bound = bound;
                p.sqrt_encoding = sq;
                double per_probe = 0, pw_num = 0;
                size_t pw_n = 0;
                for (const Sh3Radiance& sh : probes) {
                    const Sh3Radiance q = quantize_roundtrip(PackedLayout::kSh3Q28, sh, p, nullptr);
                    per_probe += std::sqrt(irradiance_energy(difference(q, sh)) / irradiance_energy(sh));
                    const double mean = luminance(sh[0], {}) / (2 * std::sqrt(kPi));
                    for (const Vec3 n : dirs) {
                        const Rgb e = irradiance(sh, n), eq = irradiance(q, n);
                        const double l = luminance(e, {});
                        if (l < 0.01 * mean) continue;
                        const double rel = (luminance(eq, {}) - l) / l;
                        pw_num += rel * rel;
                        ++pw_n;
                    }
                }
                std::printf("  %-6s sqrt %-4s %8.4f%% | %8.4f%%\n", bound == L2Bound::kTight ? "tight" : "loose",
                            sq ? "yes" : "no", 100 * per_probe / probes.size(), 100 * std::sqrt(pw_num / pw_n));
            }
    }
    std::printf("\nerror budget (tight, affine zonal): ratios alone (exact DC) vs with R11G11B10F DC\n");
    for (const char* sq : {"/lin/", "/sqrt/"}) {
        const double ratios = table[std::string("tight") + sq + "affine/exact"];
        const double total = table[std::string("tight") + sq + "affine/r11"];
        // Errors add roughly in quadrature: DC share = sqrt(total^2 - ratios^2).
        std::printf("  %-6s ratios %.4f%%  total %.4f%%  DC share ~%.4f%%\n", sq, 100 * ratios, 100 * total,
                    100 * std::sqrt(std::max(0.0, total * total - ratios * ratios)));
    }
}

TEST(QuantRealMaps, Zh3Q16IrradianceRmseIsWithinFivePercentOfZh3Lum) {
    // Audit-style table on the 8 maps (unrotated): irradiance RMSE against the SH3 irradiance
    // (Parseval, exact over the sphere) and against the map's true irradiance (direct integration
    // of the 4x-downsampled map over 1024 Fibonacci normals).
    const auto paths = test::envmap_paths();
    const auto normals = fibonacci_directions(1024);
    const std::vector<std::string> names = {"sh3",     "sh2",          "zh3_lum",        "zh3_q16",
                                            "zh3_solved_lum", "zh3_solved_q16", "sh3_q28", "sh2_q",
                                            "hall_curve",     "hall_curve_q"};
    std::map<std::string, std::vector<double>> vs_sh3, vs_true;
    std::vector<double> naive_vs_sh3;
    for (const auto& path : paths) {
        const Image img = test::load_envmap(path);
        const Sh3Radiance sh = project_latlong(img.rgb.data(), img.width, img.height, size_t(img.width) * 3, 2);
        const Image small = test::downsample_latlong(img, 4);
        // Direct integration (test::integrate_irradiance's sum) with the pixel directions and
        // solid angles computed once instead of once per normal.
        std::vector<Vec3> pix_dir;
        std::vector<double> pix_w;
        for (int y = 0; y < small.height; ++y)
            for (int x = 0; x < small.width; ++x) {
                pix_dir.push_back(latlong_direction(x, y, small.width, small.height));
                pix_w.push_back(latlong_pixel_solid_angle(y, small.width, small.height));
            }
        std::vector<Rgb> truth;
        for (const Vec3 n : normals) {
            double acc[3] = {0, 0, 0};
            for (size_t q = 0; q < pix_dir.size(); ++q) {
                const double c = dot(n, pix_dir[q]);
                if (c <= 0) continue;
                for (int k = 0; k < 3; ++k) acc[k] += pix_w[q] * c * small.rgb[3 * q + static_cast<size_t>(k)];
            }
            truth.push_back({float(acc[0] / kPi), float(acc[1] / kPi), float(acc[2] / kPi)});
        }
        // Spot check against the support twin.
        EXPECT_NEAR(truth[5].g, test::integrate_irradiance(small, normals[5]).g, 1e-4 * (1 + std::fabs(truth[5].g)));
        for (const std::string& name : names) {
            const Codec* c = find_codec(name);
            ASSERT_NE(c, nullptr) << name;
            std::vector<std::uint8_t> b(c->size_bytes);
            c->encode(sh, {}, b.data(), nullptr);
            const Sh3Radiance d = c->decode(b.data(), {});
            vs_sh3[name].push_back(std::sqrt(irradiance_energy(difference(d, sh)) / (3 * 4 * kPi)));
            double s = 0;
            for (size_t j = 0; j < normals.size(); ++j) {
                const Rgb e = irradiance(d, normals[j]);
                for (int k = 0; k < 3; ++k) s += (double(e[k]) - truth[j][k]) * (double(e[k]) - truth[j][k]);
            }
            vs_true[name].push_back(std::sqrt(s / (3.0 * normals.size())));
        }
        QuantEncodeControls naive;
        naive.refit_zonal_after_l1 = false;
        naive_vs_sh3.push_back(std::sqrt(
            irradiance_energy(difference(quantize_roundtrip(PackedLayout::kZh3Q16, sh, {}, nullptr, naive), sh)) /
            (3 * 4 * kPi)));
    }
    for (int ref = 0; ref < 2; ++ref) {
        auto& t = ref == 0 ? vs_true : vs_sh3;
        std::printf("\nirradiance RMSE vs %s\n%-15s", ref == 0 ? "TRUE map irradiance (256x128, 1024 normals)"
                                                             : "SH3 irradiance (exact, Parseval)", "");
        for (const auto& p : paths) std::printf("%10s", test::envmap_name(p).c_str());
        std::printf("%10s\n", "mean");
        for (const std::string& name : names) {
            std::printf("%-15s", name.c_str());
            double m = 0;
            for (double v : t[name]) std::printf("%10.5f", v), m += v;
            std::printf("%10.5f\n", m / t[name].size());
        }
        std::printf("%-15s", "q16/lum");
        for (size_t i = 0; i < paths.size(); ++i) std::printf("%10.4f", t["zh3_q16"][i] / t["zh3_lum"][i]);
        std::printf("\n");
    }
    std::printf("%-15s", "solved q16/f");
    for (size_t i = 0; i < paths.size(); ++i) std::printf("%10.4f", vs_sh3["zh3_solved_q16"][i] / vs_sh3["zh3_solved_lum"][i]);
    std::printf("   (vs SH3)\n");
    std::printf("%-15s", "q16 naive");
    for (double v : naive_vs_sh3) std::printf("%10.5f", v);
    std::printf("   (zonal fitted on the float axis, vs SH3)\n");
    // Target: against the true irradiance, zh3_q16 is within 5% of zh3_lum on every map.
    for (size_t i = 0; i < paths.size(); ++i)
        EXPECT_LE(vs_true["zh3_q16"][i], 1.05 * vs_true["zh3_lum"][i]) << test::envmap_name(paths[i]);
    // Refitting the zonal coefficient on the decoder's axis is never worse than the naive order.
    for (size_t i = 0; i < paths.size(); ++i) EXPECT_LE(vs_sh3["zh3_q16"][i], naive_vs_sh3[i] * (1 + 1e-6));
}

}  // namespace
}  // namespace zhc
