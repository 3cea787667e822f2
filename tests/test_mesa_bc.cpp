// A real decoder in the tests: Mesa's software OpenGL (llvmpipe) through headless EGL
// (EGL_MESA_platform_surfaceless, no display needed) uploads zhc's BC6H / BC4 / BC5 blocks with
// glCompressedTexImage2D and reads them back with glGetTexImage. BC6H must match zhc's decoder bit
// for bit (half floats); BC4/BC5 within 1/255; BC7 (zhc's cube-map reader) byte for byte.
#include "gl/egl_context.h"
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"
#include "formats/envmap/bc7.h"
#include "cube_ldr_helpers.h"
#include "support.h"

namespace zhc {
namespace {

class MesaContext : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        why_ = test::make_llvmpipe_context(EGL_OPENGL_API, EGL_OPENGL_BIT, nullptr, &egl_);
        if (!why_.empty()) return;
        renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        std::printf("GL_RENDERER: %s, GL_VERSION: %s\n", renderer_.c_str(),
                    reinterpret_cast<const char*>(glGetString(GL_VERSION)));
    }
    static void TearDownTestSuite() {
        test::destroy_context(&egl_);
    }
    void SetUp() override {
        ASSERT_TRUE(why_.empty()) << why_;
        ASSERT_NE(renderer_.find("llvmpipe"), std::string::npos) << renderer_;
    }

    // Uploads `blocks` as a width x height texture of `format` and reads level 0 back.
    template <class T>
    std::vector<T> round_trip(GLenum format, const std::vector<std::uint8_t>& blocks, int w, int h, GLenum read_format,
                              GLenum read_type, int channels) {
        GLuint tex = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glCompressedTexImage2D(GL_TEXTURE_2D, 0, format, w, h, 0, static_cast<GLsizei>(blocks.size()), blocks.data());
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        std::vector<T> out(static_cast<size_t>(w) * h * channels);
        glGetTexImage(GL_TEXTURE_2D, 0, read_format, read_type, out.data());
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        glDeleteTextures(1, &tex);
        return out;
    }

    static inline test::EglContext egl_;
    static inline std::string why_;
    static inline std::string renderer_;
};

// Random blocks with every mode code forced in turn (all 14 modes and the 4 reserved codes),
// followed by blocks zhc's encoder made from a real map at every quality level.
std::vector<std::uint8_t> bc6h_test_blocks(int* w, int* h) {
    std::vector<std::uint8_t> blocks;
    std::mt19937_64 rng(11);
    const std::uint8_t codes[] = {0x00, 0x01, 0x02, 0x06, 0x0A, 0x0E, 0x12, 0x16, 0x1A, 0x1E,
                                  0x03, 0x07, 0x0B, 0x0F, 0x13, 0x17, 0x1B, 0x1F};
    for (int k = 0; k < 18 * 64; ++k) {
        std::uint8_t b[16];
        for (int j = 0; j < 16; j += 8) {
            const std::uint64_t v = rng();
            std::memcpy(b + j, &v, 8);
        }
        const std::uint8_t code = codes[k % 18];
        b[0] = static_cast<std::uint8_t>((b[0] & (code < 2 ? 0xFC : 0xE0)) | code);
        blocks.insert(blocks.end(), b, b + 16);
    }
    const Image img = test::load_envmap(test::envmap_paths().front());
    for (const bc6h::Quality q : {bc6h::Quality::kMode11, bc6h::Quality::kFast, bc6h::Quality::kDefault,
                                  bc6h::Quality::kExhaustive}) {
        // A 64 x 16 crop (16 x 4 blocks) from a bright, detailed region.
        std::vector<float> crop(64 * 16 * 3);
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 64 * 3; ++x) crop[static_cast<size_t>(y) * 64 * 3 + x] = img.row(y + 180)[x + 1200];
        const auto enc = bc6h::encode_image(crop.data(), 64, 16, q);
        // Re-order the 16 x 4 block grid into the same 1-D list (layout handled below).
        blocks.insert(blocks.end(), enc.begin(), enc.end());
    }
    // 18*64 + 4*64 = 1408 blocks: a 64 x 22 block texture (256 x 88 texels).
    *w = 256;
    *h = static_cast<int>(blocks.size() / 16 / 64) * 4;
    return blocks;
}

