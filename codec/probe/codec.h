// zhc/codec/probe/codec.h — the one codec table (README.md "Representations"; sh3 is the hub).
//
// Every representation zhc knows is one `Codec` entry: a name, a fixed stored size per probe,
// encode from the hub (float SH3 radiance), decode to the hub, and irradiance evaluation.
// Conversion A -> B is A.decode then B.encode. The CLI, the audit, the benchmark and the fuzzers
// walk `codecs()`, so a new entry shows up everywhere without further wiring.
//
// Contracts, for every entry:
//  * encode writes exactly size_bytes bytes; it never reads or writes anything else.
//  * decode and irradiance accept ANY size_bytes bytes (safe for untrusted input): they never
//    crash or trap, never undefined behaviour. Garbage in gives numbers out: any float, +-Inf and
//    NaN included where the bytes hold a float, half or shared-exponent field that encodes them
//    (readers of files refuse those with check_finite_probes, formats/probes/probe_file.h). decode
//    is a pure function of the bytes; irradiance is what the entry's irradiance_model says of
//    decode's SH3 (for zhc's own entries: its irradiance) and is finite whenever that SH3 is
//    (tests/test_codec_table.cpp, DecodeAcceptsArbitraryBytes).
//  * the stored bytes are little-endian and the same on every machine; encode is deterministic.
//  * L0 (DC) round-trips exactly for the float representations.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
// The codec table (codecs(), find_codec) is immutable after static initialisation: any thread
// may use its entries at any time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "codec/status.h"

#include "codec/sh/sh.h"

