// Part of tests/test_runtime_gl.cpp (included once, inside its anonymous namespace): the codec table's
// GLSL formats read from runtime/zhc.glsl, the probe generators, and the error bounds.
//
// Error metric. The GPU computes in binary32 (u = 2^-24), the codec in double (then rounds to float).
// A sum of terms computed in float has an absolute error of a few u times the sum of the terms'
// MAGNITUDES, not of the result (which may cancel to 0), so every difference is measured in units of
// u * S, S a per-channel "probe scale" computed here in double (see Scale below):
//   S = Y00 |c0| + (2/3) Y1 sum_i M_i + (1/4) [0.631 sum_{L2} M_i  |  3 Y20 Z]      (irradiance)
// with M_i = |c_i|, or max(|c_i|, R_i |c0|) for quantised coefficients (R_i the ratio bound: a ratio
// decoded in float is off by a few u of R_i, not of the ratio), and for the zonal (ZH3) families
// Z = (|f20| + G |v|) (1 + kappa): f20 the zonal coefficient, v the L1 vector, G the hallucination's
// coefficient magnitude plus slope over p in [0, sqrt3] (0 when the zonal is stored), kappa the
// condition number of the axis (sum |w_k| |v_k| / |sum w_k v_k| for the luminance axis: the float
// error of the normalised axis is ~ kappa u; 1 per channel, and 1 when every L1 is exactly 0, where
// both sides take +Z exactly). A decoded coefficient is measured against its own M (sqrt3 Z for an
// expanded zonal L2 coefficient).
//
// The bounds (in u S) come from counting roundings on the longest path, first order, with the GLSL
// 4.50 precision rules (+, * correctly rounded; / 2.5 ulp; inversesqrt 2 ulp):
//  * evaluation of 9 terms: basis value (<= 3 roundings + 1 for the constant) times a coefficient
//    (1) times the band scale (1), summed (<= 8): 14; the codec's own float roundings of the
//    band-scaled coefficient and of the result: 1.5. Float layouts: C = 16.
//  * quantised ratio: (c - bv) / bv (2.5), sign-square (2 x 2.5 + 1), affine map (interval constants
//    2, multiply 1, add 1), times DC (1), irradiance-storage rescale (1): <= 13.5 on top of the 16
//    above, plus the codec's float rounding of the coefficient (1). Quantised: C = 32.
//  * decoded coefficients: float layouts are exact (bit copy; irradiance storage: one multiply by
//    1.5); quantised <= 14.5; expanded zonal L2: axis (kappa u, counted in Z) and <= 6 roundings of
//    the basis products. Decode: C = 16.
//  * An absolute 2^-120 covers flush-to-zero of denormals (GLSL allows it).
// A codec result that is not finite is not compared (garbage bytes: Inf/NaN DC); when S is within a
// factor 64 of FLT_MAX the float computation may overflow where double does not, so a non-finite
// GPU value is accepted there. Everything else must be within the bound.

// ---- codec table -> GLSL format ----------------------------------------------------------------------

// The layout families and hallucination models, as the runtimes number them (runtime/zhc.glsl's
// ZHC_LAYOUT_* / ZHC_HALL_MODE_*, generated like zhc_runtime.h's from codec/probe/runtime_table.h).
enum : std::uint32_t {
    kSh3F32 = ZHC_LAYOUT_SH3_F32, kSh2F32 = ZHC_LAYOUT_SH2_F32, kZh3F32 = ZHC_LAYOUT_ZH3_F32,
    kZh3Q16 = ZHC_LAYOUT_ZH3_Q16, kSh3Q28 = ZHC_LAYOUT_SH3_Q28, kSh2Q = ZHC_LAYOUT_SH2_Q
};
enum : std::uint32_t {
    kHallNone = ZHC_HALL_MODE_NONE, kHallAmbdir = ZHC_HALL_MODE_AMBDIR, kHallSphere = ZHC_HALL_MODE_SPHERE,
    kHallCurve = ZHC_HALL_MODE_CURVE, kHallCurveAdaptive = ZHC_HALL_MODE_CURVE_ADAPTIVE
};

struct GlslEntry {
    std::uint32_t family, hallucination;
    ZonalAxis axis;  // where the zonal axis comes from: the codec entry's CodecTraits::zonal_axis
};

