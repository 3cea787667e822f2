// zhc/formats/lightmap/lightmap_stream.cpp — streaming lightmap encode / decode / audit / synth (see
// lightmap_stream.h).
#include "formats/lightmap/lightmap_stream.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>
#include <optional>

#include "formats/lightmap/dds.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"

namespace zhc::lightmap_stream {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Decoded IrradZ planes -> the 7 floats per texel of the IrradZ EXR (I_z RGB, w_a, d xyz).
void irradz_texels(const lightmap::IrradzPlanes& p, std::vector<float>& texels) {
    const size_t n = p.wa.size();
    texels.resize(n * 7);
    for (size_t t = 0; t < n; ++t) {
        const Vec3 d = lightmap::decode_hemioct(p.d[2 * t], p.d[2 * t + 1]);
        const float v[7] = {p.iz[3 * t], p.iz[3 * t + 1], p.iz[3 * t + 2], p.wa[t],
                            static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z)};
        std::memcpy(&texels[t * 7], v, sizeof v);
    }
}

constexpr std::uint32_t kFormats[3] = {kVkFormatBc6hUfloat, kVkFormatBc5Unorm, kVkFormatBc4Unorm};
const char* const kSuffixes[3] = {".iz", ".d", ".wa"};

// The SH lightmap input of encode and audit, read with the verb's thread count.
Result<std::unique_ptr<ShLightmapSource>> open_source(const std::vector<std::string>& inputs, int threads) {
    LightmapStreamOptions so;
    so.threads = threads;
    return ShLightmapSource::open(inputs, so);
}
template <class R>
void set_size(R& r, const ShLightmapSource& in) {
    r.width = in.width();
    r.height = in.height();
}


// band_rows rounded up to whole rows of ASTC blocks (footprint.y rows) as well as of 4.
int astc_band_rows(int width, int threads, int requested, astc::Footprint f) {
    const int rows = band_rows(width, threads, requested);
    return (rows + f.y - 1) / f.y * f.y;
}

// The whole image's I_z extent (the LDR range needs it before the first block is written): a
// first pass of the fit over every band.
Result<lightmap::IzLogRange> iz_range_pass(ShLightmapSource& in, Fit fit, int threads, int rows, double* fit_seconds) {
    float min_positive = 0, max_value = 0;
    lightmap::ShLightmap band;
    for (int y0 = 0; y0 < in.height(); y0 += rows) {
        const int y1 = std::min(in.height(), y0 + rows);
        if (Status s = in.read_rows(y0, y1, band); !s) return s.error();
        const auto t = Clock::now();
        const auto planes = lightmap::fit_planes(band, fit, threads);
        *fit_seconds += since(t);
        lightmap::iz_extent(planes.iz, min_positive, max_value);
    }
    return lightmap::iz_log_range(min_positive, max_value);
}

