// Contracts every entry of the codec table must keep (codec/probe/codec.h), checked by walking the
// table: a new representation is covered here without writing a test for it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "codec/probe/codec.h"
#include "support.h"

namespace zhc {
namespace {

std::vector<Sh3Radiance> sample_hubs() {
    std::vector<Sh3Radiance> out;
    for (const std::string& path : test::envmap_paths()) {
        const Image img = test::load_envmap(path);
        out.push_back(project_latlong(img.rgb.data(), img.width, img.height, img.width * 3u));
    }
    out.push_back(project_cone(normalize_or({1, 2, 3}, {0, 0, 1}), 0.3, {5, 4, 3}) + project_constant({0.1f, 0.1f, 0.1f}));
    out.push_back(project_directional({0, 0, 1}, {1, 1, 1}));
    return out;
}

TEST(CodecTable, NamesAreUniqueAndFindable) {
    std::set<std::string> names;
    for (const Codec& c : codecs()) {
        EXPECT_TRUE(names.insert(std::string(c.name)).second) << c.name;
        EXPECT_EQ(find_codec(c.name), &c);
        EXPECT_GT(c.size_bytes, 0u);
        EXPECT_FALSE(c.summary.empty());
    }
    EXPECT_EQ(find_codec("no-such-representation"), nullptr);
    EXPECT_NE(find_codec("sh3"), nullptr);
    EXPECT_NE(find_codec("sh2"), nullptr);
}

TEST(CodecTable, SelectCodecsKeepsOrderAndNamesUnknownEntries) {
    auto all = select_codecs("");
    ASSERT_TRUE(all);
    EXPECT_EQ(all->size(), codecs().size());
    auto two = select_codecs("sh2,sh3");
    ASSERT_TRUE(two);
    ASSERT_EQ(two->size(), 2u);
    EXPECT_EQ((*two)[0]->name, "sh2");
    EXPECT_EQ((*two)[1]->name, "sh3");
    auto bad = select_codecs("sh3,nope");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(bad.error().message.find("'nope'"), std::string::npos);
    EXPECT_FALSE(select_codecs("sh3,"));  // an empty name is unknown too
}

TEST(CodecTable, EncodeWritesExactlySizeBytesAndIsDeterministic) {
    const CodecOptions o;
    for (const Codec& c : codecs()) {
        SCOPED_TRACE(std::string(c.name));
        for (const Sh3Radiance& hub : sample_hubs()) {
            // Guard bytes on both sides must survive.
            std::vector<std::uint8_t> a(c.size_bytes + 64, 0xA5), b(c.size_bytes + 64, 0x5A);
            c.encode(hub, o, a.data() + 32, nullptr);
            c.encode(hub, o, b.data() + 32, nullptr);
            for (int i = 0; i < 32; ++i) {
                EXPECT_EQ(a[i], 0xA5);
                EXPECT_EQ(a[a.size() - 1 - i], 0xA5);
            }
            EXPECT_TRUE(std::equal(a.begin() + 32, a.end() - 32, b.begin() + 32));
        }
    }
}

// The irradiance an entry's irradiance_model (codec.h) promises from decode's SH3: the same function
// (kSh3), that function clamped at 0 (kSh3Clamped), or for kOwn the function whose least-squares
// SH3 projection decode returns.
Rgb promised_irradiance(const Codec& c, const Sh3Radiance& decoded, Vec3 n) {
    Rgb e = irradiance(decoded, n);
    if (c.traits.irradiance_model == IrradianceModel::kSh3Clamped)
        for (int k = 0; k < 3; ++k) e[k] = std::max(e[k], 0.0f);
    return e;
}

TEST(CodecTable, RuntimeIrradianceMatchesDecodedHub) {
    // codec.irradiance (the runtime path) and irradiance(codec.decode(...)) describe the same function,
    // as the entry's irradiance_model says (zhc's own entries: kSh3; the engine layouts of
    // engine_layouts.h evaluate as their engine's shader does, which the model names).
    const CodecOptions o;
    const auto dirs = test::fibonacci_directions(64);
    const auto dense = test::fibonacci_directions(8192);
    for (const Codec& c : codecs()) {
        SCOPED_TRACE(std::string(c.name));
        for (const Sh3Radiance& hub : sample_hubs()) {
            std::vector<std::uint8_t> s(c.size_bytes);
            c.encode(hub, o, s.data(), nullptr);
            const Sh3Radiance d = c.decode(s.data(), o);
            const double scale = std::max({double(hub[0].r), double(hub[0].g), double(hub[0].b)});
            if (c.traits.irradiance_model == IrradianceModel::kOwn) {
                // Least squares: the residual has no SH3 component (Fibonacci quadrature, equal weights).
                double residual[9][3] = {};
                for (const Vec3 n : dense) {
                    const Rgb a = c.irradiance(s.data(), o, n), b = irradiance(d, n);
                    const std::array<double, 9> y = sh3_basis(n);
                    for (int i = 0; i < 9; ++i)
                        for (int k = 0; k < 3; ++k) residual[i][k] += (double(a[k]) - b[k]) * y[i] * 4 * kPi / dense.size();
                }
                for (int i = 0; i < 9; ++i)
                    for (int k = 0; k < 3; ++k) EXPECT_NEAR(residual[i][k], 0.0, 1e-3 * scale) << "coefficient " << i;
                continue;
            }
            for (const Vec3 n : dirs) {
                const Rgb a = c.irradiance(s.data(), o, n), b = promised_irradiance(c, d, n);
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-4 * scale);
            }
        }
    }
}

TEST(CodecTable, DecodeAcceptsArbitraryBytes) {
    // The contract of codec.h on untrusted bytes: decode and irradiance never crash (the ASan/UBSan
    // build makes that strict); decode is a pure function of the bytes (the same bits out twice,
    // NaN included); irradiance agrees with the irradiance of the decoded SH3 wherever that is
    // finite, and is non-finite only when the decoded SH3 has a non-finite coefficient.
    const CodecOptions o;
    std::mt19937 rng(11);
    const Vec3 dirs[] = {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}, {0.48f, -0.6f, 0.64f}};
    for (const Codec& c : codecs()) {
        SCOPED_TRACE(std::string(c.name));
        std::vector<std::uint8_t> s(c.size_bytes);
        for (int trial = 0; trial < 400; ++trial) {
            for (auto& b : s) b = trial == 0 ? 0x00 : trial == 1 ? 0xFF : static_cast<std::uint8_t>(rng());
            if (trial >= 200)  // small random values: the finite part of the byte space, exercised
                for (size_t i = 0; i < s.size(); i += 4) s[i + 3 < s.size() ? i + 3 : i] &= 0x3F;
            const Sh3Radiance d = c.decode(s.data(), o), again = c.decode(s.data(), o);
            ASSERT_EQ(std::memcmp(&d, &again, sizeof d), 0) << "decode is not a pure function of the bytes";
            bool finite = true;
            double mag = 0;
            for (const Rgb& coef : d.c)
                for (int k = 0; k < 3; ++k) {
                    finite = finite && std::isfinite(coef[k]);
                    mag += std::fabs(double(coef[k]));
                }
            for (const Vec3 n : dirs) {
                const Rgb fast = c.irradiance(s.data(), o, n);
                if (!finite) continue;  // anything, including NaN: the bytes hold a non-finite value
                const Rgb slow = promised_irradiance(c, d, n);
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(fast[k])) << "non-finite irradiance from a finite decode, trial " << trial;
                    // kOwn: an ambient cube is no SH3 function; RuntimeIrradianceMatchesDecodedHub
                    // checks that its decode is its projection, here only that it is finite.
                    if (mag < 1e30 && c.traits.irradiance_model != IrradianceModel::kOwn) {
                        EXPECT_NEAR(fast[k], slow[k], 1e-4 * (1 + mag)) << "trial " << trial;
                    }
                }
            }
        }
    }
}

