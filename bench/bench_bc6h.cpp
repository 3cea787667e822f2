// bench_bc6h: BC6H quality (log2-PSNR) and speed (Mpixel/s on one thread) on the eight real maps
// (as HDR images) and on IrradZ lightmaps baked from them, for the mode-11-only baseline, fast,
// default and exhaustive; BC4/BC5 (w_a, d planes) beside stb_dxt's stb_compress_bc4/bc5_block.
// Plain timing main; ratios are against baselines measured in the same run. Time is the calling
// thread's CPU time (CLOCK_THREAD_CPUTIME_ID; every encode runs on that one thread): Mpixel/s per
// thread, not depressed by other processes taking the CPU away (the 2 shared cores are often
// loaded); cache and SMT contention still show.
//   bench_bc6h [--maps DIR] [--lightmap-size N] [--sample-stride K] [--only QUALITY] [--isa baseline|avx2]
// The maps' speed (and dB) is measured on the whole maps; the dB differences to exhaustive (too slow
// for whole maps) on every K-th band of 4 rows (default 8), spread over the whole map.
// --isa picks the encoder twin (default: the best this CPU runs; both write the same bytes).
// Each summary also prints the encode's user-space instructions per pixel (perf counter, pooled
// over the images), where the kernel allows the counter.
// --only runs the listed qualities (e.g. "mode11,fast"; the others print 0): for profiling
// and quick tuning runs (the ratios and dB differences then need a full run).
#include <algorithm>
#include <cstring>
#define STB_DXT_IMPLEMENTATION
#include <stb_dxt.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "codec/lightmap/bc45.h"
#include "codec/lightmap/bc6h.h"
#include "codec/lightmap/lightmap.h"
#include "formats/envmap/envmap.h"

using namespace zhc;

namespace {

double thread_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
double seconds_since(double t0) { return thread_seconds() - t0; }

// User-space instructions retired by this thread (Linux perf counter): exact and repeatable, unlike
// the times on a shared machine. -1 where the counter is not available (no perf support, or
// perf_event_paranoid forbids it); the bench then prints n/a.
class InstructionCounter {
   public:
    InstructionCounter() {
        perf_event_attr a{};
        a.type = PERF_TYPE_HARDWARE;
        a.size = sizeof a;
        a.config = PERF_COUNT_HW_INSTRUCTIONS;
        a.disabled = 1;
        a.exclude_kernel = 1;
        a.exclude_hv = 1;
        fd_ = static_cast<int>(syscall(SYS_perf_event_open, &a, 0, -1, -1, 0));
    }
    ~InstructionCounter() {
        if (fd_ >= 0) close(fd_);
    }
    void start() {
        if (fd_ < 0) return;
        ioctl(fd_, PERF_EVENT_IOC_RESET, 0);
        ioctl(fd_, PERF_EVENT_IOC_ENABLE, 0);
    }
    double stop() {
        if (fd_ < 0) return -1;
        ioctl(fd_, PERF_EVENT_IOC_DISABLE, 0);
        long long n = 0;
        return read(fd_, &n, sizeof n) == sizeof n ? double(n) : -1;
    }

   private:
    int fd_ = -1;
};

struct Row {
    double psnr = 0, mpix = 0;
    double instructions = -1, pixels = 0;  // of the encode; -1: no counter
};

bc6h::Isa g_isa = bc6h::best_isa();

Row run_bc6h(const std::vector<float>& rgb, int w, int h, bc6h::Quality q) {
    static InstructionCounter counter;
    counter.start();
    const double t0 = thread_seconds();
    const auto blocks = bc6h::encode_image(rgb.data(), w, h, q, 1, g_isa);
    const double s = seconds_since(t0);
    const double instructions = counter.stop();
    const auto dec = bc6h::decode_image(blocks.data(), blocks.size(), w, h);
    Row r;
    r.psnr = lightmap::log2_psnr(rgb.data(), dec.data(), rgb.size());
    r.mpix = double(w) * h / s / 1e6;
    r.instructions = instructions;
    r.pixels = double(w) * h;
    return r;
}

double psnr_unorm(const std::vector<float>& ref, const std::vector<float>& dec) {
    double m = 0;
    for (size_t i = 0; i < ref.size(); ++i) m += std::pow(double(std::clamp(ref[i], 0.0f, 1.0f)) - dec[i], 2);
    m /= double(ref.size());
    return m > 0 ? 10 * std::log10(1 / m) : 999;
}

// stb baseline on the same planes (8-bit input, as stb takes it).
Row run_stb(const std::vector<float>& v, int channels, int w, int h) {
    const int bw = (w + 3) / 4, bh = (h + 3) / 4;
    std::vector<std::uint8_t> blocks(static_cast<size_t>(bw) * bh * 8 * channels);
    const double t0 = thread_seconds();
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            unsigned char src[32];
            for (int i = 0; i < 16; ++i) {
                const int x = std::min(bx * 4 + (i & 3), w - 1), y = std::min(by * 4 + (i >> 2), h - 1);
                for (int c = 0; c < channels; ++c)
                    src[i * channels + c] = static_cast<unsigned char>(
                        std::lround(std::clamp(v[(static_cast<size_t>(y) * w + x) * channels + c], 0.0f, 1.0f) * 255));
            }
            unsigned char* dst = blocks.data() + (static_cast<size_t>(by) * bw + bx) * 8 * channels;
            if (channels == 1) stb_compress_bc4_block(dst, src);
            else stb_compress_bc5_block(dst, src);
        }
    const double s = seconds_since(t0);
    const auto dec = bc45::decode_image(blocks.data(), blocks.size(), channels, w, h);
    return {psnr_unorm(v, dec), double(w) * h / s / 1e6};
}

