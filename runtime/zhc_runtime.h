/*
 * zhc_runtime.h — the consuming side of every zhc probe encoding, for engines and shaders' CPU
 * twins. One header, C99 and C++11, no allocation, no global state; depends only on <stdint.h>,
 * <stddef.h>, <math.h> and <string.h>.
 *
 * Header-only: every function is `static inline` (no implementation macro, nothing to define;
 * include it from as many translation units as you like). Link nothing (CMake: zhc_runtime).
 *
 * What it does
 *   - zhc_probe_format: what gives stored probe bytes their meaning (the .zhp header fields,
 *     docs/zhp-container.md, and the glTF ZHC_light_probes "quantization" object,
 *     docs/gltf-extension.md).
 *   - zhc_decode_probe: stored bytes -> the hub, float SH3 radiance, 27 floats, index i*3+k
 *     (coefficient i = l(l+1)+m, channel k = R,G,B), zhc's basis and Z-up axes
 *     (docs/conventions.md: Y00 = 1/(2 sqrt pi), Y1 = sqrt(3/4pi)(-y, z, -x), Y2 = ...).
 *   - zhc_probe_irradiance: irradiance at a unit normal straight from the stored bytes (the runtime
 *     path of each codec table entry).
 *   - .zhp header parsing and validation (uncompressed bodies only).
 *   - IrradZ lightmaps (docs/irradz.md): HHD / AHD evaluation from (I_z, w_a, d), the BC5
 *     hemi-octahedral direction decode, HLSH evaluation and the HLSH hemisphere / cone multiply of a
 *     probe (probe occlusion).
 *   - Probe volumes (zhc_volume): the irradiance at any point of a probe grid, trilinear blend of
 *     the 8 surrounding probes' decoded SH3 (docs/runtime.md, "Probe volumes").
 *
 * Safety: every function here is total and safe for untrusted input unless its comment says
 * otherwise: any bytes decode to finite-or-NaN numbers, never undefined behaviour, never a read
 * outside the stated sizes. Pointer arguments must point at the stated number of elements.
 *
 * Exactness: the arithmetic is IEEE double in the same order as zhc's codec (the codec/ sources), so the
 * float results equal zhc's own decoder BIT FOR BIT (tests/test_runtime_c.cpp checks every codec
 * table entry, NaN-ness included). That needs: IEEE 754 binary64/binary32 with round-to-nearest,
 * no FMA contraction (GCC/Clang: -ffp-contract=off; MSVC: /fp:precise, the default), no
 * -ffast-math, FLT_EVAL_METHOD 0 (SSE2 on x86, any 64-bit target). The IrradZ functions that use
 * sin/cos/atan2 (clamp of d below the horizon, the quadrature tables of the HLSH multiply) are bit
 * exact only with the same libm as the encoder (the test measures 0 ulp on glibc); elsewhere they
 * differ by that libm's rounding. Without those compiler settings the results differ by rounding
 * only (a few ulp of the largest term; more relative error where terms cancel; not measured).
 * Known compiler issue: GCC 12.2 at -O3 (its SLP vectorizer) was seen to drop double -> float ->
 * double roundings in inlined code (the IrradZ C_a/C_d here; a test's own float normals), which
 * changes results by 1 ulp or, after cancellation, far more. Every intermediate float rounding the
 * codec does is therefore written through a volatile here (zhc__f32_round); with that, GCC 12 -O3
 * and Clang 14 -O3 both give the codec's bits in tests/test_runtime_c.cpp, no extra flags. Code that
 * rounds its own inputs to float before calling (as a float normal) may want the same care.
 *
 * Sources: Roughton et al. 2024, "ZH3: Quadratic Zonal Harmonics" (Eq. 2, 4, 5, 9, 14, 19-21,
 * Listing 1, App. A.1); Wiederien & Sloan, ATVI-TR-24-02 (tight L2 bound, Listing 1 quantiser);
 * Roughton, SIGGRAPH 2024 Advances, "IrradZ" (HHD/AHD, HLSH); DXGI R11G11B10F, RGB9E5
 * (EXT_texture_shared_exponent) and IEEE binary16 for the DC formats.
 */
#ifndef ZHC_RUNTIME_H
#define ZHC_RUNTIME_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- enums --------------------------------------------------------------------------------- */

/* Every codec table entry (codec/probe/codec_table.cpp `codecs()`, same order). Bytes per probe in (). */
enum zhc_encoding {
    ZHC_ENC_SH3 = 0,                  /* 27 floats (108): the hub */
    ZHC_ENC_SH2 = 1,                  /* 12 floats (48): DC + L1, L2 = 0 */
    ZHC_ENC_ZH3_LUM = 2,              /* 15 floats (60): DC + L1 + zonal f20 per channel, luminance axis */
    ZHC_ENC_ZH3_CHANNEL = 3,          /* 15 floats: per-channel axes */
    ZHC_ENC_ZH3_SOLVED_LUM = 4,       /* 15 floats: decoded as zh3_lum */
    ZHC_ENC_ZH3_SOLVED_CHANNEL = 5,   /* 15 floats: decoded as zh3_channel */
    ZHC_ENC_HALL_AMBDIR = 6,          /* 12 floats: zonal hallucinated, Eq. 14, luminance axis */
    ZHC_ENC_HALL_SPHERE = 7,          /* Eq. 20 */
    ZHC_ENC_HALL_CURVE = 8,           /* Eq. 21 (a, b) */
    ZHC_ENC_HALL_AMBDIR_CHANNEL = 9,  /* the same three on per-channel axes */
    ZHC_ENC_HALL_SPHERE_CHANNEL = 10,
    ZHC_ENC_HALL_CURVE_CHANNEL = 11,
    ZHC_ENC_ZH3_LUM_AXIS_CLAMP = 12,    /* 15 floats: decoded as zh3_lum */
    ZHC_ENC_ZH3_LUM_SPHERE_CLAMP = 13,  /* 15 floats: decoded as zh3_lum */
    ZHC_ENC_SH3_DERING = 14,            /* 27 floats: decoded as sh3 */
    ZHC_ENC_ZH3_Q16 = 15,             /* 16 bytes: DC (4) + per channel [L1-1, L10, L11, zonal] */
    ZHC_ENC_ZH3_SOLVED_Q16 = 16,      /* zh3_q16 bytes */
    ZHC_ENC_SH3_Q28 = 17,             /* 28 bytes: DC (4) + per channel [L1-1 .. L22] */
    ZHC_ENC_SH2_Q = 18,               /* 16 bytes: DC slot (6) + per channel [L1-1, L10, L11] + 0 */
    ZHC_ENC_HALL_CURVE_Q = 19,        /* sh2_q bytes, zonal hallucinated at decode (Eq. 21) */
    ZHC_ENC_ZH3_DERING = 20,          /* 15 floats: decoded as zh3_lum (deringing happens at encode) */
    ZHC_ENC_ZH3_DERING_Q16 = 21,      /* zh3_q16 bytes */
    ZHC_ENC_ZH3_CHANNEL_Q16 = 22,        /* zh3_q16 bytes, per-channel axes whatever axis_mode says */
    ZHC_ENC_ZH3_SOLVED_CHANNEL_Q16 = 23, /* zh3_channel_q16 bytes */
    ZHC_ENC_HALL_SOLVED = 24,         /* 12 floats: decoded as hall_curve (the L1 is solved at encode) */
    ZHC_ENC_HALL_SOLVED_Q16 = 25,     /* sh2_q bytes: decoded as hall_curve_q */
    ZHC_ENC_HALL_ADAPTIVE_Q16 = 26,   /* sh2_q bytes + byte 15 = scale code: f20 = (0.5 min(code, 7)) x Eq. 21 */
    ZHC_ENC_COUNT = 27
};
enum zhc_stored_kind { ZHC_KIND_RADIANCE = 0, ZHC_KIND_IRRADIANCE = 1 };
enum zhc_dc_format { ZHC_DC_R11G11B10F = 0, ZHC_DC_RGB9E5 = 1, ZHC_DC_HALF = 2 };
enum zhc_l2_bound { ZHC_L2_TIGHT = 0, ZHC_L2_LOOSE = 1 };
enum zhc_zonal_mapping { ZHC_ZONAL_AFFINE = 0, ZHC_ZONAL_ZERO_PRESERVING = 1, ZHC_ZONAL_SYMMETRIC = 2 };
enum zhc_axis_mode { ZHC_AXIS_LUMINANCE = 0, ZHC_AXIS_PER_CHANNEL = 1 };
enum zhc_irradz_model { ZHC_IRRADZ_HHD = 0, ZHC_IRRADZ_AHD = 1 };

/* Error codes: one numbering with zhc's library (codec/status.h ErrorCode has the same value for
 * every class both report; table in docs/inputs.md "Error classes"). */
enum zhc_error {
    ZHC_OK = 0,
    ZHC_ERR_ARGUMENT = 1,       /* unknown encoding name, invalid zhc_probe_format, null pointer */
    ZHC_ERR_TRUNCATED = 2,      /* fewer bytes than the header / the declared body */
    ZHC_ERR_BAD_FORMAT = 3,     /* bad magic, malformed field, reserved bytes set */
    ZHC_ERR_UNSUPPORTED = 4,    /* unknown version, representation or enum value */
    ZHC_ERR_CHECKSUM = 5,       /* header or body CRC-32 mismatch */
    ZHC_ERR_TOO_LARGE = 6,      /* probe count > 2^26 or body > 2 GiB (zhc's default limits) */
    ZHC_ERR_INVALID_VALUE = 7,  /* non-finite luminance weights, grid values or positions */
    ZHC_ERR_TRAILING_BYTES = 8, /* bytes after the declared body */
    ZHC_ERR_COMPRESSED = 9,     /* valid .zhp whose body is zstd-compressed: out of this header's scope */
    ZHC_ERR_NOT_GRID = 10       /* zhc_volume_from_zhp: a valid .zhp whose layout is not a grid (none, points) */
};

/* ---- the probe format ---------------------------------------------------------------------- */

