// zhc/formats/io/exr_scanlines.cpp — see exr_scanlines.h.
//
// A ZIP chunk (OpenEXR file layout, "Compression"): the chunk's rows, each row its channels in the
// header's (alphabetical) order, each channel `width` little-endian samples; the compressor splits
// those bytes into the even-indexed half followed by the odd-indexed half, replaces each byte but
// the first by (byte - previous byte + 128) mod 256, and deflates the result as one zlib stream. A
// chunk that would not shrink is stored as it is (its packed size equals the raw size).
#include "formats/io/exr_scanlines.h"

#include <ImfChannelList.h>
#include <ImfPartType.h>
#include <ImfVersion.h>
#include <half.h>
#include <libdeflate.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace zhc {
namespace {

// t[i] = t[i - 1] + t[i] - 128 (mod 256) for i >= 1: the ZIP predictor undone. With SSE2, sixteen
// bytes at a time: their prefix sum in four shifted adds, plus the previous block's last byte.
void undo_predictor(std::uint8_t* t, std::size_t n) {
    if (n < 2) return;
    std::size_t i = 1;
#if defined(__SSE2__)
    const __m128i k128 = _mm_set1_epi8(static_cast<char>(0x80));
    __m128i carry = _mm_set1_epi8(static_cast<char>(t[0]));
    for (; i + 16 <= n; i += 16) {
        __m128i v = _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(t + i)), k128);
        v = _mm_add_epi8(v, _mm_slli_si128(v, 1));
        v = _mm_add_epi8(v, _mm_slli_si128(v, 2));
        v = _mm_add_epi8(v, _mm_slli_si128(v, 4));
        v = _mm_add_epi8(v, _mm_slli_si128(v, 8));
        v = _mm_add_epi8(v, carry);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(t + i), v);
        // Broadcast byte 15.
        const __m128i hi = _mm_unpackhi_epi8(v, v);
        carry = _mm_shuffle_epi32(_mm_unpackhi_epi16(hi, hi), 0xFF);
    }
#endif
    for (; i < n; ++i) t[i] = static_cast<std::uint8_t>(t[i - 1] + t[i] - 128);
}

// out[2 k] = t[k], out[2 k + 1] = t[(n + 1) / 2 + k]: the byte split undone.
void interleave(const std::uint8_t* t, std::size_t n, std::uint8_t* out) {
    const std::uint8_t* t1 = t;
    const std::uint8_t* t2 = t + (n + 1) / 2;
    std::size_t k = 0;
#if defined(__SSE2__)
    for (; k + 16 <= n / 2; k += 16) {
        const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t1 + k));
        const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(t2 + k));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k), _mm_unpacklo_epi8(a, b));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * k + 16), _mm_unpackhi_epi8(a, b));
    }
#endif
    for (; k < n / 2; ++k) {
        out[2 * k] = t1[k];
        out[2 * k + 1] = t2[k];
    }
    if (n % 2) out[n - 1] = t1[n / 2];
}

struct Channel {
    std::size_t row_offset = 0;  // bytes from the start of a row of the chunk
    bool half = false;
    int slice = -1;              // index into the slices, -1: not wanted
};

struct Layout {
    int width = 0, height = 0, min_y = 0, lines_per_chunk = 1;
    std::size_t row_bytes = 0;
    std::vector<Channel> channels;
};

struct DeflateFree {
    void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace

bool exr_scanlines_supported(Imf::InputFile& file) {
    if constexpr (std::endian::native != std::endian::little) return false;
    const int v = file.version();
    if (Imf::isTiled(v) || Imf::isMultiPart(v) || Imf::isNonImage(v)) return false;
    const Imf::Header& h = file.header();
    if (h.hasType() && h.type() != Imf::SCANLINEIMAGE) return false;
    const Imf::Compression c = h.compression();
    if (c != Imf::NO_COMPRESSION && c != Imf::ZIP_COMPRESSION && c != Imf::ZIPS_COMPRESSION) return false;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        const Imf::Channel& ch = it.channel();
        if ((ch.type != Imf::HALF && ch.type != Imf::FLOAT) || ch.xSampling != 1 || ch.ySampling != 1) return false;
    }
    return true;
}