TEST_F(MesaContext, Bc6hMatchesZhcDecoderBitForBit) {
    int w = 0, h = 0;
    const auto blocks = bc6h_test_blocks(&w, &h);
    ASSERT_EQ(blocks.size(), static_cast<size_t>(w / 4) * (h / 4) * 16);
    const auto gl = round_trip<std::uint16_t>(GL_COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT, blocks, w, h, GL_RGB, GL_HALF_FLOAT, 3);
    const auto ours = bc6h::decode_image(blocks.data(), blocks.size(), w, h);
    ASSERT_EQ(gl.size(), ours.size());
    size_t mismatches = 0;
    int modes_seen[18] = {};
    for (size_t b = 0; b < blocks.size() / 16; ++b) {
        const int m = bc6h::block_mode(blocks.data() + 16 * b);
        ++modes_seen[m < 0 ? 14 : m];
    }
    for (size_t i = 0; i < gl.size(); ++i)
        if (gl[i] != ours[i]) {
            if (mismatches < 5)
                ADD_FAILURE() << "texel " << i / 3 << " channel " << i % 3 << ": mesa 0x" << std::hex << gl[i]
                              << " zhc 0x" << ours[i];
            ++mismatches;
        }
    EXPECT_EQ(mismatches, 0u) << "of " << gl.size();
    for (int m = 0; m < 15; ++m) EXPECT_GT(modes_seen[m], 0) << "mode " << m;
    std::printf("BC6H: %zu blocks (%zu half values) compared with Mesa, %zu mismatches\n", blocks.size() / 16,
                gl.size(), mismatches);
}

TEST_F(MesaContext, Bc4AndBc5MatchWithinTwoLevelsAndStructurally) {
    std::mt19937_64 rng(12);
    // Random blocks (both palette kinds) and encoded gradients/noise.
    const int w = 64, h = 64;
    const int nblocks = (w / 4) * (h / 4);
    for (const int channels : {1, 2}) {
        std::vector<std::uint8_t> blocks;
        for (int b = 0; b < nblocks / 2; ++b)
            for (int k = 0; k < channels; ++k) {
                const std::uint64_t v = rng();
                std::uint8_t blk[8];
                std::memcpy(blk, &v, 8);
                blocks.insert(blocks.end(), blk, blk + 8);
            }
        std::vector<float> src(static_cast<size_t>(w) * (h / 2) * channels);
        std::uniform_real_distribution<float> u(0, 1);
        for (size_t i = 0; i < src.size(); ++i) src[i] = 0.5f * u(rng) + 0.5f * float(i % 97) / 97.0f;
        const auto enc = bc45::encode_image(src.data(), channels, w, h / 2, bc45::Quality::kDefault);
        blocks.insert(blocks.end(), enc.begin(), enc.end());
        const auto gl8 = round_trip<std::uint8_t>(channels == 1 ? GL_COMPRESSED_RED_RGTC1 : GL_COMPRESSED_RG_RGTC2, blocks,
                                                  w, h, channels == 1 ? GL_RED : GL_RG, GL_UNSIGNED_BYTE, channels);
        std::vector<float> gl(gl8.size());
        for (size_t i = 0; i < gl.size(); ++i) gl[i] = float(gl8[i]) / 255.0f;
        const auto ours = bc45::decode_image(blocks.data(), blocks.size(), channels, w, h);
        // llvmpipe samples RGTC with gallivm's 8-bit fixed-point lerp, not the format's exact
        // (7 - j) r0 + j r1) / 7, so it sits up to ~1.6/255 from the exact palette value (e.g. r0 = 255,
        // r1 = 5, index 7: exact 40.71, llvmpipe 42). We therefore check (a) |mesa - zhc| <= 2/255 and
        // (b) structurally: Mesa's value is nearer to zhc's palette entry than to any other entry of the
        // block's palette whenever the entries are > 4/255 apart (so indices and palette kinds agree).
        double worst = 0;
        size_t structural = 0;
        for (size_t i = 0; i < gl.size(); ++i) {
            const double d = std::abs(double(gl[i]) - double(ours[i]));
            worst = std::max(worst, d);
            const size_t t = i / channels, x = t % w, y = t / w, c = i % channels;
            const std::uint8_t* blk = blocks.data() + ((y / 4) * (w / 4) + x / 4) * (channels * 8) + c * 8;
            float pal_probe[16];
            std::uint8_t probe[8];
            double nearest_other = 1e9, spacing = 1e9;
            for (int j = 0; j < 8; ++j) {
                std::memcpy(probe, blk, 2);
                const std::uint64_t bits = std::uint64_t(j) * 0x249249249249ull;  // index j for all texels
                for (int k = 0; k < 6; ++k) probe[2 + k] = static_cast<std::uint8_t>(bits >> (8 * k));
                bc45::decode_bc4_block(probe, pal_probe);
                if (pal_probe[0] != ours[i]) {
                    nearest_other = std::min(nearest_other, std::abs(double(pal_probe[0]) - gl[i]));
                    spacing = std::min(spacing, std::abs(double(pal_probe[0]) - ours[i]));
                }
            }
            // Only palettes whose entries are more than 4 levels apart can tell indices apart.
            if (spacing > 4.0 / 255.0 && nearest_other <= d) ++structural;
        }
        std::printf("BC%d: %d blocks compared with Mesa, max |difference| = %.6f (x255 = %.3f), structural mismatches %zu\n",
                    channels == 1 ? 4 : 5, nblocks, worst, worst * 255, structural);
        EXPECT_EQ(structural, 0u);
        EXPECT_LE(worst, 2.0 / 255.0);
    }
}

