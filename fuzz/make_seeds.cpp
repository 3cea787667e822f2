// Writes the seed corpora of the fuzzers into fuzz/corpus/ (run from the repository root:
// build/fuzz/zhc_make_fuzz_seeds fuzz/corpus). Seeds are small valid inputs; libFuzzer mutates them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "codec/probe/codec.h"
#include "codec/bake/sky.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/dds.h"
#include "formats/lightmap/ktx2.h"
#include "codec/lightmap/bc6h.h"
#include "codec/lightmap/bc45.h"

using namespace zhc;

int main(int argc, char** argv) {
    namespace fs = std::filesystem;
    const std::string root = argc > 1 ? argv[1] : "fuzz/corpus";
    fs::create_directories(root + "/fuzz_envmap");
    fs::create_directories(root + "/fuzz_codec_decode");
    fs::create_directories(root + "/fuzz_codec_roundtrip");
    Image img;
    img.width = 8;
    img.height = 4;
    for (int i = 0; i < 8 * 4 * 3; ++i) img.rgb.push_back(0.25f * (i % 7));
    bool ok = write_exr(root + "/fuzz_envmap/small.exr", img) && write_hdr(root + "/fuzz_envmap/small.hdr", img);
    img.width = 16;
    img.height = 2;
    ok = ok && write_hdr(root + "/fuzz_envmap/rle16.hdr", img);
    const Sh3Radiance hub = project_default_lighting();
    int n = 0;
    for (const Codec& c : codecs()) {
        std::vector<std::uint8_t> bytes(1 + c.size_bytes);
        bytes[0] = static_cast<std::uint8_t>(n);
        c.encode(hub, CodecOptions{}, bytes.data() + 1, nullptr);
        ok = ok && write_file_atomic(root + "/fuzz_codec_decode/" + std::string(c.name), bytes);
        std::vector<std::uint8_t> rt(1 + 27 * 4);
        rt[0] = static_cast<std::uint8_t>(n);
        float v[27];
        for (int i = 0; i < 27; ++i) v[i] = hub[i / 3][i % 3];
        store_floats(v, rt.data() + 1);
        ok = ok && write_file_atomic(root + "/fuzz_codec_roundtrip/" + std::string(c.name), rt);
        ++n;
    }
    // KTX2: one small texture per format, and block round-trip seeds.
    fs::create_directories(root + "/fuzz_ktx2");
    fs::create_directories(root + "/fuzz_bc_roundtrip");
    std::vector<float> rgb(8 * 8 * 3), one(8 * 8), two(8 * 8 * 2);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = 0.1f * float(i % 17);
    for (size_t i = 0; i < one.size(); ++i) one[i] = float(i % 9) / 8.0f;
    for (size_t i = 0; i < two.size(); ++i) two[i] = float(i % 5) / 4.0f;
    const std::pair<std::uint32_t, std::vector<std::uint8_t>> textures[] = {
        {kVkFormatBc6hUfloat, bc6h::encode_image(rgb.data(), 8, 8, bc6h::Quality::kFast)},
        {kVkFormatBc4Unorm, bc45::encode_image(one.data(), 1, 8, 8, bc45::Quality::kFast)},
        {kVkFormatBc5Unorm, bc45::encode_image(two.data(), 2, 8, 8, bc45::Quality::kFast)}};
    std::vector<Ktx2Image> images;  // the three textures, 8 x 8, for both containers
    for (const auto& [format, blocks] : textures) {
        Ktx2Image k;
        k.vk_format = format;
        k.width = 8;
        k.height = 8;
        k.blocks = blocks;
        images.push_back(k);
    }
    for (const Ktx2Image& k : images) {
        const std::uint32_t format = k.vk_format;
        auto bytes = encode_ktx2(k);
        ok = ok && bytes && write_file_atomic(root + "/fuzz_ktx2/format" + std::to_string(format) + ".ktx2", *bytes);
    }
    // DDS: the same three textures (DX10 header), one with partial blocks, and the legacy
    // FourCC layouts ('ATI1' BC4, 'ATI2' BC5: no extension header, data at byte 128).
    fs::create_directories(root + "/fuzz_dds");
    for (const Ktx2Image& k : images) {
        const std::uint32_t format = k.vk_format;
        auto bytes = encode_dds(k);
        ok = ok && bytes && write_file_atomic(root + "/fuzz_dds/dxgi" + std::to_string(dxgi_format_for_vk(format)) + ".dds", *bytes);
        if (bytes && format != kVkFormatBc6hUfloat) {
            std::vector<std::uint8_t> legacy(bytes->begin(), bytes->begin() + 128);
            legacy.insert(legacy.end(), bytes->begin() + static_cast<std::ptrdiff_t>(kDdsDataOffset), bytes->end());
            const char* four = format == kVkFormatBc4Unorm ? "ATI1" : "ATI2";
            std::copy(four, four + 4, legacy.begin() + 84);
            ok = ok && write_file_atomic(root + "/fuzz_dds/" + four + ".dds", legacy);
        }
    }
    {
        Ktx2Image k;
        k.vk_format = kVkFormatBc6hUfloat;
        k.width = 5;
        k.height = 3;
        k.blocks = bc6h::encode_image(rgb.data(), 5, 3, bc6h::Quality::kFast);
        auto bytes = encode_dds(k);
        ok = ok && bytes && write_file_atomic(root + "/fuzz_dds/odd5x3.dds", *bytes);
    }
    for (int kind = 0; kind < 4; ++kind) {
        std::vector<std::uint8_t> b(1 + 96);
        b[0] = static_cast<std::uint8_t>(kind);
        for (size_t i = 1; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(i * 37 + kind);
        ok = ok && write_file_atomic(root + "/fuzz_bc_roundtrip/kind" + std::to_string(kind), b);
    }
    std::printf("%s\n", ok ? "seeds written" : "failed");
    return ok ? 0 : 1;
}
