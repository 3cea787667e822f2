// bench_lightmap: the lightmap encode pipeline stage by stage (read the SH lightmap EXR, IrradZ fit,
// BC6H, BC5, BC4, write the KTX2 files) in Mtexel/s and peak memory, for synthetic lightmaps of
// several sizes, beside a baseline measured in the same run: a plain OpenEXR read of the same file
// (Imf::InputFile into one float frame buffer, no checks, no conversion). Also the IrradZ fit's
// Newton solve against the golden-section reference (Solve::kSearch, the talk's method) on the
// same texels, one after the other in this process: the ratio survives a noisy machine.
//   bench_lightmap [--sizes 1024,2048,4096] [--map FILE.exr] [--quality fast|default|slow]
//                  [--ref-texels N] [--reps R] [--json FILE] [--keep DIR]
// End to end: the CPU time of stages read .. write summed (the pipeline on one thread).
// Every stage runs on one thread. Times: wall and this thread's CPU time (Mtexel/s from the CPU
// time, which other processes on the shared cores do not inflate; the wall time is printed too).
// Peak memory: VmHWM of /proc/self/status after each stage, the high-water mark reset before the
// stage by writing 5 to /proc/self/clear_refs (Linux >= 4.0), so each stage's peak includes what the
// earlier stages still hold (the planes, the blocks) but not their transients; each size runs in a
// forked child so sizes do not see each other's memory. Where the reset is refused the column is the
// process's running peak (marked "cumulative").
// The synthetic lightmap: `lightmap::synthesize_sphere` of the map at 512 x 512 (as `zhc lightmap
// synth` makes it), repeated to fill the size (per-texel cost does not depend on the content's
// period; synthesising 4096^2 directly would take a minute), written as an SH lightmap EXR to a
// temporary directory. The reference fit is timed on --ref-texels texels (default 65536, rows
// spread over the image) with the Newton solve timed on the same texels.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "codec/lightmap/lightmap.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "timing.h"

using namespace zhc;
namespace fs = std::filesystem;

namespace {

double thread_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}
double wall_seconds() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// VmHWM (peak resident set) in MB, -1 where /proc does not tell.
double peak_mb() {
    const double b = bench::proc_status_bytes("VmHWM:");
    return b < 0 ? -1 : b / (1024.0 * 1024.0);
}

constexpr int kStages = 9;
const char* const kStageNames[kStages] = {"baseline: plain OpenEXR read", "read (zhc, checked)", "fit (newton)",
                                          "BC6H I_z",                     "BC5 d",               "BC4 w_a",
                                          "write KTX2 x3",                "fit sample: reference", "fit sample: newton"};

struct StageResult {
    double cpu_s = 0, wall_s = 0, texels = 0, peak = -1;
};
struct SizeResult {
    int size = 0;
    bool peak_reset = true;
    StageResult stage[kStages];
};

// A plain OpenEXR read: every channel of the file into one interleaved float buffer.
double plain_exr_read(const std::string& path) {
    Imf::InputFile file(path.c_str(), 0);
    const Imath::Box2i dw = file.header().dataWindow();
    const size_t w = static_cast<size_t>(dw.max.x - dw.min.x + 1), h = static_cast<size_t>(dw.max.y - dw.min.y + 1);
    std::vector<std::string> names;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) names.push_back(it.name());
    const size_t nc = names.size();
    std::vector<float> buf(w * h * nc);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(buf.data()) - (size_t(dw.min.x) + size_t(dw.min.y) * w) * nc * sizeof(float);
    for (size_t c = 0; c < nc; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), nc * sizeof(float), w * nc * sizeof(float)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    double s = 0;
    for (size_t i = 0; i < buf.size(); i += 4099) s += buf[i];
    return s;
}

