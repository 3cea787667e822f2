// runtime/zhc.glsl on a real GLSL implementation: Mesa's llvmpipe through surfaceless EGL and a
// desktop GL 4.5 core context (set-up as tests/test_mesa_bc.cpp). The shader source is read from
// runtime/zhc.glsl at run time, put after "#version 450" and followed by a small compute main that
// decodes probe words from an SSBO and writes SH3 radiance and irradiance at a normal; the same
// source after "#version 310 es" runs again on llvmpipe's OpenGL ES 3.1 (smaller sample). Every entry
// of the codec table zhc's runtimes read (zhc::runtime_codecs(): all but the engine layouts) must have a GLSL decoder; each is compared with the C++ codec
// (decode_probe / Codec::irradiance) on >= 100,000 probes (coloured lights + ambient, random SH, the
// eight sample maps under random rotations) spread over header parameter sets, plus 20,000 probes of
// random bytes. DC unpacking (R11G11B10F, RGB9E5, half) must be bit-exact; the IrradZ lightmap
// evaluator is compared with irradz::evaluate on 200,000 texels, the HLSH one on 100,000 inputs.
// The error metric and its bounds: tests/gl/runtime_gl_entries.inl.

#include "gl/egl_context.h"
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/lightmap/irradz.h"
#include "codec/lightmap/lightmap.h"
#include "codec/probe/probe_set.h"
#include "codec/probe/quantize.h"
#include "codec/probe/runtime_table.h"
#include "codec/probe/zh3.h"
#include "support.h"
#include "tetra_gpu_cases.h"
#include "volume_planes_cases.h"
#include "zhc_runtime.h"
#include "zhc_runtime_params.hpp"

#ifndef ZHC_RUNTIME_GLSL_PATH
#error "ZHC_RUNTIME_GLSL_PATH (path of runtime/zhc.glsl) must be defined by the build"
#endif

namespace zhc {
namespace {

constexpr double kU = 1.0 / 16777216.0;           // 2^-24, unit roundoff of binary32
const double kAbs = std::ldexp(1.0, -120);         // flush-to-zero allowance
constexpr double kCFloat = 16, kCQuant = 32, kCDecode = 16, kCLightmap = 16;
constexpr int kOutFloats = 30;  // per item: 27 SH3 radiance + 3 irradiance

// The test main appended after zhc.glsl. Modes: 0 probe decode + irradiance, 1 IrradZ texel,
// 2 DC unpacking, 3 HLSH, 4 probe volume, 5 the ASTC LDR fallback's I_z decode, 6 the generated table,
// 7 scattered probes (zhcVolumeTetraSh3 / zhcVolumeTetraIrradiance).
// Before zhc.glsl: the probe words, bound for the volume functions (ZHC_VOLUME_WORD).
const char* kTestPrelude = R"(
layout(std430, binding = 0) readonly buffer Words { uint words[]; };
#define ZHC_VOLUME_WORD(i) words[i]
)";
// The masked variant's extra prelude: per-probe combined masks, 4 per word (ZHC_VOLUME_MASK).
const char* kTestMaskPrelude = R"(
layout(std430, binding = 3) readonly buffer Masks { uint masks[]; };
#define ZHC_VOLUME_MASK(i) ((masks[(i) >> 2] >> (8u * ((i) & 3u))) & 0xFFu)
)";
// The plane variants' extra prelude: per-probe cell-plane entries, 2 words each (ZHC_VOLUME_PLANE).
const char* kTestPlanePrelude = R"(
layout(std430, binding = 4) readonly buffer Planes { uint planeWords[]; };
#define ZHC_VOLUME_PLANE(i) uvec2(planeWords[2u * (i)], planeWords[2u * (i) + 1u])
)";
const char* kTestMain = R"(
layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer Normals { float normals[]; };
layout(std430, binding = 2) writeonly buffer Out { float outv[]; };
uniform uint uCount;
uniform uint uStride;
uniform uint uMode;
uniform uvec4 uA;  // family, hallucination, bits, sqrtEncoding
uniform uvec4 uB;  // l2Bound, dcFormat, zonalMapping, axisMode
uniform uint uKind;
uniform vec3 uLum;
uniform vec2 uCurve;
uniform vec3 uVolOrigin;
uniform vec3 uVolSpacing;
uniform uvec3 uVolCounts;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    uint o = i * 30u;
    vec3 n = vec3(normals[3u * i], normals[3u * i + 1u], normals[3u * i + 2u]);
    if (uMode == 0u) {
        ZhcFormat f = ZhcFormat(uA.x, uA.y, uA.z, uA.w, uB.x, uB.y, uB.z, uB.w, uKind, uLum, uCurve);
        uint w[27];
        for (uint k = 0u; k < 27u; ++k) w[k] = k < uStride ? words[i * uStride + k] : 0u;
        ZhcSh3 s = zhcDecode(w, f);
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) outv[o + uint(3 * c + k)] = s.c[c][k];
        vec3 e = zhcIrradiance(w, f, n);
        outv[o + 27u] = e.x; outv[o + 28u] = e.y; outv[o + 29u] = e.z;
    } else if (uMode == 1u) {
        uint b = i * 7u;
        vec3 iz = uintBitsToFloat(uvec3(words[b], words[b + 1u], words[b + 2u]));
        float wa = uintBitsToFloat(words[b + 3u]);
        vec2 uv = uintBitsToFloat(uvec2(words[b + 4u], words[b + 5u]));
        vec3 e = zhcIrradZIrradiance(iz, wa, uv, n, words[b + 6u]);
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
        vec3 d = zhcDecodeHemiOct(uv);
        outv[o + 3u] = d.x; outv[o + 4u] = d.y; outv[o + 5u] = d.z;
    } else if (uMode == 3u) {
        uint b = i * 12u;
        vec3 v[4];
        for (uint k = 0u; k < 4u; ++k)
            v[k] = uintBitsToFloat(uvec3(words[b + 3u * k], words[b + 3u * k + 1u], words[b + 3u * k + 2u]));
        vec3 e = zhcHlshIrradiance(v[0], v[1], v[2], v[3], n);
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
    } else if (uMode == 5u) {  // ASTC LDR fallback: I_z from t with the texture's (lo, hi)
        uint b = i * 5u;
        vec3 t = uintBitsToFloat(uvec3(words[b], words[b + 1u], words[b + 2u]));
        vec3 e = zhcIrradZIzFromLdr(t, uintBitsToFloat(uvec2(words[b + 3u], words[b + 4u])));
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
    } else if (uMode == 4u) {  // probe volume: normals[] holds position, normal per item
        ZhcFormat f = ZhcFormat(uA.x, uA.y, uA.z, uA.w, uB.x, uB.y, uB.z, uB.w, uKind, uLum, uCurve);
        vec3 p = vec3(normals[6u * i], normals[6u * i + 1u], normals[6u * i + 2u]);
        vec3 nn = vec3(normals[6u * i + 3u], normals[6u * i + 4u], normals[6u * i + 5u]);
        vec3 e = zhcVolumeIrradiance(ZhcVolume(uVolOrigin, uVolSpacing, uVolCounts), f, p, nn);
        outv[o] = e.x; outv[o + 1u] = e.y; outv[o + 2u] = e.z;
#ifdef ZHC_VOLUME_PLANE
        {  // the corners the cell's plane keeps at p (zhcVolumeSh3's cell)
            ZhcVolume vv = ZhcVolume(uVolOrigin, uVolSpacing, uVolCounts);
            uvec3 cn = max(vv.counts, uvec3(1u));
            vec3 t = (p - vv.origin) / vv.spacing;
            t = min(mix(vec3(0.0), t, greaterThanEqual(t, vec3(0.0))), vec3(cn - 1u));
            uvec3 i0 = min(uvec3(t), max(cn, uvec3(2u)) - 2u);
            outv[o + 3u] = float(zhcVolumePlaneKeep(ZHC_VOLUME_PLANE(i0.x + cn.x * (i0.y + cn.y * i0.z)), vv, i0, p));
        }
#endif
    } else if (uMode == 7u) {  // scattered probes: normals[] holds 4 weights, 4 probe indices, normal per item
        ZhcFormat f = ZhcFormat(uA.x, uA.y, uA.z, uA.w, uB.x, uB.y, uB.z, uB.w, uKind, uLum, uCurve);
        uint b = 11u * i;
        vec4 wt = vec4(normals[b], normals[b + 1u], normals[b + 2u], normals[b + 3u]);
        uvec4 q = uvec4(vec4(normals[b + 4u], normals[b + 5u], normals[b + 6u], normals[b + 7u]));
        vec3 nn = vec3(normals[b + 8u], normals[b + 9u], normals[b + 10u]);
        ZhcSh3 s = zhcVolumeTetraSh3(q, wt, f);
        for (int c = 0; c < 9; ++c)
            for (int k = 0; k < 3; ++k) outv[o + uint(3 * c + k)] = s.c[c][k];
        vec3 e = zhcVolumeTetraIrradiance(q, wt, f, nn);
        outv[o + 27u] = e.x; outv[o + 28u] = e.y; outv[o + 29u] = e.z;
    } else if (uMode == 6u) {  // the generated table: item i is encoding id i (ids past the end included)
        outv[o] = float(zhcEncodingBytes(i));
        outv[o + 1u] = float(zhcEncodingFamily(i));
        outv[o + 2u] = float(zhcEncodingHallucination(i));
        outv[o + 3u] = float(zhcEncodingAxis(i));
        outv[o + 4u] = float(ZHC_ENCODING_COUNT);
        outv[o + 5u] = float(ZHC_DEFAULT_BITS);
        outv[o + 6u] = ZHC_DEFAULT_LUMINANCE.x; outv[o + 7u] = ZHC_DEFAULT_LUMINANCE.y;
        outv[o + 8u] = ZHC_DEFAULT_LUMINANCE.z;
        outv[o + 9u] = ZHC_DEFAULT_CURVE.x; outv[o + 10u] = ZHC_DEFAULT_CURVE.y;
        outv[o + 11u] = float(ZHC_DEFAULT_SQRT_ENCODING + 2u * ZHC_DEFAULT_L2_BOUND + 4u * ZHC_DEFAULT_DC_FORMAT +
                              16u * ZHC_DEFAULT_KIND + 32u * ZHC_DEFAULT_ZONAL_MAPPING + 128u * ZHC_DEFAULT_AXIS_MODE);
    } else {
        uint w = words[i];
        vec3 a = zhcUnpackR11G11B10F(w), b = zhcUnpackRGB9E5(w);
        outv[o] = a.x; outv[o + 1u] = a.y; outv[o + 2u] = a.z;
        outv[o + 3u] = b.x; outv[o + 4u] = b.y; outv[o + 5u] = b.z;
        outv[o + 6u] = zhcUnpackHalf(w & 0xFFFFu); outv[o + 7u] = zhcUnpackHalf(w >> 16);
    }
}
)";

