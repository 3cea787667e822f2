#include "support.h"

#include <gtest/gtest.h>

#include "formats/probes/probe_file.h"

#include <cmath>

#include <algorithm>

#include <cstdlib>

#include <random>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace zhc::test {

namespace fs = std::filesystem;

std::vector<std::string> envmap_paths() {
    std::vector<std::string> out;
    for (const char* name : {"city", "courtyard", "forest", "interior", "night", "studio", "sunrise", "sunset"})
        out.push_back(std::string(ZHC_ENVMAP_DIR) + "/" + name + ".exr");
    return out;
}

Image load_envmap(const std::string& path) {
    auto img = read_envmap(path);
    if (!img) {
        ADD_FAILURE() << "cannot load sample map (run the README's test command, which fetches them): "
                      << img.error().message;
        return {};
    }
    return std::move(img).value();
}

std::string envmap_name(const std::string& path) { return fs::path(path).stem().string(); }

long scaled_count(long n, long at_least) {
    static const double scale = [] {
        const char* v = std::getenv("ZHC_TEST_SAMPLE_SCALE");
        const double s = v ? std::strtod(v, nullptr) : 1.0;
        return (s > 0.0 && s <= 1.0) ? s : 1.0;
    }();
    return std::min(n, std::max(at_least, static_cast<long>(std::llround(double(n) * scale))));
}

long sample_count(long n) { return scaled_count(n, std::min(n, 1000L)); }

std::vector<Vec3> fibonacci_directions(int n) {
    std::vector<Vec3> out;
    out.reserve(static_cast<size_t>(n));
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        out.push_back({r * std::cos(golden * i), r * std::sin(golden * i), z});
    }
    return out;
}

Vec3 uniform_direction(double u1, double u2) {
    const double z = 1.0 - 2.0 * u1, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

double max_abs_diff(const Sh3Radiance& a, const Sh3Radiance& b) {
    double m = 0;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) m = std::max(m, std::fabs(double(a[i][k]) - b[i][k]));
    return m;
}
double sh_distance(const Sh3Radiance& a, const Sh3Radiance& b) {
    double dc = 0, worst = 0;
    for (int k = 0; k < 3; ++k) dc = std::max(dc, std::fabs(double(b[0][k])));
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::fabs(double(a[i][k]) - b[i][k]));
    return worst / std::max(dc, 1e-30);
}

double max_abs(const Sh3Radiance& a) { return max_abs_diff(a, Sh3Radiance{}); }

Sh3Radiance project_latlong_reference(const Image& img, int sub) {
    // Each pixel split into sub x sub sub-pixels, each contributing value * Y(centre) * its exact
    // solid angle (a lat-long map of sub-times the resolution, nearest-sampled).
    double acc[9][3] = {};
    const int sw = img.width * sub, sh = img.height * sub;
    for (int y = 0; y < sh; ++y) {
        const double w = latlong_pixel_solid_angle(y, sw, sh);
        for (int x = 0; x < sw; ++x) {
            const auto basis = sh3_basis(latlong_direction(x, y, sw, sh));
            const float* p = img.row(y / sub) + (x / sub) * 3;
            for (int i = 0; i < 9; ++i)
                for (int k = 0; k < 3; ++k) acc[i][k] += w * p[k] * basis[static_cast<size_t>(i)];
        }
    }
    Sh3Radiance out;
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 3; ++k) out[i][k] = static_cast<float>(acc[i][k]);
    return out;
}

Rgb integrate_irradiance(const Image& img, Vec3 n) {
    double acc[3] = {};
    for (int y = 0; y < img.height; ++y) {
        const double w = latlong_pixel_solid_angle(y, img.width, img.height);
        for (int x = 0; x < img.width; ++x) {
            const double c = dot(n, latlong_direction(x, y, img.width, img.height));
            if (c <= 0) continue;
            const float* p = img.row(y) + x * 3;
            for (int k = 0; k < 3; ++k) acc[k] += w * c * p[k];
        }
    }
    return {static_cast<float>(acc[0] / kPi), static_cast<float>(acc[1] / kPi), static_cast<float>(acc[2] / kPi)};
}

Image downsample_latlong(const Image& img, int f) {
    Image out;
    out.width = img.width / f;
    out.height = img.height / f;
    out.rgb.assign(static_cast<size_t>(out.width) * out.height * 3, 0.0f);
    for (int y = 0; y < out.height; ++y) {
        const double big = latlong_pixel_solid_angle(y, out.width, out.height);
        for (int x = 0; x < out.width; ++x) {
            double acc[3] = {};
            for (int sy = 0; sy < f; ++sy) {
                const double w = latlong_pixel_solid_angle(y * f + sy, img.width, img.height);
                for (int sx = 0; sx < f; ++sx) {
                    const float* p = img.row(y * f + sy) + (x * f + sx) * 3;
                    for (int k = 0; k < 3; ++k) acc[k] += w * p[k];
                }
            }
            for (int k = 0; k < 3; ++k) out.row(y)[x * 3 + k] = static_cast<float>(acc[k] / big);
        }
    }
    return out;
}

namespace {
std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}
std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}
}  // namespace

CommandResult run_zhc(const std::vector<std::string>& args) {
    static int counter = 0;
    const std::string dir = temp_dir("cli_runs");
    const std::string base = dir + "/run" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
    std::string cmd = quote(ZHC_CLI_PATH);
    for (const auto& a : args) {
        cmd += ' ';  // (not " " + quote(a): g++ 12 warns a false -Wrestrict on that temporary)
        cmd += quote(a);
    }
    cmd += " > " + quote(base + ".out") + " 2> " + quote(base + ".err") + " < /dev/null";
    const int status = std::system(cmd.c_str());
    CommandResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(base + ".out");
    r.err = slurp(base + ".err");
    return r;
}