TEST(CodecTable, DcIsPreservedByEveryFloatRepresentation) {
    // L0 is exact for representations that store floats (quantised ones are checked by their own
    // error bounds): the decoded DC equals the input's.
    const CodecOptions o;
    for (const Codec& c : codecs()) {
        if (c.packed) continue;  // quantised layouts
        // Engine layouts store the DC in their engine's axes and scale (Godot's radiance / pi,
        // Unity's irradiance times Y00, halves and 8-bit ratios), so it comes back through that scale,
        // not bit for bit: tests/test_engine_layouts.cpp checks each against its engine.
        if (!c.traits.engine.empty()) continue;
        SCOPED_TRACE(std::string(c.name));
        for (const Sh3Radiance& hub : sample_hubs()) {
            std::vector<std::uint8_t> s(c.size_bytes);
            c.encode(hub, o, s.data(), nullptr);
            const Sh3Radiance d = c.decode(s.data(), o);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(d[0][k], hub[0][k]);
        }
    }
}

// CodecTraits (codec/probe/codec.h) are facts about the entry's functions; code outside the entries
// relies on them instead of names, so each is checked here against encode/decode.
TEST(CodecTable, ExactTraitHoldsAndOnlyWhereClaimed) {
    const CodecOptions o;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-100.0f, 100.0f);
    std::vector<Sh3Radiance> hubs = sample_hubs();
    for (int t = 0; t < 50; ++t) {
        Sh3Radiance h;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) h[i][k] = u(rng);
        hubs.push_back(h);
    }
    int exact_entries = 0;
    for (const Codec& c : codecs()) {
        SCOPED_TRACE(std::string(c.name));
        int differ = 0;
        for (const Sh3Radiance& hub : hubs) {
            std::vector<std::uint8_t> s(c.size_bytes);
            c.encode(hub, o, s.data(), nullptr);
            differ += !(c.decode(s.data(), o) == hub);
        }
        if (c.traits.exact) EXPECT_EQ(differ, 0) << "marked exact, but decode(encode(x)) != x";
        else EXPECT_GT(differ, 0) << "gives every hub back: mark it exact";
        exact_entries += c.traits.exact;
    }
    EXPECT_GE(exact_entries, 1) << "no exact entry: the benchmarks have no baseline";
}