// Every codec table entry's GLSL format: its runtime description (codec/probe/runtime_table.h), the
// one runtime/zhc.glsl's generated table holds (test runtime_tables.check compares the file with
// the codec table; RuntimeGl.GeneratedTableMatchesTheCodec runs the GLSL table functions).
const std::map<std::string, GlslEntry, std::less<>>& glsl_entries() {
    static const std::map<std::string, GlslEntry, std::less<>> m = [] {
        std::map<std::string, GlslEntry, std::less<>> out;
        for (const Codec& c : runtime_codecs()) {  // the engine layouts have no GLSL decoder (codec.h)
            const auto rt = runtime_entry(c);
            EXPECT_TRUE(rt.ok()) << (rt.ok() ? "" : rt.error().message);
            if (rt.ok())
                out[std::string(c.name)] = GlslEntry{std::uint32_t(rt->layout), std::uint32_t(rt->hallucination), rt->axis};
        }
        return out;
    }();
    return m;
}

// The axis the shader is told (ZhcFormat.axisMode): the entry's fixed axis, else the header's.
std::uint32_t axis_mode(const GlslEntry& e, const CodecOptions& p) {
    if (e.axis == ZonalAxis::kLuminance) return 0;
    if (e.axis == ZonalAxis::kPerChannel) return 1;
    return static_cast<std::uint32_t>(p.axis_mode);
}

// The kernel's format uniforms (ZhcFormat) of entry e stored with parameters p, and its job `mode`.
template <class Uniforms>
void set_format_uniforms(Uniforms& un, std::uint32_t mode, const GlslEntry& e, const CodecOptions& p) {
    un.mode = mode;
    un.a[0] = e.family;
    un.a[1] = e.hallucination;
    un.a[2] = static_cast<std::uint32_t>(p.bits);
    un.a[3] = p.sqrt_encoding ? 1u : 0u;
    un.b[0] = static_cast<std::uint32_t>(p.l2_bound);
    un.b[1] = static_cast<std::uint32_t>(p.dc_format);
    un.b[2] = static_cast<std::uint32_t>(p.zonal_mapping);
    un.b[3] = axis_mode(e, p);
    un.kind = static_cast<std::uint32_t>(p.kind);
    un.lum[0] = static_cast<float>(p.luminance.r);
    un.lum[1] = static_cast<float>(p.luminance.g);
    un.lum[2] = static_cast<float>(p.luminance.b);
    un.curve[0] = static_cast<float>(p.hallucinate_a);
    un.curve[1] = static_cast<float>(p.hallucinate_b);
}

bool is_quantised(std::uint32_t family) { return family >= kZh3Q16; }
bool is_zonal(const GlslEntry& e) { return e.family == kZh3F32 || e.family == kZh3Q16 || e.hallucination != kHallNone; }
bool has_l2(const GlslEntry& e) { return e.family == kSh3F32 || e.family == kSh3Q28 || is_zonal(e); }

// ---- probes ------------------------------------------------------------------------------------------

std::vector<Sh3Radiance> envmap_probes() {
    std::vector<Sh3Radiance> out;
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, static_cast<size_t>(img.width) * 3, 2));
    }
    return out;
}

Mat3 random_rotation(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const Vec3 axis = test::uniform_direction(u(rng), u(rng));
    return rotation_axis_angle(axis, 2 * kPi * u(rng));
}

Rgb random_colour(std::mt19937_64& rng, double scale) {
    std::uniform_real_distribution<double> u(0, 1);
    return {static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng)), static_cast<float>(scale * u(rng))};
}

// kind 0: several coloured lights + ambient; 1: random SH; 2: a sample map, rotated.
Sh3Radiance random_probe(std::mt19937_64& rng, const std::vector<Sh3Radiance>& maps, int kind) {
    std::uniform_real_distribution<double> u(0, 1);
    const double exposure = std::pow(10.0, -3.0 + 6.0 * u(rng));
    if (kind == 0) {
        Sh3Radiance sh = project_constant(random_colour(rng, exposure * u(rng) * 0.2));
        const int lights = 1 + static_cast<int>(u(rng) * 4);
        for (int l = 0; l < lights; ++l) {
            const Vec3 d = test::uniform_direction(u(rng), u(rng));
            const Rgb c = random_colour(rng, exposure * std::pow(10.0, 2.0 * u(rng) - 1.0));
            sh = sh + (u(rng) < 0.5 ? project_directional(d, c) : project_cone(d, 0.05 + 1.5 * u(rng), c));
        }
        return sh;
    }
    if (kind == 1) {
        std::normal_distribution<double> g(0, 1);
        Sh3Radiance sh;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) sh[i][k] = static_cast<float>(exposure * g(rng));
        if (u(rng) < 0.5)
            for (int k = 0; k < 3; ++k) sh[0][k] = std::fabs(sh[0][k]) * 4;  // mostly positive
        return sh;
    }
    Sh3Radiance sh = rotate(maps[static_cast<size_t>(u(rng) * static_cast<double>(maps.size())) % maps.size()],
                            random_rotation(rng));
    return scale(sh, exposure);
}

