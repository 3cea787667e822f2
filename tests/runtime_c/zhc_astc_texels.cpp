// zhc_astc_texels PREFIX NORMALS OUT_DIR: the reference side of js.astc_webgl. Reads an ASTC lightmap
// (PREFIX.iz.ktx2 + PREFIX.dwa.ktx2, zhc's reader), decodes both textures with astcenc's decompressor
// (formats/lightmap/astc.h) into OUT_DIR/iz.f32 and OUT_DIR/dwa.f32 (RGBA float32 per texel, row-major),
// and evaluates runtime/zhc_runtime.h's zhc_irradz_irradiance_astc on those texels at the normals of
// NORMALS (3 float64 per texel) for HHD then AHD into OUT_DIR/e.f32 (6 float32 per texel). Prints one
// JSON line: width, height, footprint, ldr, lo, hi.
#include <cstdio>
#include <fstream>
#include <vector>

#include "formats/lightmap/astc.h"
#include "formats/lightmap/ktx2.h"
#include "zhc_runtime.h"

namespace {
template <class T>
bool write_raw(const std::string& path, const std::vector<T>& v) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
    return static_cast<bool>(f);
}
}  // namespace

int main(int argc, char** argv) {
    using namespace zhc;
    if (argc != 4) {
        std::fprintf(stderr, "usage: zhc_astc_texels PREFIX NORMALS OUT_DIR\n");
        return 2;
    }
    const std::string prefix = argv[1], out = argv[3];
    auto iz = read_ktx2(prefix + ".iz.ktx2");
    auto dwa = read_ktx2(prefix + ".dwa.ktx2");
    if (!iz || !dwa) {
        std::fprintf(stderr, "%s\n", (!iz ? iz.error() : dwa.error()).message.c_str());
        return 4;
    }
    const auto fi = astc::format_of_vk(iz->vk_format), fd = astc::format_of_vk(dwa->vk_format);
    if (!fi || !fd || fd->hdr) {
        std::fprintf(stderr, "not an ASTC lightmap\n");
        return 4;
    }
    lightmap::IzLogRange range;
    if (!fi->hdr) {
        std::optional<lightmap::IzLogRange> r;
        for (const auto& kv : iz->key_values)
            if (kv.key == lightmap_astc::kRangeKey) r = lightmap_astc::parse_range_value(kv.value);
        if (!r) {
            std::fprintf(stderr, "LDR I_z without a valid %s\n", lightmap_astc::kRangeKey);
            return 4;
        }
        range = *r;
    }
    const int w = iz->width, h = iz->height;
    auto ti = astc::decode_rgba(iz->blocks.data(), iz->blocks.size(), w, h, fi->footprint, fi->hdr);
    auto td = astc::decode_rgba(dwa->blocks.data(), dwa->blocks.size(), w, h, fd->footprint, false);
    if (!ti || !td) return 4;
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    std::vector<double> normals(3 * n);
    std::ifstream nf(argv[2], std::ios::binary);
    nf.read(reinterpret_cast<char*>(normals.data()), static_cast<std::streamsize>(normals.size() * sizeof(double)));
    if (!nf) {
        std::fprintf(stderr, "%s: expected %zu float64\n", argv[2], normals.size());
        return 3;
    }
    std::vector<float> e(6 * n);
    for (size_t i = 0; i < n; ++i)
        for (int model = 0; model < 2; ++model)
            zhc_irradz_irradiance_astc(&(*ti)[4 * i], &(*td)[4 * i], fi->hdr ? 0 : 1, range.lo, range.hi, model, &normals[3 * i],
                                       &e[6 * i + 3 * static_cast<size_t>(model)]);
    if (!write_raw(out + "/iz.f32", *ti) || !write_raw(out + "/dwa.f32", *td) || !write_raw(out + "/e.f32", e)) return 7;
    std::printf("{\"width\": %d, \"height\": %d, \"footprint\": [%d, %d], \"ldr\": %s, \"lo\": %.9g, \"hi\": %.9g}\n", w, h,
                fi->footprint.x, fi->footprint.y, fi->hdr ? "false" : "true", double(range.lo), double(range.hi));
    return 0;
}