std::string read_text(const char* path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

#include "gl/runtime_gl_entries.inl"

// ---- tests ------------------------------------------------------------------------------------------

// ---- the GL side ------------------------------------------------------------------------------------

// kEs = false: desktop GL 4.5 core, "#version 450"; true: OpenGL ES 3.1, "#version 310 es" (the
// same zhc.glsl and test main, executed, not only validated).
template <bool kEs>
class RuntimeContext : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        // Desktop GL 4.5 core or ES 3.1: compute shaders and std430 SSBOs are core in both.
        const EGLint gl_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        const EGLint es_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1, EGL_NONE};
        why_ = kEs ? test::make_llvmpipe_context(EGL_OPENGL_ES_API, EGL_OPENGL_ES3_BIT, es_attr, &egl_)
                   : test::make_llvmpipe_context(EGL_OPENGL_API, EGL_OPENGL_BIT, gl_attr, &egl_);
        if (!why_.empty()) return;
        renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        std::printf("GL_RENDERER: %s, GL_VERSION: %s\n", renderer_.c_str(),
                    reinterpret_cast<const char*>(glGetString(GL_VERSION)));
        const std::string library = read_text(ZHC_RUNTIME_GLSL_PATH);
        if (library.empty()) {
            why_ = std::string("cannot read ") + ZHC_RUNTIME_GLSL_PATH;
            return;
        }
        // Four programs: the plain one, one with ZHC_VOLUME_MASK (validity and visibility), one with
        // ZHC_VOLUME_MASK and ZHC_VOLUME_PLANE, one with ZHC_VOLUME_PLANE alone on a glTF-axes grid.
        for (int variant = 0; variant < kPrograms; ++variant) {
            const bool masked = variant == kMasked || variant == kPlanes, planes = variant == kPlanes || variant == kPlanesGltf;
            const std::string source = std::string(kEs ? "#version 310 es\n" : "#version 450\n") + kTestPrelude +
                                       (masked ? kTestMaskPrelude : "") + (planes ? kTestPlanePrelude : "") +
                                       (variant == kPlanesGltf ? "#define ZHC_VOLUME_PLANE_AXES_GLTF 1\n" : "") + library + kTestMain;
            const char* src = source.c_str();
            GLuint sh = glCreateShader(GL_COMPUTE_SHADER);
            glShaderSource(sh, 1, &src, nullptr);
            glCompileShader(sh);
            GLint ok = 0;
            glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
            if (!ok) {
                char log[8192] = {};
                glGetShaderInfoLog(sh, sizeof log, nullptr, log);
                why_ = std::string("compute shader does not compile: ") + log;
                glDeleteShader(sh);
                return;
            }
            GLuint prog = glCreateProgram();
            glAttachShader(prog, sh);
            glLinkProgram(prog);
            glDeleteShader(sh);
            glGetProgramiv(prog, GL_LINK_STATUS, &ok);
            programs_[variant] = prog;
            if (!ok) {
                char log[8192] = {};
                glGetProgramInfoLog(prog, sizeof log, nullptr, log);
                why_ = std::string("program does not link: ") + log;
                return;
            }
        }
        glGenBuffers(5, buffers_);
    }
    static void TearDownTestSuite() {
        for (GLuint& prog : programs_)
            if (prog) glDeleteProgram(prog);
        if (buffers_[0]) glDeleteBuffers(5, buffers_);
        test::destroy_context(&egl_);
    }
    void SetUp() override {
        ASSERT_TRUE(why_.empty()) << why_;
        ASSERT_NE(renderer_.find("llvmpipe"), std::string::npos) << renderer_;
    }

public:
    enum Program { kPlain, kMasked, kPlanes, kPlanesGltf, kPrograms };
    struct Uniforms {
        std::uint32_t mode = 0, stride = 0;
        std::uint32_t a[4] = {0, 0, 0, 0}, b[4] = {0, 0, 0, 0};
        std::uint32_t kind = 0;
        float lum[3] = {0, 0, 0}, curve[2] = {0, 0};
    };

    // The grid of mode 4 (probe volume).
    static void set_volume(const float origin[3], const float spacing[3], const std::uint32_t counts[3]) {
        for (GLuint prog : programs_) {
            glProgramUniform3f(prog, glGetUniformLocation(prog, "uVolOrigin"), origin[0], origin[1], origin[2]);
            glProgramUniform3f(prog, glGetUniformLocation(prog, "uVolSpacing"), spacing[0], spacing[1], spacing[2]);
            glProgramUniform3ui(prog, glGetUniformLocation(prog, "uVolCounts"), counts[0], counts[1], counts[2]);
        }
    }

    // Runs the shader on `count` items; returns count * kOutFloats floats.
    // With `masks` (4 combined mask bytes per word): the ZHC_VOLUME_MASK program; with `planes` (2
    // words per probe) the `variant` program (kPlanes: masks and planes, kPlanesGltf: planes alone).
    static std::vector<float> run(const Uniforms& un, const std::vector<std::uint32_t>& words,
                                  const std::vector<float>& normals, std::size_t count,
                                  const std::vector<std::uint32_t>* masks = nullptr,
                                  const std::vector<std::uint32_t>* planes = nullptr, Program variant = kPlanes) {
        const GLuint program = programs_[planes ? variant : (masks ? kMasked : kPlain)];
        auto upload = [](GLuint buf, GLuint binding, const void* data, std::size_t bytes) {
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
            glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), nullptr,
                         GL_DYNAMIC_DRAW);
            if (bytes) glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buf);
        };
        upload(buffers_[0], 0, words.data(), words.size() * 4);
        upload(buffers_[1], 1, normals.data(), normals.size() * 4);
        upload(buffers_[2], 2, nullptr, count * kOutFloats * 4);
        if (masks) upload(buffers_[3], 3, masks->data(), masks->size() * 4);
        if (planes) upload(buffers_[4], 4, planes->data(), planes->size() * 4);
        glUseProgram(program);
        glUniform1ui(glGetUniformLocation(program, "uCount"), static_cast<GLuint>(count));
        glUniform1ui(glGetUniformLocation(program, "uStride"), un.stride);
        glUniform1ui(glGetUniformLocation(program, "uMode"), un.mode);
        glUniform4ui(glGetUniformLocation(program, "uA"), un.a[0], un.a[1], un.a[2], un.a[3]);
        glUniform4ui(glGetUniformLocation(program, "uB"), un.b[0], un.b[1], un.b[2], un.b[3]);
        glUniform1ui(glGetUniformLocation(program, "uKind"), un.kind);
        glUniform3f(glGetUniformLocation(program, "uLum"), un.lum[0], un.lum[1], un.lum[2]);
        glUniform2f(glGetUniformLocation(program, "uCurve"), un.curve[0], un.curve[1]);
        glDispatchCompute(static_cast<GLuint>((count + 63) / 64), 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<float> out(count * kOutFloats);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[2]);
        // glMapBufferRange exists in both APIs (ES has no glGetBufferSubData).
        const void* mapped =
            glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(out.size() * 4), GL_MAP_READ_BIT);
        EXPECT_NE(mapped, nullptr);
        if (mapped) std::memcpy(out.data(), mapped, out.size() * 4);
        glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        return out;
    }

protected:
    static inline test::EglContext egl_;
    static inline GLuint programs_[kPrograms] = {0, 0, 0, 0};
    static inline GLuint buffers_[5] = {0, 0, 0, 0, 0};
    static inline std::string why_, renderer_;
};