template <class F>
StageResult run_stage(bool* reset_ok, double texels, int reps, F&& fn) {
    StageResult r;
    r.texels = texels;
    std::vector<double> cpu, wall;
    *reset_ok = bench::reset_peak() && *reset_ok;
    for (int i = 0; i < reps; ++i) {
        const double w0 = wall_seconds(), c0 = thread_seconds();
        fn();
        cpu.push_back(thread_seconds() - c0);
        wall.push_back(wall_seconds() - w0);
    }
    r.peak = peak_mb();
    std::sort(cpu.begin(), cpu.end());
    std::sort(wall.begin(), wall.end());
    r.cpu_s = cpu[cpu.size() / 2];
    r.wall_s = wall[wall.size() / 2];
    return r;
}

SizeResult run_size(const Sh3Radiance& world, int size, const std::string& dir, bc6h::Quality q6, bc45::Quality q45,
                    int ref_texels, int reps) {
    SizeResult res;
    res.size = size;
    // The synthetic lightmap (not timed).
    const int tile = std::min(size, 512);
    const lightmap::ShLightmap small = lightmap::synthesize_sphere(world, tile, tile, 2);
    const std::string exr = dir + "/lm" + std::to_string(size) + ".exr";
    {
        lightmap::ShLightmap big;
        big.width = big.height = size;
        big.texels.resize(static_cast<size_t>(size) * static_cast<size_t>(size));
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                big.texels[static_cast<size_t>(y) * size + x] = small.texels[static_cast<size_t>(y % tile) * tile + (x % tile)];
        if (Status s = write_sh_lightmap_exr(exr, big); !s) {
            std::fprintf(stderr, "%s\n", s.error().message.c_str());
            std::exit(1);
        }
    }
    const double n = double(size) * size;
    bool& ok = res.peak_reset;
    res.stage[0] = run_stage(&ok, n, reps, [&] { bench::keep(plain_exr_read(exr)); });
    LightmapReadOptions ro;
    ro.max_texels = std::uint64_t(1) << 30;
    ro.max_file_bytes = std::uint64_t(64) << 30;
    lightmap::ShLightmap lm;
    res.stage[1] = run_stage(&ok, n, reps, [&] {
        auto r = read_sh_lightmap_exr(exr, ro);
        if (!r) {
            std::fprintf(stderr, "%s\n", r.error().message.c_str());
            std::exit(1);
        }
        lm = std::move(*r);
    });
    lightmap::IrradzPlanes planes;
    res.stage[2] = run_stage(&ok, n, 1, [&] { planes = lightmap::encode_planes(lm, {}, 1); });
    lightmap::Compressed c;
    c.width = c.height = size;
    res.stage[3] = run_stage(&ok, n, reps, [&] { c.bc6h = bc6h::encode_image(planes.iz.data(), size, size, q6, 1); });
    res.stage[4] = run_stage(&ok, n, reps, [&] { c.bc5 = bc45::encode_image(planes.d.data(), 2, size, size, q45, 1); });
    res.stage[5] = run_stage(&ok, n, reps, [&] { c.bc4 = bc45::encode_image(planes.wa.data(), 1, size, size, q45, 1); });
    res.stage[6] = run_stage(&ok, n, reps, [&] {
        const std::pair<const char*, std::uint32_t> files[3] = {
            {".iz.ktx2", kVkFormatBc6hUfloat}, {".d.ktx2", kVkFormatBc5Unorm}, {".wa.ktx2", kVkFormatBc4Unorm}};
        const std::vector<std::uint8_t>* blocks[3] = {&c.bc6h, &c.bc5, &c.bc4};
        std::vector<std::pair<std::string, std::vector<std::uint8_t>>> out;
        for (int i = 0; i < 3; ++i) {
            Ktx2Image k;
            k.vk_format = files[i].second;
            k.width = k.height = size;
            k.blocks = *blocks[i];
            auto bytes = encode_ktx2(k);
            if (!bytes) std::exit(1);
            out.emplace_back(dir + "/lm" + std::to_string(size) + files[i].first, std::move(*bytes));
        }
        if (!write_files_atomic(out)) std::exit(1);
    });
    // Reference vs Newton on the same texels: rows spread over the image.
    std::vector<const Sh3Radiance*> sample;
    const int rows = std::clamp(ref_texels / size, 1, size);
    for (int r = 0; r < rows; ++r) {
        const int y = static_cast<int>((static_cast<long long>(r) * size) / rows);
        for (int x = 0; x < size; ++x) sample.push_back(&lm.texels[static_cast<size_t>(y) * size + x]);
    }
    irradz::EncodeOptions ref, nwt;
    ref.solve = irradz::Solve::kSearch;
    double sum = 0;
    res.stage[7] = run_stage(&ok, double(sample.size()), 1, [&] {
        for (const Sh3Radiance* t : sample) sum += irradz::encode(*t, ref).w_a;
    });
    res.stage[8] = run_stage(&ok, double(sample.size()), 1, [&] {
        for (const Sh3Radiance* t : sample) sum += irradz::encode(*t, nwt).w_a;
    });
    bench::keep(sum);
    return res;
}