// ---- error scale (see the file comment) ----------------------------------------------------------------

double ratio_bound_radiance(int i, L2Bound bound) {
    if (i < 4) return std::sqrt(3.0);
    if (i == 6) return std::sqrt(5.0);
    return bound == L2Bound::kTight ? std::sqrt(15.0) / 2 : std::sqrt(5.0);
}

struct Scale {
    double irradiance[3];  // S per channel
    double coeff[9][3];    // scale of each decoded coefficient
    bool defined = true;   // false: ill-conditioned axis (kappa infinite), not compared
};

Scale probe_scale(const GlslEntry& e, const CodecOptions& p, const Sh3Radiance& d) {
    Scale s;
    const bool quant = is_quantised(e.family);
    const double w[3] = {p.luminance.r, p.luminance.g, p.luminance.b};
    double m[9][3];
    for (int k = 0; k < 3; ++k) {
        const double dc = std::fabs(double(d[0][k]));
        m[0][k] = dc;
        for (int i = 1; i < 9; ++i)
            m[i][k] = quant ? std::max(std::fabs(double(d[i][k])), ratio_bound_radiance(i, p.l2_bound) * dc)
                            : std::fabs(double(d[i][k]));
    }
    // Axis condition numbers.
    double kappa[3] = {1, 1, 1};
    const std::uint32_t axis = axis_mode(e, p);
    auto vec = [&](int k) { return Vec3{-double(d[3][k]), -double(d[1][k]), double(d[2][k])}; };
    auto vmag = [&](int k) { return std::sqrt(m[1][k] * m[1][k] + m[2][k] * m[2][k] + m[3][k] * m[3][k]); };
    if (is_zonal(e)) {
        if (axis == 0) {
            Vec3 lum{};
            double mag = 0;
            for (int k = 0; k < 3; ++k) {
                lum = lum + w[k] * vec(k);
                mag += std::fabs(w[k]) * vmag(k);
            }
            const double len = length(lum);
            bool all_zero = true;  // every L1 exactly 0: both sides take +Z exactly
            for (int k = 0; k < 3; ++k) all_zero = all_zero && length(vec(k)) == 0;
            for (double& kk : kappa) kk = (mag == 0 || all_zero) ? 1 : (len > 0 ? mag / len : INFINITY);
        } else {
            for (int k = 0; k < 3; ++k) {
                const double len = length(vec(k)), mag = vmag(k);
                kappa[k] = (mag == 0 || len == 0) ? 1 : mag / len;  // v exactly 0: +Z on both sides
                if (!std::isfinite(len)) kappa[k] = INFINITY;
            }
        }
    }
    // Hallucination f20 = (A p + B) |f1| below the clamp: its rounding error is a few u of
    // (|A| p + |B|) |f1|, and the error of f1 (~ kappa u |v|) propagates with the slope 2 A p + B:
    // G = max over p in [0, sqrt3] of the sum of both factors.
    double g = 0;
    auto g_of = [](double a, double b) {
        const double pmax = std::sqrt(3.0);
        return std::fabs(a) * pmax + std::fabs(b) + std::max(std::fabs(b), std::fabs(2 * a * pmax + b));
    };
    if (e.hallucination == kHallAmbdir) g = 2 * std::sqrt(15.0) / 3;
    if (e.hallucination == kHallSphere) g = g_of(2 * std::sqrt(5.0) / 3, -std::sqrt(5.0 / 3));
    if (e.hallucination == kHallCurve) g = g_of(0.6, 0.08);
    if (e.hallucination == kHallCurveAdaptive) g = g_of(3.5 * 0.6, 3.5 * 0.08);  // largest scale code
    // Hallucination in the irradiance domain (float hall_* with irradiance storage): the stored L1
    // is 2/3 of the radiance one and the zonal 1/4: the slope in radiance units is 8/3 G.
    if (p.kind == StoredKind::kIrradiance && e.family == kSh2F32) g *= 8.0 / 3.0;
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(kappa[k])) s.defined = false;
        double l1 = m[1][k] + m[2][k] + m[3][k];
        double l2 = 0;
        double zonal_scale = 0;
        if (is_zonal(e)) {
            double f20 = 0;
            for (int i = 4; i < 9; ++i) f20 += double(d[i][k]) * double(d[i][k]);
            f20 = std::sqrt(f20);
            if (quant && e.hallucination == kHallNone) f20 = std::max(f20, std::sqrt(5.0) * m[0][k]);
            zonal_scale = (f20 + g * vmag(k)) * (1 + kappa[k]);
            l2 = 3 * kY20 * zonal_scale;
            // The axis also enters the hallucinated f1 = v.a (error ~ kappa u |v|), counted in G|v|.
        } else if (has_l2(e)) {
            for (int i = 4; i < 9; ++i) l2 += 0.631 * m[i][k];
        }
        s.irradiance[k] = kY00 * m[0][k] + (2.0 / 3.0) * kY1 * l1 + 0.25 * l2;
        for (int i = 0; i < 9; ++i) s.coeff[i][k] = (i >= 4 && is_zonal(e)) ? std::sqrt(3.0) * zonal_scale : m[i][k];
        // Irradiance storage rescales L1 by 3/2 and L2 by 4 in float: relative, inside the counts.
    }
    return s;
}