using RuntimeGl = RuntimeContext<false>;
using RuntimeGles = RuntimeContext<true>;

// Every codec table entry: kBatches x 10,000 valid probes and kGarbageBatches x 10,000 of random
// bytes through Fixture's GL implementation, against the codec.
template <class Fixture>
void compare_every_codec(int kBatches, int kGarbageBatches, long min_valid) {
    constexpr int kBatchSize = 10000;
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    // Columns: valid probes, their max irradiance / decoded-coefficient error in u S; the same for
    // random bytes; random-byte probes not compared (codec output not finite / axis of a zero
    // luminance L1 whose channels do not vanish); the bounds (irradiance / decode).
    std::printf("%-22s %7s %8s %8s %7s %8s %8s %9s %8s %s\n", "encoding", "probes", "irr uS", "dec uS", "garbage",
                "irr uS", "dec uS", "nonfinite", "illcond", "bounds");
    for (const Codec& codec : runtime_codecs()) {
        const auto it = glsl_entries().find(codec.name);
        if (it == glsl_entries().end()) {
            ADD_FAILURE() << "codec table entry '" << codec.name << "' has no GLSL decoder in runtime/zhc.glsl";
            continue;
        }
        const GlslEntry& e = it->second;
        EXPECT_EQ(e.axis, codec.traits.zonal_axis) << codec.name << ": runtime/zhc.glsl's axis column";
        std::mt19937_64 rng(0x5EED0000u + codec.size_bytes * 131 + codec.name.size());
        std::uniform_real_distribution<double> u(0, 1);
        const std::size_t words = codec.size_bytes / 4;
        ASSERT_EQ(codec.size_bytes % 4, 0u);
        Tally tv, tg;  // valid probes, random bytes
        long valid = 0, garbage = 0;
        for (int b = 0; b < kBatches + kGarbageBatches; ++b) {
            const bool is_garbage = b >= kBatches;
            const CodecOptions p = batch_params(e, codec.name, is_garbage ? b - kBatches + 1 : b, rng);
            std::vector<std::uint8_t> bytes(kBatchSize * codec.size_bytes);
            std::vector<float> normals(kBatchSize * 3);
            for (int i = 0; i < kBatchSize; ++i) {
                std::uint8_t* out = bytes.data() + static_cast<size_t>(i) * codec.size_bytes;
                if (is_garbage) {
                    for (std::size_t j = 0; j < codec.size_bytes; ++j) out[j] = static_cast<std::uint8_t>(rng());
                } else {
                    const int kind = i % 10 < 4 ? 0 : (i % 10 < 7 ? 1 : 2);
                    encode_probe(codec, p, random_probe(rng, maps, kind), out, nullptr);
                }
                const Vec3 n = test::uniform_direction(u(rng), u(rng));
                normals[3 * i] = static_cast<float>(n.x);
                normals[3 * i + 1] = static_cast<float>(n.y);
                normals[3 * i + 2] = static_cast<float>(n.z);
            }
            (is_garbage ? garbage : valid) += kBatchSize;
            std::vector<std::uint32_t> w(bytes.size() / 4);
            for (std::size_t j = 0; j < w.size(); ++j)
                w[j] = std::uint32_t(bytes[4 * j]) | std::uint32_t(bytes[4 * j + 1]) << 8 |
                       std::uint32_t(bytes[4 * j + 2]) << 16 | std::uint32_t(bytes[4 * j + 3]) << 24;
            typename Fixture::Uniforms un;
            set_format_uniforms(un, 0, e, p);
            un.stride = static_cast<std::uint32_t>(words);
            const std::vector<float> gpu = Fixture::run(un, w, normals, kBatchSize);
            const bool direct = default_irradiance_path(p);
            const double c_irr = is_quantised(e.family) ? kCQuant : kCFloat;
            Tally& t = is_garbage ? tg : tv;
            for (int i = 0; i < kBatchSize; ++i) {
                const std::uint8_t* in = bytes.data() + static_cast<size_t>(i) * codec.size_bytes;
                const Sh3Radiance ref = decode_probe(codec, p, in);
                const Vec3 n{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
                const Rgb irr = direct ? codec.irradiance(in, p, n) : irradiance(ref, n);
                const Scale s = probe_scale(e, p, ref);
                if (!s.defined) {
                    bool finite = true;
                    for (int c = 0; c < 9; ++c)
                        for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(ref[c][k]);
                    ++(finite ? t.skipped_illcond : t.skipped_nonfinite);
                    continue;
                }
                const float* g = gpu.data() + static_cast<size_t>(i) * kOutFloats;
                const std::string what = std::string(codec.name) + (is_garbage ? " garbage" : "") + " batch " +
                                         std::to_string(b) + " probe " + std::to_string(i);
                for (int c = 0; c < 9; ++c)
                    for (int k = 0; k < 3; ++k)
                        check_value(t, &t.max_dec, ref[c][k], g[3 * c + k], s.coeff[c][k], kCDecode,
                                    what + " coefficient " + std::to_string(c) + "/" + std::to_string(k));
                for (int k = 0; k < 3; ++k)
                    check_value(t, &t.max_irr, irr[k], g[27 + k], s.irradiance[k], c_irr,
                                what + " irradiance " + std::to_string(k));
            }
        }
        const double c_irr = is_quantised(e.family) ? kCQuant : kCFloat;
        std::printf("%-22s %7ld %8.3f %8.3f %7ld %8.3f %8.3f %9ld %8ld %6.0f/%.0f\n", std::string(codec.name).c_str(),
                    valid, tv.max_irr, tv.max_dec, garbage, tg.max_irr, tg.max_dec, tg.skipped_nonfinite,
                    tg.skipped_illcond, c_irr, kCDecode);
        std::fflush(stdout);
        EXPECT_GE(valid, min_valid);
        for (const Tally* t : {&tv, &tg})
            EXPECT_EQ(t->failures, 0) << codec.name << ": " << t->failures << " values out of bound; first: "
                                      << t->first_failure;
        // Every valid probe is compared (finite, well-conditioned axis), and nearly all of the
        // random-byte ones (a finite value in 27 + 3 per probe).
        EXPECT_EQ(tv.skipped_nonfinite + tv.skipped_illcond, 0) << codec.name;
        EXPECT_EQ(tv.compared, valid * 30) << codec.name;
        EXPECT_GT(tg.compared, garbage * 30 / 2) << codec.name;
    }
}

TEST_F(RuntimeGl, EveryCodecDecodesAndEvaluatesLikeTheCodec) { 
    // 10,000 probes per batch; the sanitizer build runs a tenth (test::sample_count).
    compare_every_codec<RuntimeGl>(static_cast<int>(std::max(1L, test::sample_count(100000) / 10000)), 2,
                                   test::sample_count(100000));
}

// The same file as GLSL ES 3.10 (highp everywhere), executed on llvmpipe's OpenGL ES 3.1: a smaller
// sample (30,000 + 10,000 per encoding), same bounds.
TEST_F(RuntimeGles, EveryCodecDecodesAndEvaluatesLikeTheCodec) { 
    compare_every_codec<RuntimeGles>(static_cast<int>(std::max(1L, test::sample_count(30000) / 10000)), 1,
                                     test::sample_count(30000));
}

// runtime/zhc.glsl's generated table functions and constants, run on the GPU, against the codec
// table's runtime description: every id, and two ids past the end (bytes 0, family 0).
template <class Fixture>
void check_generated_table() {
    // runtime_codecs(): the table without the engine layouts, which no zhc runtime reads (codec.h).
    const auto table = runtime_codecs();
    const std::size_t n = table.size() + 2;
    typename Fixture::Uniforms un;
    un.mode = 6;
    const std::vector<float> gpu = Fixture::run(un, {0u}, std::vector<float>(3 * n, 0.0f), n);
    const CodecOptions d;
    for (std::size_t e = 0; e < n; ++e) {
        const float* r = gpu.data() + e * kOutFloats;
        if (e >= table.size()) {
            EXPECT_EQ(r[0], 0.0f) << "id " << e << " past the table: 0 bytes";
            EXPECT_EQ(r[1], 0.0f) << "id " << e << " past the table: family 0";
            continue;
        }
        const auto rt = runtime_entry(table[e]);
        ASSERT_TRUE(rt.ok()) << rt.error().message;
        const std::string name(table[e].name);
        EXPECT_EQ(r[0], float(table[e].size_bytes)) << name;
        EXPECT_EQ(r[1], float(rt->layout)) << name;
        EXPECT_EQ(r[2], float(rt->hallucination)) << name;
        EXPECT_EQ(r[3], float(rt->axis)) << name;
        EXPECT_EQ(r[4], float(table.size()));
        EXPECT_EQ(r[5], float(d.bits));
        EXPECT_EQ(r[6], float(d.luminance.r));
        EXPECT_EQ(r[7], float(d.luminance.g));
        EXPECT_EQ(r[8], float(d.luminance.b));
        EXPECT_EQ(r[9], float(d.hallucinate_a));
        EXPECT_EQ(r[10], float(d.hallucinate_b));
        EXPECT_EQ(r[11], float(int(d.sqrt_encoding) + 2 * int(d.l2_bound) + 4 * int(d.dc_format) + 16 * int(d.kind) +
                               32 * int(d.zonal_mapping) + 128 * int(d.axis_mode)));
    }
}
TEST_F(RuntimeGl, GeneratedTableMatchesTheCodec) { check_generated_table<RuntimeGl>(); }
TEST_F(RuntimeGles, GeneratedTableMatchesTheCodec) { check_generated_table<RuntimeGles>(); }

// R11G11B10F, RGB9E5 and half unpacking are integer-exact: every code of every channel.
TEST_F(RuntimeGl, DcUnpackingIsBitExact) {
    std::vector<std::uint32_t> w;
    for (std::uint32_t c = 0; c < 2048; ++c) w.push_back(c | (c << 11) | ((c & 0x3FF) << 22));  // R11G11B10F codes
    for (std::uint32_t e = 0; e < 32; ++e)
        for (std::uint32_t m = 0; m < 512; ++m) w.push_back(m | (((m * 7) & 511) << 9) | (((511 - m)) << 18) | (e << 27));
    for (std::uint32_t h = 0; h < 65536; h += 2) w.push_back(h | ((h + 1) << 16));  // every half
    std::vector<float> normals(w.size() * 3, 0.0f);
    Uniforms un;
    un.mode = 2;
    const std::vector<float> gpu = run(un, w, normals, w.size());
    long mismatches = 0;
    auto same = [](float a, float b) {
        if (std::isnan(a)) return std::isnan(b);
        std::uint32_t x, y;
        std::memcpy(&x, &a, 4);
        std::memcpy(&y, &b, 4);
        return x == y;
    };
    for (std::size_t i = 0; i < w.size(); ++i) {
        const float* g = gpu.data() + i * kOutFloats;
        const Rgb a = unpack_r11g11b10f(w[i]), b = unpack_rgb9e5(w[i]);
        const float h0 = unpack_half(static_cast<std::uint16_t>(w[i] & 0xFFFF)),
                    h1 = unpack_half(static_cast<std::uint16_t>(w[i] >> 16));
        const float want[8] = {a.r, a.g, a.b, b.r, b.g, b.b, h0, h1};
        for (int j = 0; j < 8; ++j)
            if (!same(want[j], g[j]) && mismatches++ < 5)
                ADD_FAILURE() << "word 0x" << std::hex << w[i] << std::dec << " value " << j << ": codec " << want[j]
                              << " gpu " << g[j];
    }
    EXPECT_EQ(mismatches, 0);
    std::printf("DC unpacking: %zu words, %ld mismatches (R11G11B10F, RGB9E5, binary16 all codes)\n", w.size(), mismatches);
}

// The ASTC LDR fallback's range decode (zhcIrradZIzFromLdr) against lightmap::iz_from_ldr, on ranges
// of 1 to 16 stops anywhere in [-14, 16]. GLSL's exp2 is within 3 + 2|x| ulp (GLSL 4.50 4.5.1);
// x = lo + t (hi - lo) adds 3 roundings of size u |x| (absolute, so ln 2 u |x| 2^x after exp2),
// and the subtraction of 2^lo one more: |gpu - codec| <= 8 u (3 + 3 |x|) (2^x + 2^lo).
TEST_F(RuntimeGl, AstcLdrRangeDecodeMatchesTheCodec) {
    constexpr int kItems = 100000;
    std::mt19937_64 rng(0xA57C);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::uint32_t> w(kItems * 5);
    std::vector<float> normals(kItems * 3, 0.0f), in(kItems * 5);
    for (int i = 0; i < kItems; ++i) {
        const float lo = static_cast<float>(-14 + 29 * u(rng)), hi = static_cast<float>(lo + 1 + 15 * u(rng) * u(rng));
        const float v[5] = {static_cast<float>(u(rng)), static_cast<float>(i % 9 == 0 ? 0.0 : u(rng)),
                            static_cast<float>(i % 11 == 0 ? 1.0 : u(rng)), lo, hi};
        for (int j = 0; j < 5; ++j) {
            in[5 * i + j] = v[j];
            std::memcpy(&w[5 * i + j], &v[j], 4);
        }
    }
    Uniforms un;
    un.mode = 5;
    const std::vector<float> gpu = run(un, w, normals, kItems);
    double worst = 0;
    long failures = 0;
    for (int i = 0; i < kItems; ++i) {
        const float* v = in.data() + 5 * i;
        const lightmap::IzLogRange r{v[3], v[4]};
        for (int k = 0; k < 3; ++k) {
            const double ref = lightmap::iz_from_ldr(v[k], r), g = gpu[static_cast<size_t>(i) * kOutFloats + static_cast<size_t>(k)];
            const double x = double(r.lo) + double(v[k]) * (double(r.hi) - double(r.lo));
            const double scale = kU * (3 + 3 * std::fabs(x)) * (std::exp2(x) + std::exp2(double(r.lo)));
            worst = std::max(worst, std::fabs(g - ref) / scale);
            if (!(std::fabs(g - ref) <= 8 * scale) && failures++ < 5)
                ADD_FAILURE() << "item " << i << " channel " << k << ": codec " << ref << " gpu " << g;
        }
    }
    std::printf("ASTC LDR range decode: %d items, max error %.3f x u (3 + 3|x|) (2^x + 2^lo) (bound 8)\n", kItems, worst);
    EXPECT_EQ(failures, 0);
}

// IrradZ texels (BC6H I_z, BC4 w_a, BC5 hemi-octahedral d) -> irradiance at tangent normals.
TEST_F(RuntimeGl, IrradZLightmapMatchesTheCodec) {
    constexpr int kTexels = 100000;
    std::mt19937_64 rng(0x1AAD2);
    std::uniform_real_distribution<double> u(0, 1);
    for (int model = 0; model < 2; ++model) {
        std::vector<std::uint32_t> w(kTexels * 7);
        std::vector<float> normals(kTexels * 3), in(kTexels * 6);
        for (int i = 0; i < kTexels; ++i) {
            const double ex = std::pow(10.0, -3 + 6 * u(rng));
            float v[6] = {static_cast<float>(ex * u(rng)), static_cast<float>(ex * u(rng)),
                          static_cast<float>(ex * u(rng)), static_cast<float>(-0.1 + 1.2 * u(rng)),
                          static_cast<float>(-0.05 + 1.1 * u(rng)), static_cast<float>(-0.05 + 1.1 * u(rng))};
            if (i % 7 == 0) v[3] = static_cast<float>(std::round(v[3]));  // w_a exactly 0 / 1
            for (int j = 0; j < 6; ++j) {
                in[6 * i + j] = v[j];
                std::memcpy(&w[7 * i + j], &v[j], 4);
            }
            w[7 * i + 6] = static_cast<std::uint32_t>(model);
            const Vec3 n = test::uniform_direction(u(rng), u(rng));
            normals[3 * i] = static_cast<float>(n.x);
            normals[3 * i + 1] = static_cast<float>(n.y);
            normals[3 * i + 2] = static_cast<float>(n.z);
        }
        Uniforms un;
        un.mode = 1;
        const std::vector<float> gpu = run(un, w, normals, kTexels);
        Tally t;
        double max_dir = 0;
        for (int i = 0; i < kTexels; ++i) {
            const float* v = in.data() + 6 * i;
            irradz::IrradZ p;
            p.i_z = Rgb{v[0], v[1], v[2]};
            p.w_a = v[3];
            p.d = lightmap::decode_hemioct(v[4], v[5]);
            const Vec3 n{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
            const Rgb ref = irradz::evaluate(p, model == 0 ? irradz::Model::kHhd : irradz::Model::kAhd, n);
            const float* g = gpu.data() + static_cast<size_t>(i) * kOutFloats;
            // Direction: unit vector, each component within a few u (no cancellation: |d| = 1).
            for (int j = 0; j < 3; ++j) max_dir = std::max(max_dir, std::fabs(double(g[3 + j]) - p.d[j]) / kU);
            // Scale: |C_a| h + |C_d| max(0, n.d) with |C_d| <= |I_z| / d_z, d_z >= cos 85 deg. d_z comes
            // out of the hemi-octahedral decode and the normalisation with an ABSOLUTE error of a few
            // u, so 1 / d_z has a relative error of a few u / d_z: the directional term's error is
            // a few u |I_z| (1 + 1 / d_z) / d_z, not a few u |I_z| / d_z.
            const double dz = std::max(p.d.z, irradz::kMinDz);
            for (int k = 0; k < 3; ++k)
                check_value(t, &t.max_irr, ref[k], g[k], std::fabs(double(v[k])) * (1 + (1 + 1 / dz) / dz), kCLightmap,
                            "texel " + std::to_string(i) + " channel " + std::to_string(k));
        }
        std::printf("IrradZ %s: %d texels, max irradiance error %.3f u S (bound %.0f), direction %.2f u\n",
                    model == 0 ? "HHD" : "AHD", kTexels, t.max_irr, kCLightmap, max_dir);
        EXPECT_EQ(t.failures, 0) << t.first_failure;
        EXPECT_LE(max_dir, 8.0);  // hemi-oct: 4 roundings + normalisation (inversesqrt 2 ulp, 3 ops)
        EXPECT_EQ(t.compared, 3L * kTexels);
    }
}

// HLSH (probe occlusion): I(m) = I_z m_z + C_a (1 - m_z) + c_x m_x + c_y m_y against
// irradz::evaluate(Hlsh); scale = sum of the four terms' magnitudes, 4 products + 3 sums + the
// codec's float rounding: bound 8 u S.
TEST_F(RuntimeGl, HlshMatchesTheCodec) {
    constexpr int kCount = 100000;
    std::mt19937_64 rng(0x4151);
    std::normal_distribution<double> g(0, 1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::uint32_t> w(kCount * 12);
    std::vector<float> normals(kCount * 3), in(kCount * 12);
    for (int i = 0; i < kCount; ++i) {
        const double ex = std::pow(10.0, -3 + 6 * u(rng));
        for (int j = 0; j < 12; ++j) {
            in[12 * i + j] = static_cast<float>(ex * g(rng));
            std::memcpy(&w[12 * i + j], &in[12 * i + j], 4);
        }
        const Vec3 n = test::uniform_direction(u(rng), u(rng));
        normals[3 * i] = static_cast<float>(n.x);
        normals[3 * i + 1] = static_cast<float>(n.y);
        normals[3 * i + 2] = static_cast<float>(n.z);
    }
    Uniforms un;
    un.mode = 3;
    const std::vector<float> gpu = run(un, w, normals, kCount);
    Tally t;
    for (int i = 0; i < kCount; ++i) {
        const float* v = in.data() + 12 * i;
        irradz::Hlsh h;
        h.i_z = Rgb{v[0], v[1], v[2]};
        h.c_a = Rgb{v[3], v[4], v[5]};
        h.c_x = Rgb{v[6], v[7], v[8]};
        h.c_y = Rgb{v[9], v[10], v[11]};
        const Vec3 m{normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]};
        const Rgb ref = irradz::evaluate(h, m);
        for (int k = 0; k < 3; ++k) {
            const double scale = std::fabs(v[k] * m.z) + std::fabs(v[3 + k] * (1 - m.z)) + std::fabs(v[6 + k] * m.x) +
                                 std::fabs(v[9 + k] * m.y);
            check_value(t, &t.max_irr, ref[k], gpu[static_cast<size_t>(i) * kOutFloats + static_cast<size_t>(k)], scale,
                        8, "HLSH " + std::to_string(i) + " channel " + std::to_string(k));
        }
    }
    std::printf("HLSH: %d evaluations, max error %.3f u S (bound 8)\n", kCount, t.max_irr);
    EXPECT_EQ(t.failures, 0) << t.first_failure;
    EXPECT_EQ(t.compared, 3L * kCount);
}


// Probe volumes (zhcVolumeIrradiance, mode 4) against the C header's zhc_volume_irradiance_d:
// every codec table entry, a 6x5x4 grid (default parameters) and a 5x1x3 grid (batch parameters)
// of random probes, points in and around the grid's box and at every probe, random normals.
// Bound (in u, of the summed probe scales S of the cell's 8 corners, see runtime_gl_entries.inl):
// each corner's decode and the evaluation 32 (kCQuant), blending 8 terms 16, and the trilinear
// weights: t = (p - o) / s in float is off by ~ (|p| + |o|) / s + |t| units u per axis, which moves
// each weight by at most 3 times that: 48 + 3 sum_axes ((|p| + |o|) / s + t + 2).
template <class Fixture>
void compare_volumes(int samples_per_grid) {
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    std::printf("%-22s %8s %10s %8s\n", "volume", "samples", "max u S", "skipped");
    for (const Codec& codec : runtime_codecs()) {
        const auto it = glsl_entries().find(codec.name);
        ASSERT_NE(it, glsl_entries().end()) << codec.name;
        const GlslEntry& e = it->second;
        std::mt19937_64 rng(0x701u + codec.size_bytes * 7 + codec.name.size());
        std::uniform_real_distribution<double> u(0, 1);
        Tally t;
        long compared_samples = 0, skipped = 0;
        for (int grid = 0; grid < 2; ++grid) {
            const std::uint32_t counts[3] = {grid == 0 ? 6u : 5u, grid == 0 ? 5u : 1u, grid == 0 ? 4u : 3u};
            const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
            const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
            const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
            const std::uint32_t count = counts[0] * counts[1] * counts[2];
            const CodecOptions p = batch_params(e, codec.name, grid == 0 ? 0 : 5, rng);
            std::vector<std::uint8_t> bytes(count * codec.size_bytes);
            std::vector<Sh3Radiance> decoded;
            for (std::uint32_t i = 0; i < count; ++i) {
                encode_probe(codec, p, random_probe(rng, maps, int(i % 3)), bytes.data() + i * codec.size_bytes, nullptr);
                decoded.push_back(decode_probe(codec, p, bytes.data() + i * codec.size_bytes));
            }
            zhc_probe_format fmt;
            ASSERT_TRUE(runtime_format(codec.name, p, &fmt));
            zhc_volume vol;
            ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
            // Items: position, normal (floats).
            std::vector<float> items;
            for (int i = 0; i < samples_per_grid + int(count); ++i) {
                for (int c = 0; c < 3; ++c) {
                    const double size = counts[c] > 1 ? (counts[c] - 1) * spacing[c] : 2 * spacing[c];
                    const double lo = counts[c] > 1 ? origin[c] - 0.25 * size : origin[c] - spacing[c];
                    const std::uint32_t node = std::uint32_t(i - samples_per_grid);
                    const std::uint32_t at = c == 0 ? node % counts[0] : (c == 1 ? node / counts[0] % counts[1] : node / (counts[0] * counts[1]));
                    items.push_back(i < samples_per_grid ? float(lo + 1.5 * size * u(rng)) : float(origin[c] + at * spacing[c]));
                }
                const Vec3 n = test::uniform_direction(u(rng), u(rng));
                items.push_back(float(n.x));
                items.push_back(float(n.y));
                items.push_back(float(n.z));
            }
            const std::size_t n_items = items.size() / 6;
            std::vector<std::uint32_t> w(bytes.size() / 4);
            std::memcpy(w.data(), bytes.data(), bytes.size());
            typename Fixture::Uniforms un;
            set_format_uniforms(un, 4, e, p);
            Fixture::set_volume(origin_f, spacing_f, counts);
            const std::vector<float> gpu = Fixture::run(un, w, items, n_items);
            for (std::size_t i = 0; i < n_items; ++i) {
                const double pos[3] = {items[6 * i], items[6 * i + 1], items[6 * i + 2]};
                const double nrm[3] = {items[6 * i + 3], items[6 * i + 4], items[6 * i + 5]};
                double ref[3];
                zhc_volume_irradiance_d(&vol, pos, nrm, ref);
                // The cell's corners, their scales, the weight-error factor.
                std::uint32_t i0[3];
                double extra = 0;
                for (int c = 0; c < 3; ++c) {
                    const double tt = std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1));
                    i0[c] = std::min(std::uint32_t(tt), counts[c] >= 2 ? counts[c] - 2 : 0u);
                    extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] + tt + 2;
                }
                double scale[3] = {0, 0, 0};
                bool defined = true;
                for (int b = 0; b < 8; ++b) {
                    const std::uint32_t q[3] = {i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)};
                    if (q[0] >= counts[0] || q[1] >= counts[1] || q[2] >= counts[2]) continue;
                    const Scale sc = probe_scale(e, p, decoded[q[0] + counts[0] * (q[1] + counts[1] * q[2])]);
                    defined = defined && sc.defined;
                    for (int k = 0; k < 3; ++k) scale[k] += sc.irradiance[k];
                }
                if (!defined) {
                    ++skipped;
                    continue;
                }
                ++compared_samples;
                for (int k = 0; k < 3; ++k)
                    check_value(t, &t.max_irr, ref[k], gpu[i * kOutFloats + std::size_t(k)], scale[k], 48 + 3 * extra,
                                std::string(codec.name) + " grid " + std::to_string(grid) + " sample " + std::to_string(i) +
                                    " channel " + std::to_string(k));
            }
        }
        std::printf("%-22s %8ld %10.3f %8ld\n", std::string(codec.name).c_str(), compared_samples, t.max_irr, skipped);
        EXPECT_EQ(t.failures, 0) << codec.name << ": " << t.first_failure;
        EXPECT_EQ(skipped, 0) << codec.name;  // encoded probes: every axis well conditioned
        EXPECT_EQ(t.compared, 3 * compared_samples) << codec.name;
    }
}

