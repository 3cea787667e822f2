// Shared test helpers: sample maps, direction sets, slow reference implementations, CLI runner.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "codec/sh/sh.h"
#include "formats/envmap/envmap.h"
#include "formats/lightmap/ktx2.h"

namespace zhc::test {

// The eight CC0 sample maps (../shared/data/envmaps, or the copy the setup script fetched).
std::vector<std::string> envmap_paths();
// Loads one; fails the test (ASSERT) if it cannot.
Image load_envmap(const std::string& path);
std::string envmap_name(const std::string& path);

// n directions spread uniformly over the sphere (spherical Fibonacci lattice).
std::vector<Vec3> fibonacci_directions(int n);

// Sample counts of the large statistical comparisons (the runtime decoders against the codec on
// 100,000 probes per encoding): n times ZHC_TEST_SAMPLE_SCALE from the environment (a number in
// (0, 1]; default 1), at least min(n, 1000). scripts/sanitize.sh sets 0.1: the sanitizer pass looks
// for memory errors and undefined behaviour on the same code paths, the Release pass (full
// counts) for the statistics. Thresholds never change.
long sample_count(long n);
// The same scale for the slow brute-force twins (exhaustive scans, dense sampling over many random
// inputs) where the sanitizer pass needs the code paths, not the count: n times
// ZHC_TEST_SAMPLE_SCALE, at least at_least, at most n. Without the variable (the Release pass) it is
// n, so the Release pass asserts exactly what it did before; a test using it says so in a comment.
long scaled_count(long n, long at_least);
// Uniform random unit vector from two uniforms in [0, 1).
Vec3 uniform_direction(double u1, double u2);

// Seeded draws for the randomised tests: u() uniform in [0, 1), dir() a uniform unit vector.
struct Rng {
    std::mt19937 gen;
    explicit Rng(unsigned seed) : gen(seed) {}
    double u() { return std::uniform_real_distribution<double>(0, 1)(gen); }
    // Draws are sequenced in statements: the order of evaluation of function arguments differs
    // between compilers (g++ right to left, clang left to right), and the inputs must not.
    Vec3 dir() {
        const double u1 = u();
        return uniform_direction(u1, u());
    }
};

// The four probes of the golden-bytes tests (test_quantize, test_zh3_hall_solve), given as literal floats
// (not computed with libm) so the golden inputs are bit-identical on every machine; the last one
// is out of range (a negative lobe) to exercise clamping.
std::vector<Sh3Radiance> golden_probes();

// Slow, obviously-correct twin of project_latlong: evaluates all nine basis functions at the
// centres of sub x sub sub-pixels of every pixel, times their exact solid angles.
Sh3Radiance project_latlong_reference(const Image& img, int sub = 1);
// Largest coefficient difference (and largest coefficient) over the 27 numbers of SH3 radiance.
double max_abs_diff(const Sh3Radiance& a, const Sh3Radiance& b);
double max_abs(const Sh3Radiance& a);
// Largest |a_i - b_i| over coefficients and channels, over the largest |L00| of b (the reference).
double sh_distance(const Sh3Radiance& a, const Sh3Radiance& b);
// Irradiance at n by direct integration of the map: (1/pi) sum L max(0, n.w) dw.
Rgb integrate_irradiance(const Image& img, Vec3 n);
// A box downsample that keeps total flux (solid-angle weighted), by integer factors.
Image downsample_latlong(const Image& img, int factor);

// A lat-long image whose pixels are a function of direction.
template <class F>
Image render_latlong(int w, int h, F&& radiance_of_direction) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.resize(static_cast<size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Rgb c = radiance_of_direction(latlong_direction(x, y, w, h));
            float* p = img.row(y) + x * 3;
            p[0] = c.r;
            p[1] = c.g;
            p[2] = c.b;
        }
    return img;
}

struct CommandResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};
// Runs the zhc binary with the given arguments (shell-quoted here), capturing output.
CommandResult run_zhc(const std::vector<std::string>& args);

// A directory for one test's files: $TMPDIR/zhc_tests_<uid>/<name>/<Suite.Test> (the running
// test's name; <name> alone outside a test), created if missing, so tests run in parallel never
// share a folder. It is NOT emptied (it outlives the run: run_zhc's "cli_runs" keeps outputs under
// pid-unique names). Tests that check which files exist use fresh_dir instead.
std::string temp_dir(const std::string& name);
// temp_dir(name), emptied first (for one test's own folder only).
std::string fresh_dir(const std::string& name);
void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes);
std::vector<std::uint8_t> read_bytes(const std::string& path);

// Little-endian 32-bit fields in a byte buffer (container header tests).
std::uint32_t get32(const std::vector<std::uint8_t>& b, std::size_t off);
void put32(std::vector<std::uint8_t>& b, std::size_t off, std::uint32_t v);

// A serialised .zhp with header bytes [offset, offset + values.size()) replaced and the header
// CRC (bytes 180-183) recomputed, so the field checks (not the checksum) are what a reader meets.
std::vector<std::uint8_t> zhp_with_header_edit(std::vector<std::uint8_t> bytes, std::size_t offset,
                                               std::initializer_list<std::uint8_t> values);

// A block-compressed image of the given vkFormat and size whose block bytes are a fixed pattern
// (i * 37 + 11): for container round trips.
Ktx2Image sample_block_image(std::uint32_t vk_format, int w, int h);

// Decodes `n` corrupted copies of `good` (1 to 4 random bytes overwritten, every 7th also cut
// short; seeded, so the same copies every run) with `decode`. Every accepted image must hold
// exactly its blocks, every refusal a one-line message. Returns how many were accepted.
int decode_corrupted_copies(const std::vector<std::uint8_t>& good, unsigned seed, int n,
                            const std::function<Result<Ktx2Image>(std::span<const std::uint8_t>)>& decode);

}  // namespace zhc::test