typedef struct zhc_probe_format zhc_probe_format;
struct zhc_probe_format {
    int encoding;      /* enum zhc_encoding */
    int bits;          /* 2..8 bits per quantised ratio (packed encodings) */
    int sqrt_encoding; /* 0/1: sign-preserving square root of the ratios (W&S Listing 1) */
    int l2_bound;      /* enum zhc_l2_bound: non-zonal L2 interval sqrt(15)/2 or sqrt(5) */
    int dc_format;     /* enum zhc_dc_format (half: sh2_q / hall_curve_q only) */
    int zonal_mapping; /* enum zhc_zonal_mapping: how [-sqrt(5)/2, sqrt(5)] maps to [-1, 1] */
    int axis_mode;     /* enum zhc_axis_mode: zonal axis of zh3_q16, zh3_solved_q16, hall_curve_q */
    int kind;          /* enum zhc_stored_kind: the bytes hold radiance or irradiance SH */
    double luminance[3]; /* luminance weights of the luminance axis (default Rec. 709) */
    double hallucinate_a, hallucinate_b; /* Eq. 21 curve f20 = (a p^2 + b p) f0: 0.6, 0.08 */
};

/* The name of encoding e ("sh3", "zh3_q16", ...), or NULL when e is out of range. */
static inline const char* zhc_encoding_name(int e) {
    static const char* const names[ZHC_ENC_COUNT] = {
        "sh3", "sh2", "zh3_lum", "zh3_channel", "zh3_solved_lum", "zh3_solved_channel", "hall_ambdir",
        "hall_sphere", "hall_curve", "hall_ambdir_channel", "hall_sphere_channel", "hall_curve_channel",
        "zh3_lum_axis_clamp", "zh3_lum_sphere_clamp", "sh3_dering", "zh3_q16", "zh3_solved_q16", "sh3_q28",
        "sh2_q", "hall_curve_q", "zh3_dering", "zh3_dering_q16", "zh3_channel_q16", "zh3_solved_channel_q16",
        "hall_solved", "hall_solved_q16", "hall_adaptive_q16"};
    return (e >= 0 && e < ZHC_ENC_COUNT) ? names[e] : NULL;
}

/* The other names an encoding answers to when read (codec/probe/codec_table.cpp codec_aliases():
 * App. B's zonal clamps leave irradiance negative where no zonal value helps, so only entries that
 * keep it >= 0 carry "dering" in their names). The entry's own name when `name` is an alias, else
 * `name` itself. */
#define ZHC_ENC_ZH3_LUM_DERING ZHC_ENC_ZH3_LUM_AXIS_CLAMP
#define ZHC_ENC_ZH3_LUM_DERING_SPHERE ZHC_ENC_ZH3_LUM_SPHERE_CLAMP
static inline const char* zhc__encoding_alias(const char* name) {
    static const char* const aliases[][2] = {{"zh3_lum_dering", "zh3_lum_axis_clamp"},
                                             {"zh3_lum_dering_sphere", "zh3_lum_sphere_clamp"}};
    size_t i;
    for (i = 0; i < sizeof aliases / sizeof aliases[0]; ++i)
        if (strcmp(name, aliases[i][0]) == 0) return aliases[i][1];
    return name;
}

/* Encoding from a NUL-terminated name or an alias of one (zhc__encoding_alias); -1 when unknown
 * (or NULL). */
static inline int zhc_encoding_from_name(const char* name) {
    int e;
    if (!name) return -1;
    name = zhc__encoding_alias(name);
    for (e = 0; e < ZHC_ENC_COUNT; ++e)
        if (strcmp(name, zhc_encoding_name(e)) == 0) return e;
    return -1;
}

/* Stored bytes per probe of encoding e; 0 when e is out of range. */
static inline size_t zhc_encoding_size(int e) {
    static const unsigned char sizes[ZHC_ENC_COUNT] = {108, 48, 60, 60, 60, 60, 48, 48, 48, 48,
                                                       48,  48, 60, 60, 108, 16, 16, 28, 16, 16, 60, 16,
                                                       16,  16, 48, 16, 16};
    return (e >= 0 && e < ZHC_ENC_COUNT) ? sizes[e] : 0;
}

/* 1 for the packed (quantised) encodings zh3_q16, zh3_solved_q16, sh3_q28, sh2_q, hall_curve_q,
 * zh3_dering_q16, zh3_channel_q16, zh3_solved_channel_q16, hall_solved_q16, hall_adaptive_q16. */
static inline int zhc_encoding_is_packed(int e) {
    return (e >= ZHC_ENC_ZH3_Q16 && e <= ZHC_ENC_HALL_CURVE_Q) || e == ZHC_ENC_ZH3_DERING_Q16 ||
           e == ZHC_ENC_ZH3_CHANNEL_Q16 || e == ZHC_ENC_ZH3_SOLVED_CHANNEL_Q16 || e == ZHC_ENC_HALL_SOLVED_Q16 ||
           e == ZHC_ENC_HALL_ADAPTIVE_Q16;
}
/* 1 for the packed encodings in zh3_q16 bytes that fix each channel's own axis (f->axis_mode unused). */
static inline int zhc__packed_per_channel(int e) {
    return e == ZHC_ENC_ZH3_CHANNEL_Q16 || e == ZHC_ENC_ZH3_SOLVED_CHANNEL_Q16;
}
/* The packed encodings in sh2_q's 16-byte layout (6-byte DC slot; hallucinated except sh2_q). */
static inline int zhc__sh2q_layout(int e) {
    return e == ZHC_ENC_SH2_Q || e == ZHC_ENC_HALL_CURVE_Q || e == ZHC_ENC_HALL_SOLVED_Q16 ||
           e == ZHC_ENC_HALL_ADAPTIVE_Q16;
}

/* Defaults of `zhc convert --to ENCODING` (cli/cmd_convert.cpp, codec/probe/quantize.h CodecOptions):
 * 8 bits, no sqrt, tight bound, R11G11B10F DC, affine zonal mapping, luminance axis, radiance,
 * Rec. 709 weights (0.2126, 0.7152, 0.0722), Eq. 21 a = 0.6, b = 0.08.
 * Returns ZHC_OK, or ZHC_ERR_ARGUMENT for an unknown name (f then holds the defaults with
 * encoding -1). Safe for untrusted input (name may be any NUL-terminated string). */
static inline int zhc_probe_format_init(zhc_probe_format* f, const char* encoding) {
    if (!f) return ZHC_ERR_ARGUMENT;
    f->encoding = zhc_encoding_from_name(encoding);
    f->bits = 8;
    f->sqrt_encoding = 0;
    f->l2_bound = ZHC_L2_TIGHT;
    f->dc_format = ZHC_DC_R11G11B10F;
    f->zonal_mapping = ZHC_ZONAL_AFFINE;
    f->axis_mode = ZHC_AXIS_LUMINANCE;
    f->kind = ZHC_KIND_RADIANCE;
    f->luminance[0] = 0.2126;
    f->luminance[1] = 0.7152;
    f->luminance[2] = 0.0722;
    f->hallucinate_a = 0.6;
    f->hallucinate_b = 0.08;
    return f->encoding < 0 ? ZHC_ERR_ARGUMENT : ZHC_OK;
}

/* One property of a glTF ZHC_light_probes volume (docs/gltf-extension.md) as its JSON text:
 *   "kind": "radiance" | "irradiance"        "bits": "2" .. "8"        "sqrt": "true" | "false"
 *   "l2Bound": "tight" | "loose"             "dcFormat": "r11g11b10f" | "rgb9e5" | "half"
 *   "zonalMapping": "affine" | "zero" | "symmetric"      "axisMode": "luminance" | "channel"
 * (the "quantization" object's members and the volume's "kind"; "luminanceWeights" are numbers:
 * set f->luminance directly). ZHC_OK, ZHC_ERR_UNSUPPORTED for an unknown value (as zhc's glTF
 * reader), ZHC_ERR_ARGUMENT for an unknown key; f is unchanged on error. Safe for untrusted input
 * (NUL-terminated strings). */
static inline int zhc_probe_format_set_gltf(zhc_probe_format* f, const char* key, const char* value) {
    static const char* const kinds[] = {"radiance", "irradiance"};
    static const char* const bounds[] = {"tight", "loose"};
    static const char* const dcs[] = {"r11g11b10f", "rgb9e5", "half"};
    static const char* const mappings[] = {"affine", "zero", "symmetric"};
    static const char* const axes[] = {"luminance", "channel"};
    static const char* const bools[] = {"false", "true"};
    const char* const* names;
    int count, i, *field;
    if (!f || !key || !value) return ZHC_ERR_ARGUMENT;
    if (strcmp(key, "bits") == 0) {
        if (value[0] < '2' || value[0] > '8' || value[1] != 0) return ZHC_ERR_UNSUPPORTED;
        f->bits = value[0] - '0';
        return ZHC_OK;
    }
    if (strcmp(key, "kind") == 0) names = kinds, count = 2, field = &f->kind;
    else if (strcmp(key, "l2Bound") == 0) names = bounds, count = 2, field = &f->l2_bound;
    else if (strcmp(key, "dcFormat") == 0) names = dcs, count = 3, field = &f->dc_format;
    else if (strcmp(key, "zonalMapping") == 0) names = mappings, count = 3, field = &f->zonal_mapping;
    else if (strcmp(key, "axisMode") == 0) names = axes, count = 2, field = &f->axis_mode;
    else if (strcmp(key, "sqrt") == 0) names = bools, count = 2, field = &f->sqrt_encoding;
    else return ZHC_ERR_ARGUMENT;
    for (i = 0; i < count; ++i)
        if (strcmp(value, names[i]) == 0) {
            *field = i;
            return ZHC_OK;
        }
    return ZHC_ERR_UNSUPPORTED;
}

/* ZHC_OK when f is a format zhc's writer can produce (codec/probe/quantize.cpp validate_quant_params):
 * known encoding, bits 2..8, enums in range, finite luminance weights and curve constants, half DC
 * only with the sh2_q layout (sh2_q, hall_curve_q, hall_solved_q16, hall_adaptive_q16) among the packed ones. */
static inline int zhc_probe_format_validate(const zhc_probe_format* f) {
    if (!f || !zhc_encoding_name(f->encoding)) return ZHC_ERR_ARGUMENT;
    if (f->bits < 2 || f->bits > 8) return ZHC_ERR_ARGUMENT;
    if (f->sqrt_encoding < 0 || f->sqrt_encoding > 1 || f->l2_bound < 0 || f->l2_bound > 1 || f->dc_format < 0 ||
        f->dc_format > 2 || f->zonal_mapping < 0 || f->zonal_mapping > 2 || f->axis_mode < 0 || f->axis_mode > 1 ||
        f->kind < 0 || f->kind > 1)
        return ZHC_ERR_ARGUMENT;
    if (!isfinite(f->luminance[0]) || !isfinite(f->luminance[1]) || !isfinite(f->luminance[2]) ||
        !isfinite(f->hallucinate_a) || !isfinite(f->hallucinate_b))
        return ZHC_ERR_ARGUMENT;
    /* Only the 6-byte DC slot of sh2_q's layout holds a half triple (the codec decides by layout too). */
    if (f->dc_format == ZHC_DC_HALF && zhc_encoding_is_packed(f->encoding) && !zhc__sh2q_layout(f->encoding))
        return ZHC_ERR_ARGUMENT;
    return ZHC_OK;
}

