// A program outside the zhc tree: projects an environment map, stores it as a 16-byte ZH3 probe in
// a .zhp container in memory, reads the container back and decodes it. Exit 0 only when every
// step worked and the decoded probe is the one encoded (the container round trip is bit-exact).
#include <zhc/codec.h>
#include <zhc/formats.h>

#include <cmath>
#include <cstdio>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: zhc_consumer ENVMAP\n");
        return 2;
    }
    auto image = zhc::read_envmap(argv[1]);
    if (!image) {
        std::fprintf(stderr, "zhc_consumer: %s\n", image.error().message.c_str());
        return 1;
    }
    const zhc::Sh3Radiance hub =
        zhc::project_latlong(image->rgb.data(), image->width, image->height, std::size_t(image->width) * 3);
    const zhc::Sh3Radiance hubs[1] = {hub};
    auto set = zhc::encode_probe_set(hubs, "zh3_q16", zhc::CodecOptions{}, zhc::ProbeLayout{});
    if (!set) return 1;
    auto bytes = zhc::serialize_probe_set(*set);
    if (!bytes) return 1;
    auto back = zhc::parse_probe_set(*bytes, "memory");
    if (!back || back->payload != set->payload || back->representation != "zh3_q16") return 1;
    auto decoded = zhc::decode_probe_set(*back);
    if (!decoded || decoded->size() != 1) return 1;
    const zhc::Codec* codec = zhc::find_codec("zh3_q16");
    const zhc::Sh3Radiance direct = codec->decode(set->payload.data(), zhc::CodecOptions{});
    if (!((*decoded)[0] == direct)) return 1;
    // R11G11B10F keeps the DC within 2^-6 relative (the blue channel's 5-bit mantissa).
    for (int k = 0; k < 3; ++k)
        if (!(std::fabs((*decoded)[0][0][k] - hub[0][k]) <= std::ldexp(std::fabs(hub[0][k]), -6))) return 1;
    std::printf("zhc_consumer: %zu bytes in the container, L00 = %g %g %g\n", bytes->size(), (*decoded)[0][0][0],
                (*decoded)[0][0][1], (*decoded)[0][0][2]);
    return 0;
}