// Random blocks with every BC7 mode forced in turn (the mode's bit set, the bits below it clear)
// and the reserved mode (low byte 0), as BPTC UNORM and as sRGB (the same stored values come back:
// glGetTexImage does not decode sRGB).
TEST_F(MesaContext, Bc7MatchesZhcDecoderByteForByte) {
    std::mt19937_64 rng(13);
    const int w = 256, h = 72;  // 64 x 18 blocks: 128 of each of the 9 mode codes
    std::vector<std::uint8_t> blocks;
    int modes_seen[9] = {};
    for (int k = 0; k < (w / 4) * (h / 4); ++k) {
        std::uint8_t b[16];
        for (int j = 0; j < 16; j += 8) {
            const std::uint64_t v = rng();
            std::memcpy(b + j, &v, 8);
        }
        const int mode = k % 9;
        b[0] = mode == 8 ? 0 : static_cast<std::uint8_t>((b[0] & ~((2u << mode) - 1)) | (1u << mode));
        ++modes_seen[bc7::block_mode(b)];
        blocks.insert(blocks.end(), b, b + 16);
    }
    for (int m = 0; m < 9; ++m) EXPECT_EQ(modes_seen[m], 128) << "mode " << m;
    std::vector<std::uint8_t> ours(static_cast<size_t>(w) * h * 4);
    for (int by = 0; by < h / 4; ++by)
        for (int bx = 0; bx < w / 4; ++bx) {
            std::uint8_t texels[16][4];
            bc7::decode_block(blocks.data() + 16 * (static_cast<size_t>(by) * (w / 4) + bx), texels);
            for (int t = 0; t < 16; ++t)
                std::memcpy(&ours[4 * (static_cast<size_t>(4 * by + t / 4) * w + 4 * bx + t % 4)], texels[t], 4);
        }
    for (const GLenum format : {GLenum(GL_COMPRESSED_RGBA_BPTC_UNORM), GLenum(GL_COMPRESSED_SRGB_ALPHA_BPTC_UNORM)}) {
        const auto gl = round_trip<std::uint8_t>(format, blocks, w, h, GL_RGBA, GL_UNSIGNED_BYTE, 4);
        ASSERT_EQ(gl.size(), ours.size());
        size_t mismatches = 0;
        size_t per_mode[9] = {};
        for (size_t i = 0; i < gl.size(); ++i)
            if (gl[i] != ours[i]) {
                const size_t t = i / 4, x = t % w, y = t / w;
                const int mode = bc7::block_mode(blocks.data() + 16 * ((y / 4) * (w / 4) + x / 4));
                if (mismatches < 5)
                    ADD_FAILURE() << "texel (" << x << ", " << y << ") channel " << i % 4 << " mode " << mode << ": mesa "
                                  << int(gl[i]) << " zhc " << int(ours[i]);
                ++mismatches;
                ++per_mode[mode];
            }
        EXPECT_EQ(mismatches, 0u) << "of " << gl.size();
        std::printf("BC7 (%s): %zu blocks (%zu bytes) compared with Mesa, %zu mismatches (by mode:",
                    format == GL_COMPRESSED_RGBA_BPTC_UNORM ? "UNORM" : "sRGB", blocks.size() / 16, gl.size(), mismatches);
        for (const size_t n : per_mode) std::printf(" %zu", n);
        std::printf(")\n");
    }
}