/* Stored bytes per probe of f (0 for an unknown encoding). */
static inline size_t zhc_probe_size(const zhc_probe_format* f) { return f ? zhc_encoding_size(f->encoding) : 0; }

/* ---- internal helpers (zhc__ prefix: not part of the API) ---------------------------------- */

#define ZHC__PI 3.14159265358979323846
/* Basis constants (ZH3 paper Eq. 4/5), computed exactly as codec/sh/sh.h does (sqrt is correctly
 * rounded, so these are the same doubles everywhere). */
#define ZHC__Y00 (1.0 / (2.0 * sqrt(ZHC__PI)))
#define ZHC__Y1 sqrt(3.0 / (4.0 * ZHC__PI))
#define ZHC__Y2 sqrt(15.0 / (4.0 * ZHC__PI))
#define ZHC__Y20 sqrt(5.0 / (16.0 * ZHC__PI))
#define ZHC__Y22 sqrt(15.0 / (16.0 * ZHC__PI))
/* Irradiance band scales of the normalised clamped cosine: 1, 2/3, 1/4 (Ramamoorthi & Hanrahan). */
#define ZHC__BAND1 (2.0 / 3.0)
#define ZHC__BAND2 (1.0 / 4.0)

/* x rounded to float and back: the codec's intermediate float roundings (and floats this header
 * wrote and reads back for more double arithmetic). Through a volatile because GCC 12.2 at -O3 was
 * seen to drop such roundings when SLP-vectorizing inlined code (wrong code: the tests caught
 * differences of 1 ulp and, after cancellation, far more; a 40-line reproducer is in the project
 * notes); a volatile store cannot be elided. Costs one store and load. */
static inline double zhc__f32_round(double x) {
    volatile float f = (float)x;
    return f;
}

/* std::clamp / std::max / std::min semantics (NaN behaviour included). */
static inline double zhc__clamp(double v, double lo, double hi) { return v < lo ? lo : (hi < v ? hi : v); }
static inline double zhc__max(double a, double b) { return a < b ? b : a; }

static inline uint32_t zhc__u32(const uint8_t* p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static inline uint64_t zhc__u64(const uint8_t* p) { return (uint64_t)zhc__u32(p) | ((uint64_t)zhc__u32(p + 4) << 32); }
static inline float zhc__f32(const uint8_t* p) {
    uint32_t b = zhc__u32(p);
    float v;
    memcpy(&v, &b, 4);
    return v;
}
static inline double zhc__f64(const uint8_t* p) {
    uint64_t b = zhc__u64(p);
    double v;
    memcpy(&v, &b, 8);
    return v;
}

/* The nine SH3 basis functions at unit direction d (codec/sh/sh.h sh3_basis). */
static inline void zhc__sh3_basis(const double d[3], double y[9]) {
    const double x = d[0], yy = d[1], z = d[2];
    y[0] = ZHC__Y00;
    y[1] = -ZHC__Y1 * yy;
    y[2] = ZHC__Y1 * z;
    y[3] = -ZHC__Y1 * x;
    y[4] = ZHC__Y2 * x * yy;
    y[5] = -ZHC__Y2 * yy * z;
    y[6] = ZHC__Y20 * (3.0 * z * z - 1.0);
    y[7] = -ZHC__Y2 * x * z;
    y[8] = ZHC__Y22 * (x * x - yy * yy);
}

/* normalize_or(a, +Z): a / |a|, or +Z when |a| is 0 or not finite. */
static inline void zhc__normalize_or_z(const double a[3], double out[3]) {
    const double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double s;
    if (!(len > 0.0) || !isfinite(len)) {
        out[0] = 0.0;
        out[1] = 0.0;
        out[2] = 1.0;
        return;
    }
    s = 1.0 / len;
    out[0] = s * a[0];
    out[1] = s * a[1];
    out[2] = s * a[2];
}

/* ---- shared evaluation --------------------------------------------------------------------- */

/* Irradiance at unit normal n of SH radiance with `count` (4 or 9) coefficients, sh[i*3+k]:
 * E(n) = sum_i s_l c_i Y_i(n), s_l = 1, 2/3, 1/4, the scaled coefficients rounded to float first
 * (codec/sh/sh.cpp irradiance = evaluate(to_irradiance(L), n)). */
static inline void zhc__sh_irradiance(const float* sh, int count, const double n[3], float rgb[3]) {
    double y[9], acc[3] = {0.0, 0.0, 0.0};
    int i, k;
    zhc__sh3_basis(n, y);
    for (i = 0; i < count; ++i) {
        const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
        for (k = 0; k < 3; ++k) acc[k] += zhc__f32_round(sh[i * 3 + k] * s) * y[i];
    }
    for (k = 0; k < 3; ++k) rgb[k] = (float)acc[k];
}

/* Irradiance at unit normal n (double) of SH3 radiance sh3[27]: bit-equal to zhc::irradiance. */
static inline void zhc_sh3_irradiance(const float sh3[27], const double n[3], float rgb[3]) {
    zhc__sh_irradiance(sh3, 9, n, rgb);
}

/* ---- ZH3 (codec/probe/zh3_fit.cpp) --------------------------------------------------------------- */

/* Zonal axes of the three channels from the linear SH lin[12] (DC, L1-1, L10, L11 x RGB):
 * luminance mode: normalize(sum_k w_k v_k), per-channel: normalize(v_k), with the L1 vector
 * v = (-f11, -f1-1, f10) (the optimal linear direction, ZH3 paper Sec. 3.1/3.2); +Z when zero. */
static inline void zhc__zh3_axes(const float lin[12], int per_channel, const double w[3], double axes[3][3]) {
    double v[3][3], s[3];
    int k;
    for (k = 0; k < 3; ++k) {
        v[k][0] = -(double)lin[9 + k];
        v[k][1] = -(double)lin[3 + k];
        v[k][2] = (double)lin[6 + k];
    }
    if (!per_channel) {
        for (k = 0; k < 3; ++k) s[k] = w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k];
        zhc__normalize_or_z(s, axes[0]);
        memcpy(axes[1], axes[0], sizeof axes[0]);
        memcpy(axes[2], axes[0], sizeof axes[0]);
    } else {
        for (k = 0; k < 3; ++k) zhc__normalize_or_z(v[k], axes[k]);
    }
}

/* ZH3 expansion to the hub (Eq. 2 on a zonal function): L2 of channel k is
 * f20_k sqrt(4 pi / 5) Y2(a_k); DC and L1 are copied. */
static inline void zhc__zh3_expand(const float lin[12], const float zonal[3], int per_channel, const double w[3],
                                   float out[27]) {
    double axes[3][3], y[9];
    const double s = sqrt(4.0 * ZHC__PI / 5.0);
    int k, m;
    zhc__zh3_axes(lin, per_channel, w, axes);
    memcpy(out, lin, 12 * sizeof(float));
    for (k = 0; k < 3; ++k) {
        zhc__sh3_basis(axes[k], y);
        for (m = 0; m < 5; ++m) out[(4 + m) * 3 + k] = (float)((double)zonal[k] * s * y[4 + m]);
    }
}

/* ZH3 irradiance at n (Listing 1): E_k = Y00 f0 + (2/3) Y1 (v_k . n) + (1/4) f20 Y20 (3 z^2 - 1),
 * z = a_k . n. */
static inline void zhc__zh3_irradiance(const float lin[12], const float zonal[3], int per_channel, const double w[3],
                                       const double n[3], float rgb[3]) {
    double axes[3][3];
    int k;
    zhc__zh3_axes(lin, per_channel, w, axes);
    for (k = 0; k < 3; ++k) {
        const double* a = axes[k];
        const double z = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        const double vx = -(double)lin[9 + k], vy = -(double)lin[3 + k], vz = (double)lin[6 + k];
        const double e = ZHC__Y00 * (double)lin[k] + ZHC__BAND1 * ZHC__Y1 * (vx * n[0] + vy * n[1] + vz * n[2]) +
                         ZHC__BAND2 * (double)zonal[k] * ZHC__Y20 * (3.0 * z * z - 1.0);
        rgb[k] = (float)e;
    }
}

/* Hallucinated radiance zonal coefficient (ZH3 paper Sec. 3.4, Listing 1) from DC f0 and the L1
 * projected on the zonal axis f1 (its absolute value is used), p = clamp(|f1| / f0, 0, sqrt 3):
 *   model 0 (Eq. 14, ambient + directional): f20 = sqrt(15)/3 |f1|
 *   model 1 (Eq. 19/20, sphere light):       f20 = (2 sqrt(5)/3 p^2 - sqrt(5/3) p) f0
 *   model 2 (Eq. 21, curve fit):             f20 = (a p^2 + b p) f0
 * f0 <= 0 or not finite gives 0 for models 1 and 2. */
static inline double zhc_hallucinate_zonal(int model, double f0, double f1, double a, double b) {
    double p;
    f1 = fabs(f1);
    if (model == 0) return sqrt(15.0) / 3.0 * f1;
    if (!(f0 > 0) || !isfinite(f0)) return 0.0;
    p = zhc__clamp(f1 / f0, 0.0, sqrt(3.0));
    if (model == 1) return (2.0 * sqrt(5.0) / 3.0 * p * p - sqrt(5.0 / 3.0) * p) * f0;
    return (a * p * p + b * p) * f0;
}

/* Hallucinated zonal coefficients of the three channels (codec/probe/zh3_hallucinate.cpp). */
static inline void zhc__hallucinate(const float lin[12], int model, int per_channel, const double w[3], double a,
                                    double b, float zonal[3]) {
    double axes[3][3];
    int k;
    zhc__zh3_axes(lin, per_channel, w, axes);
    for (k = 0; k < 3; ++k) {
        const double vx = -(double)lin[9 + k], vy = -(double)lin[3 + k], vz = (double)lin[6 + k];
        const double f1 = vx * axes[k][0] + vy * axes[k][1] + vz * axes[k][2];
        zonal[k] = (float)zhc__f32_round(zhc_hallucinate_zonal(model, (double)lin[k], f1, a, b));
    }
}