// Running maxima of |gpu - codec| / (u S) and the failure log of one encoding.
struct Tally {
    double max_irr = 0, max_dec = 0;
    long compared = 0, skipped_nonfinite = 0, skipped_illcond = 0, overflow_ok = 0, failures = 0;
    std::string first_failure;
};

// Compares one value; bound in units of u * scale.
void check_value(Tally& t, double* max_seen, double ref, float gpu, double scale, double c, const std::string& what) {
    if (!std::isfinite(ref)) {
        ++t.skipped_nonfinite;
        return;
    }
    ++t.compared;
    if (!std::isfinite(gpu)) {
        if (scale * 64 >= FLT_MAX) {
            ++t.overflow_ok;
            return;
        }
    } else {
        const double err = std::fabs(double(gpu) - ref);
        const double units = scale > 0 ? err / (kU * scale) : (err > 0 ? INFINITY : 0);
        if (err <= kAbs) return;
        *max_seen = std::max(*max_seen, units);
        if (err <= c * kU * scale + kAbs) return;
    }
    if (t.failures++ == 0) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s: codec %.9g gpu %.9g scale %.6g (%.2f u S, bound %.0f)", what.c_str(), ref,
                      double(gpu), scale, std::fabs(double(gpu) - ref) / (kU * scale), c);
        t.first_failure = buf;
    }
}

// Parameter sets for batch b of an encoding.
CodecOptions batch_params(const GlslEntry& e, std::string_view name, int b, std::mt19937_64& rng) {
    CodecOptions p;
    if (b == 0) return p;  // the defaults (Codec::irradiance is the reference)
    std::uniform_real_distribution<double> u(0, 1);
    if (b % 4 == 3) p.luminance = {0.05 + u(rng), 0.05 + u(rng), 0.05 + u(rng)};
    p.kind = (b % 2) ? StoredKind::kIrradiance : StoredKind::kRadiance;
    if (is_quantised(e.family)) {
        p.bits = 2 + (b * 3) % 7;
        p.sqrt_encoding = (b / 2) % 2;
        p.l2_bound = (b / 3) % 2 ? L2Bound::kLoose : L2Bound::kTight;
        p.dc_format = static_cast<DcFormat>(b % 3);
        if (e.family != kSh2Q && p.dc_format == DcFormat::kHalf) p.dc_format = DcFormat::kRGB9E5;
        p.zonal_mapping = static_cast<ZonalMapping>((b / 2) % 3);
        p.axis_mode = (b / 4) % 2 ? ZonalAxisMode::kPerChannel : ZonalAxisMode::kLuminance;
        if (b == 1) p.bits = 8;
    }
    EXPECT_TRUE(validate_quant_params(p, name).ok()) << name << " batch " << b;
    return p;
}

bool default_irradiance_path(const CodecOptions& p) {
    const CodecOptions d;
    return p.kind == StoredKind::kRadiance && p.zonal_mapping == d.zonal_mapping && p.axis_mode == d.axis_mode;
}

