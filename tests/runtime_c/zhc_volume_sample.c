/* zhc_volume_sample FILE.zhp POINTS.txt [--plain]: builds a probe volume from a grid .zhp, or a
 * points .zhp with tetrahedra, with runtime/zhc_runtime.h alone (zhc_volume_from_zhp) and prints, for every line
 * "px py pz nx ny nz" of POINTS.txt (floats), the irradiance zhc_volume_irradiance gives at that
 * position and normal: "%.9g %.9g %.9g" (enough digits to read back the same float). --plain drops
 * the file's validity and visibility masks and cell planes (plain trilinear blending: what a sampler
 * that cannot read them, such as three.js's LightProbeGrid texture, computes).
 * Exit codes: 0 ok, 1 usage/IO, 2 + zhc_error when the file is not a volume. Built as strict C99
 * (tests/runtime_c); tests/test_runtime_c_volume.cpp runs it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "zhc_runtime.h"

static unsigned char* read_all(const char* path, size_t* size) {
    FILE* in = fopen(path, "rb");
    unsigned char* data;
    long n;
    if (!in) return NULL;
    if (fseek(in, 0, SEEK_END) != 0 || (n = ftell(in)) < 0 || fseek(in, 0, SEEK_SET) != 0) {
        fclose(in);
        return NULL;
    }
    data = (unsigned char*)malloc(n > 0 ? (size_t)n : 1);
    if (!data || fread(data, 1, (size_t)n, in) != (size_t)n) {
        fclose(in);
        free(data);
        return NULL;
    }
    fclose(in);
    *size = (size_t)n;
    return data;
}

int main(int argc, char** argv) {
    unsigned char* data;
    size_t size = 0;
    zhc_volume volume;
    FILE* points;
    float p[3], n[3], rgb[3];
    int r;
    if (argc != 3 && !(argc == 4 && strcmp(argv[3], "--plain") == 0)) {
        fprintf(stderr, "usage: %s FILE.zhp POINTS.txt [--plain]\n", argv[0]);
        return 1;
    }
    data = read_all(argv[1], &size);
    if (!data) {
        fprintf(stderr, "%s: cannot read\n", argv[1]);
        return 1;
    }
    r = zhc_volume_from_zhp(&volume, data, size);
    if (r != ZHC_OK) {
        fprintf(stderr, "%s: not a probe volume (error %d)\n", argv[1], r);
        free(data);
        return 2 + r;
    }
    if (argc == 4) volume.validity = volume.visibility = volume.planes = NULL;
    points = fopen(argv[2], "r");
    if (!points) {
        fprintf(stderr, "%s: cannot open\n", argv[2]);
        free(data);
        return 1;
    }
    while (fscanf(points, "%f %f %f %f %f %f", &p[0], &p[1], &p[2], &n[0], &n[1], &n[2]) == 6) {
        zhc_volume_irradiance(&volume, p, n, rgb);
        printf("%.9g %.9g %.9g\n", rgb[0], rgb[1], rgb[2]);
    }
    r = ferror(points) || !feof(points);
    fclose(points);
    free(data);
    if (r) fprintf(stderr, "%s: unreadable line\n", argv[2]);
    return r ? 1 : 0;
}