// The pipeline's time per texel: read, fit, BC6H, BC5, BC4 and write one after the other on one
// thread (CPU or wall seconds for the whole image), what `zhc lightmap encode --threads 1` spends.
double end_to_end(const SizeResult& r, bool wall) {
    double s = 0;
    for (int i = 1; i <= 6; ++i) s += wall ? r.stage[i].wall_s : r.stage[i].cpu_s;
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<int> sizes = {1024, 2048};
    std::string map = std::string(ZHC_ENVMAP_DIR) + "/courtyard.exr", json, keep, quality = "fast";
    int ref_texels = 65536, reps = 1;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has = i + 1 < argc;
        if (a == "--sizes" && has) {
            sizes.clear();
            std::string s = argv[++i];
            for (size_t p = 0; p < s.size();) {
                const size_t e = s.find(',', p);
                const int v = std::atoi(s.substr(p, e == std::string::npos ? std::string::npos : e - p).c_str());
                if (v >= 4 && v <= 16384) sizes.push_back(v);
                p = e == std::string::npos ? s.size() : e + 1;
            }
        } else if (a == "--map" && has) map = argv[++i];
        else if (a == "--quality" && has) quality = argv[++i];
        else if (a == "--ref-texels" && has) ref_texels = std::max(1, std::atoi(argv[++i]));
        else if (a == "--reps" && has) reps = std::max(1, std::atoi(argv[++i]));
        else if (a == "--json" && has) json = argv[++i];
        else if (a == "--keep" && has) keep = argv[++i];
        else {
            std::fprintf(stderr,
                         "usage: %s [--sizes 1024,2048,4096] [--map FILE.exr] [--quality fast|default|slow] [--ref-texels N] "
                         "[--reps R] [--json FILE] [--keep DIR]\n",
                         argv[0]);
            return 2;
        }
    }
    if (sizes.empty()) {
        std::fprintf(stderr, "--sizes: no size in [4, 16384]\n");
        return 2;
    }
    const lightmap::QualityPreset* preset = lightmap::find_quality_preset(quality);
    if (!preset) {
        std::fprintf(stderr, "--quality: unknown preset '%s' (the names of zhc lightmap encode --quality)\n", quality.c_str());
        return 2;
    }
    const bc6h::Quality q6 = preset->bc6h;
    const bc45::Quality q45 = preset->bc45;
    auto img = read_envmap(map);
    if (!img) {
        std::fprintf(stderr, "%s\n", img.error().message.c_str());
        return 1;
    }
    const Sh3Radiance world = project_latlong(img->rgb.data(), img->width, img->height, static_cast<size_t>(img->width) * 3, 2);
    const fs::path dir = keep.empty() ? fs::temp_directory_path() / ("zhc_bench_lightmap_" + std::to_string(::getpid())) : fs::path(keep);
    fs::create_directories(dir);

    std::printf("bench_lightmap: %s, BC quality %s, one thread per stage; Mtexel/s from thread CPU time (wall in brackets);\n"
                "peak = VmHWM during the stage (reset before it); reference fit = golden-section search (Solve::kSearch)\n",
                fs::path(map).filename().c_str(), quality.c_str());
    std::vector<SizeResult> results;
    for (const int size : sizes) {
        // Each size in a child process: its own peak memory, nothing left over from other sizes.
        int fd[2];
        if (pipe(fd) != 0) return 1;
        const pid_t pid = fork();
        if (pid == 0) {
            close(fd[0]);
            const SizeResult r = run_size(world, size, dir.string(), q6, q45, ref_texels, reps);
            const ssize_t wrote = write(fd[1], &r, sizeof r);
            _exit(wrote == static_cast<ssize_t>(sizeof r) ? 0 : 1);
        }
        close(fd[1]);
        SizeResult r;
        size_t got = 0;
        while (got < sizeof r) {
            const ssize_t k = read(fd[0], reinterpret_cast<char*>(&r) + got, sizeof r - got);
            if (k <= 0) break;
            got += static_cast<size_t>(k);
        }
        close(fd[0]);
        int status = 0;
        waitpid(pid, &status, 0);
        if (got != sizeof r || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            std::fprintf(stderr, "size %d: the child run failed\n", size);
            return 1;
        }
        results.push_back(r);
        std::printf("\n%d x %d (%.1f Mtexel)%s\n", size, size, double(size) * size / 1e6, r.peak_reset ? "" : "  [peak: cumulative]");
        std::printf("  %-30s %12s %16s %10s %12s\n", "stage", "Mtexel/s", "(wall Mtexel/s)", "peak MB", "vs baseline");
        const double base = r.stage[0].texels / r.stage[0].cpu_s / 1e6;
        for (int s = 0; s < kStages; ++s) {
            const StageResult& st = r.stage[s];
            const double m = st.texels / st.cpu_s / 1e6;
            std::printf("  %-30s %12.3f %16.3f %10.0f %12.3f\n", kStageNames[s], m, st.texels / st.wall_s / 1e6, st.peak, m / base);
        }
        std::printf("  %-30s %12.3f %16.3f\n", "end to end (stages 2-7)", r.stage[1].texels / end_to_end(r, false) / 1e6,
                    r.stage[1].texels / end_to_end(r, true) / 1e6);
        std::printf("  fit: newton / reference speed on the same %.0f texels: %.2fx (%.3f vs %.3f us/texel)\n", r.stage[7].texels,
                    r.stage[7].cpu_s / r.stage[8].cpu_s, r.stage[8].cpu_s / r.stage[8].texels * 1e6,
                    r.stage[7].cpu_s / r.stage[7].texels * 1e6);
        std::fflush(stdout);
    }
    if (!json.empty()) {
        std::ofstream out(json);
        out << "{\n  \"benchmark\": \"lightmap\",\n  \"map\": \"" << fs::path(map).filename().string() << "\",\n  \"quality\": \""
            << quality << "\",\n  \"sizes\": [\n";
        for (size_t i = 0; i < results.size(); ++i) {
            const SizeResult& r = results[i];
            out << "    {\"size\": " << r.size << ", \"peak_is_per_stage\": " << (r.peak_reset ? "true" : "false")
                << ", \"fit_speedup_newton_vs_reference\": " << r.stage[7].cpu_s / r.stage[8].cpu_s
                << ", \"end_to_end_cpu_s\": " << end_to_end(r, false)
                << ", \"end_to_end_mtexel_per_s\": " << r.stage[1].texels / end_to_end(r, false) / 1e6 << ", \"stages\": [\n";
            for (int s = 0; s < kStages; ++s) {
                const StageResult& st = r.stage[s];
                char buf[400];
                std::snprintf(buf, sizeof buf,
                              "      {\"stage\": \"%s\", \"texels\": %.0f, \"cpu_s\": %.6f, \"wall_s\": %.6f, \"mtexel_per_s\": %.4f, "
                              "\"peak_mb\": %.1f}%s\n",
                              kStageNames[s], st.texels, st.cpu_s, st.wall_s, st.texels / st.cpu_s / 1e6, st.peak,
                              s + 1 < kStages ? "," : "");
                out << buf;
            }
            out << "    ]}" << (i + 1 < results.size() ? "," : "") << "\n";
        }
        if (!bench::finish_json(out, json)) return 1;
    }
    if (keep.empty()) fs::remove_all(dir);
    return 0;
}