Result<EncodeResult> encode_astc(const std::vector<std::string>& inputs, const std::string& prefix, const EncodeOptions& o,
                                 bool* output_failed) {
    auto out_error = [&](Error e) {
        if (output_failed) *output_failed = true;
        return e;
    };
    if (o.dds)
        return make_error(ErrorCode::kUnsupported, prefix + ".iz.dds: --container dds: DDS has no ASTC formats; ASTC targets write KTX2 only");
    if (!astc::footprint_supported(o.footprint))
        return make_error(ErrorCode::kUnsupported, "--footprint " + std::to_string(o.footprint.x) + "x" + std::to_string(o.footprint.y) +
                                                       ": zhc writes 4x4, 5x5, 6x6, 8x8");
    auto src = open_source(inputs, o.threads);
    if (!src) return src.error();
    ShLightmapSource& in = **src;
    EncodeResult r;
    set_size(r, in);
    r.coefficients = in.coefficients();
    const int rows = astc_band_rows(r.width, o.threads, o.band_rows, o.footprint);
    lightmap_astc::Options ao;
    ao.footprint = o.footprint;
    ao.effort = astc_effort(o.bc6h_quality);
    ao.ldr_iz = o.target == Target::kAstcLdr;
    std::vector<Ktx2KeyValue> iz_kv;
    if (ao.ldr_iz) {
        auto range = iz_range_pass(in, o.fit, o.threads, rows, &r.timing.fit);
        if (!range) return range.error();
        ao.range = *range;
        iz_kv.push_back({lightmap_astc::kRangeKey, lightmap_astc::range_value(ao.range)});
    }
    const std::uint32_t formats[2] = {ao.ldr_iz ? astc::vk_format_ldr(o.footprint) : astc::vk_format_hdr(o.footprint),
                                      astc::vk_format_ldr(o.footprint)};
    const std::vector<std::string> paths = {prefix + ".iz.ktx2", prefix + ".dwa.ktx2"};
    AtomicFileSet out;
    std::uint64_t expected[2] = {};
    for (size_t f = 0; f < 2; ++f) {
        auto header = ktx2_header(formats[f], r.width, r.height, f == 0 ? iz_kv : std::vector<Ktx2KeyValue>{});
        if (!header) return out_error(make_error(header.error().code, paths[f] + ": " + header.error().message));
        if (f == 0)
            if (Status s = out.open(paths); !s) return out_error(s.error());
        if (Status s = out.write(f, header->data(), header->size()); !s) return out_error(s.error());
        expected[f] = header->size() + ktx2_level_bytes(formats[f], r.width, r.height);
    }
    lightmap::ShLightmap band;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        auto t = Clock::now();
        if (Status s = in.read_rows(y0, y1, band); !s) return s.error();
        r.timing.read += since(t);
        t = Clock::now();
        const auto planes = lightmap::fit_planes(band, o.fit, o.threads);
        r.timing.fit += since(t);
        t = Clock::now();
        auto c = lightmap_astc::compress(planes, ao, o.threads);
        if (!c) return c.error();
        r.timing.compress += since(t);
        t = Clock::now();
        if (Status s = out.write(0, c->iz.data(), c->iz.size()); !s) return out_error(s.error());
        if (Status s = out.write(1, c->dwa.data(), c->dwa.size()); !s) return out_error(s.error());
        r.timing.write += since(t);
        r.block_bytes += c->bytes();
        if (o.progress) o.progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    for (size_t f = 0; f < 2; ++f)
        if (out.written(f) != expected[f])
            return make_error(ErrorCode::kInternal, paths[f] + ": wrote " + std::to_string(out.written(f)) + " bytes, expected " +
                                                        std::to_string(expected[f]));
    const auto t = Clock::now();
    if (Status s = out.commit(); !s) return out_error(s.error());
    r.timing.write += since(t);
    return r;
}