/* ---- DC formats (codec/probe/quantize.cpp) ------------------------------------------------------- */

/* Unsigned float with a 5-bit exponent (bias 15) and mbits mantissa bits; exponent 31 is
 * +Inf (mantissa 0) or NaN, as the hardware formats. */
static inline float zhc__unpack_ufloat(uint32_t code, int mbits) {
    const uint32_t e = code >> mbits, m = code & ((1u << mbits) - 1u);
    if (e == 0) return (float)ldexp((double)m, -14 - mbits);
    if (e == 31) return m == 0 ? (float)INFINITY : (float)NAN;
    return (float)ldexp(1.0 + ldexp((double)m, -mbits), (int)e - 15);
}

/* DXGI_FORMAT_R11G11B10_FLOAT: R bits 0-10, G 11-21, B 22-31 (6/6/5 mantissa bits). */
static inline void zhc_unpack_r11g11b10f(uint32_t bits, float rgb[3]) {
    rgb[0] = zhc__unpack_ufloat(bits & 0x7FFu, 6);
    rgb[1] = zhc__unpack_ufloat((bits >> 11) & 0x7FFu, 6);
    rgb[2] = zhc__unpack_ufloat(bits >> 22, 5);
}

/* DXGI_FORMAT_R9G9B9E5_SHAREDEXP: value = mantissa * 2^(e - 15 - 9). */
static inline void zhc_unpack_rgb9e5(uint32_t bits, float rgb[3]) {
    const int e = (int)(bits >> 27) - 15 - 9;
    rgb[0] = (float)ldexp((double)(bits & 0x1FFu), e);
    rgb[1] = (float)ldexp((double)((bits >> 9) & 0x1FFu), e);
    rgb[2] = (float)ldexp((double)((bits >> 18) & 0x1FFu), e);
}

/* IEEE 754 binary16. */
static inline float zhc_unpack_half(uint16_t bits) {
    const float mag = zhc__unpack_ufloat(bits & 0x7FFFu, 10);
    return (bits & 0x8000u) ? -mag : mag;
}

/* ---- the ratio quantiser (codec/probe/quantize.cpp RatioCoder::decode) --------------------------- */

/* Interval [lo, hi] of c_i / c_0 (ZH3 App. A; W&S Sec. 3) for SH index i (1..8), or of the ZH3
 * zonal coefficient (zonal_coef = 1): L1 +-sqrt(3); L2 zonal [-sqrt(5)/2, sqrt(5)]; L2 non-zonal
 * +-sqrt(15)/2 (tight) or +-sqrt(5) (loose); irradiance scales them by 2/3 (L1), 1/4 (L2). */
static inline void zhc__ratio_interval(int i, int zonal_coef, int kind, int l2_bound, double* lo, double* hi) {
    const int l = (zonal_coef || i >= 4) ? 2 : 1;
    const double s = kind == ZHC_KIND_IRRADIANCE ? (l == 1 ? ZHC__BAND1 : ZHC__BAND2) : 1.0;
    if (l == 1) {
        *lo = -sqrt(3.0) * s;
        *hi = sqrt(3.0) * s;
    } else if (zonal_coef || i == 6) {
        *lo = -sqrt(5.0) / 2.0 * s;
        *hi = sqrt(5.0) * s;
    } else {
        const double b = (l2_bound == ZHC_L2_TIGHT ? sqrt(15.0) / 2.0 : sqrt(5.0)) * s;
        *lo = -b;
        *hi = b;
    }
}

/* Decoded ratio of a stored code (docs/quantization.md Sec. 2): bv = 2^(bits-1) - 1,
 * q = min(code, 2 bv), t = (q - bv) / bv, with sqrt t = t |t|; then t -> ratio: affine
 * ((t (hi - lo) + (hi + lo)) / 2) for every coefficient except the zonal ones under the
 * zero-preserving (t hi or t (-lo)) or symmetric (t max(hi, -lo)) mapping. */
static inline double zhc__ratio_decode(const zhc_probe_format* f, int i, int zonal_coef, uint8_t code) {
    const int bv = (1 << (f->bits - 1)) - 1;
    const int c = code < 2 * bv ? code : 2 * bv;
    const int zonal = zonal_coef || i == 6;
    double lo, hi, t = (double)(c - bv) / bv;
    zhc__ratio_interval(i, zonal_coef, f->kind, f->l2_bound, &lo, &hi);
    if (f->sqrt_encoding) t = t * fabs(t);
    if (!zonal || f->zonal_mapping == ZHC_ZONAL_AFFINE) return 0.5 * (t * (hi - lo) + (hi + lo));
    if (f->zonal_mapping == ZHC_ZONAL_ZERO_PRESERVING) return t >= 0 ? t * hi : t * -lo;
    return t * zhc__max(hi, -lo);
}

/* Packed layouts -> the stored-domain coefficients q[i][k] (double) of the layout, then divided by
 * the band scale (irradiance kind) and rounded to float: codec/probe/quantize.cpp decode_packed. */
static inline void zhc__decode_packed(const zhc_probe_format* f, const uint8_t* in, float out[27]) {
    double q[9][3];
    float dc[3];
    int i, k, last;
    const int layout = (f->encoding == ZHC_ENC_SH3_Q28) ? 1 : (zhc__sh2q_layout(f->encoding) ? 2 : 0);
    /* A 4-byte DC slot cannot hold half: there half means R11G11B10F (zhc never writes it). */
    const int dcf = (f->dc_format == ZHC_DC_HALF && layout != 2) ? ZHC_DC_R11G11B10F : f->dc_format;
    memset(q, 0, sizeof q);
    if (dcf == ZHC_DC_RGB9E5) {
        zhc_unpack_rgb9e5(zhc__u32(in), dc);
    } else if (dcf == ZHC_DC_HALF) {
        for (k = 0; k < 3; ++k) dc[k] = zhc_unpack_half((uint16_t)(in[2 * k] | (in[2 * k + 1] << 8)));
    } else {
        zhc_unpack_r11g11b10f(zhc__u32(in), dc);
    }
    last = layout == 1 ? 8 : 3;
    for (k = 0; k < 3; ++k) {
        q[0][k] = dc[k];
        for (i = 1; i <= last; ++i) {
            const int off = layout == 0 ? 4 + 4 * k + (i - 1) : (layout == 1 ? 4 + 8 * k + (i - 1) : 6 + 3 * k + (i - 1));
            q[i][k] = zhc__ratio_decode(f, i, 0, in[off]) * dc[k];
        }
    }
    if (layout == 0) {
        /* zh3_q16: the zonal axis from the dequantised L1 (rounded to float), the L2 band is
         * zq * sqrt(4 pi / 5) Y2(axis) (ZH3 paper Eq. 2/6). */
        float lin[12];
        double axes[3][3], y[9];
        const double s = sqrt(4.0 * ZHC__PI / 5.0);
        for (i = 0; i < 4; ++i)
            for (k = 0; k < 3; ++k) lin[i * 3 + k] = (float)zhc__f32_round(q[i][k]);
        zhc__zh3_axes(lin, f->axis_mode == ZHC_AXIS_PER_CHANNEL || zhc__packed_per_channel(f->encoding), f->luminance,
                      axes);
        for (k = 0; k < 3; ++k) {
            const double zq = zhc__ratio_decode(f, 6, 1, in[4 + 4 * k + 3]) * dc[k];
            zhc__sh3_basis(axes[k], y);
            for (i = 0; i < 5; ++i) q[4 + i][k] = zq * (s * y[4 + i]);
        }
    }
    for (i = 0; i < 9; ++i) {
        const double s = f->kind == ZHC_KIND_IRRADIANCE ? (i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2)) : 1.0;
        for (k = 0; k < 3; ++k) out[i * 3 + k] = (float)(q[i][k] / s);
    }
}

/* ---- decoding ------------------------------------------------------------------------------ */

/* Which decoder an encoding uses. */
enum { ZHC__D_SH3, ZHC__D_SH2, ZHC__D_ZH3, ZHC__D_HALL, ZHC__D_PACKED };
static inline int zhc__decoder(int e) {
    if (e == ZHC_ENC_SH3 || e == ZHC_ENC_SH3_DERING) return ZHC__D_SH3;
    if (e == ZHC_ENC_SH2) return ZHC__D_SH2;
    if ((e >= ZHC_ENC_HALL_AMBDIR && e <= ZHC_ENC_HALL_CURVE_CHANNEL) || e == ZHC_ENC_HALL_SOLVED) return ZHC__D_HALL;
    if (zhc_encoding_is_packed(e)) return ZHC__D_PACKED;
    return ZHC__D_ZH3;
}
/* Hallucination model of the float hallucinated encodings (0 Eq. 14, 1 Eq. 20, 2 Eq. 21). */
static inline int zhc__hall_model(int e) { return e == ZHC_ENC_HALL_SOLVED ? 2 : (e - ZHC_ENC_HALL_AMBDIR) % 3; }
/* Per-channel axes for the float ZH3 / hallucinated encodings (their own mode, not f->axis_mode). */
static inline int zhc__float_per_channel(int e) {
    return e == ZHC_ENC_ZH3_CHANNEL || e == ZHC_ENC_ZH3_SOLVED_CHANNEL ||
           (e >= ZHC_ENC_HALL_AMBDIR_CHANNEL && e <= ZHC_ENC_HALL_CURVE_CHANNEL);
}

/* Decodes one probe: `bytes` holds zhc_probe_size(f) bytes (any values: safe for untrusted
 * input); writes the hub, SH3 radiance, radiance_sh3[i*3+k] (coefficient i, channel k).
 * Equals zhc::decode_probe(codec, params, bytes) bit for bit:
 *   sh3, sh3_dering: the 27 little-endian floats; sh2: 12 floats, L2 = 0.
 *   zh3_*: L2_k = f20_k sqrt(4pi/5) Y2(a_k), a_k the zonal axis from the stored L1.
 *   hall_*: f20 hallucinated (zhc_hallucinate_zonal) then expanded as zh3.
 *   packed: DC decoded, c_i = ratio(code) DC (docs/quantization.md); zh3_q16 adds the zonal L2 on
 *     the axis of the dequantised L1 (f->axis_mode; zh3_channel_q16, zh3_solved_channel_q16: always
 *     each channel's own); hall_curve_q adds the Eq. 21 zonal L2 to the
 *     decoded sh2_q on f->axis_mode's axis.
 *   kind = irradiance: the stored band-scaled coefficients are turned back into radiance
 *     (float entries: c * (1 / s_l), rounded to float; packed: q / s_l, as zhc does).
 * Returns ZHC_OK, or ZHC_ERR_ARGUMENT (output zeroed) when zhc_probe_format_validate fails. */
