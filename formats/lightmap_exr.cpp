// zhc/formats/lightmap_exr.cpp — SH lightmap and IrradZ OpenEXR files (see lightmap_exr.h).
#include "lightmap_exr.h"

#include <IlmThreadPool.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "exr_memory.h"
#include "file_io.h"

namespace zhc {
namespace {

std::string sh_channel(int i, int k) { return "sh" + std::to_string(i) + "." + "RGB"[k]; }

}  // namespace

Result<lightmap::ShLightmap> read_sh_lightmap_exr(const std::string& path, const LightmapReadOptions& o) {
    auto bytes = read_file_bytes(path, o.max_file_bytes);
    if (!bytes) return bytes.error();
    const auto& b = *bytes;
    if (b.size() < 4 || !(b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01))
        return make_error(ErrorCode::kBadFormat, path + ": not an OpenEXR file (bad magic at byte 0)");
    auto check = [&](std::uint64_t w, std::uint64_t h) -> Status {
        if (w * h > o.max_texels)
            return make_error(ErrorCode::kTooLarge, path + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                                        " texels exceed the limit " + std::to_string(o.max_texels));
        return Ok{};
    };
    ExrLayout layout;
    if (Status s = validate_exr_header(b, path, check, &layout); !s) return s.error();
    // Every chunk inside the file before the texels are allocated; nothing after the last one.
    auto end = exr_data_end(b, path, layout);
    if (!end) return end.error();
    if (*end != b.size())
        return make_error(ErrorCode::kTrailingBytes, path + ": " + std::to_string(b.size() - *end) +
                                                         " trailing bytes after the OpenEXR data (which ends at byte " +
                                                         std::to_string(*end) + ")");
    try {
        Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
        ExrMemoryStream stream(b, path);
        const int threads = std::max(1, o.threads);
        if (threads > 1 && IlmThread::ThreadPool::globalThreadPool().numThreads() < threads)
            IlmThread::ThreadPool::globalThreadPool().setNumThreads(threads);
        Imf::InputFile file(stream, threads > 1 ? threads : 0);
        const Imath::Box2i dw = file.header().dataWindow();
        const std::int64_t w = std::int64_t(dw.max.x) - dw.min.x + 1, h = std::int64_t(dw.max.y) - dw.min.y + 1;
        if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, path + ": empty data window");
        if (static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) > o.max_texels)
            return make_error(ErrorCode::kTooLarge, path + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                                        " texels exceed the limit " + std::to_string(o.max_texels));
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k)
                if (!file.header().channels().findChannel(sh_channel(i, k)))
                    return make_error(ErrorCode::kBadFormat, path + ": missing channel \"" + sh_channel(i, k) +
                                                                 "\" (an SH lightmap has sh0.R .. sh8.B)");
        lightmap::ShLightmap lm;
        lm.width = static_cast<int>(w);
        lm.height = static_cast<int>(h);
        std::vector<float> buf(static_cast<size_t>(w) * static_cast<size_t>(h) * 27);
        Imf::FrameBuffer fb;
        const size_t xs = 27 * sizeof(float), ys = xs * static_cast<size_t>(w);
        char* base = reinterpret_cast<char*>(buf.data()) - (static_cast<std::ptrdiff_t>(dw.min.x) * static_cast<std::ptrdiff_t>(xs) +
                                                             static_cast<std::ptrdiff_t>(dw.min.y) * static_cast<std::ptrdiff_t>(ys));
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k)
                fb.insert(sh_channel(i, k), Imf::Slice(Imf::FLOAT, base + (i * 3 + k) * sizeof(float), xs, ys));
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        lm.texels.resize(static_cast<size_t>(w) * static_cast<size_t>(h));
        for (size_t t = 0; t < lm.texels.size(); ++t)
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) {
                    const float v = buf[t * 27 + static_cast<size_t>(i * 3 + k)];
                    if (!std::isfinite(v))
                        return make_error(ErrorCode::kInvalidValue, path + ": non-finite value in channel " + sh_channel(i, k) +
                                                                        " at texel (" + std::to_string(t % static_cast<size_t>(w)) +
                                                                        ", " + std::to_string(t / static_cast<size_t>(w)) + ")");
                    lm.texels[t][i][k] = v;
                }
        return lm;
    } catch (const std::exception& e) {
        std::string what = e.what();
        if (const auto nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
        return make_error(ErrorCode::kBadFormat, path + ": cannot read OpenEXR (" + what + ")");
    }
}

namespace {
Status write_channels(const std::string& path, int w, int h, const std::vector<std::string>& names, const std::vector<float>& data) {
    return write_via_temporary(path, [&](const std::string& tmp) -> Status {
        try {
            Imf::Header header(w, h);
            header.compression() = Imf::ZIP_COMPRESSION;
            for (const auto& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
            Imf::OutputFile out(tmp.c_str(), header);
            Imf::FrameBuffer fb;
            const size_t nc = names.size(), xs = nc * sizeof(float), ys = xs * static_cast<size_t>(w);
            char* base = reinterpret_cast<char*>(const_cast<float*>(data.data()));
            for (size_t c = 0; c < nc; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
            out.setFrameBuffer(fb);
            out.writePixels(h);
            return Ok{};
        } catch (const std::exception& e) {
            return make_error(ErrorCode::kIoError, path + ": cannot write OpenEXR (" + e.what() + ")");
        }
    });
}
}  // namespace

Status write_sh_lightmap_exr(const std::string& path, const lightmap::ShLightmap& lm) {
    std::vector<std::string> names;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) names.push_back(sh_channel(i, k));
    std::vector<float> data(lm.texels.size() * 27);
    for (size_t t = 0; t < lm.texels.size(); ++t)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) data[t * 27 + static_cast<size_t>(i * 3 + k)] = lm.texels[t][i][k];
    return write_channels(path, lm.width, lm.height, names, data);
}

Status write_irradz_exr(const std::string& path, const lightmap::IrradzPlanes& p) {
    const std::vector<std::string> names = {"Iz.R", "Iz.G", "Iz.B", "wa", "d.X", "d.Y", "d.Z"};
    const size_t n = p.wa.size();
    std::vector<float> data(n * 7);
    for (size_t t = 0; t < n; ++t) {
        const Vec3 d = lightmap::decode_hemioct(p.d[2 * t], p.d[2 * t + 1]);
        const float v[7] = {p.iz[3 * t], p.iz[3 * t + 1], p.iz[3 * t + 2], p.wa[t],
                            static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z)};
        std::memcpy(&data[t * 7], v, sizeof v);
    }
    return write_channels(path, p.width, p.height, names, data);
}

}  // namespace zhc