Row run_ours45(const std::vector<float>& v, int channels, int w, int h, bc45::Quality q) {
    const double t0 = thread_seconds();
    const auto blocks = bc45::encode_image(v.data(), channels, w, h, q, 1);
    const double s = seconds_since(t0);
    const auto dec = bc45::decode_image(blocks.data(), blocks.size(), channels, w, h);
    return {psnr_unorm(v, dec), double(w) * h / s / 1e6};
}

}  // namespace

int main(int argc, char** argv) {
    std::string dir = ZHC_ENVMAP_DIR;
    int lm_size = 256, stride = 8;
    std::string only;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--maps")) dir = argv[i + 1];
        if (!std::strcmp(argv[i], "--lightmap-size")) lm_size = std::atoi(argv[i + 1]);
        if (!std::strcmp(argv[i], "--sample-stride")) stride = std::max(1, std::atoi(argv[i + 1]));
        if (!std::strcmp(argv[i], "--only")) only = argv[i + 1];
        if (!std::strcmp(argv[i], "--isa")) g_isa = std::strcmp(argv[i + 1], "baseline") ? bc6h::Isa::kAvx2 : bc6h::Isa::kBaseline;
    }
    std::vector<std::string> paths;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".exr") paths.push_back(e.path().string());
    std::sort(paths.begin(), paths.end());
    const bc6h::Quality qs[4] = {bc6h::Quality::kMode11, bc6h::Quality::kFast, bc6h::Quality::kDefault,
                                 bc6h::Quality::kExhaustive};
    const char* qn[4] = {"mode11", "fast", "default", "exhaustive"};
    auto wanted = [&](int k) { return only.empty() || only.find(qn[k]) != std::string::npos; };
    if (!bc6h::isa_supported(g_isa)) g_isa = bc6h::Isa::kBaseline;
    std::printf("BC6H log2-PSNR (dB, l(v) = log2(max(v, 2^-14)), peak 30) and Mpixel/s on 1 thread (thread CPU time); encoder: %s\n",
                bc6h::isa_name(g_isa));
    std::printf("Real maps: mode11, fast and default on the whole map; every quality (exhaustive, the slow reference,\n"
                "included) on a sample of every %d-th band of 4 rows spread over the whole map (\"rows/%d\" lines), for\n"
                "the dB differences. Lightmaps (%d x %d): every quality on the whole image.\n", stride, stride, lm_size, lm_size);
    std::printf("%-22s | %-15s | %-15s | %-15s | %-15s\n", "image", qn[0], qn[1], qn[2], qn[3]);
    // sum[set][quality][dB, Mpix/s]; set 0 = whole maps, 1 = sampled map rows, 2 = lightmaps.
    double sum[3][4][2] = {};
    double instr[3][4][2] = {};  // [set][quality][instructions, pixels], pooled over the images
    int count[3] = {0, 0, 0};
    std::vector<std::vector<float>> wa_planes, d_planes;
    auto print_row = [&](const std::string& name, const Row r[4], int set) {
        std::printf("%-22s |", name.c_str());
        for (int k = 0; k < 4; ++k) {
            std::printf(" %6.2f %6.2f |", r[k].psnr, r[k].mpix);
            sum[set][k][0] += r[k].psnr;
            sum[set][k][1] += r[k].mpix;
            if (r[k].instructions >= 0) instr[set][k][0] += r[k].instructions, instr[set][k][1] += r[k].pixels;
        }
        std::printf("\n");
        ++count[set];
        std::fflush(stdout);
    };
    for (int pass = 0; pass < 2; ++pass) {
        for (const auto& path : paths) {
            auto img = read_envmap(path);
            if (!img) {
                std::fprintf(stderr, "%s\n", img.error().message.c_str());
                return 1;
            }
            const std::string name = std::filesystem::path(path).stem().string();
            if (pass == 0) {
                const std::vector<float>& rgb = img->rgb;
                const int w = img->width, h = img->height;
                Row full[4], sampled[4];
                for (int k = 0; k < 3; ++k)
                    if (wanted(k)) full[k] = run_bc6h(rgb, w, h, qs[k]);
                // The sample: block rows 0, stride, 2 stride, ... (whole 4-row bands, so the
                // blocks are the map's own), stacked into one image.
                std::vector<float> band;
                int hs = 0;
                for (int y0 = 0; y0 < h; y0 += 4 * stride) {
                    const int rows = std::min(4, h - y0);
                    band.insert(band.end(), rgb.begin() + static_cast<std::ptrdiff_t>(y0) * w * 3,
                                rgb.begin() + static_cast<std::ptrdiff_t>(y0 + rows) * w * 3);
                    hs += rows;
                }
                for (int k = 0; k < 4; ++k)
                    if (wanted(k)) sampled[k] = run_bc6h(band, w, hs, qs[k]);
                print_row(name, full, 0);
                print_row("  rows/" + std::to_string(stride), sampled, 1);
            } else {
                // A lightmap baked from the map: the sphere lit by its SH3, IrradZ-encoded; the I_z plane.
                const Sh3Radiance world = project_latlong(img->rgb.data(), img->width, img->height,
                                                          static_cast<size_t>(img->width) * 3, 2);
                const auto lm = lightmap::synthesize_sphere(world, lm_size, lm_size, 2);
                const auto planes = lightmap::encode_planes(lm, {}, 2);
                wa_planes.push_back(planes.wa);
                d_planes.push_back(planes.d);
                Row r[4];
                for (int k = 0; k < 4; ++k)
                    if (wanted(k)) r[k] = run_bc6h(planes.iz, lm_size, lm_size, qs[k]);
                print_row("lm:" + name, r, 2);
            }
        }
        for (int set : pass == 0 ? std::vector<int>{0, 1} : std::vector<int>{2}) {
            const char* label = set == 0 ? "MEAN real maps" : set == 1 ? "MEAN map rows sample" : "MEAN lightmaps";
            std::printf("%-22s |", label);
            for (int k = 0; k < 4; ++k) std::printf(" %6.2f %6.2f |", sum[set][k][0] / count[set], sum[set][k][1] / count[set]);
            if (set != 0) {
                std::printf("\n%-22s |", "  dB vs exhaustive");
                for (int k = 0; k < 4; ++k) std::printf(" %+6.2f        |", (sum[set][k][0] - sum[set][3][0]) / count[set]);
            }
            std::printf("\n%-22s |", "  speed / mode11");
            for (int k = 0; k < 4; ++k) std::printf(" %6.3f        |", sum[set][k][1] / sum[set][0][1]);
            std::printf("\n%-22s |", "  instr/pixel (pooled)");
            for (int k = 0; k < 4; ++k) {
                if (instr[set][k][1] > 0) std::printf(" %8.0f      |", instr[set][k][0] / instr[set][k][1]);
                else std::printf(" %8s      |", "n/a");
            }
            std::printf("\n");
        }
    }
    std::printf("\nBC4 (w_a plane) and BC5 (d plane) of the lightmaps: PSNR (dB, unorm) and Mpixel/s on 1 thread (CPU time)\n");
    std::printf("%-22s | %-15s | %-15s | %-15s\n", "plane", "stb", "zhc fast", "zhc default");
    for (int ch = 1; ch <= 2; ++ch) {
        double s[3][2] = {};
        for (size_t i = 0; i < wa_planes.size(); ++i) {
            const auto& v = ch == 1 ? wa_planes[i] : d_planes[i];
            const Row a = run_stb(v, ch, lm_size, lm_size), b = run_ours45(v, ch, lm_size, lm_size, bc45::Quality::kFast),
                      c = run_ours45(v, ch, lm_size, lm_size, bc45::Quality::kDefault);
            const Row rr[3] = {a, b, c};
            for (int k = 0; k < 3; ++k) s[k][0] += rr[k].psnr, s[k][1] += rr[k].mpix;
        }
        const double n = double(wa_planes.size());
        std::printf("%-22s | %6.2f %6.2f | %6.2f %6.2f | %6.2f %6.2f\n", ch == 1 ? "BC4 w_a (mean of 8)" : "BC5 d (mean of 8)",
                    s[0][0] / n, s[0][1] / n, s[1][0] / n, s[1][1] / n, s[2][0] / n, s[2][1] / n);
    }
    return 0;
}