static inline int zhc_decode_probe(const zhc_probe_format* f, const void* bytes, float radiance_sh3[27]) {
    const uint8_t* in = (const uint8_t*)bytes;
    float lin[12], zonal[3];
    int i, k, per_channel;
    memset(radiance_sh3, 0, 27 * sizeof(float));
    if (zhc_probe_format_validate(f) != ZHC_OK || !bytes) return ZHC_ERR_ARGUMENT;
    switch (zhc__decoder(f->encoding)) {
        case ZHC__D_SH3:
            for (i = 0; i < 27; ++i) radiance_sh3[i] = zhc__f32(in + 4 * i);
            break;
        case ZHC__D_SH2:
            for (i = 0; i < 12; ++i) radiance_sh3[i] = zhc__f32(in + 4 * i);
            break;
        case ZHC__D_ZH3:
            for (i = 0; i < 12; ++i) lin[i] = zhc__f32(in + 4 * i);
            for (k = 0; k < 3; ++k) zonal[k] = zhc__f32(in + 48 + 4 * k);
            zhc__zh3_expand(lin, zonal, zhc__float_per_channel(f->encoding), f->luminance, radiance_sh3);
            break;
        case ZHC__D_HALL:
            per_channel = zhc__float_per_channel(f->encoding);
            for (i = 0; i < 12; ++i) lin[i] = zhc__f32(in + 4 * i);
            zhc__hallucinate(lin, zhc__hall_model(f->encoding), per_channel, f->luminance, f->hallucinate_a,
                             f->hallucinate_b, zonal);
            zhc__zh3_expand(lin, zonal, per_channel, f->luminance, radiance_sh3);
            break;
        default:
            zhc__decode_packed(f, in, radiance_sh3);
            if (zhc__sh2q_layout(f->encoding) && f->encoding != ZHC_ENC_SH2_Q) {
                /* ZH3 paper Sec. 3.4.3, Eq. 21 on the decoder's axis (quantize.cpp hallucinate_curve);
                 * hall_adaptive_q16 scales a and b by s = 0.5 min(byte 15, 7) (codec/probe/zh3_hall_solve.cpp). */
                const double s = f->encoding == ZHC_ENC_HALL_ADAPTIVE_Q16 ? 0.5 * (in[15] < 7 ? in[15] : 7) : 1.0;
                per_channel = f->axis_mode == ZHC_AXIS_PER_CHANNEL;
                for (i = 0; i < 12; ++i) lin[i] = (float)zhc__f32_round(radiance_sh3[i]);
                zhc__hallucinate(lin, 2, per_channel, f->luminance, s * f->hallucinate_a, s * f->hallucinate_b, zonal);
                zhc__zh3_expand(lin, zonal, per_channel, f->luminance, radiance_sh3);
            }
            return ZHC_OK;
    }
    if (f->kind == ZHC_KIND_IRRADIANCE) {
        /* codec/sh/sh.h to_radiance: inverse band scales 1, 1 / (2/3), 1 / (1/4). */
        for (i = 0; i < 9; ++i) {
            const double s = i == 0 ? 1.0 / 1.0 : (i < 4 ? 1.0 / ZHC__BAND1 : 1.0 / ZHC__BAND2);
            for (k = 0; k < 3; ++k) radiance_sh3[i * 3 + k] = (float)(zhc__f32_round(radiance_sh3[i * 3 + k]) * s);
        }
    }
    return ZHC_OK;
}

/* Irradiance (normalised clamped-cosine convolution: constant radiance 1 gives 1) at the unit
 * normal n, world axes, straight from the stored bytes; `bytes` as zhc_decode_probe (any values).
 * With kind = radiance it is what the codec table entry's `irradiance` does, bit for bit:
 *   sh3, sh2, sh3_dering: sum_i s_l c_i Y_i(n) over the stored coefficients (4 for sh2);
 *   zh3_*, hall_*: Listing 1, E = Y00 f0 + (2/3) Y1 (L1 . n) + (1/4) f20 Y20 (3 (a.n)^2 - 1);
 *   packed: the SH3 irradiance of the decoded hub.
 * With kind = irradiance: the SH3 irradiance of the decoded (radiance) hub, i.e.
 * zhc::irradiance(zhc::decode_probe(...), n). An invalid format writes zeros.
 * n need not be normalised (the result scales with it); it is used as given. */
static inline void zhc_probe_irradiance_d(const zhc_probe_format* f, const void* bytes, const double n[3], float rgb[3]) {
    const uint8_t* in = (const uint8_t*)bytes;
    float lin[12], zonal[3], sh[27];
    int i, k, per_channel, dec;
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (zhc_probe_format_validate(f) != ZHC_OK || !bytes) return;
    dec = zhc__decoder(f->encoding);
    if (f->kind == ZHC_KIND_IRRADIANCE || dec == ZHC__D_PACKED) {
        zhc_decode_probe(f, bytes, sh);
        for (i = 0; i < 27; ++i) sh[i] = (float)zhc__f32_round(sh[i]); /* see zhc__f32_round */
        zhc__sh_irradiance(sh, 9, n, rgb);
        return;
    }
    per_channel = zhc__float_per_channel(f->encoding);
    switch (dec) {
        case ZHC__D_SH3:
        case ZHC__D_SH2:
            for (i = 0; i < (dec == ZHC__D_SH3 ? 27 : 12); ++i) sh[i] = zhc__f32(in + 4 * i);
            zhc__sh_irradiance(sh, dec == ZHC__D_SH3 ? 9 : 4, n, rgb);
            return;
        case ZHC__D_ZH3:
            for (i = 0; i < 12; ++i) lin[i] = zhc__f32(in + 4 * i);
            for (k = 0; k < 3; ++k) zonal[k] = zhc__f32(in + 48 + 4 * k);
            break;
        default: /* hallucinated */
            for (i = 0; i < 12; ++i) lin[i] = zhc__f32(in + 4 * i);
            zhc__hallucinate(lin, zhc__hall_model(f->encoding), per_channel, f->luminance, f->hallucinate_a,
                             f->hallucinate_b, zonal);
            break;
    }
    zhc__zh3_irradiance(lin, zonal, per_channel, f->luminance, n, rgb);
}

/* zhc_probe_irradiance_d with a float normal (converted to double exactly). */
static inline void zhc_probe_irradiance(const zhc_probe_format* f, const void* bytes, const float n[3], float rgb[3]) {
    double nd[3];
    nd[0] = n[0];
    nd[1] = n[1];
    nd[2] = n[2];
    zhc_probe_irradiance_d(f, bytes, nd, rgb);
}

/* ---- .zhp container (docs/zhp-container.md, version 1) ------------------------------------- */

#define ZHC_ZHP_HEADER_BYTES 184

/* What the header says about the body (all offsets from the start of the file). */
typedef struct zhc_zhp_info {
    uint64_t probe_count;
    uint32_t probe_size;          /* bytes per probe = zhc_probe_size(format) */
    int layout;                   /* 0 none, 1 grid, 2 explicit positions */
    int compressed;               /* 1: zstd body (this header cannot read it) */
    double grid_origin[3], grid_spacing[3];
    uint32_t grid_counts[3];      /* probe (x,y,z) is number x + nx (y + ny z) */
    uint64_t positions_offset;    /* layout 2: count x 3 f32 (x, y, z); else 0 */
    uint64_t payload_offset;      /* probe i at payload_offset + i * probe_size (uncompressed) */
    uint64_t body_bytes;          /* uncompressed body size */
    uint64_t stored_body_bytes;   /* body size in the file */
    uint32_t body_crc32;
} zhc_zhp_info;

/* CRC-32, IEEE 802.3 (reflected 0xEDB88320, init and final XOR 0xFFFFFFFF); continue a running
 * CRC by passing the previous result as `crc` (start with 0). crc32("123456789") = 0xCBF43926. */
static inline uint32_t zhc_crc32(uint32_t crc, const void* data, size_t size) {
    const uint8_t* p = (const uint8_t*)data;
    size_t i;
    int b;
    crc = ~crc;
    for (i = 0; i < size; ++i) {
        crc ^= p[i];
        for (b = 0; b < 8; ++b) crc = (crc & 1u) ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
    }
    return ~crc;
}

/* The header of a .zhp file: `header` holds `size` bytes (the whole file or at least its first
 * 184). Checks, in zhc's reader order (formats/probes/probe_file.cpp): magic (a short prefix of it:
 * TRUNCATED, else BAD_FORMAT), version 1 (UNSUPPORTED), 184 bytes present (TRUNCATED), header CRC-32
 * (CHECKSUM), header size 184, reserved bytes zero (BAD_FORMAT), enum ranges of kind, DC format, L2
 * bound, zonal mapping, axis mode, compression, layout (UNSUPPORTED), sqrt 0/1 and bits 2..8
 * (BAD_FORMAT), representation name printable ASCII, zero padded (BAD_FORMAT) and known
 * (UNSUPPORTED), bytes per probe = the encoding's (BAD_FORMAT), luminance weights finite
 * (INVALID_VALUE), half DC only on sh2_q / hall_curve_q (BAD_FORMAT), probe count <= 2^26
 * (TOO_LARGE), grid values finite (INVALID_VALUE), grid counts multiply to the count or grid fields
 * all +0 without a grid (BAD_FORMAT), body bytes = count (12 [positions] + probe size) (BAD_FORMAT)
 * and <= 2 GiB (TOO_LARGE), stored body = body when uncompressed, <= ZSTD_compressBound when
 * compressed (BAD_FORMAT). Does not look at the body (see zhc_zhp_open).
 * On ZHC_OK fills f (format, a/b the codec's 0.6/0.08) and info (either may be NULL).
 * Safe for untrusted input. */