// Masked probe volumes (ZHC_VOLUME_MASK: validity and visibility, docs/runtime.md "Validity and
// visibility") against the C header with zhc_volume::validity / ::visibility set: a 6x5x4 grid per
// entry, random validity (1 in 4 invalid) and masks (each bit set with p = 1/2), combined on upload
// as valid ? visibility : 0, random points inside and around the box. Bound: compare_volumes' for
// the weights, divided by the masked weight sum M (each renormalised weight m_b / M carries the
// absolute errors of the m_b over M, twice), with the scales of the cell's corners. Where M is
// below 1e-3 the masked blend is ill-conditioned (a few u of t move the cell's only visible corner
// in or out of weight 0): such samples are counted, not compared, and must stay rare. Plus a grid
// whose probes are all invalid: the fallback, the plain trilinear blend, within compare_volumes'
// bound.
template <class Fixture>
void compare_masked_volumes(int samples) {
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    std::printf("%-22s %8s %10s %8s\n", "masked volume", "samples", "max u S", "skipped");
    for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"})
        for (int all_invalid = 0; all_invalid < 2; ++all_invalid) {
            const Codec* codec = find_codec(name);
            ASSERT_NE(codec, nullptr);
            const GlslEntry& e = glsl_entries().at(name);
            std::mt19937_64 rng(0x3a5u + codec->size_bytes + unsigned(all_invalid));
            std::uniform_real_distribution<double> u(0, 1);
            const std::uint32_t counts[3] = {6, 5, 4};
            const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
            const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
            const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
            const std::uint32_t count = counts[0] * counts[1] * counts[2];
            const CodecOptions p{};
            std::vector<std::uint8_t> bytes(count * codec->size_bytes), validity(count), visibility(count);
            std::vector<Sh3Radiance> decoded;
            std::vector<std::uint32_t> masks((count + 3) / 4, 0);
            for (std::uint32_t i = 0; i < count; ++i) {
                encode_probe(*codec, p, random_probe(rng, maps, int(i % 3)), bytes.data() + i * codec->size_bytes, nullptr);
                decoded.push_back(decode_probe(*codec, p, bytes.data() + i * codec->size_bytes));
                validity[i] = all_invalid ? 0 : (rng() % 4 == 0 ? 0 : 1);
                visibility[i] = std::uint8_t(rng());
                const std::uint32_t combined = validity[i] ? visibility[i] : 0u;
                masks[i / 4] |= combined << (8 * (i % 4));
            }
            zhc_probe_format fmt;
            ASSERT_TRUE(runtime_format(name, p, &fmt));
            zhc_volume vol;
            ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
            vol.validity = validity.data();
            vol.visibility = visibility.data();
            std::vector<float> items;
            for (int i = 0; i < samples; ++i) {
                for (int c = 0; c < 3; ++c) {
                    const double size = (counts[c] - 1) * spacing[c];
                    items.push_back(float(origin[c] - 0.25 * size + 1.5 * size * u(rng)));
                }
                const Vec3 n = test::uniform_direction(u(rng), u(rng));
                items.push_back(float(n.x));
                items.push_back(float(n.y));
                items.push_back(float(n.z));
            }
            std::vector<std::uint32_t> w(bytes.size() / 4);
            std::memcpy(w.data(), bytes.data(), bytes.size());
            typename Fixture::Uniforms un;
            set_format_uniforms(un, 4, e, p);
            Fixture::set_volume(origin_f, spacing_f, counts);
            const std::vector<float> gpu = Fixture::run(un, w, items, std::size_t(samples), &masks);
            Tally t;
            long compared = 0, skipped = 0, renormalised = 0;
            for (int i = 0; i < samples; ++i) {
                const double pos[3] = {items[6 * size_t(i)], items[6 * size_t(i) + 1], items[6 * size_t(i) + 2]};
                const double nrm[3] = {items[6 * size_t(i) + 3], items[6 * size_t(i) + 4], items[6 * size_t(i) + 5]};
                double ref[3];
                zhc_volume_irradiance_d(&vol, pos, nrm, ref);
                std::uint32_t i0[3];
                double f[3], extra = 0;
                for (int c = 0; c < 3; ++c) {
                    const double tt = std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1));
                    i0[c] = std::min(std::uint32_t(tt), counts[c] - 2);
                    f[c] = tt - i0[c];
                    extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] + tt + 2;
                }
                double scale[3] = {0, 0, 0}, masked_sum = 0;
                for (int b = 0; b < 8; ++b) {
                    const std::uint32_t q[3] = {i0[0] + (b & 1), i0[1] + ((b >> 1) & 1), i0[2] + (b >> 2)};
                    const std::uint32_t idx = q[0] + counts[0] * (q[1] + counts[1] * q[2]);
                    const double wb = ((b & 1) ? f[0] : 1 - f[0]) * ((b >> 1 & 1) ? f[1] : 1 - f[1]) * ((b >> 2) ? f[2] : 1 - f[2]);
                    if (validity[idx] && ((visibility[idx] >> (7 - b)) & 1)) masked_sum += wb;
                    const Scale sc = probe_scale(e, p, decoded[idx]);
                    for (int k = 0; k < 3; ++k) scale[k] += sc.irradiance[k];
                }
                double bound = 48 + 3 * extra;
                if (masked_sum > 0) {
                    if (masked_sum < 1e-3) {
                        ++skipped;
                        continue;
                    }
                    bound = 2 * bound / masked_sum;
                    ++renormalised;
                }
                ++compared;
                for (int k = 0; k < 3; ++k)
                    check_value(t, &t.max_irr, ref[k], gpu[size_t(i) * kOutFloats + std::size_t(k)], scale[k], bound,
                                std::string(name) + " sample " + std::to_string(i) + " channel " + std::to_string(k));
            }
            std::printf("%-22s %8ld %10.3f %8ld%s\n", name, compared, t.max_irr, skipped, all_invalid ? " (all invalid)" : "");
            EXPECT_EQ(t.failures, 0) << name << ": " << t.first_failure;
            EXPECT_EQ(t.compared, 3 * compared) << name;
            EXPECT_LE(skipped, samples / 100) << name;
            EXPECT_TRUE(all_invalid ? renormalised == 0 : renormalised > samples / 2) << name << ": " << renormalised;
        }
}

