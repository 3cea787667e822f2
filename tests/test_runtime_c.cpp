// runtime/zhc_runtime.h (the C consuming side of every probe encoding) against the codec itself:
// every codec table entry, >= 100,000 encoded probes and >= 100,000 arbitrary byte strings each,
// default and non-default storage parameters; IrradZ / HLSH / hemi-octahedral functions. The .zhp
// header parsing is tested in test_runtime_c_zhp.cpp (helpers: runtime_c_helpers.h).
// 
// Bit equality is the claim: floats are compared by bit pattern, except that any NaN equals any
// NaN (payloads of NaNs produced by arithmetic are not part of the contract). The largest ulp
// distance of every function is measured and printed (the exactness table of the notes) and must
// be 0. Built with -ffp-contract=off like the codec (tests/runtime_c/CMakeLists.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "codec/probe/runtime_table.h"
#include "formats/probes/probe_file.h"
#include "runtime_c_helpers.h"
#include "support.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

namespace zhc {
namespace {

using namespace runtime_c_test;

zhc_probe_format format_of(std::string_view codec, const CodecOptions& p) {
    zhc_probe_format f;
    EXPECT_TRUE(runtime_format(codec, p, &f)) << codec;
    return f;
}

// A float-representable unit-ish normal (the runtime takes float normals).
Vec3 random_float_normal(std::mt19937_64& rng) {
    const Vec3 d = random_direction(rng);
    volatile float x = float(d.x), y = float(d.y), z = float(d.z);
    return {double(x), double(y), double(z)};
}

// What the codec says the irradiance of stored bytes is, for these params (see zhc_runtime.h):
// the table entry's runtime path for radiance float entries, else the irradiance of the decoded hub.
Rgb codec_irradiance(const Codec& c, const CodecOptions& p, const std::uint8_t* bytes, Vec3 n) {
    PackedLayout layout;
    if (p.kind == StoredKind::kRadiance && !packed_layout_from_name(c.name, &layout))
        return c.irradiance(bytes, p, n);
    return irradiance(decode_probe(c, p, bytes), n);
}

struct EntryStats {
    MaxUlp decode_default, decode_table, decode_params, irr_default, irr_table, irr_params, bytes_decode, bytes_irr;
    std::uint64_t probes = 0, random_bytes = 0, nan_outputs = 0;
};

void compare_probe(const Codec& c, const CodecOptions& p, const std::uint8_t* bytes, std::mt19937_64& rng,
                   MaxUlp& dec, MaxUlp& irr, EntryStats& st, MaxUlp* table_dec = nullptr, MaxUlp* table_irr = nullptr) {
    const zhc_probe_format f = format_of(c.name, p);
    float rt[27];
    ASSERT_EQ(zhc_decode_probe(&f, bytes, rt), ZHC_OK);
    const Sh3Radiance ref = decode_probe(c, p, bytes);
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) {
            dec.add(rt[i * 3 + k], ref[i][k], std::string(c.name) + " decode coef " + std::to_string(i));
            st.nan_outputs += std::isnan(rt[i * 3 + k]);
        }
    if (table_dec) {  // the table entry's own decode, default options
        const Sh3Radiance t = c.decode(bytes, CodecOptions{});
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) table_dec->add(rt[i * 3 + k], t[i][k], std::string(c.name) + " table decode");
    }
    const Vec3 n = random_float_normal(rng);
    const float nf[3] = {float(n.x), float(n.y), float(n.z)};
    float e[3];
    zhc_probe_irradiance(&f, bytes, nf, e);
    const Rgb ref_e = codec_irradiance(c, p, bytes, n);
    for (int k = 0; k < 3; ++k) irr.add(e[k], ref_e[k], std::string(c.name) + " irradiance");
    if (table_irr) {
        const Rgb t = c.irradiance(bytes, CodecOptions{}, n);
        for (int k = 0; k < 3; ++k) table_irr->add(e[k], t[k], std::string(c.name) + " table irradiance");
    }
}

// ---- the table ---------------------------------------------------------------------------------