static inline int zhc_zhp_parse_header(zhc_probe_format* f, zhc_zhp_info* info, const void* header, size_t size) {
    static const uint8_t magic[8] = {0x89, 'Z', 'H', 'P', 0x0D, 0x0A, 0x1A, 0x0A};
    const uint8_t* h = (const uint8_t*)header;
    zhc_probe_format fmt;
    zhc_zhp_info inf;
    char name[32];
    size_t len, i;
    uint64_t count, raw_expected, raw, stored, pos_bytes;
    uint32_t counts[3];
    double grid[6];
    int c;
    if (info) memset(info, 0, sizeof *info);
    if (size == 0) return ZHC_ERR_TRUNCATED;
    if (!h) return ZHC_ERR_ARGUMENT;
    if (memcmp(h, magic, size < 8 ? size : 8) != 0) return ZHC_ERR_BAD_FORMAT;
    if (size < 10) return ZHC_ERR_TRUNCATED;
    if ((h[8] | (h[9] << 8)) != 1) return ZHC_ERR_UNSUPPORTED;
    if (size < ZHC_ZHP_HEADER_BYTES) return ZHC_ERR_TRUNCATED;
    if (zhc_crc32(0, h, 180) != zhc__u32(h + 180)) return ZHC_ERR_CHECKSUM;
    if ((h[10] | (h[11] << 8)) != ZHC_ZHP_HEADER_BYTES) return ZHC_ERR_BAD_FORMAT;
    if ((h[21] | h[22] | h[23]) || zhc__u32(h + 68) || zhc__u32(h + 156)) return ZHC_ERR_BAD_FORMAT;
    if (h[12] > 1 || h[14] > 2 || h[15] > 1 || h[17] > 2 || h[18] > 1 || h[19] > 1 || h[20] > 2)
        return ZHC_ERR_UNSUPPORTED;
    if (h[16] > 1) return ZHC_ERR_BAD_FORMAT;
    if (h[13] < 2 || h[13] > 8) return ZHC_ERR_BAD_FORMAT;
    len = 0;
    while (len < 32 && h[24 + len] != 0) ++len;
    if (len == 0 || len == 32) return ZHC_ERR_BAD_FORMAT;
    for (i = len; i < 32; ++i)
        if (h[24 + i] != 0) return ZHC_ERR_BAD_FORMAT;
    for (i = 0; i < len; ++i)
        if (h[24 + i] < 0x21 || h[24 + i] > 0x7E) return ZHC_ERR_BAD_FORMAT;
    memcpy(name, h + 24, 32);
    zhc_probe_format_init(&fmt, name);
    if (fmt.encoding < 0) return ZHC_ERR_UNSUPPORTED;
    if (zhc__u32(h + 64) != zhc_encoding_size(fmt.encoding)) return ZHC_ERR_BAD_FORMAT;
    fmt.kind = h[12];
    fmt.bits = h[13];
    fmt.dc_format = h[14];
    fmt.l2_bound = h[15];
    fmt.sqrt_encoding = h[16];
    fmt.zonal_mapping = h[17];
    fmt.axis_mode = h[18];
    for (c = 0; c < 3; ++c) fmt.luminance[c] = zhc__f64(h + 72 + 8 * c);
    if (!isfinite(fmt.luminance[0]) || !isfinite(fmt.luminance[1]) || !isfinite(fmt.luminance[2]))
        return ZHC_ERR_INVALID_VALUE;
    if (zhc_probe_format_validate(&fmt) != ZHC_OK) return ZHC_ERR_BAD_FORMAT;
    count = zhc__u64(h + 56);
    if (count > ((uint64_t)1 << 26)) return ZHC_ERR_TOO_LARGE;
    memset(&inf, 0, sizeof inf);
    inf.layout = h[20];
    inf.compressed = h[19];
    inf.probe_count = count;
    inf.probe_size = (uint32_t)zhc_encoding_size(fmt.encoding);
    for (c = 0; c < 3; ++c) {
        grid[c] = zhc__f64(h + 96 + 8 * c);
        grid[3 + c] = zhc__f64(h + 120 + 8 * c);
        counts[c] = zhc__u32(h + 144 + 4 * c);
    }
    if (inf.layout == 1) {
        for (c = 0; c < 6; ++c)
            if (!isfinite(grid[c])) return ZHC_ERR_INVALID_VALUE;
        /* counts[0] * counts[1] fits 64 bits; the product must equal count <= 2^26. */
        {
            const uint64_t xy = (uint64_t)counts[0] * counts[1];
            if (counts[2] == 0 ? count != 0 : (xy > count || xy * counts[2] != count)) return ZHC_ERR_BAD_FORMAT;
        }
        for (c = 0; c < 3; ++c) {
            inf.grid_origin[c] = grid[c];
            inf.grid_spacing[c] = grid[3 + c];
            inf.grid_counts[c] = counts[c];
        }
    } else {
        for (c = 0; c < 6; ++c)
            if (grid[c] != 0.0 || signbit(grid[c])) return ZHC_ERR_BAD_FORMAT;
        if (counts[0] | counts[1] | counts[2]) return ZHC_ERR_BAD_FORMAT;
    }
    pos_bytes = inf.layout == 2 ? count * 12 : 0;
    raw_expected = pos_bytes + count * inf.probe_size;
    raw = zhc__u64(h + 160);
    if (raw != raw_expected) return ZHC_ERR_BAD_FORMAT;
    if (raw > ((uint64_t)1 << 31)) return ZHC_ERR_TOO_LARGE;
    stored = zhc__u64(h + 168);
    if (!inf.compressed && stored != raw) return ZHC_ERR_BAD_FORMAT;
    /* ZSTD_COMPRESSBOUND (zstd.h): s + s/256 + (s < 128 KiB ? (128 KiB - s) / 2048 : 0). */
    if (inf.compressed && stored > raw + (raw >> 8) + (raw < (128u << 10) ? ((128u << 10) - raw) >> 11 : 0))
        return ZHC_ERR_BAD_FORMAT;
    inf.body_bytes = raw;
    inf.stored_body_bytes = stored;
    inf.body_crc32 = zhc__u32(h + 176);
    inf.positions_offset = inf.layout == 2 ? ZHC_ZHP_HEADER_BYTES : 0;
    inf.payload_offset = ZHC_ZHP_HEADER_BYTES + pos_bytes;
    if (f) *f = fmt;
    if (info) *info = inf;
    return ZHC_OK;
}

/* A whole .zhp file in memory (`file`, `size` bytes): the header as zhc_zhp_parse_header, then
 * file size = 184 + stored body (TRUNCATED / TRAILING_BYTES), body CRC-32 (CHECKSUM), a compressed
 * body (ZHC_ERR_COMPRESSED: f and info are still filled, the payload offset is meaningless), finite
 * positions (INVALID_VALUE). On ZHC_OK probe i's bytes are at file + info->payload_offset +
 * i * info->probe_size. Safe for untrusted input; accepts exactly the uncompressed files zhc's
 * reader accepts, with the same error class. */
static inline int zhc_zhp_open(zhc_probe_format* f, zhc_zhp_info* info, const void* file, size_t size) {
    const uint8_t* p = (const uint8_t*)file;
    zhc_probe_format fmt;
    zhc_zhp_info inf;
    uint64_t have, i;
    int r = zhc_zhp_parse_header(&fmt, &inf, file, size);
    if (r != ZHC_OK) return r;
    have = (uint64_t)size - ZHC_ZHP_HEADER_BYTES;
    if (have < inf.stored_body_bytes) return ZHC_ERR_TRUNCATED;
    if (have > inf.stored_body_bytes) return ZHC_ERR_TRAILING_BYTES;
    if (zhc_crc32(0, p + ZHC_ZHP_HEADER_BYTES, (size_t)have) != inf.body_crc32) return ZHC_ERR_CHECKSUM;
    if (f) *f = fmt;
    if (info) *info = inf;
    if (inf.compressed) return ZHC_ERR_COMPRESSED;
    if (inf.layout == 2)
        for (i = 0; i < inf.probe_count * 3; ++i)
            if (!isfinite(zhc__f32(p + ZHC_ZHP_HEADER_BYTES + 4 * i))) return ZHC_ERR_INVALID_VALUE;
    return ZHC_OK;
}

/* The format alone from a .zhp header (>= 184 bytes of it): zhc_zhp_parse_header without the body
 * info. Non-zero (a zhc_error) for a bad header. Safe for untrusted input. */
static inline int zhc_probe_format_from_zhp(zhc_probe_format* f, const void* header, size_t size) {
    return zhc_zhp_parse_header(f, NULL, header, size);
}

/* ---- probe volumes (docs/runtime.md, "Probe volumes") --------------------------------------- */

/* A grid of probes: probe (x, y, z) (x < counts[0], ...) is number x + counts[0] (y + counts[1] z),
 * at origin + (x spacing[0], y spacing[1], z spacing[2]), its stored bytes at
 * probes + number * probe_size. The volume REFERS to the caller's bytes (nothing is copied): they
 * must outlive it. Fill it with zhc_volume_from_zhp or zhc_volume_init (which validate), not by hand. */
typedef struct zhc_volume {
    zhc_probe_format format;
    const uint8_t* probes;  /* counts[0] counts[1] counts[2] probes of probe_size bytes */
    size_t probe_size;      /* zhc_probe_size(&format) */
    double origin[3];       /* position of probe (0, 0, 0), the probe set's frame (zhc axes for .zhp) */
    double spacing[3];      /* > 0, finite */
    uint32_t counts[3];     /* >= 1 each, product <= 2^26 */
} zhc_volume;

/* A volume from its parts: format (validated: ZHC_ERR_ARGUMENT), the stored probes (`size` bytes,
 * at least counts[0] counts[1] counts[2] zhc_probe_size(format): else ZHC_ERR_TRUNCATED; bytes
 * beyond that are ignored), the grid: every count >= 1 (ZHC_ERR_INVALID_VALUE), their product
 * <= 2^26 (ZHC_ERR_TOO_LARGE, zhc's limit), origin finite and spacing finite and > 0, and the far
 * corner origin + (count - 1) spacing finite (ZHC_ERR_INVALID_VALUE). Null pointers:
 * ZHC_ERR_ARGUMENT. On any error v is zeroed (probes NULL). Safe for untrusted input. */
