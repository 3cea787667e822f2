// Writes the seed corpora of the fuzzers into fuzz/corpus/ (run from the repository root:
// build/fuzz/zhc_make_fuzz_seeds fuzz/corpus). Seeds are small valid inputs; libFuzzer mutates them.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "codec/codec.h"
#include "codec/sky.h"
#include "formats/envmap.h"
#include "formats/file_io.h"

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
    std::printf("%s\n", ok ? "seeds written" : "failed");
    return ok ? 0 : 1;
}