TEST(RuntimeC, EveryCodecTableEntryIsKnownWithItsSizeInOrder) {
    // runtime_codecs(): the table without the engine layouts, which no zhc runtime reads (codec.h).
    const auto table = runtime_codecs();
    ASSERT_EQ(table.size(), size_t(ZHC_ENC_COUNT)) << "a codec table entry without runtime support (or vice versa)";
    for (size_t e = 0; e < table.size(); ++e) {
        const std::string name(table[e].name);
        EXPECT_EQ(zhc_encoding_from_name(name.c_str()), int(e)) << name;
        ASSERT_NE(zhc_encoding_name(int(e)), nullptr);
        EXPECT_EQ(name, zhc_encoding_name(int(e)));
        EXPECT_EQ(zhc_encoding_size(int(e)), table[e].size_bytes) << name;
        PackedLayout layout;
        EXPECT_EQ(zhc_encoding_is_packed(int(e)) != 0, packed_layout_from_name(name, &layout)) << name;
        // The generated row (the decoders choose by it) is the codec entry's runtime description;
        // the bit-exact decode tests below show that the decoders it selects are the entry's.
        const auto rt = runtime_entry(table[e]);
        ASSERT_TRUE(rt.ok()) << rt.error().message;
        const zhc_encoding_info* info = zhc_encoding_info_of(int(e));
        ASSERT_NE(info, nullptr);
        EXPECT_EQ(info->layout, unsigned(rt->layout)) << name;
        EXPECT_EQ(info->hallucination, unsigned(rt->hallucination)) << name;
        EXPECT_EQ(info->axis, unsigned(rt->axis)) << name;
        EXPECT_EQ(info->axis, unsigned(table[e].traits.zonal_axis)) << name;
        EXPECT_EQ(info->hallucination, unsigned(table[e].traits.hallucination)) << name;
        if (table[e].packed) {
            EXPECT_EQ(info->layout, unsigned(ZHC_LAYOUT_ZH3_Q16) + unsigned(table[e].packed->layout)) << name;
        }
        zhc_probe_format f;
        ASSERT_EQ(zhc_probe_format_init(&f, name.c_str()), ZHC_OK);
        // The defaults are zhc convert's (CodecOptions) and the codec's curve constants.
        const CodecOptions d;
        const CodecOptions o;
        EXPECT_EQ(f.bits, d.bits);
        EXPECT_EQ(f.sqrt_encoding, int(d.sqrt_encoding));
        EXPECT_EQ(f.l2_bound, int(d.l2_bound));
        EXPECT_EQ(f.dc_format, int(d.dc_format));
        EXPECT_EQ(f.zonal_mapping, int(d.zonal_mapping));
        EXPECT_EQ(f.axis_mode, int(d.axis_mode));
        EXPECT_EQ(f.kind, int(d.kind));
        EXPECT_EQ(f.luminance[0], d.luminance.r);
        EXPECT_EQ(f.luminance[1], d.luminance.g);
        EXPECT_EQ(f.luminance[2], d.luminance.b);
        EXPECT_EQ(f.hallucinate_a, o.hallucinate_a);
        EXPECT_EQ(f.hallucinate_b, o.hallucinate_b);
        EXPECT_EQ(zhc_probe_size(&f), table[e].size_bytes);
        // The same validity rule as the codec's.
        for (int dc = 0; dc < 3; ++dc) {
            CodecOptions p;
            p.dc_format = DcFormat(dc);
            f.dc_format = dc;
            EXPECT_EQ(zhc_probe_format_validate(&f) == ZHC_OK, bool(validate_quant_params(p, name))) << name << dc;
        }
    }
    // The codec table's aliases name their entries here too (a .zhp or glTF volume may carry one),
    // as the generated defines do.
    for (const CodecAlias& a : codec_aliases()) {
        const std::string alias(a.alias), name(a.name);
        EXPECT_GE(zhc_encoding_from_name(name.c_str()), 0) << name;
        EXPECT_EQ(zhc_encoding_from_name(alias.c_str()), zhc_encoding_from_name(name.c_str())) << alias;
        zhc_probe_format fa;
        ASSERT_EQ(zhc_probe_format_init(&fa, alias.c_str()), ZHC_OK) << alias;
        EXPECT_STREQ(zhc_encoding_name(fa.encoding), name.c_str());
    }
    EXPECT_EQ(int(ZHC_ENC_ZH3_LUM_DERING), int(ZHC_ENC_ZH3_LUM_AXIS_CLAMP));
    EXPECT_EQ(int(ZHC_ENC_ZH3_LUM_DERING_SPHERE), int(ZHC_ENC_ZH3_LUM_SPHERE_CLAMP));
    EXPECT_EQ(zhc_encoding_from_name("zh3_lum_dering_"), -1);
    zhc_probe_format f;
    EXPECT_NE(zhc_probe_format_init(&f, "sh4"), ZHC_OK);
    EXPECT_NE(zhc_probe_format_init(&f, ""), ZHC_OK);
    EXPECT_NE(zhc_probe_format_init(&f, nullptr), ZHC_OK);
    float out[27];
    std::uint8_t bytes[108] = {};
    EXPECT_EQ(zhc_decode_probe(&f, bytes, out), ZHC_ERR_ARGUMENT);  // encoding -1
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3_q28"), ZHC_OK);
    for (int bits : {0, 1, 9, 100}) {
        f.bits = bits;
        EXPECT_EQ(zhc_decode_probe(&f, bytes, out), ZHC_ERR_ARGUMENT) << bits;
    }
}