std::string temp_dir(const std::string& name) {
    // One folder per test: ctest runs tests in parallel processes, and two tests writing the same
    // file names into one shared folder would race (a test sees the other's half-written file).
    fs::path p = fs::temp_directory_path() / ("zhc_tests_" + std::to_string(::getuid())) / name;
    if (const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info())
        p /= std::string(t->test_suite_name()) + "." + t->name();
    std::error_code ec;
    fs::create_directories(p, ec);
    return p.string();
}

std::string fresh_dir(const std::string& name) {
    const std::string dir = temp_dir(name);
    std::error_code ec;
    fs::remove_all(dir, ec);
    fs::create_directories(dir, ec);
    return dir;
}

std::uint32_t get32(const std::vector<std::uint8_t>& b, std::size_t off) {
    return std::uint32_t(b[off]) | std::uint32_t(b[off + 1]) << 8 | std::uint32_t(b[off + 2]) << 16 | std::uint32_t(b[off + 3]) << 24;
}
void put32(std::vector<std::uint8_t>& b, std::size_t off, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b[off + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(v >> (8 * k));
}

std::vector<std::uint8_t> zhp_with_header_edit(std::vector<std::uint8_t> bytes, std::size_t offset,
                                               std::initializer_list<std::uint8_t> values) {
    std::size_t i = offset;
    for (std::uint8_t v : values) bytes[i++] = v;
    put32(bytes, 180, crc32({bytes.data(), 180}));
    return bytes;
}

Ktx2Image sample_block_image(std::uint32_t vk_format, int w, int h) {
    Ktx2Image img;
    img.vk_format = vk_format;
    img.width = w;
    img.height = h;
    img.blocks.resize(static_cast<size_t>((w + 3) / 4) * static_cast<size_t>((h + 3) / 4) * ktx2_block_bytes(vk_format));
    for (size_t i = 0; i < img.blocks.size(); ++i) img.blocks[i] = static_cast<std::uint8_t>(i * 37 + 11);
    return img;
}

int decode_corrupted_copies(const std::vector<std::uint8_t>& good, unsigned seed, int n,
                            const std::function<Result<Ktx2Image>(std::span<const std::uint8_t>)>& decode) {
    std::mt19937 rng(seed);
    int accepted = 0;
    for (int t = 0; t < n; ++t) {
        auto b = good;
        const int flips = 1 + t % 4;
        for (int k = 0; k < flips; ++k) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
        if (t % 7 == 0) b.resize(rng() % b.size());
        auto r = decode(b);
        if (r.ok()) {
            ++accepted;
            EXPECT_EQ(r->blocks.size(), static_cast<size_t>((r->width + 3) / 4) * static_cast<size_t>((r->height + 3) / 4) *
                                            ktx2_block_bytes(r->vk_format));
        } else {
            EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << r.error().message;
        }
    }
    return accepted;
}

void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::uint8_t> read_bytes(const std::string& path) {
    const std::string s = slurp(path);
    return {s.begin(), s.end()};
}

std::vector<Sh3Radiance> golden_probes() {
    const float p[4][9][3] = {
        {{3.5f, 3.25f, 2.75f}, {0.5f, 0.375f, 0.25f}, {1.25f, 1.0f, 0.75f}, {-0.625f, -0.5f, -0.375f},
         {0.125f, 0.1f, 0.05f}, {-0.25f, -0.2f, -0.15f}, {0.75f, 0.6f, 0.45f}, {0.3f, 0.2f, 0.1f},
         {-0.0625f, -0.05f, -0.04f}},
        {{1.0f, 2.0f, 4.0f}, {0.1f, 0.2f, 0.4f}, {-0.3f, -0.6f, -1.2f}, {0.2f, 0.4f, 0.8f},
         {0.05f, 0.1f, 0.2f}, {0.02f, 0.04f, 0.08f}, {-0.4f, -0.8f, -1.6f}, {0.01f, 0.02f, 0.04f},
         {0.3f, 0.6f, 1.2f}},
        {{0.01f, 0.02f, 0.005f}, {0.005f, 0.0f, -0.002f}, {0.0f, 0.01f, 0.0f}, {-0.001f, 0.002f, 0.0f},
         {0.0f, 0.0f, 0.0f}, {0.001f, -0.002f, 0.0005f}, {0.004f, 0.008f, 0.002f}, {0.0f, 0.0f, 0.0f},
         {-0.002f, 0.001f, 0.0f}},
        // Out of range (a negative lobe): exercises clamping.
        {{1.0f, 1.0f, 1.0f}, {3.0f, 0.0f, -3.0f}, {0.0f, 2.0f, 0.0f}, {0.0f, 0.0f, 1.0f},
         {2.5f, -2.5f, 0.0f}, {0.0f, 0.0f, 0.0f}, {-1.5f, 2.5f, 0.0f}, {0.0f, 0.0f, 0.0f},
         {0.0f, 0.0f, 0.0f}},
    };
    std::vector<Sh3Radiance> out(4);
    for (int n = 0; n < 4; ++n)
        for (int i = 0; i < 9; ++i)
            for (int k = 0; k < 3; ++k) out[static_cast<size_t>(n)][i][k] = p[n][i][k];
    return out;
}

}  // namespace zhc::test
