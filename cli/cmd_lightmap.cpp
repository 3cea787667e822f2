// zhc lightmap {encode, decode, audit, synth}: IrradZ directional lightmaps (docs/irradz.md,
// docs/lightmap-formats.md). Input: an SH lightmap EXR (channels sh0.R .. sh8.B, tangent-frame SH3
// radiance). Output: PREFIX.iz.ktx2 (BC6H_UFLOAT), PREFIX.d.ktx2 (BC5_UNORM), PREFIX.wa.ktx2
// (BC4_UNORM): 2.5 bytes per texel; with --container dds the same blocks in PREFIX.{iz,d,wa}.dds.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "json_output.h"
#include "codec/lightmap.h"
#include "formats/dds.h"
#include "formats/envmap.h"
#include "formats/file_io.h"
#include "formats/ktx2.h"
#include "formats/lightmap_exr.h"
#include "formats/lightmap_report.h"

namespace zhc::cli {
namespace cmd_lightmap {  // one namespace per verb file: the CLI is a unity build
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Options {
    std::string input, output, quality = "default", solve = "newton";
    std::string container;  // encode: "" = ktx2; decode: "" = auto
    std::string part;       // synth: EXR part of the environment map
    std::string html;       // audit: also write the HTML report here
    int threads = 1, size = 256, stride = 17;
    bool json = false;
};

bc6h::Quality bc6h_quality(const std::string& q) {
    return q == "fast" ? bc6h::Quality::kFast : (q == "slow" ? bc6h::Quality::kExhaustive : bc6h::Quality::kDefault);
}
bc45::Quality bc45_quality(const std::string& q) { return q == "fast" ? bc45::Quality::kFast : bc45::Quality::kDefault; }

Ktx2Image ktx(std::uint32_t fmt, const lightmap::Compressed& c, const std::vector<std::uint8_t>& blocks) {
    Ktx2Image k;
    k.vk_format = fmt;
    k.width = c.width;
    k.height = c.height;
    k.blocks = blocks;
    return k;
}

// The SH lightmap, its EXR blocks decompressed on the verb's threads.
Result<lightmap::ShLightmap> read_input(const Options& o) {
    LightmapReadOptions ro;
    ro.threads = o.threads;
    return read_sh_lightmap_exr(o.input, ro);
}

int run_encode(const Options& o) {
    auto lm = read_input(o);
    if (!lm) return report(lm.error());
    irradz::EncodeOptions eo;
    eo.solve = o.solve == "old" ? irradz::Solve::kOld : (o.solve == "search" ? irradz::Solve::kSearch : irradz::Solve::kNewton);
    const auto t0 = Clock::now();
    const auto planes = lightmap::encode_planes(*lm, eo, o.threads);
    const double t_fit = since(t0);
    const auto t1 = Clock::now();
    const auto c = lightmap::compress(planes, bc6h_quality(o.quality), bc45_quality(o.quality), o.threads);
    const double t_bc = since(t1);
    const bool dds = o.container == "dds";
    const std::string ext = dds ? ".dds" : ".ktx2";
    const std::pair<std::string, Ktx2Image> images[3] = {{o.output + ".iz" + ext, ktx(kVkFormatBc6hUfloat, c, c.bc6h)},
                                                         {o.output + ".d" + ext, ktx(kVkFormatBc5Unorm, c, c.bc5)},
                                                         {o.output + ".wa" + ext, ktx(kVkFormatBc4Unorm, c, c.bc4)}};
    // All three files or none: encoded in memory first, then written as one unit.
    std::vector<std::pair<std::string, std::vector<std::uint8_t>>> files;
    for (const auto& [path, img] : images) {
        auto bytes = dds ? encode_dds(img) : encode_ktx2(img);
        if (!bytes) return report_output(make_error(bytes.error().code, path + ": " + bytes.error().message));
        files.emplace_back(path, std::move(*bytes));
    }
    if (auto s = write_files_atomic(files); !s) return report_output(s.error());
    const double texels = double(lm->width) * lm->height;
    std::printf("%s: %dx%d texels -> %s.{iz,d,wa}%s (%zu bytes of blocks, %.3f bytes/texel)\n", o.input.c_str(),
                lm->width, lm->height, o.output.c_str(), ext.c_str(), c.bc6h.size() + c.bc5.size() + c.bc4.size(),
                double(c.bc6h.size() + c.bc5.size() + c.bc4.size()) / texels);
    std::printf("IrradZ fit %.3f s (%.2f Mtexel/s), block compression (%s) %.3f s (%.2f Mtexel/s), %d thread(s)\n", t_fit,
                texels / t_fit / 1e6, o.quality.c_str(), t_bc, texels / t_bc / 1e6, o.threads);
    return kExitOk;
}

int run_decode(const Options& o) {
    // --container auto: KTX2 (the default container) when PREFIX.iz.ktx2 exists, else DDS when
    // PREFIX.iz.dds exists; with both sets present KTX2 wins (--container dds reads the DDS set).
    std::string container = o.container;
    if (container.empty() || container == "auto") {
        std::error_code ec;
        if (std::filesystem::exists(o.input + ".iz.ktx2", ec)) container = "ktx2";
        else if (std::filesystem::exists(o.input + ".iz.dds", ec)) container = "dds";
        else return report(make_error(ErrorCode::kIoError, o.input + ": neither " + o.input + ".iz.ktx2 nor " + o.input + ".iz.dds exists"));
    }
    const bool dds = container == "dds";
    const std::string ext = dds ? ".dds" : ".ktx2";
    lightmap::Compressed c;
    const std::pair<std::string, std::uint32_t> files[3] = {
        {o.input + ".iz" + ext, kVkFormatBc6hUfloat}, {o.input + ".d" + ext, kVkFormatBc5Unorm}, {o.input + ".wa" + ext, kVkFormatBc4Unorm}};
    for (int f = 0; f < 3; ++f) {
        auto img = dds ? read_dds(files[f].first) : read_ktx2(files[f].first);
        if (!img) return report(img.error());
        if (img->vk_format != files[f].second)
            return report(make_error(ErrorCode::kBadFormat,
                                     files[f].first + (dds ? ": dxgiFormat " + std::to_string(dxgi_format_for_vk(img->vk_format)) +
                                                                 ", expected " + std::to_string(dxgi_format_for_vk(files[f].second))
                                                           : ": vkFormat " + std::to_string(img->vk_format) + ", expected " +
                                                                 std::to_string(files[f].second))));
        if (f == 0) {
            c.width = img->width;
            c.height = img->height;
        } else if (img->width != c.width || img->height != c.height) {
            return report(make_error(ErrorCode::kBadFormat, files[f].first + ": size " + std::to_string(img->width) + "x" +
                                                                 std::to_string(img->height) + " differs from " + files[0].first));
        }
        (f == 0 ? c.bc6h : (f == 1 ? c.bc5 : c.bc4)) = std::move(img->blocks);
    }
    const auto planes = lightmap::decompress(c);
    if (auto s = write_irradz_exr(o.output, planes); !s) return report_output(s.error());
    std::printf("%s.{iz,d,wa}%s: %dx%d -> %s (Iz.R Iz.G Iz.B wa d.X d.Y d.Z)\n", o.input.c_str(), ext.c_str(), c.width, c.height,
                o.output.c_str());
    return kExitOk;
}

int run_audit(const Options& o) {
    auto lm = read_input(o);
    if (!lm) return report(lm.error());
    const double texels = double(lm->width) * lm->height;
    irradz::EncodeOptions eo;
    auto t0 = Clock::now();
    const auto search = lightmap::encode_planes(*lm, eo, o.threads);
    const double t_fit = since(t0);
    eo.solve = irradz::Solve::kOld;
    const auto old_way = lightmap::encode_planes(*lm, eo, o.threads);
    t0 = Clock::now();
    const auto c = lightmap::compress(search, bc6h_quality(o.quality), bc45_quality(o.quality), o.threads);
    const double t_bc = since(t0);
    const auto after = lightmap::decompress(c);
    const auto a = lightmap::audit(*lm, search, old_way, after, static_cast<size_t>(o.stride));
    if (!o.html.empty()) {  // formats/lightmap_report.h: pictures before/after block compression, error, tables
        const auto page = lightmap_audit_html(ZHC_VERSION, {{"input", o.input}, {"quality", o.quality},
                                              {"stride", std::to_string(o.stride)}, {"threads", std::to_string(o.threads)}}, search, after, a);
        if (Status s = write_lightmap_html_report(o.html, page); !s) return report_output(s.error());
        std::fprintf(stderr, "report: %s\n", o.html.c_str());
    }
    if (o.json) {
        nlohmann::ordered_json j;
        j["input"] = o.input;
        j["width"] = lm->width;
        j["height"] = lm->height;
        j["quality"] = o.quality;
        j["texels_audited"] = a.texels_sampled;
        j["mean_irradiance_at_normal"] = a.mean_iz;
        j["hemi_rmse"] = {{"old_way", a.rmse_old}, {"search", a.rmse_search}, {"search_after_bc", a.rmse_after_bc}};
        j["psnr_db"] = {{"iz_bc6h_log2", a.psnr_iz_log2}, {"wa_bc4", a.psnr_wa}, {"d_bc5", a.psnr_d}};
        j["d_error_deg"] = {{"mean", a.d_mean_deg}, {"max", a.d_max_deg}};
        j["mtexel_per_s"] = {{"irradz_fit", texels / t_fit / 1e6}, {"block_compression", texels / t_bc / 1e6}};
        j["threads"] = o.threads;
        print_json("lightmap audit", j);
        return kExitOk;
    }
    std::printf("%s: %dx%d texels, %zu audited (every %d-th), quality %s, %d thread(s)\n", o.input.c_str(), lm->width,
                lm->height, a.texels_sampled, o.stride, o.quality.c_str(), o.threads);
    std::printf("hemispherical irradiance RMSE vs SH3 (mean irradiance at normal %.5g):\n", a.mean_iz);
    std::printf("  old way (optimal linear direction, spherical Gram)  %.6g  (%.2f%%)\n", a.rmse_old, 100 * a.rmse_old / a.mean_iz);
    std::printf("  search (hemispherical Gram, golden-section d)       %.6g  (%.2f%%)\n", a.rmse_search, 100 * a.rmse_search / a.mean_iz);
    std::printf("  search after BC6H + BC5 + BC4                       %.6g  (%.2f%%)\n", a.rmse_after_bc, 100 * a.rmse_after_bc / a.mean_iz);
    std::printf("PSNR per texture: I_z BC6H %.2f dB (log2), w_a BC4 %.2f dB, d BC5 %.2f dB (angle mean %.3f deg, max %.2f deg)\n",
                a.psnr_iz_log2, a.psnr_wa, a.psnr_d, a.d_mean_deg, a.d_max_deg);
    std::printf("speed: IrradZ fit %.2f Mtexel/s, block compression %.2f Mtexel/s\n", texels / t_fit / 1e6, texels / t_bc / 1e6);
    return kExitOk;
}

int run_synth(const Options& o) {
    EnvmapReadOptions ro;
    ro.part = o.part;
    auto img = read_envmap(o.input, ro);
    if (!img) return report(img.error());
    const Sh3Radiance world = project_envmap(*img, o.threads);
    const auto lm = lightmap::synthesize_sphere(world, o.size, o.size, o.threads);
    if (auto s = write_sh_lightmap_exr(o.output, lm); !s) return report_output(s.error());
    std::printf("%s -> %s: %dx%d SH lightmap of a sphere lit by the map's SH3 (channels sh0.R .. sh8.B)\n", o.input.c_str(),
                o.output.c_str(), o.size, o.size);
    return kExitOk;
}

const VerbRegistration registration(60, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* lm = app.add_subcommand("lightmap", "IrradZ directional lightmaps: encode/decode/audit/synth");
    lm->require_subcommand(1);
    auto quality = [&](CLI::App* s) {
        s->add_option("--quality", o->quality, "block compression: fast | default | slow (exhaustive BC6H)")
            ->check(CLI::IsMember({"fast", "default", "slow"}));
        add_threads_option(s, o->threads, "output identical for any count");
    };
    CLI::App* enc = lm->add_subcommand("encode", "SH lightmap EXR -> PREFIX.iz.ktx2 (BC6H) + PREFIX.d.ktx2 (BC5) + PREFIX.wa.ktx2 (BC4), or .dds");
    enc->add_option("IN", o->input, "SH lightmap EXR (channels sh0.R .. sh8.B)")->required();
    enc->add_option("-o,--output", o->output, "output prefix")->required();
    enc->add_option("--container", o->container, "ktx2 (default) | dds (DX10 header): PREFIX.{iz,d,wa}.ktx2 or .dds")
        ->check(CLI::IsMember({"ktx2", "dds"}));
    enc->add_option("--solve", o->solve, "newton (hemispherical Gram, Newton on d) | search (the same by golden section: the reference) | old")->check(CLI::IsMember({"newton", "search", "old"}));
    quality(enc);
    CLI::App* dec = lm->add_subcommand("decode", "PREFIX.{iz,d,wa}.ktx2 or .dds -> IrradZ EXR (Iz.R Iz.G Iz.B wa d.X d.Y d.Z)");
    dec->add_option("PREFIX", o->input, "prefix given to encode")->required();
    dec->add_option("--container", o->container, "auto (default: .ktx2 if PREFIX.iz.ktx2 exists, else .dds) | ktx2 | dds")
        ->check(CLI::IsMember({"auto", "ktx2", "dds"}));
    dec->add_option("-o,--output", o->output, "output EXR")->required();
    CLI::App* aud = lm->add_subcommand("audit", "hemispherical error before/after block compression, PSNR per texture, speed");
    aud->add_option("IN", o->input, "SH lightmap EXR")->required();
    aud->add_option("--stride", o->stride, "audit every N-th texel")->check(CLI::Range(1, 1 << 20));
    add_json_flag(aud, o->json);
    aud->add_option("--html", o->html, "also write one self-contained HTML report (pictures before/after block compression, error map, tables)");
    quality(aud);
    CLI::App* syn = lm->add_subcommand("synth", "synthetic SH lightmap: a sphere lit by an environment map's SH3");
    syn->add_option("ENVMAP", o->input, "EXR (lat-long or cube) or .hdr environment map")->required();
    add_envmap_read_options(syn, nullptr, o->part);
    syn->add_option("-o,--output", o->output, "output SH lightmap EXR")->required();
    syn->add_option("--size", o->size, "width = height in texels")->check(CLI::Range(4, 4096));
    add_threads_option(syn, o->threads, "output identical for any count");
    return [o, enc, dec, aud, syn] {
        o->threads = resolve_threads(o->threads);  // 0 = all cores
        if (enc->parsed()) return run_encode(*o);
        if (dec->parsed()) return run_decode(*o);
        if (aud->parsed()) return run_audit(*o);
        if (syn->parsed()) return run_synth(*o);
        return static_cast<int>(kExitUsage);
    };
});

}  // namespace
}  // namespace cmd_lightmap
}  // namespace zhc::cli
