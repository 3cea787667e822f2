// An engine tool built with zhc added by add_subdirectory: encodes an analytic probe (a sky of
// radiance 1 + 0.5 z, whose SH3 is known in closed form) into every representation of the codec
// table, and checks that the C runtime (zhc_runtime.h) decodes each stored probe to exactly the
// floats the codec decodes. Exit 0 only when every entry agrees bit for bit.
#include <zhc/codec.h>

#include "zhc_runtime.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

int main() {
    // L(w) = 1 + 0.5 z: L00 = sqrt(4 pi) * 1 * Y00-normalisation and L10 from z = sqrt(4 pi / 3) Y10.
    const double pi = 3.14159265358979323846;
    zhc::Sh3Radiance hub{};
    for (int k = 0; k < 3; ++k) {
        hub[0][k] = float(std::sqrt(4 * pi));
        hub[2][k] = float(0.5 * std::sqrt(4 * pi / 3));
    }
    int checked = 0;
    for (const zhc::Codec& codec : zhc::runtime_codecs()) {  // the engine layouts have no C decoder
        const zhc::CodecOptions options{};
        std::vector<std::uint8_t> bytes(codec.size_bytes);
        codec.encode(hub, options, bytes.data(), nullptr);
        const zhc::Sh3Radiance expected = codec.decode(bytes.data(), options);
        zhc_probe_format format;
        if (zhc_probe_format_init(&format, std::string(codec.name).c_str()) != ZHC_OK) {
            std::fprintf(stderr, "codec_consumer: the C runtime does not know %s\n", std::string(codec.name).c_str());
            return 1;
        }
        float got[27];
        if (zhc_decode_probe(&format, bytes.data(), got) != ZHC_OK) return 1;
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) {
                const float want = expected[i][k];
                if (std::memcmp(&got[i * 3 + k], &want, sizeof(float)) != 0) {
                    std::fprintf(stderr, "codec_consumer: %s coefficient %d channel %d: runtime %.9g, codec %.9g\n",
                                 std::string(codec.name).c_str(), i, k, got[i * 3 + k], want);
                    return 1;
                }
            }
        ++checked;
    }
    if (checked < 20) return 1;
    std::printf("codec_consumer: %d representations decode identically in the codec and the C runtime\n", checked);
    return 0;
}