// Cell planes and corner regions (ZHC_VOLUME_PLANE, docs/runtime.md "Cell planes", "Corner
// regions") against the C header with zhc_volume::planes set: a 6x5x4 grid per entry, an entry in 3
// of 4 cells, a third of them corner regions (random thresholds, some axes unbounded, random
// directions), the others planes (random normal code, through a random point of the cell, the
// corners' sides as the bake writes them), uploaded as 2 words per probe. `gltf` false: the kPlanes program (masks and planes) with random validity (1 in 4 invalid)
// and visibility (each bit set with p = 3/4); true: the kPlanesGltf program (planes alone,
// ZHC_VOLUME_PLANE_AXES_GLTF) on the same volume in glTF axes (grid, probe order and sides bits
// permuted, normal codes kept, regions' per-axis fields permuted), sampled at the permuted points,
// against the header on the zhc-axes volume. Per sample: the corners the entry keeps (the shader's
// zhcVolumePlaneKeep) equal the header's, and the irradiance lies within compare_masked_volumes'
// bound, the weight part divided by the kept weight sum M (samples with 0 < M < 1e-3 counted, not
// compared). Points within 1e-4 |spacing| of their cell's plane or of a bounding plane of its region
// (or 1e-5 cell widths of a face between cells), where float and double may pick different sides,
// are counted, not compared. The header's region keeps equal planes_test::region_keep (the spec's
// twin), and samples fall both inside and outside regions.
template <class Fixture>
void compare_plane_volumes(int samples, bool gltf) {
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    std::printf("%-22s %8s %10s %8s %6s %8s %9s %10s %s\n", gltf ? "planes (glTF axes)" : "masks + planes", "samples", "max u S", "skipped", "near",
                "by plane", "in region", "out region", "corner sets");
    for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"}) {
        const Codec* codec = find_codec(name);
        ASSERT_NE(codec, nullptr);
        const GlslEntry& e = glsl_entries().at(name);
        std::mt19937_64 rng(0x9a7u + codec->size_bytes + (gltf ? 1u : 0u));
        std::uniform_real_distribution<double> u(0, 1);
        const std::uint32_t counts[3] = {6, 5, 4};
        const float origin_f[3] = {-1.5f, 2.0f, 0.25f}, spacing_f[3] = {0.75f, 0.5f, 1.25f};
        const double origin[3] = {origin_f[0], origin_f[1], origin_f[2]};
        const double spacing[3] = {spacing_f[0], spacing_f[1], spacing_f[2]};
        const std::uint32_t count = counts[0] * counts[1] * counts[2];
        const CodecOptions p{};
        std::vector<std::uint8_t> bytes(count * codec->size_bytes), validity(count), visibility(count);
        std::vector<Sh3Radiance> decoded;
        std::vector<std::uint32_t> masks((count + 3) / 4, 0);
        for (std::uint32_t i = 0; i < count; ++i) {
            encode_probe(*codec, p, random_probe(rng, maps, int(i % 3)), bytes.data() + i * codec->size_bytes, nullptr);
            decoded.push_back(decode_probe(*codec, p, bytes.data() + i * codec->size_bytes));
            validity[i] = rng() % 4 == 0 ? 0 : 1;
            visibility[i] = std::uint8_t(rng() | rng());
            masks[i / 4] |= std::uint32_t(validity[i] ? visibility[i] : 0u) << (8 * (i % 4));
        }
        const std::vector<std::uint8_t> planes = planes_test::random_cell_planes(rng, origin, spacing, counts, 0.75, 1.0 / 3);
        zhc_probe_format fmt;
        ASSERT_TRUE(runtime_format(name, p, &fmt));
        zhc_volume vol;
        ASSERT_EQ(zhc_volume_init(&vol, &fmt, bytes.data(), bytes.size(), origin, spacing, counts), ZHC_OK);
        if (!gltf) {
            vol.validity = validity.data();
            vol.visibility = visibility.data();
        }
        vol.planes = planes.data();
        // The GPU's copy: zhc axes, or glTF axes (probe words and plane entries in glTF order).
        const planes_test::GltfGrid g = planes_test::gltf_grid(origin, spacing, counts);
        std::vector<std::uint8_t> gpu_bytes = bytes;
        if (gltf)
            for (std::uint32_t j = 0; j < count; ++j)
                std::memcpy(gpu_bytes.data() + j * codec->size_bytes, bytes.data() + g.gltf_to_zhc[j] * codec->size_bytes, codec->size_bytes);
        const std::vector<std::uint32_t> plane_words = planes_test::plane_words(gltf ? planes_test::gltf_planes(g, planes) : planes);
        std::vector<float> items;
        std::vector<double> positions;  // zhc axes
        for (int i = 0; i < samples; ++i) {
            float pos[3];
            for (int c = 0; c < 3; ++c) {
                const double size = (counts[c] - 1) * spacing[c];
                pos[c] = float(origin[c] - 0.25 * size + 1.5 * size * u(rng));
                positions.push_back(pos[c]);
            }
            for (int c = 0; c < 3; ++c) items.push_back(gltf ? pos[(c + 1) % 3] : pos[c]);
            const Vec3 n = test::uniform_direction(u(rng), u(rng));
            items.push_back(float(n.x));
            items.push_back(float(n.y));
            items.push_back(float(n.z));
        }
        std::vector<std::uint32_t> w(gpu_bytes.size() / 4);
        std::memcpy(w.data(), gpu_bytes.data(), gpu_bytes.size());
        typename Fixture::Uniforms un;
        set_format_uniforms(un, 4, e, p);
        if (gltf) {
            const float go[3] = {float(g.origin[0]), float(g.origin[1]), float(g.origin[2])};
            const float gs[3] = {float(g.spacing[0]), float(g.spacing[1]), float(g.spacing[2])};
            Fixture::set_volume(go, gs, g.counts);
        } else {
            Fixture::set_volume(origin_f, spacing_f, counts);
        }
        const std::vector<float> gpu = Fixture::run(un, w, items, std::size_t(samples), gltf ? nullptr : &masks, &plane_words,
                                                    gltf ? Fixture::kPlanesGltf : Fixture::kPlanes);
        Tally t;
        long compared = 0, skipped = 0, near = 0, by_plane = 0, region_in = 0, region_out = 0, twin_wrong = 0, keep_compared = 0, keep_wrong = 0;
        std::string first_keep;
        for (int i = 0; i < samples; ++i) {
            const double* pos = positions.data() + 3 * size_t(i);
            const double nrm[3] = {items[6 * size_t(i) + 3], items[6 * size_t(i) + 4], items[6 * size_t(i) + 5]};
            const planes_test::Sample sm = planes_test::sample(vol, pos);
            if (sm.near) {
                ++near;
                continue;
            }
            const unsigned want_keep = gltf ? planes_test::gltf_sides(std::uint8_t(sm.plane_keep)) : sm.plane_keep;
            const unsigned got_keep = unsigned(gpu[size_t(i) * kOutFloats + 3]);
            ++keep_compared;
            if (got_keep != want_keep && keep_wrong++ == 0)
                first_keep = std::string(name) + " sample " + std::to_string(i) + ": shader keeps " + std::to_string(got_keep) +
                             ", C " + std::to_string(want_keep);
            by_plane += sm.plane_keep != 0xFF;
            if (sm.region) ++(sm.inside ? region_in : region_out);
            twin_wrong += sm.region_twin_differs;
            double ref[3];
            zhc_volume_irradiance_d(&vol, pos, nrm, ref);
            double scale[3] = {0, 0, 0}, extra = 0;
            for (int c = 0; c < 3; ++c)
                extra += (std::fabs(pos[c]) + std::fabs(origin[c])) / spacing[c] +
                         std::min(std::max((pos[c] - origin[c]) / spacing[c], 0.0), double(counts[c] - 1)) + 2;
            for (int b = 0; b < 8; ++b) {
                const std::uint32_t q[3] = {sm.i0[0] + (b & 1), sm.i0[1] + ((b >> 1) & 1), sm.i0[2] + (b >> 2)};
                const Scale sc = probe_scale(e, p, decoded[q[0] + counts[0] * (q[1] + counts[1] * q[2])]);
                for (int k = 0; k < 3; ++k) scale[k] += sc.irradiance[k];
            }
            double bound = 48 + 3 * extra;
            if (sm.kept_sum > 0) {
                if (sm.kept_sum < 1e-3) {
                    ++skipped;
                    continue;
                }
                bound = 2 * bound / sm.kept_sum;
            }
            ++compared;
            for (int k = 0; k < 3; ++k)
                check_value(t, &t.max_irr, ref[k], gpu[size_t(i) * kOutFloats + std::size_t(k)], scale[k], bound,
                            std::string(name) + " sample " + std::to_string(i) + " channel " + std::to_string(k));
        }
        std::printf("%-22s %8ld %10.3f %8ld %6ld %8ld %9ld %10ld %ld of %ld equal\n", name, compared, t.max_irr, skipped, near, by_plane,
                    region_in, region_out,
                    keep_compared - keep_wrong, keep_compared);
        EXPECT_EQ(t.failures, 0) << name << ": " << t.first_failure;
        EXPECT_EQ(t.compared, 3 * compared) << name;
        EXPECT_EQ(keep_wrong, 0) << first_keep;
        EXPECT_LE(skipped, samples / 100) << name;
        EXPECT_LE(near, samples / 100) << name;
        EXPECT_GT(by_plane, samples / 4) << name << ": the planes act";
        EXPECT_EQ(twin_wrong, 0) << name << ": the header's corner region keeps differ from the spec's twin";
        EXPECT_GT(region_in, samples / 100) << name << ": samples inside corner regions";
        EXPECT_GT(region_out, samples / 100) << name << ": samples outside corner regions, in their cells";
    }
}