Result<DecodeResult> decode_astc(const std::string& prefix, const BlockFileLayout& iz_layout, const std::string& output,
                                 int band_rows_requested, const ProgressFn& progress, bool* output_failed) {
    auto out_error = [&](Error e) {
        if (output_failed) *output_failed = true;
        return e;
    };
    const std::string paths[2] = {prefix + ".iz.ktx2", prefix + ".dwa.ktx2"};
    const auto iz_format = astc::format_of_vk(iz_layout.vk_format);
    lightmap_astc::Options ao;
    ao.footprint = iz_format->footprint;
    ao.ldr_iz = !iz_format->hdr;
    if (ao.ldr_iz) {
        const Ktx2KeyValue* kv = nullptr;
        for (const auto& e : iz_layout.key_values)
            if (e.key == lightmap_astc::kRangeKey) kv = &e;
        if (kv == nullptr)
            return make_error(ErrorCode::kBadFormat, paths[0] + ": key/value data: LDR ASTC I_z without the key " +
                                                         std::string(lightmap_astc::kRangeKey));
        const auto range = lightmap_astc::parse_range_value(kv->value);
        if (!range)
            return make_error(ErrorCode::kBadFormat, paths[0] + ": key/value data/" + std::string(lightmap_astc::kRangeKey) +
                                                         ": not two finite floats \"lo hi\" with lo < hi");
        ao.range = *range;
    }
    auto dwa_layout = read_ktx2_layout(paths[1]);
    if (!dwa_layout) return dwa_layout.error();
    if (dwa_layout->vk_format != astc::vk_format_ldr(ao.footprint))
        return make_error(ErrorCode::kBadFormat, paths[1] + ": vkFormat " + std::to_string(dwa_layout->vk_format) + ", expected " +
                                                     std::to_string(astc::vk_format_ldr(ao.footprint)) + " (ASTC UNORM, the footprint of " +
                                                     paths[0] + ")");
    if (dwa_layout->width != iz_layout.width || dwa_layout->height != iz_layout.height)
        return make_error(ErrorCode::kBadFormat, paths[1] + ": size " + std::to_string(dwa_layout->width) + "x" +
                                                     std::to_string(dwa_layout->height) + " differs from " + paths[0]);
    FileRangeReader readers[2];
    for (int f = 0; f < 2; ++f)
        if (Status s = readers[f].open(paths[f]); !s) return s.error();
    const std::uint64_t offsets[2] = {iz_layout.data_offset, dwa_layout->data_offset};
    DecodeResult r;
    r.width = iz_layout.width;
    r.height = iz_layout.height;
    r.target = ao.ldr_iz ? Target::kAstcLdr : Target::kAstc;
    r.footprint = ao.footprint;
    auto writer = ExrBandWriter::open(output, r.width, r.height, irradz_channel_names(), false);
    if (!writer) return out_error(writer.error());
    const int rows = astc_band_rows(r.width, 1, band_rows_requested, ao.footprint);
    const std::uint64_t bw = static_cast<std::uint64_t>((r.width + ao.footprint.x - 1) / ao.footprint.x);
    std::vector<float> texels;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        lightmap_astc::Compressed c;
        c.width = r.width;
        c.height = y1 - y0;
        c.options = ao;
        const std::uint64_t block_rows = static_cast<std::uint64_t>((c.height + ao.footprint.y - 1) / ao.footprint.y);
        const std::uint64_t first = static_cast<std::uint64_t>(y0 / ao.footprint.y);
        std::vector<std::uint8_t>* blocks[2] = {&c.iz, &c.dwa};
        for (int f = 0; f < 2; ++f) {
            blocks[f]->resize(static_cast<size_t>(block_rows * bw * 16));
            if (Status s = readers[f].read(offsets[f] + first * bw * 16, blocks[f]->data(), blocks[f]->size()); !s) return s.error();
        }
        auto p = lightmap_astc::decompress(c, y0);
        if (!p) return make_error(p.error().code, paths[0] + ": " + p.error().message);
        irradz_texels(*p, texels);
        if (Status s = (*writer)->write_rows(texels.data(), c.height); !s) return out_error(s.error());
        if (progress) progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    if (Status s = (*writer)->commit(); !s) return out_error(s.error());
    return r;
}

}  // namespace

astc::Effort astc_effort(bc6h::Quality q) {
    if (q == bc6h::Quality::kExhaustive) return astc::Effort::kThorough;
    if (q == bc6h::Quality::kFast || q == bc6h::Quality::kMode11) return astc::Effort::kFast;
    return astc::Effort::kMedium;
}

int band_rows(int width, int threads, int requested) {
    if (requested > 0) return (std::min(requested, 1 << 20) + 3) / 4 * 4;
    const int by_size = (1 << 18) / std::max(1, width) / 4 * 4;
    return std::max({4, by_size, 4 * std::clamp(threads, 1, 16)});
}

