// ZH3 on per-channel axes in zh3_q16 bytes: the fitted entry and the code search (zh3_channel_q16.h).
//
// Source: Roughton et al. 2024, "ZH3: Quadratic Zonal Harmonics": Sec. 3.1 (each channel's own
// optimal linear direction as its zonal axis, derived from the stored L1 so it costs no bits),
// Eq. 9 (least-squares zonal coefficient), Eq. 11 (the irradiance error of a linear SH plus its
// zonal fit), App. A.1 (the 16-byte layout). zhc's addition: because the decoder derives the axis
// from the DEQUANTISED L1, the encoder solves over what is stored — the L1 codes themselves — by
// measuring the decoder's error (encode -> decode -> measure) for neighbouring codes.
#include "codec/probe/zh3_channel_q16.h"

#include <algorithm>
#include <cmath>

#include "codec/probe/zh3.h"

namespace zhc {

namespace {
const double kSqrtFourPiOverFive = std::sqrt(4.0 * kPi / 5.0);

CodecOptions per_channel(CodecOptions p) {
    p.axis_mode = ZonalAxisMode::kPerChannel;
    return p;
}

// The 4-byte DC slot of zh3_q16 holds R11G11B10F or RGB9E5; a half DC there means R11G11B10F
// (quantize.cpp does the same, validate_quant_params rejects the combination).
DcFormat q16_dc_format(DcFormat f) { return f == DcFormat::kHalf ? DcFormat::kR11G11B10F : f; }

constexpr int kL1Offset = 4;  // byte 4 + 4k + j: channel k, L1 index j + 1; j = 3: zonal
int code_offset(int k, int j) { return kL1Offset + 4 * k + j; }

// Irradiance weight of a stored band: (irradiance band scale / stored band scale)^2.
double band_weight(StoredKind kind, int l) {
    const double stored = kind == StoredKind::kIrradiance ? kIrradianceBandScale[l] : 1.0;
    const double f = kIrradianceBandScale[l] / stored;
    return f * f;
}
}  // namespace

namespace {
// What one channel's search needs besides the problem: the coders (built once) and the decoded L1
// ratio of each code, filled on first use (the three L1 indices share one interval).
struct SearchContext {
    RatioCoder l1, zonal;
    std::array<double, 256> l1_value;
    std::array<bool, 256> known{};
    explicit SearchContext(const CodecOptions& p) : l1(ratio_coder(1, p)), zonal(zonal_coder(p)) {}
    double l1_ratio(std::uint8_t code) {
        if (!known[code]) {
            l1_value[code] = l1.decode(code);
            known[code] = true;
        }
        return l1_value[code];
    }
};

double code_error(const ChannelCodeProblem& pr, SearchContext& cx, const std::array<std::uint8_t, 3>& l1,
                  std::uint8_t* best_zonal) {
    double l[3];
    double e1 = 0;
    for (int j = 0; j < 3; ++j) {
        l[j] = cx.l1_ratio(l1[static_cast<size_t>(j)]);
        const double d = l[j] - pr.t1[static_cast<size_t>(j)];
        e1 += d * d;
    }
    // The decoder's axis: the channel's optimal linear direction normalize(-f11, -f1-1, f10).
    const Vec3 axis = normalize_or({-l[2], -l[0], l[1]}, {0, 0, 1});
    const auto y = sh3_basis(axis);
    double pz = 0, t2sq = 0;
    for (int m = 0; m < 5; ++m) {
        pz += pr.t2[static_cast<size_t>(m)] * kSqrtFourPiOverFive * y[static_cast<size_t>(4 + m)];
        t2sq += pr.t2[static_cast<size_t>(m)] * pr.t2[static_cast<size_t>(m)];
    }
    bool clamped = false;
    const std::uint8_t code = cx.zonal.encode(pz, &clamped);
    const double zq = cx.zonal.decode(code);
    if (best_zonal) *best_zonal = code;
    // |zq v - t2|^2 with |v| = 1; never below 0 in exact arithmetic.
    const double e2 = std::max(t2sq - 2.0 * zq * pz + zq * zq, 0.0);
    return pr.w1 * e1 + pr.w2 * e2;
}
}  // namespace

double channel_code_error(const ChannelCodeProblem& pr, const CodecOptions& p, const std::array<std::uint8_t, 3>& l1,
                          std::uint8_t* best_zonal) {
    SearchContext cx(p);
    return code_error(pr, cx, l1, best_zonal);
}

ChannelCodes solve_channel_codes(const ChannelCodeProblem& pr, const CodecOptions& p,
                                 const std::array<std::uint8_t, 3>* starts, int start_count, int* evaluations) {
    SearchContext cx(p);
    const int top = 2 * quant_half_range(p.bits);
    int evals = 0;
    ChannelCodes best;
    double best_e = INFINITY;
    bool have = false;
    for (int s = 0; s < start_count; ++s) {
        std::array<std::uint8_t, 3> c = starts[s];
        for (auto& v : c) v = static_cast<std::uint8_t>(std::min<int>(v, top));
        double e = code_error(pr, cx, c, nullptr);
        ++evals;
        // Steepest descent over the +-1 box; E strictly decreases, so it ends (the cap is a guard).
        for (int step = 0; step < 4 * top; ++step) {
            std::array<std::uint8_t, 3> step_best = c;
            double step_e = e;
            for (int d0 = -1; d0 <= 1; ++d0)
                for (int d1 = -1; d1 <= 1; ++d1)
                    for (int d2 = -1; d2 <= 1; ++d2) {
                        const int n[3] = {c[0] + d0, c[1] + d1, c[2] + d2};
                        if ((d0 | d1 | d2) == 0) continue;
                        if (std::min({n[0], n[1], n[2]}) < 0 || std::max({n[0], n[1], n[2]}) > top) continue;
                        const std::array<std::uint8_t, 3> cand = {static_cast<std::uint8_t>(n[0]),
                                                                  static_cast<std::uint8_t>(n[1]),
                                                                  static_cast<std::uint8_t>(n[2])};
                        const double ce = code_error(pr, cx, cand, nullptr);
                        ++evals;
                        if (ce < step_e) {
                            step_e = ce;
                            step_best = cand;
                        }
                    }
            if (!(step_e < e)) break;
            e = step_e;
            c = step_best;
        }
        if (!have || e < best_e) {
            have = true;
            best_e = e;
            best.l1 = c;
        }
    }
    code_error(pr, cx, best.l1, &best.zonal);
    if (evaluations) *evaluations += evals + 1;
    return best;
}

namespace {

// zh3_channel_q16: the zh3_q16 encoder with the per-channel axis (zonal refitted on the decoder's axis).
void encode_fit(const Sh3Radiance& in, const CodecOptions& p, std::uint8_t* out, EncodeStats* stats) {
    encode_packed(PackedLayout::kZh3Q16, in, per_channel(p), out, stats);
}

// zh3_solved_channel_q16: start from the fitted bytes; per channel, search the L1 codes from two
// starts (the fitted codes and the quantised L1 of the float per-channel axis solve, zh3_solve)
// for the lowest error of the decoded probe; the zonal code is the best for the final L1.
void encode_solved(const Sh3Radiance& in, const CodecOptions& params, std::uint8_t* out, EncodeStats* stats) {
    const CodecOptions p = per_channel(params);
    EncodeStats fit_stats;
    encode_packed(PackedLayout::kZh3Q16, in, p, out, &fit_stats);
    if (stats) stats->clamped_ratios += fit_stats.clamped_ratios;
    EncodeStats solve_stats;
    const Zh3 solved = zh3_solve(in, ZonalAxisMode::kPerChannel, p, &solve_stats);
    if (stats) stats->solver_iterations += solve_stats.solver_iterations;
    const Rgb dc = load_dc(out, q16_dc_format(p.dc_format));
    const double s1 = p.kind == StoredKind::kIrradiance ? kIrradianceBandScale[1] : 1.0;
    const double s2 = p.kind == StoredKind::kIrradiance ? kIrradianceBandScale[2] : 1.0;
    for (int k = 0; k < 3; ++k) {
        const double d = dc[k];
        if (!(d > 0.0) || !std::isfinite(d)) continue;  // no ratio scale: keep the fitted bytes
        ChannelCodeProblem pr;
        pr.w1 = band_weight(p.kind, 1);
        pr.w2 = band_weight(p.kind, 2);
        bool finite = true;
        std::array<std::uint8_t, 3> starts[2];
        for (int j = 0; j < 3; ++j) {
            pr.t1[static_cast<size_t>(j)] = in[j + 1][k] * s1 / d;
            const double solved_ratio = solved.linear[j + 1][k] * s1 / d;
            finite = finite && std::isfinite(pr.t1[static_cast<size_t>(j)]) && std::isfinite(solved_ratio);
            starts[0][static_cast<size_t>(j)] = out[code_offset(k, j)];
            bool clamped = false;
            starts[1][static_cast<size_t>(j)] = ratio_coder(j + 1, p).encode(solved_ratio, &clamped);
        }
        for (int m = 0; m < 5; ++m) {
            pr.t2[static_cast<size_t>(m)] = in[4 + m][k] * s2 / d;
            finite = finite && std::isfinite(pr.t2[static_cast<size_t>(m)]);
        }
        if (!finite) continue;  // non-finite input: the fitted bytes (ratios stored as 0 / clamped)
        // Descend from the better start only (the float solve's L1 is the continuous optimum; the
        // fitted codes are the fallback when it rounds badly).
        const double e0 = channel_code_error(pr, p, starts[0], nullptr);
        const double e1 = channel_code_error(pr, p, starts[1], nullptr);
        const ChannelCodes c = solve_channel_codes(pr, p, e1 < e0 ? &starts[1] : &starts[0], 1, nullptr);
        for (int j = 0; j < 3; ++j) out[code_offset(k, j)] = c.l1[static_cast<size_t>(j)];
        out[code_offset(k, 3)] = c.zonal;
    }
}

Sh3Radiance decode(const std::uint8_t* in, const CodecOptions& p) {
    return decode_packed(PackedLayout::kZh3Q16, in, per_channel(p));
}

constexpr PackedCodec kChannelQ16{PackedLayout::kZh3Q16, encode_fit, decode};
constexpr PackedCodec kSolvedChannelQ16{PackedLayout::kZh3Q16, encode_solved, decode};

const Codec kCodecs[] = {
    packed_codec<kChannelQ16>("zh3_channel_q16",
                              "zh3_q16 bytes on per-channel axes (each from its decoded L1); zonal refitted",
                              ZonalAxis::kPerChannel),
    packed_codec<kSolvedChannelQ16>(
        "zh3_solved_channel_q16",
        "zh3_channel_q16 bytes; encoder searches the L1/zonal codes for the least decoded error (Eq. 11)",
        ZonalAxis::kPerChannel),
};
}  // namespace

std::span<const Codec> zh3_channel_q16_codecs() { return kCodecs; }

}  // namespace zhc