// Scattered probes (zhcVolumeTetraSh3 / zhcVolumeTetraIrradiance, docs/runtime.md "Scattered
// probes (`points` layout)"): 150 random positions tetrahedralised by formats/probes/tetra.h (qhull),
// probes encoded as sh3, zh3_q16, sh3_q28 and hall_adaptive_q16, with and without validity (1 in 4
// invalid), against the C header's zhc_volume_sh3 / zhc_volume_irradiance_d at points inside and
// outside the hull and at every probe, the shader given the 4 probes and weights (as float) of
// zhc_volume_tetra_weights. Every weight-0 probe index is replaced by that of a probe of 0xFF bytes,
// which decodes to NaN / Inf: the result stays finite only if the blend does not read it. Bound:
// compare_volumes' decode, evaluation and blend terms, 48 u S with S = sum_k w_k S_k (the weights
// are a partition of unity; rounding each to float moves it by u w_k, inside the 48); decoded SH3
// within kCDecode + 8 u of sum_k w_k M_k.
template <class Fixture>
void compare_tetra_volumes(int samples) {
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    std::printf("%-22s %8s %8s %10s %10s %8s\n", "scattered probes", "samples", "outside", "max u S", "dec. u M", "skipped");
    for (const char* name : {"sh3", "zh3_q16", "sh3_q28", "hall_adaptive_q16"})
        for (int with_validity = 0; with_validity < 2; ++with_validity) {
            const Codec* codec = find_codec(name);
            ASSERT_NE(codec, nullptr);
            const GlslEntry& e = glsl_entries().at(name);
            std::mt19937_64 rng(0x7e7u + codec->size_bytes + unsigned(with_validity));
            const std::vector<std::array<float, 3>> positions = tetra_test::random_positions(rng, 150);
            std::vector<Sh3Radiance> hubs;
            std::vector<std::uint8_t> validity;
            for (std::uint32_t i = 0; i < positions.size(); ++i) {
                hubs.push_back(random_probe(rng, maps, int(i % 3)));
                if (with_validity) validity.push_back(rng() % 4 == 0 ? 0 : 1);
            }
            const CodecOptions p{};
            tetra_test::PointsVolume v;
            tetra_test::make_points_volume(v, *codec, p, positions, hubs, validity);
            ASSERT_TRUE(v.error.empty()) << v.error;
            ASSERT_TRUE(tetra_test::nan_probe_poisons(v)) << name;
            const std::vector<tetra_test::Sample> ss = tetra_test::samples(rng, v, samples, true, test::uniform_direction);
            std::vector<float> items;
            for (const tetra_test::Sample& sm : ss) {
                for (int k = 0; k < 4; ++k) items.push_back(float(sm.weights[k]));
                for (int k = 0; k < 4; ++k) items.push_back(float(sm.probes[k]));
                for (int c = 0; c < 3; ++c) items.push_back(sm.normal[c]);
            }
            std::vector<std::uint32_t> w(v.bytes.size() / 4);
            std::memcpy(w.data(), v.bytes.data(), v.bytes.size());
            typename Fixture::Uniforms un;
            set_format_uniforms(un, 7, e, p);
            const std::vector<float> gpu = Fixture::run(un, w, items, ss.size());
            Tally t;
            long compared = 0, outside = 0, skipped = 0, dropped = 0;
            for (std::size_t i = 0; i < ss.size(); ++i) {
                const tetra_test::Sample& sm = ss[i];
                const double pos[3] = {sm.pos[0], sm.pos[1], sm.pos[2]};
                const double nrm[3] = {sm.normal[0], sm.normal[1], sm.normal[2]};
                double ref[3], ref_sh[27];
                zhc_volume_irradiance_d(&v.vol, pos, nrm, ref);
                zhc_volume_sh3(&v.vol, pos, ref_sh);
                ASSERT_GE(sm.outside, 0);
                outside += sm.outside;
                double scale[3] = {0, 0, 0}, coeff[9][3] = {};
                bool defined = true;
                for (int k = 0; k < 4; ++k) {
                    if (sm.weights[k] == 0.0) {
                        dropped += with_validity && sm.outside == 0 && i < std::size_t(samples);  // not at a probe
                        continue;
                    }
                    const Scale sc = probe_scale(e, p, v.decoded[sm.probes[k]]);
                    defined = defined && sc.defined;
                    for (int c = 0; c < 3; ++c) {
                        scale[c] += sm.weights[k] * sc.irradiance[c];
                        for (int j = 0; j < 9; ++j) coeff[j][c] += sm.weights[k] * sc.coeff[j][c];
                    }
                }
                if (!defined) {
                    ++skipped;
                    continue;
                }
                ++compared;
                const std::string what = std::string(name) + (with_validity ? " (validity)" : "") + " sample " + std::to_string(i);
                for (int c = 0; c < 3; ++c)
                    check_value(t, &t.max_irr, ref[c], gpu[i * kOutFloats + 27 + std::size_t(c)], scale[c], 48, what + " channel " + std::to_string(c));
                for (int j = 0; j < 9; ++j)
                    for (int c = 0; c < 3; ++c)
                        check_value(t, &t.max_dec, ref_sh[3 * j + c], gpu[i * kOutFloats + std::size_t(3 * j + c)], coeff[j][c], kCDecode + 8,
                                    what + " coefficient " + std::to_string(3 * j + c));
            }
            std::printf("%-22s %8ld %8ld %10.3f %10.3f %8ld%s\n", name, compared, outside, t.max_irr, t.max_dec, skipped,
                        with_validity ? " (validity)" : "");
            EXPECT_EQ(t.failures, 0) << name << ": " << t.first_failure;
            EXPECT_EQ(t.compared, 30 * compared) << name << ": every value finite";
            EXPECT_EQ(skipped, 0) << name;
            EXPECT_GT(outside, long(ss.size()) / 3) << name << ": points outside the hull";
            EXPECT_LT(outside, long(ss.size()) * 9 / 10) << name << ": points inside the hull";
            if (with_validity) {
                EXPECT_GT(dropped, long(ss.size()) / 10) << name << ": validity drops probes inside the hull";
            }
        }
}