// BC7 cube maps whose blocks Mesa's BPTC encoder wrote: llvmpipe compresses RGBA8 faces on
// upload to a BPTC internal format (glTexImage2D), glGetCompressedTexImage returns its blocks and
// glGetTexImage its own decode of them. The blocks go into KTX2 and DDS cube maps (containers
// assembled by this test's writers, cube_ldr_helpers.h: no Debian 12 tool writes BC7 KTX2 / DDS)
// that zhc reads: every texel must be Mesa's decode under the format's transfer function, and the
// projection must be the analytic function's SH within the bound of the measured texel error.
TEST_F(MesaContext, Bc7CubeMapsEncodedByMesaReadAndProject) {
    using namespace cube_test;
    const int n = 64;
    const Linear fn;
    const Image lin = render_cube(n, fn);
    for (const bool srgb : {true, false}) {
        SCOPED_TRACE(srgb ? "sRGB" : "UNORM");
        Bytes blocks, mesa_texels;
        for (int face = 0; face < 6; ++face) {
            Bytes rgba;
            for (int r = 0; r < n; ++r)
                for (int c = 0; c < n; ++c) {
                    const float* p = lin.row(face * n + r) + 3 * c;
                    for (int k = 0; k < 3; ++k) {
                        const double v = srgb ? srgb_oetf_twin(p[k]) : p[k];
                        rgba.push_back(static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255)));
                    }
                    rgba.push_back(255);
                }
            GLuint tex = 0;
            glGenTextures(1, &tex);
            glBindTexture(GL_TEXTURE_2D, tex);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
            glPixelStorei(GL_PACK_ALIGNMENT, 1);
            glTexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_COMPRESSED_SRGB_ALPHA_BPTC_UNORM : GL_COMPRESSED_RGBA_BPTC_UNORM, n, n, 0, GL_RGBA,
                         GL_UNSIGNED_BYTE, rgba.data());
            GLint compressed = 0, size = 0;
            glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_COMPRESSED, &compressed);
            glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_COMPRESSED_IMAGE_SIZE, &size);
            ASSERT_EQ(compressed, GL_TRUE);
            ASSERT_EQ(size, (n / 4) * (n / 4) * 16);
            Bytes face_blocks(static_cast<size_t>(size)), face_texels(static_cast<size_t>(n) * n * 4);
            glGetCompressedTexImage(GL_TEXTURE_2D, 0, face_blocks.data());
            glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, face_texels.data());
            ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
            glDeleteTextures(1, &tex);
            blocks.insert(blocks.end(), face_blocks.begin(), face_blocks.end());
            mesa_texels.insert(mesa_texels.end(), face_texels.begin(), face_texels.end());
        }
        int modes[9] = {};
        for (size_t b = 0; b < blocks.size(); b += 16) ++modes[bc7::block_mode(blocks.data() + b)];
        std::printf("Mesa's BC7 %s blocks by mode:", srgb ? "sRGB" : "UNORM");
        for (const int m : modes) std::printf(" %d", m);
        std::printf("\n");
        const std::string dir = test::temp_dir("mesa_bc7");
        const Bytes ktx2 = ktx2_one_level(srgb ? 146 : 145, 1, n, blocks);
        DdsPf pf;
        pf.dxgi = srgb ? 99 : 98;
        const Bytes dds_file = dds(pf, n, blocks);
        for (const auto& [name, file] : {std::pair<std::string, const Bytes*>{"cube.ktx2", &ktx2}, {"cube.dds", &dds_file}}) {
            SCOPED_TRACE(name);
            EnvmapReadOptions o;
            o.warn = [](const std::string&) {};
            EnvmapInfo info;
            auto img = read_envmap_memory(*file, name, o, &info);
            ASSERT_TRUE(img) << img.error().message;
            EXPECT_EQ(info.channels, srgb ? "BC7 sRGB" : "BC7 UNORM");
            double worst = 0, e = 0;
            for (size_t i = 0; i < img->rgb.size(); ++i) {
                const double byte = mesa_texels[4 * (i / 3) + i % 3] / 255.0;
                worst = std::max(worst, std::fabs(img->rgb[i] - (srgb ? srgb_eotf_twin(byte) : byte)));
                e = std::max(e, std::fabs(static_cast<double>(img->rgb[i]) - lin.rgb[i]));
            }
            EXPECT_LT(worst, 2e-6);  // Mesa's decode, by the transfer function
            const double bound = e / fn.c[2] + 1e-4;  // sqrt(4 pi) e / |L00| + the quadrature's 1e-4
            const double d = test::sh_distance(project_envmap(*img), fn.sh());
            std::printf("%s %s: %.2e of |L00| (texel error %.4f, bound %.2e), |zhc - Mesa| %.1e\n", name.c_str(),
                        srgb ? "sRGB" : "UNORM", d, e, bound, worst);
            EXPECT_LT(d, bound);
            EXPECT_LT(e, 0.1);  // the function, not noise (Mesa's fast encoder writes mode 4 blocks only)
            // Through the CLI: project reads the file (the UNORM one with its read-as-linear warning).
            const std::string path = dir + "/" + (srgb ? "srgb_" : "unorm_") + name;
            test::write_bytes(path, *file);
            const auto run = test::run_zhc({"project", path, "--json"});
            EXPECT_EQ(run.exit_code, 0) << run.err;
            EXPECT_EQ(run.err.find("read as linear") != std::string::npos, !srgb) << run.err;
        }
    }
}

}  // namespace
}  // namespace zhc