namespace zhc {

// How the DC term of a quantised layout is stored (ZH3 paper App. A.1).
enum class DcFormat : std::uint8_t { kR11G11B10F = 0, kRGB9E5 = 1, kHalf = 2 };
// Bound used for the non-zonal L2 ratios (Wiederien & Sloan: sqrt(15)/2 is tight).
enum class L2Bound : std::uint8_t { kTight = 0, kLoose = 1 };

// Whether stored SH are radiance or irradiance (band scales 1, 2/3, 1/4 applied). The ratio
// intervals of irradiance are the radiance ones times the band scale (ZH3 paper App. A.1).
enum class StoredKind : std::uint8_t { kRadiance = 0, kIrradiance = 1 };

// How the asymmetric zonal interval [lo, hi] = [-sqrt(5)/2, sqrt(5)] is mapped to [-1, 1].
enum class ZonalMapping : std::uint8_t {
    // t = (2 r - (hi + lo)) / (hi - lo): the whole code range covers exactly the interval, so the
    // step is 3/4 of the symmetric one; ratio 0 falls between codes.
    kAffine = 0,
    // t = r / hi for r >= 0, r / -lo for r < 0: ratio 0 stays at code 0 (what the square-root
    // encoding wants, its precision is concentrated there); negative side has half the step.
    kZeroPreserving = 1,
    // t = r / sqrt(5): the symmetric interval of Listing 1 (Wiederien & Sloan), for comparison.
    kSymmetric = 2,
};

// Which axis a ZH3 zonal coefficient lies on.
enum class ZonalAxisMode : std::uint8_t {
    kLuminance = 0,   // one axis from the luminance-weighted L1 (Sec. 3.2), default
    kPerChannel = 1,  // each channel's own optimal linear direction (Sec. 3.1)
};

// The one parameter type: every entry's encode / decode / irradiance, the quantiser
// (quantize.h) and the probe container (probe_set.h, ProbeSet::params) take it. Two groups of fields:
//  * storage parameters (luminance .. axis_mode below): they change what stored bytes mean, so the
//    .zhp header and the glTF extension store them and decoders need them;
//  * encoder controls (solver_*, hallucinate_*, dering_punctual): they only choose which bytes an
//    encoder writes (hallucinate_a/b are also decoder constants of the hall_* entries, fixed at the
//    defaults in files). Each entry reads the fields that concern it.
// The storage parameters of CodecOptions below, listed once: X(field) for each field that changes
// what stored bytes mean, except `luminance` (three doubles, not an enum or integer). Code that
// copies or compares the storage parameters walks this list (same_storage below,
// runtime/zhc_runtime_params.hpp, the runtime table generator); a new storage field added to the
// struct goes here too.
#define ZHC_CODEC_STORAGE_FIELDS(X) X(bits) X(sqrt_encoding) X(l2_bound) X(dc_format) X(kind) X(zonal_mapping) X(axis_mode)

struct CodecOptions {
    LuminanceWeights luminance;
    // ZH3 axis solve (ZH3 paper Sec. 3.3): L-BFGS iteration cap per start (a convergence guard; the
    // solves stop on the relative gradient or step first) and the relative gradient tolerance.
    int solver_iterations = 200;
    double solver_tolerance = 1e-5;
    // Curve-fit hallucination, ZH3 paper Eq. 21: f20 = (a p^2 + b p) f0.
    double hallucinate_a = 0.6;
    double hallucinate_b = 0.08;
    // Quantised layouts (ZH3 paper App. A.1; Wiederien & Sloan).
    int bits = 8;                 // 2..8 per ratio; codes use the low `bits` bits of a byte
    bool sqrt_encoding = false;   // sign-preserving square root before rounding
    L2Bound l2_bound = L2Bound::kTight;
    DcFormat dc_format = DcFormat::kR11G11B10F;
    StoredKind kind = StoredKind::kRadiance;
    ZonalMapping zonal_mapping = ZonalMapping::kAffine;
    ZonalAxisMode axis_mode = ZonalAxisMode::kLuminance;  // zh3_q16's stored axis (container field)
    // Deringing (Sloan 2017): treat the source as punctual lights (extra windowing).
    bool dering_punctual = false;
};

// true when a and b have the same storage parameters (ZHC_CODEC_STORAGE_FIELDS and the luminance
// weights, compared exactly): bytes stored under a decode the same under b.
inline bool same_storage(const CodecOptions& a, const CodecOptions& b) {
#define ZHC_SAME_FIELD(field) a.field == b.field &&
    return ZHC_CODEC_STORAGE_FIELDS(ZHC_SAME_FIELD) a.luminance.r == b.luminance.r &&
           a.luminance.g == b.luminance.g && a.luminance.b == b.luminance.b;
#undef ZHC_SAME_FIELD
}

// What an encode noticed; all counters are per call and optional to read.
struct EncodeStats {
    int clamped_ratios = 0;      // quantiser: ratios outside their bound interval, clamped
    bool dering_clamped = false; // ZH3 App. B clamp or SH3 windowing changed the coefficients
    int solver_iterations = 0;   // ZH3 axis solve: iterations used
};

struct PackedCodec;  // quantize.h

// Along which axis the decoder expands the zonal L2 term of a probe (ZH3 paper Sec. 3.1/3.2).
enum class ZonalAxis : std::uint8_t {
    kNone = 0,        // no zonal term: the L2 band is stored whole or dropped (sh3, sh2, sh3_q28, sh2_q)
    kLuminance = 1,   // one axis shared by R, G, B: the luminance-weighted L1 direction
    kPerChannel = 2,  // each channel's own L1 direction
    kFromParams = 3,  // the storage parameters' axis mode (quantised layouts; the container stores it)
};

// The zonal L2 term a decoder hallucinates from the stored linear SH (ZH3 paper Sec. 3.4), as the
// runtimes (runtime/) name it: their decoders choose by this, never by the entry's name or id.
enum class ZonalHallucination : std::uint8_t {
    kNone = 0,                // the L2 band is stored (or dropped)
    kAmbientDirectional = 1,  // Eq. 14: f20 = sqrt(15)/3 |f1|
    kSphere = 2,              // Eq. 20: f20 = (2 sqrt(5)/3 p^2 - sqrt(5/3) p) f0
    kCurve = 3,               // Eq. 21: f20 = (a p^2 + b p) f0
    kCurveAdaptive = 4,       // Eq. 21 with a, b times s = 0.5 min(byte 15, 7) (sh2_q layout only)
};

// How an entry's irradiance relates to the SH3 its decode returns. zhc's own entries are kSh3; the
// engine layouts (engine_layouts.h) evaluate irradiance as their engine's shader does, which is not
// always an SH3 function.
enum class IrradianceModel : std::uint8_t {
    kSh3 = 0,         // irradiance = the irradiance of decode's SH3
    kSh3Clamped = 1,  // = max(0, the irradiance of decode's SH3) per channel: the shader clamps
    kOwn = 2,         // the entry's own reconstruction (ambient cubes, not SH3 functions); decode
                      // returns its least-squares SH3 projection over the sphere
};

// What code outside an entry may ask about it instead of testing its name. Each field is a fact
// about the entry's bytes or decoder; tests check every one of them against the entry's functions
// (tests/test_codec_table.cpp; zonal_axis and hallucination through the runtimes' decoders:
// test_runtime_c bit for bit, the GLSL and HLSL tests).
struct CodecTraits {
    // decode(encode(x)) == x bit for bit for every finite hub (the entry stores the hub itself: sh3).
    // The first exact entry is the baseline of size and speed comparisons, and a round trip through
    // an exact entry may be skipped.
    bool exact = false;
    // 0: the bytes are opaque to containers. 2 or 3: they are the hub's first float_bands^2
    // coefficients as little-endian floats, [coefficient][R, G, B], read back unchanged, so a
    // container may store them as float RGB triples (glTF VEC3 accessor, Draco attributes per
    // band): sh3 3, sh2 2. (sh3_dering has that byte layout too but keeps 0: its glTF files have
    // always stored a byte array, and they stay the same.)
    int float_bands = 0;
    ZonalAxis zonal_axis = ZonalAxis::kNone;
    ZonalHallucination hallucination = ZonalHallucination::kNone;
    IrradianceModel irradiance_model = IrradianceModel::kSh3;
    // The engine whose stored layout this entry is ("Unity APV"; engine_layouts.h), empty for zhc's
    // own representations. The audit, the benchmark and the reports measure engine layouts beside
    // zhc's; zhc's runtimes, containers' runtime readers and the choice of a representation skip
    // them (runtime_codecs() below; codec/audit/choice.h).
    std::string_view engine = {};
};

struct Codec {
    std::string_view name;
    std::string_view summary;  // one line for `zhc --help` and the audit legend
    std::size_t size_bytes;    // stored bytes per probe
    void (*encode)(const Sh3Radiance& in, const CodecOptions& options, std::uint8_t* out,
                   EncodeStats* stats);
    Sh3Radiance (*decode)(const std::uint8_t* in, const CodecOptions& options);
    // Irradiance at unit normal n straight from the stored bytes (the runtime path).
    Rgb (*irradiance)(const std::uint8_t* in, const CodecOptions& options, Vec3 n);
    CodecTraits traits = {};
    // Quantised layouts only (null otherwise): the layout and the entry's encode/decode with every
    // storage parameter (quantize.h), which the probe container uses instead of the two above.
    const PackedCodec* packed = nullptr;
};

// The whole table, in a stable order (audit and benchmark rows follow it).
std::span<const Codec> codecs();
// The entries zhc's runtimes decode (runtime/, docs/runtime.md): the table without the engine
// layouts (CodecTraits::engine), which are the engines' own formats. They sit at the end of the
// table, so this is a prefix of codecs() and an entry's runtime encoding id (its place in the
// table) is the same in both. Code that pairs the table with the runtimes walks this.
std::span<const Codec> runtime_codecs();
// The entry named `name`, or the entry an alias (codec_aliases below) stands for; nullptr when
// neither names one. Code that stores or prints a name takes the entry's own (Codec::name), so an
// alias is read and never written.
const Codec* find_codec(std::string_view name);

// Names accepted for an entry besides its own: readers of .zhp and glTF files and the command line
// take them, writers never write them. An entry's name says "dering" only when its encoder
// guarantees irradiance >= 0 everywhere (tests/test_codec_names.cpp, DeringNamesAreNonNegative),
// so App. B's clamps, which leave irradiance negative where no zonal value helps, are named for
// what they do and answer to their "dering" names here.
struct CodecAlias {
    std::string_view alias;  // accepted on input
    std::string_view name;   // the entry it stands for
};
std::span<const CodecAlias> codec_aliases();
// A comma-separated list of names ("sh3,zh3_lum") -> entries in that order; empty -> the whole
// table. An unknown name is kInvalidArgument naming it and listing the known ones.
Result<std::vector<const Codec*>> select_codecs(std::string_view comma_separated_names);

// The table is made of parts, one per codec module (`std::span<const Codec> PART()` defined next to
// the module's entries); codec/probe/codec_table.cpp lists them, one line each.

// Little-endian float storage helpers shared by the float representations.
void store_floats(std::span<const float> values, std::uint8_t* out);
void load_floats(const std::uint8_t* in, std::span<float> values);

}  // namespace zhc
