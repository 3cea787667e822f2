// zhc/codec/probe/engine_layouts.h — the probe layouts engines ship, as codec-table entries
// (docs/engine-layouts.md).
//
// Each entry stores one probe exactly as an engine stores it (its axes, normalisation, quantisation
// and packing) and evaluates irradiance the way that engine's shader does, written from the
// engine's published code or documentation (each entry's source is in engine_layouts() and in a
// comment at its functions). They sit at the end of the codec table (codec_table.cpp) with
// CodecTraits::engine set, so the audit, the benchmark and the reports measure them beside zhc's own
// representations; zhc's runtimes do not read them (runtime_codecs(), codec.h).
//
// Irradiance is in zhc's units, E(n) = (1/pi) int L max(0, n.w) dw (sh.h): an engine whose shader
// returns pi times that (three.js's) is divided by pi, stated at the entry. Normals are zhc's; each
// entry turns them into the engine's axes by its `axes` matrix first.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "codec/probe/codec.h"
#include "codec/sh/sh.h"

namespace zhc {

// What the benchmark, the reports and the docs say of an engine layout beside its codec entry.
struct EngineLayoutInfo {
    std::string_view codec;          // the codec-table entry ("unity_apv_l1")
    std::string_view engine;         // the engine and feature ("Unity Adaptive Probe Volumes, L1")
    std::string_view source;         // the files and functions the entry follows, or what it is inferred from
    // Engine axes from zhc's: v_engine = axes * v_zhc (a signed permutation; det -1 for left-handed
    // engines). Stated per entry; a converter writing the engine's files uses the same matrix.
    Mat3 axes;
    std::size_t gpu_bytes = 0;       // bytes per probe in GPU memory (0: none; the CPU blends per object)
    std::size_t disk_bytes = 0;      // bytes per probe in the engine's baked files (0: no file format)
    int fetches = 0;                 // texture fetches (or buffer reads) per shading sample
    std::string_view interpolation;  // how the engine blends probes ("hardware trilinear", ...)
    // true: the GPU's filtering blends the stored probes before the shader decodes them, so a
    // shader cannot drop single corners (zhc's validity, visibility masks and cell planes need the
    // eight corners apart: 8 loads and a blend in the shader, as zhc's runtimes do).
    bool hardware_filtered = false;
    // What the engine's shader reads of a stored probe: its texel values (the numbers the texture
    // fetches, or the CPU's reads, return: unorm as byte / 255, halves, floats, shared exponents
    // decoded), texel_count of them in the engine's texel order, and the shader from texel values
    // (zhc's normal in, zhc's units out). The entry's irradiance is shade(texels(bytes)); a
    // hardware-filtered volume blends the texels of the corner probes and then shades (its
    // decode runs on the blend: Unity's ratios multiply the blended L0, Source 2's RGBM the blended
    // multiplier), which bench/bench_volume.cpp models.
    int texel_count = 0;
    void (*texels)(const std::uint8_t* stored, double* out) = nullptr;
    Rgb (*shade)(const double* texels, Vec3 n) = nullptr;
};
// The most texels any layout has (texel_count <= kMaxEngineTexels).
inline constexpr int kMaxEngineTexels = 36;

// Every engine layout, in the order of their codec-table entries.
std::span<const EngineLayoutInfo> engine_layouts();
// The layout of the entry named `codec_name`; nullptr when it is not an engine layout.
const EngineLayoutInfo* find_engine_layout(std::string_view codec_name);

// The nine real SH3 coefficients of the normalised irradiance of `hub`, in an engine's axes and in
// the basis without the Condon-Shortley sign (Y1 = sqrt(3/4pi) (y, z, x), Y2 = sqrt(15/4pi) xy,
// sqrt(15/4pi) yz, sqrt(5/16pi) (3z^2 - 1), sqrt(15/4pi) xz, sqrt(15/16pi) (x^2 - y^2)): the form
// three.js, Godot, Unity and Unreal bake into (up to their own scales). [coefficient][channel].
using EngineSh = std::array<std::array<double, 3>, 9>;
EngineSh engine_irradiance_sh(const Sh3Radiance& hub, const Mat3& axes);
// The inverse: the radiance hub whose normalised irradiance has these engine-axes coefficients.
Sh3Radiance hub_from_engine_irradiance_sh(const EngineSh& sh, const Mat3& axes);

// The codec table part of codec/probe/engine_layouts.cpp (last in codec_table.cpp).
std::span<const Codec> engine_codecs();

// RGBM with an 8-bit multiplier (source2_ambient_cube): value = rgb * m * kRgbmRange, rgb and m in
// [0, 1] as bytes / 255.
inline constexpr double kRgbmRange = 16.0;

}  // namespace zhc