Result<EncodeResult> encode(const std::vector<std::string>& inputs, const std::string& prefix, const EncodeOptions& o,
                            bool* output_failed) {
    if (o.target != Target::kBc) return encode_astc(inputs, prefix, o, output_failed);
    auto out_error = [&](Error e) {
        if (output_failed) *output_failed = true;
        return e;
    };
    auto src = open_source(inputs, o.threads);
    if (!src) return src.error();
    ShLightmapSource& in = **src;
    EncodeResult r;
    set_size(r, in);
    r.coefficients = in.coefficients();
    const std::string ext = o.dds ? ".dds" : ".ktx2";
    std::vector<std::string> paths;
    for (const char* s : kSuffixes) paths.push_back(prefix + s + ext);
    AtomicFileSet out;
    std::uint64_t expected[3] = {};
    for (int f = 0; f < 3; ++f) {
        auto header = o.dds ? dds_header(kFormats[f], r.width, r.height) : ktx2_header(kFormats[f], r.width, r.height);
        if (!header) return out_error(make_error(header.error().code, paths[static_cast<size_t>(f)] + ": " + header.error().message));
        if (f == 0)
            if (Status s = out.open(paths); !s) return out_error(s.error());
        if (Status s = out.write(static_cast<size_t>(f), header->data(), header->size()); !s) return out_error(s.error());
        expected[f] = header->size() + ktx2_level_bytes(kFormats[f], r.width, r.height);
    }
    const int rows = band_rows(r.width, o.threads, o.band_rows);
    lightmap::ShLightmap band;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        auto t = Clock::now();
        if (Status s = in.read_rows(y0, y1, band); !s) return s.error();
        r.timing.read += since(t);
        t = Clock::now();
        const auto planes = lightmap::fit_planes(band, o.fit, o.threads);
        r.timing.fit += since(t);
        t = Clock::now();
        const auto c = lightmap::compress(planes, o.bc6h_quality, o.bc45_quality, o.threads);
        r.timing.compress += since(t);
        t = Clock::now();
        const std::vector<std::uint8_t>* blocks[3] = {&c.bc6h, &c.bc5, &c.bc4};
        for (size_t f = 0; f < 3; ++f)
            if (Status s = out.write(f, blocks[f]->data(), blocks[f]->size()); !s) return out_error(s.error());
        r.timing.write += since(t);
        r.block_bytes += c.bc6h.size() + c.bc5.size() + c.bc4.size();
        if (o.progress) o.progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    for (size_t f = 0; f < 3; ++f)
        if (out.written(f) != expected[f])
            return make_error(ErrorCode::kInternal, paths[f] + ": wrote " + std::to_string(out.written(f)) + " bytes, expected " +
                                                        std::to_string(expected[f]));
    const auto t = Clock::now();
    if (Status s = out.commit(); !s) return out_error(s.error());
    r.timing.write += since(t);
    return r;
}

Result<DecodeResult> decode(const std::string& prefix, bool dds, const std::string& output, int band_rows_requested,
                            const ProgressFn& progress, bool* output_failed) {
    auto out_error = [&](Error e) {
        if (output_failed) *output_failed = true;
        return e;
    };
    const std::string ext = dds ? ".dds" : ".ktx2";
    BlockFileLayout layout[3];
    FileRangeReader readers[3];
    std::string paths[3];
    for (int f = 0; f < 3; ++f) {
        paths[f] = prefix + kSuffixes[f] + ext;
        auto l = dds ? read_dds_layout(paths[f]) : read_ktx2_layout(paths[f]);
        if (!l) return l.error();
        if (f == 0 && !dds && astc::format_of_vk(l->vk_format))
            return decode_astc(prefix, *l, output, band_rows_requested, progress, output_failed);
        if (l->vk_format != kFormats[f])
            return make_error(ErrorCode::kBadFormat,
                              paths[f] + (dds ? ": dxgiFormat " + std::to_string(dxgi_format_for_vk(l->vk_format)) + ", expected " +
                                                    std::to_string(dxgi_format_for_vk(kFormats[f]))
                                              : ": vkFormat " + std::to_string(l->vk_format) + ", expected " + std::to_string(kFormats[f])));
        if (f > 0 && (l->width != layout[0].width || l->height != layout[0].height))
            return make_error(ErrorCode::kBadFormat, paths[f] + ": size " + std::to_string(l->width) + "x" + std::to_string(l->height) +
                                                         " differs from " + paths[0]);
        layout[f] = *l;
        if (Status s = readers[f].open(paths[f]); !s) return s.error();
    }
    DecodeResult r;
    r.width = layout[0].width;
    r.height = layout[0].height;
    auto writer = ExrBandWriter::open(output, r.width, r.height, irradz_channel_names(), false);
    if (!writer) return out_error(writer.error());
    const int rows = band_rows(r.width, 1, band_rows_requested);
    const std::uint64_t bw = static_cast<std::uint64_t>((r.width + 3) / 4);
    std::vector<float> texels;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        lightmap::Compressed c;
        c.width = r.width;
        c.height = y1 - y0;
        const std::uint64_t block_rows = static_cast<std::uint64_t>((c.height + 3) / 4), first = static_cast<std::uint64_t>(y0 / 4);
        std::vector<std::uint8_t>* blocks[3] = {&c.bc6h, &c.bc5, &c.bc4};
        for (int f = 0; f < 3; ++f) {
            const std::uint64_t bb = ktx2_block_bytes(kFormats[f]);
            blocks[f]->resize(static_cast<size_t>(block_rows * bw * bb));
            if (Status s = readers[f].read(layout[f].data_offset + first * bw * bb, blocks[f]->data(), blocks[f]->size()); !s)
                return s.error();
        }
        const auto p = lightmap::decompress(c);
        irradz_texels(p, texels);
        if (Status s = (*writer)->write_rows(texels.data(), c.height); !s) return out_error(s.error());
        if (progress) progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    if (Status s = (*writer)->commit(); !s) return out_error(s.error());
    return r;
}

