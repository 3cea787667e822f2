// Compiles runtime/zhc_runtime.h as strict C++11 (-Wall -Wextra -Werror -pedantic) and calls every
// public function once, so a construct that is C-only (or C++-only) fails the build.
#include "zhc_runtime.h"

int zhc_runtime_cxx11_smoke() {
    zhc_probe_format f;
    unsigned char bytes[108] = {0};
    float sh[27], rgb[3], iz[3] = {1, 1, 1}, ca[3], cx[3], cy[3];
    const float n[3] = {0, 0, 1};
    const double nd[3] = {0, 0, 1};
    double d[3], frame[9];
    zhc_zhp_info info;
    zhc_hlsh_tables t;
    int r = zhc_probe_format_init(&f, "zh3_q16");
    r |= zhc_decode_probe(&f, bytes, sh);
    r |= zhc_probe_format_set_gltf(&f, "dcFormat", "rgb9e5");
    zhc_probe_irradiance(&f, bytes, n, rgb);
    zhc_sh3_irradiance(sh, nd, rgb);
    r |= zhc_probe_format_from_zhp(&f, bytes, sizeof bytes) == ZHC_OK;
    r |= zhc_zhp_open(&f, &info, bytes, sizeof bytes) == ZHC_OK;
    zhc_decode_hemioct(0.5f, 0.5f, d);
    zhc_irradz_irradiance_texel(iz, 0.5f, 0.5f, 0.5f, ZHC_IRRADZ_HHD, nd, rgb);
    zhc_hlsh_evaluate(iz, iz, iz, iz, nd, rgb);
    zhc_frame_from_z(nd, frame);
    zhc_hlsh_tables_init(&t, 0.0);
    zhc_hlsh_multiply(&t, sh, frame, iz, ca, cx, cy);
    r |= zhc_crc32(0, bytes, 9) != 0;
    {
        zhc_volume v;
        const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1}, pd[3] = {0.5, 0, 0};
        const uint32_t counts[3] = {1, 1, 1};
        double e[3], blended[27];
        zhc_probe_format sh3;
        r |= zhc_probe_format_init(&sh3, "sh3");
        r |= zhc_volume_init(&v, &sh3, bytes, sizeof bytes, origin, spacing, counts);
        r |= zhc_volume_from_zhp(&v, bytes, sizeof bytes) == ZHC_OK;
        zhc_volume_irradiance(&v, n, n, rgb);
        zhc_volume_irradiance_d(&v, pd, nd, e);
        zhc_volume_sh3(&v, pd, blended);
    }
    r |= static_cast<int>(zhc_probe_size(&f)) + zhc_encoding_is_packed(f.encoding);
    return r + static_cast<int>(zhc_hallucinate_zonal(2, 1.0, 0.5, f.hallucinate_a, f.hallucinate_b));
}
