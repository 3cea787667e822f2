// The streaming lightmap readers from untrusted bytes. The first byte picks the reader, the rest is
// the file: 0 — an SH lightmap EXR through ShLightmapSource (open, then every row in bands of 4:
// a total function, every value finite, L2 zero for linear-SH input); 1 / 2 — a KTX2 / DDS file
// through read_ktx2_layout / read_dds_layout, which must accept exactly what decode_ktx2 /
// decode_dds accept, with the same description and the level data at the end of the file.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "formats/lightmap/dds.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"

namespace {

std::string scratch_path() {
    static const std::string path = "/tmp/zhc_fuzz_lightmap_stream_" + std::to_string(::getpid());
    return path;
}

void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
}

void check_exr(const std::string& path) {
    zhc::LightmapStreamOptions o;
    o.max_texels = 1 << 14;
    auto src = zhc::ShLightmapSource::open({path}, o);
    if (!src) return;
    zhc::ShLightmapSource& in = **src;
    if (in.coefficients() != 4 && in.coefficients() != 9) std::abort();
    zhc::lightmap::ShLightmap band;
    for (int y = 0; y < in.height(); y += 4) {
        const int y1 = std::min(in.height(), y + 4);
        if (!in.read_rows(y, y1, band)) return;
        if (band.width != in.width() || band.height != y1 - y) std::abort();
        for (const auto& t : band.texels)
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) {
                    if (!std::isfinite(t[i][k])) std::abort();
                    if (i >= in.coefficients() && t[i][k] != 0) std::abort();
                }
    }
}

template <class Decode, class Layout>
void check_container(const std::string& path, const std::uint8_t* data, std::size_t size, Decode decode, Layout layout) {
    auto whole = decode(std::span<const std::uint8_t>(data, size), path);
    auto head = layout(path);
    if (whole.ok() != head.ok()) std::abort();
    if (!whole.ok()) {
        if (whole.error().code != head.error().code || whole.error().message != head.error().message) std::abort();
        return;
    }
    if (head->vk_format != whole->vk_format || head->width != whole->width || head->height != whole->height) std::abort();
    if (head->data_offset + whole->blocks.size() != size) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    const std::string path = scratch_path();
    write_file(path, data + 1, size - 1);
    switch (data[0] % 3) {
        case 0: check_exr(path); break;
        case 1:
            check_container(path, data + 1, size - 1, [](auto b, const std::string& n) { return zhc::decode_ktx2(b, n); },
                            [](const std::string& p) { return zhc::read_ktx2_layout(p); });
            break;
        default:
            check_container(path, data + 1, size - 1, [](auto b, const std::string& n) { return zhc::decode_dds(b, n); },
                            [](const std::string& p) { return zhc::read_dds_layout(p); });
            break;
    }
    std::remove(path.c_str());
    return 0;
}