TEST(RuntimeC, GltfQuantizationStringsMapToTheStorageParams) {
    // The strings of docs/gltf-extension.md and formats/probes/gltf_probes.cpp, and the enum values the
    // codec gives them (CodecOptions).
    struct Case {
        const char* key;
        const char* value;
        int zhc_probe_format::*field;
        int expected;
    };
    const Case cases[] = {
        {"kind", "radiance", &zhc_probe_format::kind, int(StoredKind::kRadiance)},
        {"kind", "irradiance", &zhc_probe_format::kind, int(StoredKind::kIrradiance)},
        {"l2Bound", "tight", &zhc_probe_format::l2_bound, int(L2Bound::kTight)},
        {"l2Bound", "loose", &zhc_probe_format::l2_bound, int(L2Bound::kLoose)},
        {"dcFormat", "r11g11b10f", &zhc_probe_format::dc_format, int(DcFormat::kR11G11B10F)},
        {"dcFormat", "rgb9e5", &zhc_probe_format::dc_format, int(DcFormat::kRGB9E5)},
        {"dcFormat", "half", &zhc_probe_format::dc_format, int(DcFormat::kHalf)},
        {"zonalMapping", "affine", &zhc_probe_format::zonal_mapping, int(ZonalMapping::kAffine)},
        {"zonalMapping", "zero", &zhc_probe_format::zonal_mapping, int(ZonalMapping::kZeroPreserving)},
        {"zonalMapping", "symmetric", &zhc_probe_format::zonal_mapping, int(ZonalMapping::kSymmetric)},
        {"axisMode", "luminance", &zhc_probe_format::axis_mode, int(ZonalAxisMode::kLuminance)},
        {"axisMode", "channel", &zhc_probe_format::axis_mode, int(ZonalAxisMode::kPerChannel)},
        {"sqrt", "false", &zhc_probe_format::sqrt_encoding, 0},
        {"sqrt", "true", &zhc_probe_format::sqrt_encoding, 1},
    };
    for (const Case& c : cases) {
        zhc_probe_format f;
        ASSERT_EQ(zhc_probe_format_init(&f, "sh2_q"), ZHC_OK);
        f.*c.field = 77;
        ASSERT_EQ(zhc_probe_format_set_gltf(&f, c.key, c.value), ZHC_OK) << c.key << " " << c.value;
        EXPECT_EQ(f.*c.field, c.expected) << c.key << " " << c.value;
        // Unknown values and keys leave the format unchanged.
        const zhc_probe_format before = f;
        EXPECT_EQ(zhc_probe_format_set_gltf(&f, c.key, "Half"), ZHC_ERR_UNSUPPORTED);
        EXPECT_EQ(zhc_probe_format_set_gltf(&f, c.key, ""), ZHC_ERR_UNSUPPORTED);
        EXPECT_EQ(std::memcmp(&before, &f, sizeof f), 0);
    }
    zhc_probe_format f;
    ASSERT_EQ(zhc_probe_format_init(&f, "sh3_q28"), ZHC_OK);
    for (int bits = 2; bits <= 8; ++bits) {
        const std::string v = std::to_string(bits);
        ASSERT_EQ(zhc_probe_format_set_gltf(&f, "bits", v.c_str()), ZHC_OK);
        EXPECT_EQ(f.bits, bits);
    }
    for (const char* bad : {"1", "9", "10", "08", "", "x", "3 "})
        EXPECT_EQ(zhc_probe_format_set_gltf(&f, "bits", bad), ZHC_ERR_UNSUPPORTED) << bad;
    EXPECT_EQ(f.bits, 8);
    EXPECT_EQ(zhc_probe_format_set_gltf(&f, "encoding", "sh3"), ZHC_ERR_ARGUMENT);
    EXPECT_EQ(zhc_probe_format_set_gltf(&f, nullptr, "x"), ZHC_ERR_ARGUMENT);
    EXPECT_EQ(zhc_probe_format_set_gltf(&f, "bits", nullptr), ZHC_ERR_ARGUMENT);
}

