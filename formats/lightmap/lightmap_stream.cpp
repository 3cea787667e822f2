// zhc/formats/lightmap/lightmap_stream.cpp — streaming lightmap encode / decode / audit / synth (see
// lightmap_stream.h).
#include "formats/lightmap/lightmap_stream.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "formats/lightmap/dds.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"

namespace zhc::lightmap_stream {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

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


}  // namespace

int band_rows(int width, int threads, int requested) {
    if (requested > 0) return (std::min(requested, 1 << 20) + 3) / 4 * 4;
    const int by_size = (1 << 18) / std::max(1, width) / 4 * 4;
    return std::max({4, by_size, 4 * std::clamp(threads, 1, 16)});
}

Result<EncodeResult> encode(const std::vector<std::string>& inputs, const std::string& prefix, const EncodeOptions& o,
                            bool* output_failed) {
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
        const size_t n = p.wa.size();
        texels.resize(n * 7);
        for (size_t t = 0; t < n; ++t) {
            const Vec3 d = lightmap::decode_hemioct(p.d[2 * t], p.d[2 * t + 1]);
            const float v[7] = {p.iz[3 * t], p.iz[3 * t + 1], p.iz[3 * t + 2], p.wa[t],
                                static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z)};
            std::memcpy(&texels[t * 7], v, sizeof v);
        }
        if (Status s = (*writer)->write_rows(texels.data(), c.height); !s) return out_error(s.error());
        if (progress) progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    if (Status s = (*writer)->commit(); !s) return out_error(s.error());
    return r;
}

Result<AuditResult> audit(const std::vector<std::string>& inputs, const AuditOptions& o) {
    auto src = open_source(inputs, o.threads);
    if (!src) return src.error();
    ShLightmapSource& in = **src;
    AuditResult r;
    set_size(r, in);
    lightmap::AuditAccumulator acc(o.stride);
    const int rows = band_rows(r.width, o.threads, o.band_rows);
    lightmap::ShLightmap band;
    for (int y0 = 0; y0 < r.height; y0 += rows) {
        const int y1 = std::min(r.height, y0 + rows);
        auto t = Clock::now();
        if (Status s = in.read_rows(y0, y1, band); !s) return s.error();
        r.timing.read += since(t);
        t = Clock::now();
        const auto search = lightmap::fit_planes(band, Fit::kNewton, o.threads);  // irradz::EncodeOptions' default, as lightmap audit
        r.timing.fit += since(t);
        const auto old_way = lightmap::fit_planes(band, Fit::kOld, o.threads);
        t = Clock::now();
        const auto c = lightmap::compress(search, o.bc6h_quality, o.bc45_quality, o.threads);
        r.timing.compress += since(t);
        acc.add(band, search, old_way, lightmap::decompress(c));
        if (o.progress) o.progress(static_cast<std::uint64_t>(y1), static_cast<std::uint64_t>(r.height));
    }
    r.audit = acc.result();
    return r;
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