// The plain audit is the BC target alone: audit_targets' base result with no targets listed.
Result<AuditResult> audit(const std::vector<std::string>& inputs, const AuditOptions& o) {
    AuditResult r;
    if (auto t = audit_targets(inputs, o, {}, &r); !t) return t.error();
    return r;
}

std::optional<TargetSpec> parse_target(const std::string& text) {
    TargetSpec t;
    t.name = text;
    std::string kind = text, fp;
    if (const auto colon = text.find(':'); colon != std::string::npos) {
        kind = text.substr(0, colon);
        fp = text.substr(colon + 1);
        if (fp.empty()) return std::nullopt;
    }
    if (kind == "bc") {
        if (!fp.empty()) return std::nullopt;
        return t;
    }
    if (kind == "astc") t.target = Target::kAstc;
    else if (kind == "astc-ldr") t.target = Target::kAstcLdr;
    else if (kind == "astc-split") t.target = Target::kAstc, t.split_dwa = true;
    else if (kind == "plain-astc") t.target = Target::kAstc, t.plain = true;
    else return std::nullopt;
    if (!fp.empty()) {
        const auto x = fp.find('x');
        if (x == std::string::npos || x == 0 || x + 1 >= fp.size() || fp.size() > 5) return std::nullopt;
        for (size_t i = 0; i < fp.size(); ++i)
            if (i != x && (fp[i] < '0' || fp[i] > '9')) return std::nullopt;
        t.footprint = {std::stoi(fp.substr(0, x)), std::stoi(fp.substr(x + 1))};
    }
    if (!astc::footprint_supported(t.footprint)) return std::nullopt;
    return t;
}