// ---- every entry: encoded probes and random bytes ----------------------------------------------

std::map<std::string, EntryStats>& all_stats() {
    static std::map<std::string, EntryStats> s;
    return s;
}

class RuntimeCEntry : public ::testing::TestWithParam<std::string> {};

TEST_P(RuntimeCEntry, DecodeAndIrradianceEqualTheCodecBitForBit) {
    const Codec* c = find_codec(GetParam());
    ASSERT_NE(c, nullptr);
    EntryStats& st = all_stats()[GetParam()];
    std::mt19937_64 rng(0x15C0DE + std::hash<std::string>{}(GetParam()));
    const int kProbes = static_cast<int>(test::sample_count(100000));  // per kind of input
    std::vector<std::uint8_t> bytes(c->size_bytes);
    // Default parameters: the table entry itself (encode with default options).
    for (int i = 0; i < kProbes; ++i) {
        const Sh3Radiance hub = random_probe(rng, std::uint64_t(i));
        const CodecOptions p;
        encode_probe(*c, p, hub, bytes.data(), nullptr);
        compare_probe(*c, p, bytes.data(), rng, st.decode_default, st.irr_default, st, &st.decode_table, &st.irr_table);
        ++st.probes;
        if (HasFatalFailure()) return;
    }
    // Non-default parameters (bits 2..8, sqrt, bound, DC format, zonal mapping, axis, kind, weights).
    for (int i = 0; i < kProbes; ++i) {
        const Sh3Radiance hub = random_probe(rng, std::uint64_t(i));
        const CodecOptions p = random_params(rng, c->name);
        encode_probe(*c, p, hub, bytes.data(), nullptr);
        compare_probe(*c, p, bytes.data(), rng, st.decode_params, st.irr_params, st);
        ++st.probes;
        if (HasFatalFailure()) return;
    }
    // Arbitrary bytes (half of them under random parameters); special float patterns are frequent.
    for (int i = 0; i < kProbes; ++i) {
        for (auto& b : bytes) b = std::uint8_t(rng());
        if (rng() % 4 == 0)
            for (size_t j = 0; j + 4 <= bytes.size(); j += 4)
                if (rng() % 3 == 0) bytes[j + 3] = std::uint8_t((rng() % 2) ? 0x7F : 0xFF), bytes[j + 2] |= 0x80;
        const CodecOptions p = (i % 2) ? random_params(rng, c->name) : CodecOptions{};
        compare_probe(*c, p, bytes.data(), rng, st.bytes_decode, st.bytes_irr, st);
        ++st.random_bytes;
        if (HasFatalFailure()) return;
    }
    EXPECT_EQ(st.decode_default.worst, 0u) << st.decode_default.where;
    EXPECT_EQ(st.decode_table.worst, 0u) << st.decode_table.where;
    EXPECT_EQ(st.decode_params.worst, 0u) << st.decode_params.where;
    EXPECT_EQ(st.irr_default.worst, 0u) << st.irr_default.where;
    EXPECT_EQ(st.irr_table.worst, 0u) << st.irr_table.where;
    EXPECT_EQ(st.irr_params.worst, 0u) << st.irr_params.where;
    EXPECT_EQ(st.bytes_decode.worst, 0u) << st.bytes_decode.where;
    EXPECT_EQ(st.bytes_irr.worst, 0u) << st.bytes_irr.where;
    auto u = [](const MaxUlp& m) { return static_cast<unsigned long long>(m.worst); };
    std::printf("| %-22s | %7llu | %7llu | %3llu | %3llu | %3llu | %3llu | %3llu | %3llu | %3llu | %3llu | %8llu |\n",
                GetParam().c_str(), static_cast<unsigned long long>(st.probes),
                static_cast<unsigned long long>(st.random_bytes), u(st.decode_default), u(st.decode_table),
                u(st.decode_params), u(st.bytes_decode), u(st.irr_default), u(st.irr_table), u(st.irr_params),
                u(st.bytes_irr), static_cast<unsigned long long>(st.nan_outputs));
}