// Analytic fields through zhcVolumeTetraIrradiance, against the double twin of the field itself
// (not the C header): every probe equal (sh3 and zh3_q16) gives that probe's irradiance everywhere,
// inside and outside the hull, within 48 u S of the probe; an SH3 field affine in position stored as
// sh3 is reproduced inside the hull within 48 u S of sum_k w_k S_k (the stored float rounding of the
// probes, u each, is inside it).
template <class Fixture>
void check_tetra_fields(int samples) {
    const std::vector<Sh3Radiance> maps = envmap_probes();
    ASSERT_EQ(maps.size(), 8u);
    for (const char* name : {"sh3", "zh3_q16", "affine"}) {
        const bool affine = std::string(name) == "affine";
        const Codec* codec = find_codec(affine ? "sh3" : name);
        ASSERT_NE(codec, nullptr);
        const GlslEntry& e = glsl_entries().at(std::string(codec->name));
        std::mt19937_64 rng(0xf1e1du + codec->size_bytes + (affine ? 1u : 0u));
        const std::vector<std::array<float, 3>> positions = tetra_test::random_positions(rng, 120);
        const Sh3Radiance constant = random_probe(rng, maps, 0);
        const tetra_test::AffineField field = tetra_test::random_affine(rng);
        std::vector<Sh3Radiance> hubs;
        for (const auto& q : positions) hubs.push_back(affine ? field.hub_at(q) : constant);
        const CodecOptions p{};
        tetra_test::PointsVolume v;
        tetra_test::make_points_volume(v, *codec, p, positions, hubs, {});
        ASSERT_TRUE(v.error.empty()) << v.error;
        const std::vector<tetra_test::Sample> ss = tetra_test::samples(rng, v, samples, false, test::uniform_direction);
        std::vector<float> items;
        for (const tetra_test::Sample& sm : ss) {
            for (int k = 0; k < 4; ++k) items.push_back(float(sm.weights[k]));
            for (int k = 0; k < 4; ++k) items.push_back(float(sm.probes[k]));
            for (int c = 0; c < 3; ++c) items.push_back(sm.normal[c]);
        }
        std::vector<std::uint32_t> w(v.bytes.size() / 4);
        std::memcpy(w.data(), v.bytes.data(), v.bytes.size());
        typename Fixture::Uniforms un;
        set_format_uniforms(un, 7, e, p);
        const std::vector<float> gpu = Fixture::run(un, w, items, ss.size());
        Tally t;
        long compared = 0;
        for (std::size_t i = 0; i < ss.size(); ++i) {
            const tetra_test::Sample& sm = ss[i];
            if (affine && sm.outside) continue;
            double sh[27], want[3], scale[3] = {0, 0, 0};
            if (affine) {
                const double x[3] = {sm.pos[0], sm.pos[1], sm.pos[2]};
                field.at(x, sh);
            } else {
                for (int j = 0; j < 27; ++j) sh[j] = v.decoded[0][j / 3][j % 3];
            }
            tetra_test::irradiance_twin(sh, sm.normal, want);
            for (int k = 0; k < 4; ++k) {  // constant: the probe's own S (weights sum to 1)
                const Scale sc = probe_scale(e, p, v.decoded[affine ? sm.probes[k] : 0]);
                for (int c = 0; c < 3; ++c) scale[c] += sm.weights[k] * sc.irradiance[c];
            }
            ++compared;
            for (int c = 0; c < 3; ++c)
                check_value(t, &t.max_irr, want[c], gpu[i * kOutFloats + 27 + std::size_t(c)], scale[c], 48,
                            std::string(name) + " sample " + std::to_string(i) + " channel " + std::to_string(c));
        }
        std::printf("%-22s %8ld samples, max %.3f u S\n", affine ? "affine field (sh3)" : (std::string("constant ") + name).c_str(),
                    compared, t.max_irr);
        EXPECT_EQ(t.failures, 0) << name << ": " << t.first_failure;
        EXPECT_EQ(t.compared, 3 * compared) << name;
        EXPECT_GT(compared, affine ? long(samples) / 4 : long(ss.size()) - 1) << name;
    }
}