TEST(CodecTable, FloatBandsTraitIsTheStoredLayout) {
    const CodecOptions o;
    int float_entries = 0;
    for (const Codec& c : codecs()) {
        const int bands = c.traits.float_bands;
        if (bands == 0) continue;
        SCOPED_TRACE(std::string(c.name));
        ++float_entries;
        ASSERT_TRUE(bands == 2 || bands == 3);
        const std::size_t n = static_cast<std::size_t>(bands * bands);
        ASSERT_EQ(c.size_bytes, n * 12);
        for (const Sh3Radiance& hub : sample_hubs()) {
            std::vector<float> values;
            for (std::size_t i = 0; i < n; ++i)
                for (int k = 0; k < 3; ++k) values.push_back(hub[i][k]);
            std::vector<std::uint8_t> want(c.size_bytes), got(c.size_bytes);
            store_floats(values, want.data());
            c.encode(hub, o, got.data(), nullptr);
            EXPECT_EQ(got, want);  // the first bands^2 coefficients as floats, [coefficient][channel]
            const Sh3Radiance d = c.decode(got.data(), o);
            for (std::size_t i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) EXPECT_EQ(d[i][k], i < n ? hub[i][k] : 0.0f) << i << " " << k;
        }
    }
    EXPECT_GE(float_entries, 1);
}

}  // namespace
}  // namespace zhc