std::vector<std::string> entry_names() {
    std::vector<std::string> out;
    for (const Codec& c : runtime_codecs()) out.emplace_back(c.name);  // the engine layouts have no runtime decoder
    return out;
}
INSTANTIATE_TEST_SUITE_P(AllEntries, RuntimeCEntry, ::testing::ValuesIn(entry_names()),
                         [](const auto& info) { return info.param; });

// ---- DC formats --------------------------------------------------------------------------------

TEST(RuntimeC, DcUnpackersEqualTheCodecOnEveryHalfAndManyPackedWords) {
    for (std::uint32_t h = 0; h < 65536; ++h) {
        const float a = zhc_unpack_half(std::uint16_t(h)), b = unpack_half(std::uint16_t(h));
        ASSERT_EQ(ulp_distance(a, b), 0u) << h;
    }
    std::mt19937_64 rng(7);
    for (int i = 0; i < 1000000; ++i) {
        const std::uint32_t w = std::uint32_t(rng());
        float r[3];
        zhc_unpack_r11g11b10f(w, r);
        const Rgb cr = unpack_r11g11b10f(w);
        zhc_unpack_rgb9e5(w, r + 0);
        const Rgb ce = unpack_rgb9e5(w);
        for (int k = 0; k < 3; ++k) ASSERT_EQ(ulp_distance(r[k], ce[k]), 0u) << w;
        zhc_unpack_r11g11b10f(w, r);
        for (int k = 0; k < 3; ++k) ASSERT_EQ(ulp_distance(r[k], cr[k]), 0u) << w;
    }
}

// ---- IrradZ / HLSH / hemi-octahedral -------------------------------------------------------

double wild(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    switch (rng() % 16) {
        case 0: return NAN;
        case 1: return INFINITY;
        case 2: return -1.0;
        case 3: return 0.0;
        default: return 3 * u(rng) - 1;
    }
}

TEST(RuntimeC, IrradzFunctionsEqualTheCodec) {
    std::mt19937_64 rng(2024);
    std::uniform_real_distribution<double> u(0, 1);
    MaxUlp hemioct, hhd, ahd, texel, hlsh_eval;
    for (int i = 0; i < 300000; ++i) {
        // Hemi-octahedral decode, including out-of-range and NaN inputs.
        const float uu = float(i % 5 == 0 ? wild(rng) : u(rng)), vv = float(i % 7 == 0 ? wild(rng) : u(rng));
        double d[3];
        zhc_decode_hemioct(uu, vv, d);
        const Vec3 cd = lightmap::decode_hemioct(uu, vv);
        for (int k = 0; k < 3; ++k) hemioct.add(float(d[k]), float(cd[k]), "hemioct");
        ASSERT_TRUE(d[0] == cd.x && d[1] == cd.y && d[2] == cd.z) << uu << " " << vv;
        // HHD / AHD from (I_z, w_a, d) at a tangent normal: d anywhere (below the horizon, zero).
        irradz::IrradZ p;
        p.i_z = {float(u(rng) * 4), float(u(rng) * 4), float(i % 11 == 0 ? wild(rng) : u(rng))};
        p.w_a = i % 3 == 0 ? wild(rng) : u(rng);
        p.d = i % 13 == 0 ? Vec3{0, 0, 0} : random_direction(rng);
        const Vec3 n = random_direction(rng);
        const double dd[3] = {p.d.x, p.d.y, p.d.z}, nn[3] = {n.x, n.y, n.z};
        const float iz[3] = {p.i_z.r, p.i_z.g, p.i_z.b};
        for (int model = 0; model < 2; ++model) {
            float e[3];
            zhc_irradz_irradiance(iz, p.w_a, dd, model, nn, e);
            const Rgb ce = irradz::evaluate(p, model == 0 ? irradz::Model::kHhd : irradz::Model::kAhd, n);
            for (int k = 0; k < 3; ++k) (model == 0 ? hhd : ahd).add(e[k], ce[k], model == 0 ? "irradz HHD" : "irradz AHD");
        }
        // The texel path: textures hold I_z, w_a and the hemi-octahedral (u, v).
        lightmap::IrradzPlanes planes;
        planes.width = planes.height = 1;
        planes.iz = {iz[0], iz[1], iz[2]};
        planes.wa = {float(p.w_a)};
        planes.d = {uu, vv};
        float e[3];
        zhc_irradz_irradiance_texel(iz, float(p.w_a), uu, vv, ZHC_IRRADZ_HHD, nn, e);
        const Rgb ct = irradz::evaluate(planes.texel(0), irradz::Model::kHhd, n);
        for (int k = 0; k < 3; ++k) texel.add(e[k], ct[k], "irradz texel");
        // HLSH evaluation.
        irradz::Hlsh h;
        for (int k = 0; k < 3; ++k) {
            h.i_z[k] = float(u(rng));
            h.c_a[k] = float(u(rng));
            h.c_x[k] = float(u(rng) - 0.5);
            h.c_y[k] = float(u(rng) - 0.5);
        }
        const float hi[3] = {h.i_z.r, h.i_z.g, h.i_z.b}, ha[3] = {h.c_a.r, h.c_a.g, h.c_a.b},
                    hx[3] = {h.c_x.r, h.c_x.g, h.c_x.b}, hy[3] = {h.c_y.r, h.c_y.g, h.c_y.b};
        zhc_hlsh_evaluate(hi, ha, hx, hy, nn, e);
        const Rgb ch = irradz::evaluate(h, n);
        for (int k = 0; k < 3; ++k) hlsh_eval.add(e[k], ch[k], "hlsh evaluate");
    }
    std::printf("irradz ulp: hemioct %llu, HHD %llu, AHD %llu, texel %llu, HLSH evaluate %llu\n",
                (unsigned long long)hemioct.worst, (unsigned long long)hhd.worst, (unsigned long long)ahd.worst,
                (unsigned long long)texel.worst, (unsigned long long)hlsh_eval.worst);
    EXPECT_EQ(hemioct.worst, 0u) << hemioct.where;
    EXPECT_EQ(hhd.worst, 0u) << hhd.where;
    EXPECT_EQ(ahd.worst, 0u) << ahd.where;
    EXPECT_EQ(texel.worst, 0u) << texel.where;
    EXPECT_EQ(hlsh_eval.worst, 0u) << hlsh_eval.where;
}