TEST_F(RuntimeGl, ProbeVolumesMatchTheCHeader) { compare_volumes<RuntimeGl>(int(test::sample_count(10000))); }
TEST_F(RuntimeGl, MaskedProbeVolumesMatchTheCHeader) { compare_masked_volumes<RuntimeGl>(int(test::sample_count(10000))); }
TEST_F(RuntimeGles, MaskedProbeVolumesMatchTheCHeader) { compare_masked_volumes<RuntimeGles>(int(test::sample_count(2000))); }
TEST_F(RuntimeGles, ProbeVolumesMatchTheCHeader) { compare_volumes<RuntimeGles>(int(test::sample_count(2000))); }
TEST_F(RuntimeGl, PlaneProbeVolumesMatchTheCHeader) { compare_plane_volumes<RuntimeGl>(int(test::sample_count(10000)), false); }
TEST_F(RuntimeGl, PlaneProbeVolumesInGltfAxesMatchTheCHeader) { compare_plane_volumes<RuntimeGl>(int(test::sample_count(10000)), true); }
TEST_F(RuntimeGles, PlaneProbeVolumesMatchTheCHeader) { compare_plane_volumes<RuntimeGles>(int(test::sample_count(2000)), false); }
TEST_F(RuntimeGles, PlaneProbeVolumesInGltfAxesMatchTheCHeader) { compare_plane_volumes<RuntimeGles>(int(test::sample_count(2000)), true); }
TEST_F(RuntimeGl, ScatteredProbesMatchTheCHeader) { compare_tetra_volumes<RuntimeGl>(int(test::sample_count(10000))); }
TEST_F(RuntimeGles, ScatteredProbesMatchTheCHeader) { compare_tetra_volumes<RuntimeGles>(int(test::sample_count(2000))); }
TEST_F(RuntimeGl, ScatteredProbesKeepConstantAndAffineFields) { check_tetra_fields<RuntimeGl>(int(test::sample_count(4000))); }

}  // namespace
}  // namespace zhc
