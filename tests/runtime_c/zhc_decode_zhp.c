/* zhc_decode_zhp FILE.zhp [--irradiance nx ny nz]: decodes every probe of an uncompressed .zhp with
 * runtime/zhc_runtime.h alone and prints one line per probe: its 27 SH3 radiance floats
 * (coefficient-major, index i*3+k) with %.9g (enough digits to read back the same float).
 * With --irradiance it prints the three irradiance floats at that normal instead.
 * Exit codes: 0 ok, 1 usage/IO, 2 + zhc_error otherwise. Built as strict C99 (tests/runtime_c). */
#include <stdio.h>
#include <stdlib.h>

#include "zhc_runtime.h"

int main(int argc, char** argv) {
    FILE* in;
    unsigned char* data;
    long size;
    zhc_probe_format format;
    zhc_zhp_info info;
    uint64_t i;
    int r, k, irradiance = 0;
    float n[3] = {0.0f, 0.0f, 1.0f};
    if (argc != 2 && argc != 6) {
        fprintf(stderr, "usage: %s FILE.zhp [--irradiance nx ny nz]\n", argv[0]);
        return 1;
    }
    if (argc == 6) {
        irradiance = 1;
        for (k = 0; k < 3; ++k) n[k] = (float)atof(argv[3 + k]);
    }
    in = fopen(argv[1], "rb");
    if (!in) {
        fprintf(stderr, "%s: cannot open\n", argv[1]);
        return 1;
    }
    if (fseek(in, 0, SEEK_END) != 0 || (size = ftell(in)) < 0 || fseek(in, 0, SEEK_SET) != 0) {
        fclose(in);
        return 1;
    }
    data = (unsigned char*)malloc(size > 0 ? (size_t)size : 1);
    if (!data || fread(data, 1, (size_t)size, in) != (size_t)size) {
        fclose(in);
        free(data);
        return 1;
    }
    fclose(in);
    r = zhc_zhp_open(&format, &info, data, (size_t)size);
    if (r != ZHC_OK) {
        fprintf(stderr, "%s: not a readable uncompressed .zhp (error %d)\n", argv[1], r);
        free(data);
        return 2 + r;
    }
    for (i = 0; i < info.probe_count; ++i) {
        const unsigned char* probe = data + info.payload_offset + i * info.probe_size;
        if (irradiance) {
            float rgb[3];
            zhc_probe_irradiance(&format, probe, n, rgb);
            printf("%.9g %.9g %.9g\n", rgb[0], rgb[1], rgb[2]);
        } else {
            float sh[27];
            r = zhc_decode_probe(&format, probe, sh);
            if (r != ZHC_OK) {
                free(data);
                return 2 + r;
            }
            for (k = 0; k < 27; ++k) printf(k ? " %.9g" : "%.9g", sh[k]);
            printf("\n");
        }
    }
    free(data);
    return 0;
}