static inline int zhc_volume_init(zhc_volume* v, const zhc_probe_format* format, const void* probes, size_t size,
                                  const double origin[3], const double spacing[3], const uint32_t counts[3]) {
    uint64_t count = 1;
    int c;
    if (!v) return ZHC_ERR_ARGUMENT;
    memset(v, 0, sizeof *v);
    if (!format || !probes || !origin || !spacing || !counts) return ZHC_ERR_ARGUMENT;
    if (zhc_probe_format_validate(format) != ZHC_OK) return ZHC_ERR_ARGUMENT;
    for (c = 0; c < 3; ++c) {
        if (counts[c] < 1) return ZHC_ERR_INVALID_VALUE;
        if (!isfinite(origin[c]) || !isfinite(spacing[c]) || !(spacing[c] > 0.0)) return ZHC_ERR_INVALID_VALUE;
        if (!isfinite(origin[c] + (double)(counts[c] - 1) * spacing[c])) return ZHC_ERR_INVALID_VALUE;
    }
    for (c = 0; c < 3; ++c) {
        count *= counts[c]; /* each factor <= 2^32 and checked below before the next: no overflow */
        if (count > ((uint64_t)1 << 26)) return ZHC_ERR_TOO_LARGE;
    }
    if ((uint64_t)size / zhc_probe_size(format) < count) return ZHC_ERR_TRUNCATED;
    v->format = *format;
    v->probes = (const uint8_t*)probes;
    v->probe_size = zhc_probe_size(format);
    for (c = 0; c < 3; ++c) {
        v->origin[c] = origin[c];
        v->spacing[c] = spacing[c];
        v->counts[c] = counts[c];
    }
    return ZHC_OK;
}

/* A volume from a whole .zhp file in memory (`file`, `size` bytes; the volume points into them):
 * zhc_zhp_open's checks and error codes (ZHC_ERR_COMPRESSED for a zstd body), then
 * ZHC_ERR_NOT_GRID for a valid file without a grid layout (none, or scattered `points`: see
 * docs/runtime.md for what to do with those), then the grid checks of zhc_volume_init (an empty
 * grid, spacing <= 0 or a far corner that overflows: ZHC_ERR_INVALID_VALUE). On error v is zeroed.
 * Safe for untrusted input (any bytes, any size). */
static inline int zhc_volume_from_zhp(zhc_volume* v, const void* file, size_t size) {
    zhc_probe_format f;
    zhc_zhp_info info;
    int r;
    if (!v) return ZHC_ERR_ARGUMENT;
    memset(v, 0, sizeof *v);
    r = zhc_zhp_open(&f, &info, file, size);
    if (r != ZHC_OK) return r;
    if (info.layout != 1) return ZHC_ERR_NOT_GRID;
    return zhc_volume_init(v, &f, (const uint8_t*)file + info.payload_offset, (size_t)(size - info.payload_offset),
                           info.grid_origin, info.grid_spacing, info.grid_counts);
}

/* The grid coordinate along one axis: t = (p - origin) / spacing clamped to [0, n - 1] (NaN: 0),
 * the cell's first probe i0 (<= n - 2 when n >= 2, so that the cell [i0, i0 + 1] exists) and the
 * weight f = t - i0 in [0, 1] of probe i0 + 1. For n = 1: i0 = 0, f = 0 (the one probe). */
static inline void zhc__volume_axis(double p, double origin, double spacing, uint32_t n, uint32_t* i0, double* f) {
    double t = (p - origin) / spacing;
    const double hi = (double)(n - 1);
    uint32_t i;
    if (!(t >= 0.0)) t = 0.0; /* below the box, or NaN */
    if (t > hi) t = hi;
    i = (uint32_t)floor(t);
    if (n >= 2 && i > n - 2) i = n - 2;
    *i0 = i;
    *f = n >= 2 ? t - (double)i : 0.0;
}

/* SH3 radiance at `position` (the probe set's frame): the trilinear blend of the decoded SH3 of the
 * 8 probes of the grid cell containing the position (clamped to the grid's box first, so outside
 * the box the value is that of the nearest point of the box), weights
 * w = prod_axes (f or 1 - f), accumulated in double in a fixed order. Probes of weight 0 are not
 * read (a probe that decodes to NaN affects only the cells around it). sh3[i*3+k] as
 * zhc_decode_probe. An invalid volume (zeroed, or not from zhc_volume_init/from_zhp) gives zeros. */
static inline void zhc_volume_sh3(const zhc_volume* v, const double position[3], double sh3[27]) {
    uint32_t i0[3];
    double f[3];
    int c, corner, j;
    memset(sh3, 0, 27 * sizeof(double));
    if (!v || !v->probes || v->probe_size == 0) return;
    for (c = 0; c < 3; ++c) zhc__volume_axis(position[c], v->origin[c], v->spacing[c], v->counts[c], &i0[c], &f[c]);
    for (corner = 0; corner < 8; ++corner) {
        const int bx = corner & 1, by = (corner >> 1) & 1, bz = (corner >> 2) & 1;
        const double w = (bx ? f[0] : 1.0 - f[0]) * (by ? f[1] : 1.0 - f[1]) * (bz ? f[2] : 1.0 - f[2]);
        size_t index;
        float probe[27];
        if (w == 0.0) continue; /* also every corner beyond a count-1 axis (its f is 0) */
        index = (size_t)(i0[0] + (uint32_t)bx) +
                (size_t)v->counts[0] * ((size_t)(i0[1] + (uint32_t)by) + (size_t)v->counts[1] * (size_t)(i0[2] + (uint32_t)bz));
        zhc_decode_probe(&v->format, v->probes + index * v->probe_size, probe);
        for (j = 0; j < 27; ++j) sh3[j] += w * (double)probe[j];
    }
}

/* Irradiance (zhc's normalised kernel: constant radiance 1 gives 1) at `position` for a surface of
 * normal `normal` (both in the probe set's frame; the normal is normalised here, zero or not
 * finite: +Z): E(n) = sum_i s_l c_i Y_i(n), s_l = 1, 2/3, 1/4, of the blended SH3 c of
 * zhc_volume_sh3. By linearity this equals the trilinear blend of the 8 probes' own irradiance at
 * n. Decodes at most 8 probes, evaluates once. Double precision throughout. */
static inline void zhc_volume_irradiance_d(const zhc_volume* v, const double position[3], const double normal[3],
                                           double rgb[3]) {
    double sh[27], n[3], y[9];
    int i, k;
    zhc_volume_sh3(v, position, sh);
    zhc__normalize_or_z(normal, n);
    zhc__sh3_basis(n, y);
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    for (i = 0; i < 9; ++i) {
        const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
        for (k = 0; k < 3; ++k) rgb[k] += s * sh[i * 3 + k] * y[i];
    }
}

/* zhc_volume_irradiance_d with float arguments and result (the double result rounded once). */
static inline void zhc_volume_irradiance(const zhc_volume* v, const float position[3], const float normal[3],
                                         float rgb[3]) {
    double p[3], n[3], e[3];
    int c;
    for (c = 0; c < 3; ++c) {
        p[c] = position[c];
        n[c] = normal[c];
    }
    zhc_volume_irradiance_d(v, p, n, e);
    for (c = 0; c < 3; ++c) rgb[c] = (float)e[c];
}

/* ---- IrradZ lightmaps (codec/lightmap/irradz.h, codec/lightmap/lightmap.h, docs/irradz.md) ------------------- */

/* Directions are kept at most 85 degrees from the normal (d_z >= cos 85deg) so that
 * C_d = (1 - w_a) I_z / d_z stays bounded. */
#define ZHC_IRRADZ_MAX_THETA (85.0 * ZHC__PI / 180.0)

/* BC5 hemi-octahedral direction decode (codec/lightmap/lightmap.cpp decode_hemioct): (u, v) in [0, 1]^2
 * (clamped; NaN gives +Z), a = 2u - 1, b = 2v - 1, p = ((a + b)/2, (a - b)/2),
 * d = normalize(p.x, p.y, max(0, 1 - |p.x| - |p.y|)). Always a unit vector with d_z >= 0. */
static inline void zhc_decode_hemioct(float u, float v, double d[3]) {
    const double a = 2.0 * zhc__clamp((double)u, 0.0, 1.0) - 1, b = 2.0 * zhc__clamp((double)v, 0.0, 1.0) - 1;
    double p[3];
    p[0] = (a + b) / 2;
    p[1] = (a - b) / 2;
    p[2] = zhc__max(0.0, 1 - fabs(p[0]) - fabs(p[1]));
    zhc__normalize_or_z(p, d);
}

/* Irradiance at the tangent-space unit normal n (surface normal +Z) of an IrradZ texel
 * (I_z rgb, w_a, unit direction d), codec/lightmap/irradz.cpp evaluate(IrradZ):
 *   d clamped to theta <= 85 deg (azimuth kept), w = clamp(w_a, 0, 1),
 *   C_a = w I_z, C_d = (1 - w) I_z / d_z (both rounded to float),
 *   HHD (model 0, default): E(n) = C_a (1 + n_z) / 2 + C_d max(0, n.d)
 *   AHD (model 1):          E(n) = C_a + C_d max(0, n.d). */
static inline void zhc_irradz_irradiance(const float i_z[3], double w_a, const double d_in[3], int model,
                                         const double n[3], float rgb[3]) {
    double d[3], w, h, c;
    int k;
    zhc__normalize_or_z(d_in, d);
    if (!(d[2] >= cos(ZHC_IRRADZ_MAX_THETA))) {
        const double phi = atan2(d[1], d[0]);
        d[0] = sin(ZHC_IRRADZ_MAX_THETA) * cos(phi);
        d[1] = sin(ZHC_IRRADZ_MAX_THETA) * sin(phi);
        d[2] = cos(ZHC_IRRADZ_MAX_THETA);
    }
    w = zhc__clamp(w_a, 0.0, 1.0);
    h = model == ZHC_IRRADZ_AHD ? 1.0 : (1 + n[2]) / 2;
    c = zhc__max(0.0, n[0] * d[0] + n[1] * d[1] + n[2] * d[2]);
    for (k = 0; k < 3; ++k) {
        /* C_a and C_d are floats in the codec (irradz::Lighting). */
        const double ca = zhc__f32_round(w * i_z[k]), cd = zhc__f32_round((1 - w) * i_z[k] / d[2]);
        rgb[k] = (float)(ca * h + cd * c);
    }
}

/* The texel as stored in the textures: I_z (BC6H), w_a (BC4), d as hemi-octahedral (u, v) (BC5). */
static inline void zhc_irradz_irradiance_texel(const float i_z[3], float w_a, float u, float v, int model,
                                               const double n[3], float rgb[3]) {
    double d[3];
    zhc_decode_hemioct(u, v, d);
    zhc_irradz_irradiance(i_z, (double)w_a, d, model, n, rgb);
}

/* HLSH evaluation at tangent-space unit normal m: I(m) = I_z m_z + C_a (1 - m_z) + c_x m_x + c_y m_y. */
static inline void zhc_hlsh_evaluate(const float i_z[3], const float c_a[3], const float c_x[3], const float c_y[3],
                                     const double m[3], float rgb[3]) {
    int k;
    for (k = 0; k < 3; ++k)
        rgb[k] = (float)(i_z[k] * m[2] + c_a[k] * (1 - m[2]) + c_x[k] * m[0] + c_y[k] * m[1]);
}

