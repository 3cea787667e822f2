// zhc/formats/lightmap/lightmap_exr.cpp — SH lightmap and IrradZ OpenEXR files (see lightmap_exr.h).
#include "formats/lightmap/lightmap_exr.h"

#include <IlmThreadPool.h>
#include <ImfChannelList.h>
#include <half.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <span>
#include <stdexcept>

#include "formats/io/exr_memory.h"
#include "formats/io/exr_scanlines.h"
#include "formats/io/file_io.h"

namespace zhc {
namespace {

std::string sh_channel(int i, int k) { return "sh" + std::to_string(i) + "." + "RGB"[k]; }

// The checks every input EXR passes before anything is decoded: the magic, a header within
// max_texels, and every chunk inside the file with nothing after the last one. Fills *layout.
Status check_exr_file(std::span<const std::uint8_t> b, const std::string& path, std::uint64_t max_texels,
                      ExrLayout* layout) {
    if (b.size() < 4 || !(b[0] == 0x76 && b[1] == 0x2f && b[2] == 0x31 && b[3] == 0x01))
        return make_error(ErrorCode::kBadFormat, path + ": not an OpenEXR file (bad magic at byte 0)" + git_lfs_hint(b));
    auto check = [&](std::uint64_t w, std::uint64_t h) -> Status {
        if (w * h > max_texels)
            return make_error(ErrorCode::kTooLarge, path + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                                        " texels exceed the limit " + std::to_string(max_texels));
        return Ok{};
    };
    if (Status s = validate_exr_header(b, path, check, layout); !s) return s;
    auto end = exr_data_end(b, path, *layout);
    if (!end) return end.error();
    if (*end != b.size())
        return make_error(ErrorCode::kTrailingBytes, path + ": " + std::to_string(b.size() - *end) +
                                                         " trailing bytes after the OpenEXR data (which ends at byte " +
                                                         std::to_string(*end) + ")");
    return Ok{};
}

}  // namespace

Result<LightmapExrSummary> describe_lightmap_exr(std::span<const std::uint8_t> b, const std::string& name, std::uint64_t max_texels) {
    ExrLayout layout;
    if (Status s = check_exr_file(b, name, max_texels, &layout); !s) return s.error();
    try {
        Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
        ExrMemoryStream stream(b, name);
        Imf::InputFile file(stream, 0);
        const Imath::Box2i dw = file.header().dataWindow();
        LightmapExrSummary out;
        out.width = dw.max.x - dw.min.x + 1;
        out.height = dw.max.y - dw.min.y + 1;
        const Imf::ChannelList& ch = file.header().channels();
        int types = 0;
        for (auto it = ch.begin(); it != ch.end(); ++it) {
            out.channels.push_back(it.name());
            types |= 1 << static_cast<int>(it.channel().type);
        }
        out.pixel_type = types == 1 << Imf::HALF ? "half" : types == 1 << Imf::FLOAT ? "float" : types == 1 << Imf::UINT ? "uint" : "mixed";
        auto has_all = [&](const std::vector<std::string>& names) {
            for (const auto& n : names)
                if (!ch.findChannel(n)) return false;
            return true;
        };
        std::vector<std::string> linear;
        for (int i = 0; i < 4; ++i)
            for (int k = 0; k < 3; ++k) linear.push_back(sh_channel(i, k));
        bool any_l2 = false;
        for (int i = 4; i < 9; ++i)
            for (int k = 0; k < 3; ++k) any_l2 = any_l2 || ch.findChannel(sh_channel(i, k));
        if (has_all(sh_lightmap_channel_names())) out.kind = "sh3";
        else if (has_all(linear) && !any_l2) out.kind = "linear-sh";
        else if (has_all(irradz_channel_names())) out.kind = "irradz";
        return out;
    } catch (const std::exception& e) {
        std::string what = e.what();
        if (const auto nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
        return make_error(ErrorCode::kBadFormat, name + ": cannot read OpenEXR (" + what + ")");
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

// ---- streaming --------------------------------------------------------------------------------

namespace zhc {
namespace {

static_assert(sizeof(Sh3Radiance) == 27 * sizeof(float), "the EXR frame buffer addresses Sh3Radiance as 27 floats");

// A read-only mapping of a regular file (pages are dropped from the process after each band, so
// the resident size stays near one band); other files (pipes) are read into memory.
class MappedFile {
public:
    ~MappedFile() {
        if (map_) ::munmap(map_, size_);
    }
    Status open(const std::string& path, std::uint64_t max_bytes) {
        std::error_code ec;
        const auto st = std::filesystem::status(path, ec);
        if (!ec && std::filesystem::is_regular_file(st)) {
            const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
            if (fd < 0) return make_error(ErrorCode::kIoError, path + ": cannot open (" + std::strerror(errno) + ")");
            record_input(path);
            struct stat sb {};
            if (::fstat(fd, &sb) != 0) {
                ::close(fd);
                return make_error(ErrorCode::kIoError, path + ": cannot stat");
            }
            const std::uint64_t size = static_cast<std::uint64_t>(sb.st_size);
            if (size > max_bytes) {
                ::close(fd);
                return make_error(ErrorCode::kTooLarge, path + ": file larger than the limit of " + std::to_string(max_bytes) + " bytes");
            }
            if (size == 0) {
                ::close(fd);
                return Ok{};
            }
            void* m = ::mmap(nullptr, static_cast<size_t>(size), PROT_READ, MAP_PRIVATE, fd, 0);
            ::close(fd);
            if (m == MAP_FAILED) return make_error(ErrorCode::kIoError, path + ": cannot map (" + std::strerror(errno) + ")");
            map_ = m;
            size_ = static_cast<size_t>(size);
            return Ok{};
        }
        auto b = read_file_bytes(path, max_bytes);
        if (!b) return b.error();
        copy_ = std::move(*b);
        return Ok{};
    }
    std::span<const std::uint8_t> bytes() const {
        if (map_) return {static_cast<const std::uint8_t*>(map_), size_};
        return copy_;
    }
    // Lets the kernel take back the pages read so far (they stay in the page cache).
    void release() {
        if (map_) ::madvise(map_, size_, MADV_DONTNEED);
    }

private:
    void* map_ = nullptr;
    size_t size_ = 0;
    std::vector<std::uint8_t> copy_;
};

struct ExrInput {
    std::string path;
    MappedFile file;
    std::unique_ptr<ExrMemoryStream> stream;
    std::unique_ptr<Imf::InputFile> exr;
    Imath::Box2i dw;
    bool fast = false;  // ZIP / ZIPS / uncompressed scanlines: decode_exr_scanlines, else readPixels
};

class ExrSource final : public ShLightmapSource {
public:
    int width() const override { return width_; }
    int height() const override { return height_; }
    int coefficients() const override { return coefficients_; }

    Status open_all(const std::vector<std::string>& paths, const LightmapStreamOptions& o) {
        if (paths.size() != 1 && paths.size() != 4 && paths.size() != 9)
            return make_error(ErrorCode::kInvalidArgument, std::to_string(paths.size()) +
                                                               " input files: give one SH lightmap EXR, or 4 (linear SH) or 9 (SH3) EXRs, one per coefficient");
        const int threads = std::max(1, o.threads);
        threads_ = threads;
        if (threads > 1 && IlmThread::ThreadPool::globalThreadPool().numThreads() < threads)
            IlmThread::ThreadPool::globalThreadPool().setNumThreads(threads);
        for (const auto& path : paths) {
            auto in = std::make_unique<ExrInput>();
            in->path = path;
            if (Status s = in->file.open(path, o.max_file_bytes); !s) return s;
            const auto b = in->file.bytes();
            ExrLayout layout;
            if (Status s = check_exr_file(b, path, o.max_texels, &layout); !s) return s;
            try {
                Imf::Header::setMaxImageSize(1 << 20, 1 << 20);
                in->stream = std::make_unique<ExrMemoryStream>(b, path);
                in->exr = std::make_unique<Imf::InputFile>(*in->stream, threads > 1 ? threads : 0);
                in->dw = in->exr->header().dataWindow();
                in->fast = exr_scanlines_supported(*in->exr);
            } catch (const std::exception& e) {
                return exr_error(path, e);
            }
            const std::int64_t w = std::int64_t(in->dw.max.x) - in->dw.min.x + 1, h = std::int64_t(in->dw.max.y) - in->dw.min.y + 1;
            if (w <= 0 || h <= 0) return make_error(ErrorCode::kBadFormat, path + ": empty data window");
            if (static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) > o.max_texels)
                return make_error(ErrorCode::kTooLarge, path + ": " + std::to_string(w) + "x" + std::to_string(h) +
                                                            " texels exceed the limit " + std::to_string(o.max_texels));
            if (inputs_.empty()) {
                width_ = static_cast<int>(w);
                height_ = static_cast<int>(h);
            } else if (w != width_ || h != height_) {
                return make_error(ErrorCode::kBadFormat, path + ": " + std::to_string(w) + "x" + std::to_string(h) + " differs from " +
                                                             paths[0] + " (" + std::to_string(width_) + "x" + std::to_string(height_) + ")");
            }
            inputs_.push_back(std::move(in));
        }
        if (paths.size() == 1) {
            const Imf::ChannelList& ch = inputs_[0]->exr->header().channels();
            bool any_l2 = false;
            for (int i = 4; i < 9; ++i)
                for (int k = 0; k < 3; ++k) any_l2 = any_l2 || ch.findChannel(sh_channel(i, k)) != nullptr;
            coefficients_ = any_l2 ? 9 : 4;
            for (int i = 0; i < coefficients_; ++i)
                for (int k = 0; k < 3; ++k) {
                    if (!ch.findChannel(sh_channel(i, k)))
                        return make_error(ErrorCode::kBadFormat,
                                          paths[0] + ": missing channel \"" + sh_channel(i, k) +
                                              (any_l2 ? "\" (an SH lightmap has sh0.R .. sh8.B)"
                                                      : "\" (an SH lightmap has sh0.R .. sh8.B; a linear-SH one sh0.R .. sh3.B)"));
                    slots_.push_back({0, sh_channel(i, k), i * 3 + k});
                }
        } else {
            coefficients_ = static_cast<int>(paths.size());
            for (int i = 0; i < coefficients_; ++i)
                for (int k = 0; k < 3; ++k) {
                    const std::string name(1, "RGB"[k]);
                    if (!inputs_[static_cast<size_t>(i)]->exr->header().channels().findChannel(name))
                        return make_error(ErrorCode::kBadFormat, paths[static_cast<size_t>(i)] + ": missing channel \"" + name +
                                                                     "\" (one file per SH coefficient has R, G, B)");
                    slots_.push_back({static_cast<size_t>(i), name, i * 3 + k});
                }
        }
        return Ok{};
    }

    Status read_rows(int y0, int y1, lightmap::ShLightmap& band) override {
        if (y0 < 0 || y1 > height_ || y0 >= y1) return make_error(ErrorCode::kInvalidArgument, "read_rows: bad row range");
        band.width = width_;
        band.height = y1 - y0;
        const size_t n = static_cast<size_t>(width_) * static_cast<size_t>(band.height);
        band.texels.resize(n);
        const size_t xs = sizeof(Sh3Radiance), ys = xs * static_cast<size_t>(width_);
        for (size_t f = 0; f < inputs_.size(); ++f) {
            ExrInput& in = *inputs_[f];
            if (in.fast) {
                std::vector<ExrFloatSlice> slices;
                for (const Slot& s : slots_)
                    if (s.file == f)
                        slices.push_back({s.channel, reinterpret_cast<char*>(band.texels.data()) + static_cast<size_t>(s.offset) * sizeof(float), xs, ys});
                if (Status st = decode_exr_scanlines(*in.exr, in.path, y0, y1, slices, threads_); !st) return st;
                in.file.release();
                continue;
            }
            try {
                Imf::FrameBuffer fb;
                char* base = reinterpret_cast<char*>(band.texels.data()) -
                             (static_cast<std::ptrdiff_t>(in.dw.min.x) * static_cast<std::ptrdiff_t>(xs) +
                              (static_cast<std::ptrdiff_t>(in.dw.min.y) + y0) * static_cast<std::ptrdiff_t>(ys));
                for (const Slot& s : slots_)
                    if (s.file == f) fb.insert(s.channel, Imf::Slice(Imf::FLOAT, base + static_cast<size_t>(s.offset) * sizeof(float), xs, ys));
                in.exr->setFrameBuffer(fb);
                in.exr->readPixels(in.dw.min.y + y0, in.dw.min.y + y1 - 1);
            } catch (const std::exception& e) {
                return exr_error(in.path, e);
            }
            in.file.release();
        }
        for (size_t t = 0; t < n; ++t)
            for (int i = coefficients_; i < 9; ++i) band.texels[t][i] = Rgb{};
        // Every float of the band finite (exponent bits not all ones), in one pass the compiler
        // vectorises; only where one is not does the loop below find the first to name it.
        static_assert(sizeof(Sh3Radiance) == 27 * sizeof(float));
        const std::uint32_t* bits = reinterpret_cast<const std::uint32_t*>(band.texels.data());
        std::uint32_t bad = 0;
        for (size_t i = 0; i < n * 27; ++i) bad |= static_cast<std::uint32_t>((bits[i] & 0x7f800000u) == 0x7f800000u);
        if (!bad) return Ok{};
        for (size_t t = 0; t < n; ++t) {
            Sh3Radiance& r = band.texels[t];
            for (const Slot& s : slots_) {
                const float v = r[s.offset / 3][s.offset % 3];
                if (!std::isfinite(v))
                    return make_error(ErrorCode::kInvalidValue,
                                      inputs_[s.file]->path + ": non-finite value in channel " + s.channel + " at texel (" +
                                          std::to_string(t % static_cast<size_t>(width_)) + ", " +
                                          std::to_string(static_cast<size_t>(y0) + t / static_cast<size_t>(width_)) + ")");
            }
        }
        return Ok{};
    }

private:
    static Error exr_error(const std::string& path, const std::exception& e) {
        std::string what = e.what();
        if (const auto nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
        return make_error(ErrorCode::kBadFormat, path + ": cannot read OpenEXR (" + what + ")");
    }
    struct Slot {
        size_t file;
        std::string channel;
        int offset;  // float index in Sh3Radiance: coefficient * 3 + colour
    };
    std::vector<std::unique_ptr<ExrInput>> inputs_;
    std::vector<Slot> slots_;
    int width_ = 0, height_ = 0, coefficients_ = 9, threads_ = 1;
};

class ExrWriter final : public ExrBandWriter {
public:
    ~ExrWriter() override {
        out_.reset();
        if (!tmp_.empty()) {
            std::error_code ec;
            std::filesystem::remove(tmp_, ec);
            release_temporary_path(tmp_);
        }
    }
    Status open(const std::string& path, int w, int h, const std::vector<std::string>& names, bool half, int threads) {
        if (w <= 0 || h <= 0 || names.empty()) return make_error(ErrorCode::kInvalidArgument, path + ": empty image");
        path_ = path;
        width_ = w;
        height_ = h;
        channels_ = names.size();
        names_ = names;
        half_ = half;
        tmp_ = temporary_path_for(path);
        try {
            Imf::Header header(w, h);
            header.compression() = Imf::ZIP_COMPRESSION;
            for (const auto& n : names) header.channels().insert(n, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
            threads = std::max(1, threads);
            if (threads > 1 && IlmThread::ThreadPool::globalThreadPool().numThreads() < threads)
                IlmThread::ThreadPool::globalThreadPool().setNumThreads(threads);
            out_ = std::make_unique<Imf::OutputFile>(tmp_.c_str(), header, threads > 1 ? threads : 0);
        } catch (const std::exception& e) {
            return make_error(ErrorCode::kIoError, path + ": cannot write OpenEXR (" + e.what() + ")");
        }
        return Ok{};
    }
    Status write_rows(const float* data, int rows) override {
        if (!out_ || rows <= 0 || next_row_ + rows > height_)
            return make_error(ErrorCode::kInvalidArgument, path_ + ": rows beyond the image");
        try {
            Imf::FrameBuffer fb;
            // OpenEXR writes a channel only from a slice of its own type: HALF output converts here.
            const size_t values = static_cast<size_t>(rows) * static_cast<size_t>(width_) * channels_;
            if (half_) {
                halves_.resize(values);
                for (size_t i = 0; i < values; ++i) halves_[i] = Imath::half(data[i]);
            }
            const size_t bytes = half_ ? sizeof(Imath::half) : sizeof(float);
            const size_t xs = channels_ * bytes, ys = xs * static_cast<size_t>(width_);
            char* base = (half_ ? reinterpret_cast<char*>(halves_.data()) : reinterpret_cast<char*>(const_cast<float*>(data))) -
                         static_cast<std::ptrdiff_t>(next_row_) * static_cast<std::ptrdiff_t>(ys);
            for (size_t c = 0; c < channels_; ++c)
                fb.insert(names_[c], Imf::Slice(half_ ? Imf::HALF : Imf::FLOAT, base + c * bytes, xs, ys));
            out_->setFrameBuffer(fb);
            out_->writePixels(rows);
            next_row_ += rows;
        } catch (const std::exception& e) {
            return make_error(ErrorCode::kIoError, path_ + ": cannot write OpenEXR (" + e.what() + ")");
        }
        return Ok{};
    }
    Status commit() override {
        if (!out_ || next_row_ != height_) return make_error(ErrorCode::kInternal, path_ + ": commit before every row was written");
        try {
            out_.reset();  // writes the offset table and closes the file
        } catch (const std::exception& e) {
            return make_error(ErrorCode::kIoError, path_ + ": cannot write OpenEXR (" + e.what() + ")");
        }
        std::error_code ec;
        std::filesystem::rename(tmp_, path_, ec);
        if (ec) return make_error(ErrorCode::kIoError, path_ + ": cannot write (" + ec.message() + ")");
        release_temporary_path(tmp_);
        tmp_.clear();
        record_output(path_);
        return Ok{};
    }

private:
    std::string path_, tmp_;
    std::vector<std::string> names_;
    std::unique_ptr<Imf::OutputFile> out_;
    std::vector<Imath::half> halves_;
    bool half_ = false;
    int width_ = 0, height_ = 0, next_row_ = 0;
    size_t channels_ = 0;
};

}  // namespace

Result<std::unique_ptr<ShLightmapSource>> ShLightmapSource::open(const std::vector<std::string>& paths,
                                                                 const LightmapStreamOptions& options) {
    auto s = std::make_unique<ExrSource>();
    if (Status st = s->open_all(paths, options); !st) return st.error();
    return std::unique_ptr<ShLightmapSource>(std::move(s));
}

Result<lightmap::ShLightmap> read_sh_lightmap_exr(const std::string& path, const LightmapReadOptions& o) {
    // The streaming source read in one band: the same checks, decoders and messages.
    LightmapStreamOptions so;
    so.max_texels = o.max_texels;
    so.max_file_bytes = o.max_file_bytes;
    so.threads = o.threads;
    ExrSource src;
    if (Status s = src.open_all({path}, so); !s) return s.error();
    if (src.coefficients() != 9)
        return make_error(ErrorCode::kBadFormat, path + ": missing channel \"sh4.R\" (an SH lightmap has sh0.R .. sh8.B)");
    lightmap::ShLightmap lm;
    if (Status s = src.read_rows(0, src.height(), lm); !s) return s.error();
    return lm;
}

Result<std::unique_ptr<ExrBandWriter>> ExrBandWriter::open(const std::string& path, int width, int height,
                                                           const std::vector<std::string>& names, bool half, int threads) {
    auto w = std::make_unique<ExrWriter>();
    if (Status st = w->open(path, width, height, names, half, threads); !st) return st.error();
    return std::unique_ptr<ExrBandWriter>(std::move(w));
}

std::vector<std::string> sh_lightmap_channel_names() {
    std::vector<std::string> names;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) names.push_back(sh_channel(i, k));
    return names;
}
std::vector<std::string> irradz_channel_names() { return {"Iz.R", "Iz.G", "Iz.B", "wa", "d.X", "d.Y", "d.Z"}; }

}  // namespace zhc