TEST(RuntimeC, HlshMultiplyAndItsTablesEqualTheCodec) {
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0, 1);
    MaxUlp frame_ulp, hlsh, rot;
    for (double cos_alpha : {0.0, 0.5, -0.3, -1.0, 1.0, 0.9, 2.0, -7.0}) {
        zhc_hlsh_tables t;
        zhc_hlsh_tables_init(&t, cos_alpha);
        const auto g = irradz::cap_gram(cos_alpha);
        for (int i = 0; i < 81; ++i) ASSERT_EQ(t.gram[i], g[size_t(i)]) << cos_alpha << " " << i;
        if (cos_alpha == 0.0) {
            for (int i = 0; i < 81; ++i) ASSERT_EQ(t.gram[i], irradz::hemisphere_gram()[size_t(i)]);
        }
        for (int i = 0; i < 20000; ++i) {
            const Sh3Radiance world = random_probe(rng, std::uint64_t(i));
            const Vec3 n = i % 50 == 0 ? Vec3{0.95, 0.1, 0.0} : random_direction(rng);
            const Mat3 frame = frame_from_z(n);
            double fr[9];
            const double nn[3] = {n.x, n.y, n.z};
            zhc_frame_from_z(nn, fr);
            for (int j = 0; j < 9; ++j) ASSERT_EQ(fr[j], frame.m[size_t(j)]);
            float sh[27];
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) sh[c * 3 + k] = world[c][k];
            float rotated[27];
            zhc_sh3_rotate(sh, fr, rotated);
            const Sh3Radiance cr = rotate(world, frame);
            for (int c = 0; c < 9; ++c)
                for (int k = 0; k < 3; ++k) rot.add(rotated[c * 3 + k], cr[c][k], "rotate");
            float iz[3], ca[3], cx[3], cy[3];
            zhc_hlsh_multiply(&t, sh, fr, iz, ca, cx, cy);
            const irradz::Hlsh h = irradz::hlsh_multiply(world, frame, cos_alpha);
            for (int k = 0; k < 3; ++k) {
                hlsh.add(iz[k], h.i_z[k], "hlsh i_z");
                hlsh.add(ca[k], h.c_a[k], "hlsh c_a");
                hlsh.add(cx[k], h.c_x[k], "hlsh c_x");
                hlsh.add(cy[k], h.c_y[k], "hlsh c_y");
            }
        }
    }
    std::printf("hlsh ulp: rotate %llu, multiply %llu\n", (unsigned long long)rot.worst, (unsigned long long)hlsh.worst);
    EXPECT_EQ(rot.worst, 0u) << rot.where;
    EXPECT_EQ(hlsh.worst, 0u) << hlsh.where;
}

}  // namespace
}  // namespace zhc