Result<std::vector<TargetAudit>> audit_targets(const std::vector<std::string>& inputs, const AuditOptions& o,
                                               const std::vector<TargetSpec>& targets, AuditResult* base) {
    auto src = open_source(inputs, o.threads);
    if (!src) return src.error();
    ShLightmapSource& in = **src;
    AuditResult r;
    set_size(r, in);
    // Bands of whole block rows for every footprint: a multiple of the lcm of 4 and their heights.
    int unit = 4;
    for (const auto& t : targets) unit = std::lcm(unit, t.footprint.y);
    int rows = band_rows(r.width, o.threads, o.band_rows);
    rows = (rows + unit - 1) / unit * unit;
    std::vector<TargetAudit> out(targets.size());
    std::vector<lightmap::AuditAccumulator> accs;
    for (size_t k = 0; k < targets.size(); ++k) {
        out[k].spec = targets[k];
        accs.emplace_back(o.stride, targets[k].plain ? irradz::Model::kAhd : irradz::Model::kHhd);
    }
    lightmap::AuditAccumulator base_acc(o.stride);
    lightmap::IzLogRange range;
    bool any_ldr = false;
    for (const auto& t : targets) any_ldr = any_ldr || t.target == Target::kAstcLdr;
    if (any_ldr) {
        double unused = 0;
        auto rr = iz_range_pass(in, Fit::kNewton, o.threads, rows, &unused);
        if (!rr) return rr.error();
        range = *rr;
    }
    lightmap::ShLightmap band;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        auto t = Clock::now();
        if (Status s = in.read_rows(y0, y1, band); !s) return s.error();
        r.timing.read += since(t);
        t = Clock::now();
        const auto search = lightmap::fit_planes(band, Fit::kNewton, o.threads);
        r.timing.fit += since(t);
        const auto old_way = lightmap::fit_planes(band, Fit::kTalkBaseline, o.threads);
        // The BC target (also the plain audit's numbers, *base): compressed once per band.
        std::optional<lightmap::IrradzPlanes> bc_after;
        double bc_seconds = 0;
        std::uint64_t bc_bytes = 0;
        const auto bc = [&]() -> const lightmap::IrradzPlanes& {
            if (!bc_after) {
                const auto t0 = Clock::now();
                const auto c = lightmap::compress(search, o.bc6h_quality, o.bc45_quality, o.threads);
                bc_seconds = since(t0);
                r.timing.compress += bc_seconds;
                bc_bytes = c.bc6h.size() + c.bc5.size() + c.bc4.size();
                bc_after = lightmap::decompress(c);
            }
            return *bc_after;
        };
        if (base) base_acc.add(band, search, old_way, bc());
        for (size_t k = 0; k < targets.size(); ++k) {
            const TargetSpec& spec = targets[k];
            t = Clock::now();
            if (spec.target == Target::kBc) {
                accs[k].add(band, search, old_way, bc());
                out[k].encode_seconds += bc_seconds;
                out[k].bytes += bc_bytes;
                continue;
            }
            lightmap_astc::Options ao;
            ao.footprint = spec.footprint;
            ao.effort = astc_effort(o.bc6h_quality);
            ao.ldr_iz = spec.target == Target::kAstcLdr;
            ao.range = range;
            ao.split_dwa = spec.split_dwa;
            if (spec.plain) {
                // Godot-style: the irradiance at the normal, one HDR texture; no direction.
                std::vector<float> e(search.iz.size());
                for (size_t i = 0; i < band.texels.size(); ++i) {
                    const Rgb v = evaluate(to_irradiance(band.texels[i]), {0, 0, 1});
                    for (int c = 0; c < 3; ++c) e[3 * i + static_cast<size_t>(c)] = static_cast<float>(v[c]);
                }
                auto blocks = astc::encode(e.data(), 3, band.width, band.height, spec.footprint, true, ao.effort, o.threads);
                if (!blocks) return blocks.error();
                out[k].encode_seconds += since(t);
                out[k].bytes += blocks->size();
                auto dec = astc::decode_rgba(blocks->data(), blocks->size(), band.width, band.height, spec.footprint, true);
                if (!dec) return dec.error();
                lightmap::IrradzPlanes after = search;
                for (size_t i = 0; i < after.wa.size(); ++i) {
                    for (size_t c = 0; c < 3; ++c) after.iz[3 * i + c] = (*dec)[4 * i + c];
                    after.wa[i] = 1;
                    after.d[2 * i] = after.d[2 * i + 1] = 0.5f;  // +Z (unused with w_a = 1)
                }
                accs[k].add(band, search, old_way, after);
                continue;
            }
            auto c = lightmap_astc::compress(search, ao, o.threads);
            if (!c) return c.error();
            out[k].encode_seconds += since(t);
            out[k].bytes += c->bytes();
            auto after = lightmap_astc::decompress(*c);
            if (!after) return after.error();
            accs[k].add(band, search, old_way, *after);
        }
        if (o.progress) o.progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    for (size_t k = 0; k < targets.size(); ++k) out[k].audit = accs[k].result();
    if (base) {
        r.audit = base_acc.result();
        *base = r;
    }
    return out;
}

Status synth(const Sh3Radiance& world, int width, int height, const std::string& output, bool half, int threads,
             int band_rows_requested, const ProgressFn& progress) {
    auto writer = ExrBandWriter::open(output, width, height, sh_lightmap_channel_names(), half, threads);
    if (!writer) return writer.error();
    const int rows = band_rows(width, threads, band_rows_requested);
    std::vector<float> data;
    for (int y0 = 0; y0 < height; y0 += rows) {
        const int y1 = std::min(height, y0 + rows);
        const auto band = lightmap::synthesize_sphere_rows(world, width, height, y0, y1, threads);
        data.resize(band.texels.size() * 27);
        for (size_t t = 0; t < band.texels.size(); ++t)
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) data[t * 27 + static_cast<size_t>(i * 3 + k)] = band.texels[t][i][k];
        if (Status s = (*writer)->write_rows(data.data(), y1 - y0); !s) return s;
        if (progress) progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(height));
    }
    return (*writer)->commit();
}

}  // namespace zhc::lightmap_stream
