// zhc/formats/engines/engine_files.h — the probe files engines load, written and read by zhc
// (docs/engine-files.md): one bake serves every engine.
//
// Each entry of engine_files() is one engine's file format for baked probes: a writer from zhc's
// probes (hub radiance SH3 + layout, in zhc's axes and units) to the file's bytes, exactly as the
// engine loads them, and a reader back (of zhc's files and of the files the engine's own tools
// write). The probes a file holds are those of an engine layout (codec/probe/engine_layouts.h,
// `layout_codec`): a write then read equals round_trip_probes(hub, layout_codec) within the
// file's number format. `zhc convert` and `zhc bake` pick an entry with --engine NAME; a file is
// recognised on input by `sniff`.
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "codec/probe/probe_set.h"
#include "codec/status.h"

namespace zhc {

// What a writer is given: radiance probes in zhc's axes and units (the hub) and where they are.
struct EngineFileInput {
    std::span<const Sh3Radiance> hub;
    ProbeLayout layout;                                     // grid or positions (kNone is refused)
    std::span<const std::uint8_t> validity;                 // empty, or 1 byte per probe (1 = valid)
    std::span<const std::array<std::uint32_t, 4>> tetrahedra;  // a positions layout's, if any (else computed)
};

// A writer's result: the file's bytes and what the user should know (one line each: e.g. the
// transform to give the volume's entity, probes merged as duplicates).
struct EngineFileOutput {
    std::vector<std::uint8_t> bytes;
    std::vector<std::string> notes;
};

// A reader's result: the probes in zhc's terms, and what it assumed where the file is silent
// (e.g. "the file holds no bounds: the unit cube centred at the origin").
struct EngineFileProbes {
    std::vector<Sh3Radiance> hub;
    ProbeLayout layout;
    std::vector<std::uint8_t> validity;  // empty when the file has none
    std::vector<std::string> notes;
};

struct EngineFile {
    std::string_view name;         // --engine NAME ("godot_lightmap_gi")
    std::string_view engine;       // "Godot 4 LightmapGIData (text resource)"
    std::string_view extension;    // the output's extension (".tres")
    std::string_view layout_codec; // the engine layout its probes are stored in ("godot_l2")
    std::string_view source;       // the engine's files and functions the format follows
    // True when the bytes are this format (only this one among engine_files()).
    bool (*sniff)(std::span<const std::uint8_t> bytes) = nullptr;
    // kInvalidArgument for probes the format cannot hold (layout, count limits), naming why.
    Result<EngineFileOutput> (*write)(const EngineFileInput& in) = nullptr;
    // Strict and safe for untrusted bytes (bounded allocation, one-line errors naming `name`).
    Result<EngineFileProbes> (*read)(std::span<const std::uint8_t> bytes, const std::string& name) = nullptr;
};

// How far a converted bake is from its source: irradiance of `back` (what the file gives back)
// against `source` at 64 spherical-Fibonacci normals per probe (codec/sh/sh.h irradiance), over
// every probe and channel. rms: RMS of the differences / RMS of the source's values; max: the
// largest |difference| / the largest |source value|. Both 0 for identical probes; sizes must match.
struct EngineFileError {
    double rms = 0;
    double max = 0;
};
EngineFileError engine_file_error(std::span<const Sh3Radiance> source, std::span<const Sh3Radiance> back);

// Every engine file format, in a fixed order.
std::span<const EngineFile> engine_files();
// The entry named `name`; nullptr when none.
const EngineFile* find_engine_file(std::string_view name);
// The entry whose sniff accepts the bytes; nullptr when none.
const EngineFile* sniff_engine_file(std::span<const std::uint8_t> bytes);

}  // namespace zhc