Status decode_exr_scanlines(Imf::InputFile& file, const std::string& path, int y0, int y1,
                            std::span<const ExrFloatSlice> slices, int threads) {
    const Imf::Header& h = file.header();
    const Imath::Box2i dw = h.dataWindow();
    Layout L;
    L.width = dw.max.x - dw.min.x + 1;
    L.height = dw.max.y - dw.min.y + 1;
    L.min_y = dw.min.y;
    L.lines_per_chunk = h.compression() == Imf::ZIP_COMPRESSION ? 16 : 1;
    if (y0 < 0 || y1 > L.height || y0 >= y1) return make_error(ErrorCode::kInvalidArgument, path + ": bad row range");
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        Channel c;
        c.row_offset = L.row_bytes;
        c.half = it.channel().type == Imf::HALF;
        for (std::size_t s = 0; s < slices.size(); ++s)
            if (slices[s].channel == it.name()) c.slice = static_cast<int>(s);
        L.row_bytes += static_cast<std::size_t>(L.width) * (c.half ? 2 : 4);
        L.channels.push_back(c);
    }
    for (const ExrFloatSlice& s : slices)
        if (!h.channels().findChannel(s.channel))
            return make_error(ErrorCode::kBadFormat, path + ": missing channel \"" + s.channel + "\"");

    const int first_chunk = y0 / L.lines_per_chunk, last_chunk = (y1 - 1) / L.lines_per_chunk;
    const int chunks = last_chunk - first_chunk + 1;
    const int workers = std::clamp(threads, 1, chunks);
    std::mutex file_mutex;  // rawPixelData fills one buffer inside the InputFile
    std::atomic<int> next{first_chunk};
    // Each worker's first failure and its chunk. Chunks are taken in order and every chunk taken is
    // decoded, so the failure with the lowest chunk is the file's first bad chunk whatever the thread
    // count: that one is reported.
    std::vector<Status> status(static_cast<std::size_t>(workers), Status{Ok{}});
    std::vector<int> failed_chunk(static_cast<std::size_t>(workers), last_chunk + 1);

    auto work = [&](int worker) {
        std::unique_ptr<libdeflate_decompressor, DeflateFree> inflater(libdeflate_alloc_decompressor());
        std::vector<std::uint8_t> packed, raw, bytes;
        Status& st = status[static_cast<std::size_t>(worker)];
        if (!inflater) {
            st = make_error(ErrorCode::kIoError, path + ": out of memory for the ZIP decoder");
            failed_chunk[static_cast<std::size_t>(worker)] = first_chunk - 1;
            return;
        }
        for (int chunk = next++; chunk <= last_chunk; chunk = next++) {
            failed_chunk[static_cast<std::size_t>(worker)] = chunk;  // reset below when it decodes
            const int row0 = chunk * L.lines_per_chunk;
            const int rows = std::min(L.lines_per_chunk, L.height - row0);
            const std::size_t n = static_cast<std::size_t>(rows) * L.row_bytes;
            // One worker reads the chunk where OpenEXR leaves it; several copy it out under the lock.
            std::span<const std::uint8_t> chunk_bytes;
            try {
                std::unique_lock<std::mutex> lock(file_mutex, std::defer_lock);
                if (workers > 1) lock.lock();
                const char* data = nullptr;
                int size = 0;
                file.rawPixelData(L.min_y + row0, data, size);
                if (size < 0 || (data == nullptr && size > 0)) throw std::runtime_error("bad chunk size");
                if (workers > 1) {
                    packed.assign(data, data + size);
                    chunk_bytes = packed;
                } else {
                    chunk_bytes = {reinterpret_cast<const std::uint8_t*>(data), static_cast<size_t>(size)};
                }
            } catch (const std::exception& e) {
                std::string what = e.what();
                if (const auto nl = what.find('\n'); nl != std::string::npos) what.resize(nl);
                st = make_error(ErrorCode::kBadFormat, path + ": cannot read OpenEXR (" + what + ")");
                return;
            }
            const std::uint8_t* src = chunk_bytes.data();
            if (chunk_bytes.size() != n) {
                // Compressed: ZIP or ZIPS (a NONE chunk or a stored one has exactly the raw size).
                std::size_t got = 0;
                raw.resize(n);
                if (h.compression() == Imf::NO_COMPRESSION || chunk_bytes.size() > n ||
                    libdeflate_zlib_decompress(inflater.get(), chunk_bytes.data(), chunk_bytes.size(), raw.data(), n, &got) !=
                        LIBDEFLATE_SUCCESS ||
                    got != n) {
                    st = make_error(ErrorCode::kBadFormat, path + ": corrupt OpenEXR chunk at row " + std::to_string(L.min_y + row0) +
                                                               " (its data does not decompress to the " + std::to_string(n) +
                                                               " bytes of its rows)");
                    return;
                }
                undo_predictor(raw.data(), n);
                bytes.resize(n);
                interleave(raw.data(), n, bytes.data());
                src = bytes.data();
            }
            for (int r = std::max(row0, y0); r < std::min(row0 + rows, y1); ++r) {
                const std::uint8_t* row = src + static_cast<std::size_t>(r - row0) * L.row_bytes;
                for (const Channel& c : L.channels) {
                    if (c.slice < 0) continue;
                    const ExrFloatSlice& s = slices[static_cast<std::size_t>(c.slice)];
                    char* out = s.base + static_cast<std::size_t>(r - y0) * s.y_stride;
                    const std::uint8_t* in = row + c.row_offset;
                    if (c.half) {
                        for (int x = 0; x < L.width; ++x) {
                            std::uint16_t bits;
                            std::memcpy(&bits, in + 2 * static_cast<std::size_t>(x), 2);
                            Imath::half hv;
                            hv.setBits(bits);
                            const float f = hv;
                            std::memcpy(out + static_cast<std::size_t>(x) * s.x_stride, &f, 4);
                        }
                    } else if (s.x_stride == 4) {
                        std::memcpy(out, in, 4 * static_cast<std::size_t>(L.width));
                    } else {
                        for (int x = 0; x < L.width; ++x)
                            std::memcpy(out + static_cast<std::size_t>(x) * s.x_stride, in + 4 * static_cast<std::size_t>(x), 4);
                    }
                }
            }
            failed_chunk[static_cast<std::size_t>(worker)] = last_chunk + 1;
        }
    };
    if (workers == 1) {
        work(0);
    } else {
        std::vector<std::thread> pool;
        for (int w = 1; w < workers; ++w) pool.emplace_back(work, w);
        work(0);
        for (auto& t : pool) t.join();
    }
    const auto first = std::min_element(failed_chunk.begin(), failed_chunk.end());
    if (*first <= last_chunk) return status[static_cast<std::size_t>(first - failed_chunk.begin())];
    return Ok{};
}

}  // namespace zhc