/* Frame around unit z (codec/sh/sh.cpp frame_from_z), row-major 3x3 whose third column is z. */
static inline void zhc_frame_from_z(const double z_axis[3], double frame[9]) {
    double z[3], hx[3], x[3], y[3];
    zhc__normalize_or_z(z_axis, z);
    if (fabs(z[0]) < 0.9) {
        hx[0] = 1, hx[1] = 0, hx[2] = 0;
    } else {
        hx[0] = 0, hx[1] = 1, hx[2] = 0;
    }
    {
        double cr[3];
        cr[0] = hx[1] * z[2] - hx[2] * z[1];
        cr[1] = hx[2] * z[0] - hx[0] * z[2];
        cr[2] = hx[0] * z[1] - hx[1] * z[0];
        {
            const double len = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            if (!(len > 0.0) || !isfinite(len)) {
                x[0] = 1, x[1] = 0, x[2] = 0;
            } else {
                const double s = 1.0 / len;
                x[0] = s * cr[0], x[1] = s * cr[1], x[2] = s * cr[2];
            }
        }
    }
    y[0] = z[1] * x[2] - z[2] * x[1];
    y[1] = z[2] * x[0] - z[0] * x[2];
    y[2] = z[0] * x[1] - z[1] * x[0];
    frame[0] = x[0], frame[1] = y[0], frame[2] = z[0];
    frame[3] = x[1], frame[4] = y[1], frame[5] = z[1];
    frame[6] = x[2], frame[7] = y[2], frame[8] = z[2];
}

/* Precomputed tables of the HLSH multiply for one cone: the cap Gram matrix
 * G_ij = integral over {w_z >= cos_alpha} of Y_i Y_j (cos_alpha = 0: hemisphere, -1: identity)
 * and the hemisphere projections of the HLSH functions (1 - z), x, y and Y_i(+Z). */
typedef struct zhc_hlsh_tables {
    double gram[81];
    double p_one_minus_z[9], p_x[9], p_y[9], y_up[9];
} zhc_hlsh_tables;

/* Gauss-Legendre rule of 10 nodes on [-1, 1] (Newton on P_10; codec/lightmap/irradz.cpp). */
static inline void zhc__gauss_legendre10(double x[10], double w[10]) {
    const int n = 10;
    int i, it, k;
    for (i = 0; i < n; ++i) {
        double z = cos(ZHC__PI * (i + 0.75) / (n + 0.5)), dp = 1;
        for (it = 0; it < 100; ++it) {
            double p0 = 1, p1 = z, dz;
            for (k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1);
            dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16) break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1 - z * z) * dp * dp);
    }
}

/* Product rule over the cap z >= c (Gauss-Legendre in z, 16 uniform points in phi; exact for the
 * degree-4 integrands): node j of ring i written to dir, its weight returned. */
static inline double zhc__cap_node(const double glx[10], const double glw[10], double c, int i, int j, double dir[3]) {
    const double half = (1 - c) / 2;
    const double z = c + half * (glx[i] + 1);
    const double s = sqrt(zhc__max(0.0, 1 - z * z));
    const double phi = 2 * ZHC__PI * (j + 0.5) / 16;
    dir[0] = s * cos(phi);
    dir[1] = s * sin(phi);
    dir[2] = z;
    return half * glw[i] * 2 * ZHC__PI / 16;
}

/* Fills t for cones of half-angle alpha (cos_alpha clamped to [-1, 1]); ~30k flops, once per cone
 * angle. Equals zhc's tables (codec/lightmap/irradz.cpp cap_gram, Tables) bit for bit with the same libm. */
static inline void zhc_hlsh_tables_init(zhc_hlsh_tables* t, double cos_alpha) {
    double glx[10], glw[10], dir[3], y[9], up[3] = {0.0, 0.0, 1.0};
    const double c = zhc__clamp(cos_alpha, -1.0, 1.0);
    int i, j, a, b;
    memset(t, 0, sizeof *t);
    zhc__gauss_legendre10(glx, glw);
    for (i = 0; i < 10; ++i)
        for (j = 0; j < 16; ++j) {
            const double wt = zhc__cap_node(glx, glw, c, i, j, dir);
            zhc__sh3_basis(dir, y);
            for (a = 0; a < 9; ++a)
                for (b = 0; b < 9; ++b) t->gram[a * 9 + b] += wt * y[a] * y[b];
        }
    for (i = 0; i < 10; ++i)
        for (j = 0; j < 16; ++j) {
            const double wt = zhc__cap_node(glx, glw, 0.0, i, j, dir);
            zhc__sh3_basis(dir, y);
            for (a = 0; a < 9; ++a) {
                t->p_one_minus_z[a] += wt * y[a] * (1 - dir[2]);
                t->p_x[a] += wt * y[a] * dir[0];
                t->p_y[a] += wt * y[a] * dir[1];
            }
        }
    zhc__sh3_basis(up, t->y_up);
}

/* Rotates SH3 radiance by R (row-major): g(d) = f(R^T d) (codec/sh/sh.cpp rotate: L1 as a vector,
 * L2 as the traceless quadratic form Q -> R Q R^T). */
static inline void zhc_sh3_rotate(const float in[27], const double r[9], float out[27]) {
    int k, i, j, l;
    for (k = 0; k < 3; ++k) {
        double v[3], rv[3], a[5], q[9], rq[9], o[9];
        const double y1 = ZHC__Y1, y2 = ZHC__Y2, y20 = ZHC__Y20, y22 = ZHC__Y22;
        out[k] = in[k];
        v[0] = y1 * -(double)in[9 + k];
        v[1] = y1 * -(double)in[3 + k];
        v[2] = y1 * (double)in[6 + k];
        for (i = 0; i < 3; ++i) rv[i] = r[i * 3] * v[0] + r[i * 3 + 1] * v[1] + r[i * 3 + 2] * v[2];
        out[3 + k] = (float)(-rv[1] / y1);
        out[6 + k] = (float)(rv[2] / y1);
        out[9 + k] = (float)(-rv[0] / y1);
        for (i = 0; i < 5; ++i) a[i] = in[(4 + i) * 3 + k];
        {
            const double xy = 0.5 * y2 * a[0], yz = -0.5 * y2 * a[1], xz = -0.5 * y2 * a[3];
            q[0] = -y20 * a[2] + y22 * a[4], q[1] = xy, q[2] = xz;
            q[3] = xy, q[4] = -y20 * a[2] - y22 * a[4], q[5] = yz;
            q[6] = xz, q[7] = yz, q[8] = 2.0 * y20 * a[2];
        }
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) {
                double s = 0;
                for (l = 0; l < 3; ++l) s += r[i * 3 + l] * q[l * 3 + j];
                rq[i * 3 + j] = s;
            }
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) {
                double s = 0;
                for (l = 0; l < 3; ++l) s += rq[i * 3 + l] * r[j * 3 + l]; /* (R Q) R^T */
                o[i * 3 + j] = s;
            }
        a[0] = 2.0 * o[1] / y2;
        a[1] = -2.0 * o[5] / y2;
        a[2] = (2.0 * o[8] - o[0] - o[4]) / (6.0 * y20);
        a[3] = -2.0 * o[2] / y2;
        a[4] = (o[0] - o[4]) / (2.0 * y22);
        for (i = 0; i < 5; ++i) out[(4 + i) * 3 + k] = (float)a[i];
    }
}

/* HLSH hemisphere / cone multiply of a probe (codec/lightmap/irradz.cpp hlsh_multiply): world SH3 radiance
 * sh3[27], the normal's frame (row-major, third column = n, e.g. zhc_frame_from_z) and the tables
 * of the cone (zhc_hlsh_tables_init(t, cos_alpha); cos_alpha = 0 is the hemisphere):
 *   L_t = rotate(L, frame^T) (tangent frame), O = G_cap L_t (SH3 product with the cap),
 *   T = irradiance SH of O (band scales 1, 2/3, 1/4, rounded to float),
 *   I_z = T(+Z) (exact constraint); over z >= 0 the HLSH functions (1 - z), x, y are orthogonal:
 *   C_a = (<T, 1 - z> - I_z pi/3) / (2 pi/3), c_x = <T, x> / (2 pi/3), c_y = <T, y> / (2 pi/3). */
static inline void zhc_hlsh_multiply(const zhc_hlsh_tables* t, const float sh3[27], const double frame[9],
                                     float i_z[3], float c_a[3], float c_x[3], float c_y[3]) {
    double ft[9];
    float tangent[27], occluded[27];
    const double n11 = 2 * ZHC__PI / 3, nz1 = ZHC__PI / 3, nxx = 2 * ZHC__PI / 3;
    int i, j, k;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) ft[i * 3 + j] = frame[j * 3 + i];
    zhc_sh3_rotate(sh3, ft, tangent);
    for (i = 0; i < 27; ++i) tangent[i] = (float)zhc__f32_round(tangent[i]); /* see zhc__f32_round */
    for (k = 0; k < 3; ++k)
        for (i = 0; i < 9; ++i) {
            double s = 0;
            for (j = 0; j < 9; ++j) s += t->gram[i * 9 + j] * tangent[j * 3 + k];
            occluded[i * 3 + k] = (float)zhc__f32_round(s);
        }
    for (k = 0; k < 3; ++k) {
        double v[9], iz = 0, p1 = 0, px = 0, py = 0;
        for (i = 0; i < 9; ++i) {
            const double s = i == 0 ? 1.0 : (i < 4 ? ZHC__BAND1 : ZHC__BAND2);
            v[i] = zhc__f32_round(occluded[i * 3 + k] * s);
        }
        for (i = 0; i < 9; ++i) iz += v[i] * t->y_up[i];
        for (i = 0; i < 9; ++i) p1 += v[i] * t->p_one_minus_z[i];
        for (i = 0; i < 9; ++i) px += v[i] * t->p_x[i];
        for (i = 0; i < 9; ++i) py += v[i] * t->p_y[i];
        i_z[k] = (float)iz;
        c_a[k] = (float)((p1 - iz * nz1) / n11);
        c_x[k] = (float)(px / nxx);
        c_y[k] = (float)(py / nxx);
    }
}

#ifdef __cplusplus
}
#endif

#endif /* ZHC_RUNTIME_H */
