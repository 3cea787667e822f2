// zhc lightmap {encode, decode, audit, synth}: IrradZ directional lightmaps (docs/irradz.md,
// docs/lightmap-formats.md), streamed in bands of rows (formats/lightmap/lightmap_stream.h). Input: an SH
// lightmap EXR (channels sh0.R .. sh8.B, tangent-frame SH3 radiance; or linear SH sh0.R .. sh3.B;
// or one EXR per coefficient). Output: PREFIX.iz.ktx2 (BC6H_UFLOAT), PREFIX.d.ktx2 (BC5_UNORM), PREFIX.wa.ktx2
// (BC4_UNORM): 2.5 bytes per texel; with --container dds the same blocks in PREFIX.{iz,d,wa}.dds.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "json_output.h"
#include "codec/lightmap/lightmap.h"
#include "formats/lightmap/astc.h"
#include "formats/lightmap/dds.h"
#include "formats/envmap/envmap.h"
#include "formats/io/file_io.h"
#include "formats/lightmap/ktx2.h"
#include "formats/lightmap/lightmap_exr.h"
#include "formats/report/lightmap_report.h"
#include "formats/lightmap/lightmap_stream.h"
#include "progress.h"

namespace zhc::cli {
namespace cmd_lightmap {  // one namespace per verb file: the CLI is a unity build
namespace {

struct Options {
    std::vector<std::string> inputs;
    std::string input, output, quality = "default", solve = "newton";
    std::string container;  // encode: "" = ktx2; decode: "" = auto
    std::string part;       // synth: EXR part of the environment map
    LatLongConvention latlong = LatLongConvention::kOpenExr;  // synth: lat-long orientation
    std::string html;       // audit: also write the HTML report here (whole-image path)
    std::string paths_base; // audit: --paths-relative-to
    std::string target = "bc", footprint = "4x4";  // encode
    bool footprint_given = false;                   // encode: --footprint on the command line
    std::vector<std::string> targets;               // audit: side-by-side comparison
    int threads = 0, size = 256, height = 0, stride = 17, band_rows = 0;
    bool json = false, half = false;
    ProgressFlags progress;
};

// --quality and --solve take their names from the library's tables (CLI11 has checked the name).
bc6h::Quality bc6h_quality(const std::string& q) { return lightmap::find_quality_preset(q)->bc6h; }
bc45::Quality bc45_quality(const std::string& q) { return lightmap::find_quality_preset(q)->bc45; }

// "a: summary; b: summary; ..." and the names, for an option's help and its check.
template <class Table>
std::string choices_help(const Table& table) {
    std::string s;
    for (const auto& e : table) s += (s.empty() ? "" : "; ") + std::string(e.name) + ": " + std::string(e.summary);
    return s;
}
template <class Table>
std::vector<std::string> choice_names(const Table& table) {
    std::vector<std::string> v;
    for (const auto& e : table) v.emplace_back(e.name);
    return v;
}

// The SH lightmap input(s): one EXR, several (one per coefficient), or one name with "{i}", which
// stands for the coefficient index: the files for i = 0..8 if all nine exist, else i = 0..3.
std::vector<std::string> input_files(const std::vector<std::string>& given) {
    if (given.size() != 1) return given;
    const std::string& pattern = given[0];
    const auto at = pattern.find("{i}");
    if (at == std::string::npos) return given;
    auto name = [&](int i) { return pattern.substr(0, at) + std::to_string(i) + pattern.substr(at + 3); };
    std::vector<std::string> files;
    std::error_code ec;
    int n = 9;
    for (int i = 0; i < 9; ++i)
        if (!std::filesystem::exists(name(i), ec)) {
            n = 4;
            break;
        }
    for (int i = 0; i < n; ++i) files.push_back(name(i));
    return files;
}

std::string inputs_text(const std::vector<std::string>& files) {
    std::string s;
    for (const auto& f : files) s += (s.empty() ? "" : " + ") + f;
    return s;
}
// The inputs as a report names them: relative to --paths-relative-to when given.
std::string shown_inputs(const std::vector<std::string>& files, const std::string& base) {
    std::vector<std::string> shown;
    for (const std::string& f : files) shown.push_back(shown_path(f, base));
    return inputs_text(shown);
}

// Whether `path` is a KTX2 file whose vkFormat is an ASTC format zhc writes (an I_z plane of an
// ASTC target). Reads the 16 header bytes directly: the file is not an input of the command.
bool is_astc_ktx2(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return false;
    std::uint8_t h[16] = {};
    const bool whole = std::fread(h, 1, sizeof h, f) == sizeof h;
    std::fclose(f);
    static constexpr std::uint8_t kKtx2Id[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
    if (!whole || std::memcmp(h, kKtx2Id, sizeof kKtx2Id) != 0) return false;
    const std::uint32_t vk = std::uint32_t(h[12]) | std::uint32_t(h[13]) << 8 | std::uint32_t(h[14]) << 16 | std::uint32_t(h[15]) << 24;
    return astc::format_of_vk(vk).has_value();
}

// The planes of the other target under `prefix`, which a new encode leaves stale (decode would pair
// them with the new ones, or --container dds read an older lightmap): after a bc encode, the ASTC
// planes PREFIX.dwa.ktx2 and (when this encode wrote DDS) an ASTC PREFIX.iz.ktx2; after an astc or
// astc-ldr encode, the BC planes PREFIX.d.ktx2, PREFIX.wa.ktx2 and PREFIX.{iz,d,wa}.dds. The same
// target's other container (a bc set in both KTX2 and DDS) is kept: both hold the same target.
std::vector<std::string> other_target_planes(const std::string& prefix, bool astc, bool dds) {
    std::vector<std::string> candidates;
    if (astc) {
        for (const char* p : {".d.ktx2", ".wa.ktx2", ".iz.dds", ".d.dds", ".wa.dds"}) candidates.push_back(prefix + p);
    } else {
        candidates.push_back(prefix + ".dwa.ktx2");
        if (dds && is_astc_ktx2(prefix + ".iz.ktx2")) candidates.push_back(prefix + ".iz.ktx2");
    }
    std::vector<std::string> present;
    std::error_code ec;
    for (const std::string& c : candidates)
        if (std::filesystem::is_regular_file(c, ec)) present.push_back(c);
    return present;
}

int run_encode(const Options& o) {
    const auto files = input_files(o.inputs);
    const bool astc = o.target != "bc";
    if (astc && o.container == "dds")
        return report(make_error(ErrorCode::kUnsupported, "--container dds: DDS has no ASTC formats; --target " + o.target +
                                                              " writes KTX2 only (PREFIX.iz.ktx2, PREFIX.dwa.ktx2)"));
    if (!astc && o.footprint_given) {
        std::fprintf(stderr, "zhc: error: --footprint %s: --target bc does not use it (the ASTC block footprint: give --target astc or astc-ldr)\n",
                     o.footprint.c_str());
        return kExitUsage;
    }
    const std::string out_ext = o.container == "dds" ? ".dds" : ".ktx2";
    const std::vector<const char*> planes = astc ? std::vector<const char*>{".iz", ".dwa"} : std::vector<const char*>{".iz", ".d", ".wa"};
    for (const char* plane : planes)
        if (int rc = refuse_output_over_input("-o", o.output + plane + out_ext, files); rc != kExitOk) return rc;
    if (int rc = refuse_unwritable_output("-o", o.output + planes[0] + out_ext); rc != kExitOk) return rc;
    lightmap_stream::EncodeOptions eo;
    eo.target = o.target == "astc" ? lightmap_stream::Target::kAstc
                                   : (o.target == "astc-ldr" ? lightmap_stream::Target::kAstcLdr : lightmap_stream::Target::kBc);
    eo.footprint = {o.footprint[0] - '0', o.footprint[2] - '0'};  // CLI11 checked: 4x4, 5x5, 6x6, 8x8
    eo.fit = lightmap::find_fit(o.solve)->fit;
    eo.bc6h_quality = bc6h_quality(o.quality);
    eo.bc45_quality = bc45_quality(o.quality);
    eo.threads = o.threads;
    eo.band_rows = o.band_rows;
    eo.dds = o.container == "dds";
    Progress progress("zhc lightmap encode", "rows", o.progress);
    if (progress.enabled()) eo.progress = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    bool output_failed = false;
    auto r = lightmap_stream::encode(files, o.output, eo, &output_failed);
    progress.finish();
    if (!r) return output_failed ? report_output(r.error()) : report(r.error());
    const std::string ext = eo.dds ? ".dds" : ".ktx2";
    // Only now, with the new planes in place: a failed encode leaves the earlier set whole.
    for (const std::string& stale : other_target_planes(o.output, astc, eo.dds)) {
        std::error_code ec;
        const bool removed = std::filesystem::remove(stale, ec);
        if (ec)
            return report_output(make_error(ErrorCode::kIoError, stale + ": a plane of the other target under this prefix, stale next to the "
                                                                 "new planes, cannot be removed (" + ec.message() + ")"));
        if (removed)
            std::fprintf(stderr, "zhc: note: removed %s: a %s plane of an earlier encode under this prefix (this --target %s wrote %s.%s%s)\n",
                         stale.c_str(), astc ? "bc" : "astc", o.target.c_str(), o.output.c_str(), astc ? "{iz,dwa}" : "{iz,d,wa}", ext.c_str());
    }
    const double texels = double(r->width) * r->height;
    std::printf("%s: %dx%d texels -> %s.%s%s (%s; %llu bytes of blocks, %.3f bytes/texel)\n", inputs_text(files).c_str(), r->width,
                r->height, o.output.c_str(), astc ? "{iz,dwa}" : "{iz,d,wa}", ext.c_str(),
                astc ? (o.target + " " + o.footprint).c_str() : "bc", static_cast<unsigned long long>(r->block_bytes), double(r->block_bytes) / texels);
    std::printf("IrradZ fit %.3f s (%.2f Mtexel/s), block compression (%s) %.3f s (%.2f Mtexel/s), %d thread(s)\n", r->timing.fit,
                texels / r->timing.fit / 1e6, o.quality.c_str(), r->timing.compress, texels / r->timing.compress / 1e6, o.threads);
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
    if (int rc = refuse_output_over_input("-o", o.output, {o.input + ".iz" + ext, o.input + ".d" + ext, o.input + ".wa" + ext});
        rc != kExitOk)
        return rc;
    Progress progress("zhc lightmap decode", "rows", o.progress);
    lightmap_stream::ProgressFn fn;
    if (progress.enabled()) fn = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    bool output_failed = false;
    auto r = lightmap_stream::decode(o.input, dds, o.output, o.band_rows, fn, &output_failed);
    progress.finish();
    if (!r) return output_failed ? report_output(r.error()) : report(r.error());
    if (r->target == lightmap_stream::Target::kBc)
        std::printf("%s.{iz,d,wa}%s: %dx%d -> %s (Iz.R Iz.G Iz.B wa d.X d.Y d.Z)\n", o.input.c_str(), ext.c_str(), r->width, r->height,
                    o.output.c_str());
    else
        std::printf("%s.{iz,dwa}.ktx2 (%s %dx%d): %dx%d -> %s (Iz.R Iz.G Iz.B wa d.X d.Y d.Z)\n", o.input.c_str(),
                    r->target == lightmap_stream::Target::kAstc ? "astc" : "astc-ldr", r->footprint.x, r->footprint.y, r->width,
                    r->height, o.output.c_str());
    return kExitOk;
}

// audit --html: the report needs the whole image's planes, so this path reads the whole lightmap
// (one EXR, at most 4096 x 4096) in one piece.
// extra: rows appended to the summary table (audit --targets: one per target).
int run_audit_html(const Options& o, const std::string& input, const std::vector<LightmapHtmlRow>& extra = {}) {
    LightmapReadOptions ro;
    ro.threads = o.threads;
    auto lm = read_sh_lightmap_exr(input, ro);
    if (!lm) return report(lm.error());
    irradz::EncodeOptions eo;
    const auto search = lightmap::encode_planes(*lm, eo, o.threads);
    eo.solve = irradz::Solve::kTalkBaseline;
    const auto old_way = lightmap::encode_planes(*lm, eo, o.threads);
    const auto c = lightmap::compress(search, bc6h_quality(o.quality), bc45_quality(o.quality), o.threads);
    const auto after = lightmap::decompress(c);
    const auto a = lightmap::audit(*lm, search, old_way, after, static_cast<size_t>(o.stride));
    auto page = lightmap_audit_html(ZHC_VERSION, {{"input", shown_path(input, o.paths_base)}, {"quality", o.quality},
                                    {"stride", std::to_string(o.stride)}, {"threads", std::to_string(o.threads)}}, search, after, a);
    page.rows.insert(page.rows.end(), extra.begin(), extra.end());
    if (Status s = write_lightmap_html_report(o.html, page); !s) return report_output(s.error());
    std::fprintf(stderr, "report: %s\n", o.html.c_str());
    return kExitOk;
}

// audit --targets: the targets side by side on the same fit (and with --html, one summary row each
// in the BC report).
int run_audit_targets(const Options& o, const std::vector<std::string>& files) {
    std::vector<lightmap_stream::TargetSpec> specs;
    for (const auto& t : o.targets) {
        auto spec = lightmap_stream::parse_target(t);
        if (!spec)
            return report(make_error(ErrorCode::kInvalidArgument, "--targets: " + t +
                                                                      ": not bc, astc[:NxN], astc-ldr[:NxN], astc-split[:NxN] or plain-astc[:NxN] "
                                                                      "(N x N: 4x4, 5x5, 6x6, 8x8)"));
        specs.push_back(*spec);
    }
    lightmap_stream::AuditOptions ao;
    ao.bc6h_quality = bc6h_quality(o.quality);
    ao.bc45_quality = bc45_quality(o.quality);
    ao.threads = o.threads;
    ao.band_rows = o.band_rows;
    ao.stride = static_cast<size_t>(o.stride);
    Progress progress("zhc lightmap audit", "rows", o.progress);
    if (progress.enabled()) ao.progress = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    lightmap_stream::AuditResult base;
    auto r = lightmap_stream::audit_targets(files, ao, specs, &base);
    progress.finish();
    if (!r) return report(r.error());
    const double texels = double(base.width) * base.height;
    const std::string input = inputs_text(files);
    if (!o.html.empty()) {
        std::vector<LightmapHtmlRow> rows;
        for (const auto& t : *r) {
            char name[128];
            std::snprintf(name, sizeof name, "target %s (%.3f bytes/texel)", t.spec.name.c_str(), double(t.bytes) / texels);
            rows.push_back({name, t.audit.rmse_after_bc, t.audit.rmse_after_bc / t.audit.mean_iz});
        }
        if (const int rc = run_audit_html(o, files[0], rows); rc != kExitOk) return rc;
    }
    if (o.json) {
        // The plain audit's object (the BC target), then the targets side by side.
        const auto& a = base.audit;
        nlohmann::ordered_json j;
        j["input"] = shown_inputs(files, o.paths_base);
        j["width"] = base.width;
        j["height"] = base.height;
        j["quality"] = o.quality;
        j["texels_audited"] = a.texels_sampled;
        j["mean_irradiance_at_normal"] = a.mean_iz;
        j["hemi_rmse"] = {{"old_way", a.rmse_old}, {"search", a.rmse_search}, {"search_after_bc", a.rmse_after_bc}};
        j["psnr_db"] = {{"iz_bc6h_log2", a.psnr_iz_log2}, {"wa_bc4", a.psnr_wa}, {"d_bc5", a.psnr_d}};
        j["d_error_deg"] = {{"mean", a.d_mean_deg}, {"max", a.d_max_deg}};
        j["mtexel_per_s"] = {{"irradz_fit", texels / base.timing.fit / 1e6}, {"block_compression", texels / base.timing.compress / 1e6}};
        nlohmann::ordered_json arr = nlohmann::ordered_json::array();
        for (const auto& t : *r) {
            nlohmann::ordered_json e;
            e["target"] = t.spec.name;
            e["bytes_per_texel"] = double(t.bytes) / texels;
            e["hemi_rmse"] = t.audit.rmse_after_bc;
            if (!t.spec.plain) e["psnr_db"] = {{"iz_log2", t.audit.psnr_iz_log2}, {"wa", t.audit.psnr_wa}, {"d", t.audit.psnr_d}};
            e["encode_mtexel_per_s"] = texels / std::max(1e-9, t.encode_seconds) / 1e6;
            arr.push_back(e);
        }
        j["threads"] = o.threads;
        j["targets"] = arr;
        print_json("lightmap audit", j);
        return kExitOk;
    }
    const auto& a0 = (*r)[0].audit;
    std::printf("%s: %dx%d texels, %zu audited (every %d-th), quality %s, %d thread(s)\n", input.c_str(), base.width, base.height,
                a0.texels_sampled, o.stride, o.quality.c_str(), o.threads);
    std::printf("hemispherical irradiance RMSE vs SH3 (mean irradiance at normal %.5g): fit before compression %.6g (%.2f%%)\n", a0.mean_iz,
                a0.rmse_search, 100 * a0.rmse_search / a0.mean_iz);
    std::printf("%-16s %8s %12s %8s %10s %8s %8s %12s\n", "target", "B/texel", "hemi RMSE", "%", "I_z log2", "w_a", "d", "Mtexel/s");
    for (const auto& t : *r) {
        const auto& a = t.audit;
        if (t.spec.plain)
            std::printf("%-16s %8.3f %12.6g %7.2f%% %10s %8s %8s %12.3f\n", t.spec.name.c_str(), double(t.bytes) / texels, a.rmse_after_bc,
                        100 * a.rmse_after_bc / a.mean_iz, "-", "-", "-", texels / std::max(1e-9, t.encode_seconds) / 1e6);
        else
            std::printf("%-16s %8.3f %12.6g %7.2f%% %10.2f %8.2f %8.2f %12.3f\n", t.spec.name.c_str(), double(t.bytes) / texels,
                        a.rmse_after_bc, 100 * a.rmse_after_bc / a.mean_iz, a.psnr_iz_log2, a.psnr_wa, a.psnr_d,
                        texels / std::max(1e-9, t.encode_seconds) / 1e6);
    }
    std::printf("(PSNR in dB: I_z log2-domain, w_a and d against the fit; plain-astc: irradiance at the normal only, no direction)\n");
    return kExitOk;
}

int run_audit(const Options& o) {
    const auto files = input_files(o.inputs);
    if (!o.html.empty()) {
        if (int rc = refuse_output_over_input("--html", o.html, files); rc != kExitOk) return rc;
        if (files.size() != 1)
            return report(make_error(ErrorCode::kInvalidArgument, "lightmap audit --html takes one SH lightmap EXR"));
    }
    if (!o.targets.empty()) return run_audit_targets(o, files);
    if (!o.html.empty())
        if (const int rc = run_audit_html(o, files[0]); rc != kExitOk) return rc;
    lightmap_stream::AuditOptions ao;
    ao.bc6h_quality = bc6h_quality(o.quality);
    ao.bc45_quality = bc45_quality(o.quality);
    ao.threads = o.threads;
    ao.band_rows = o.band_rows;
    ao.stride = static_cast<size_t>(o.stride);
    Progress progress("zhc lightmap audit", "rows", o.progress);
    if (progress.enabled()) ao.progress = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    auto r = lightmap_stream::audit(files, ao);
    progress.finish();
    if (!r) return report(r.error());
    const auto& a = r->audit;
    const double texels = double(r->width) * r->height;
    const double t_fit = r->timing.fit, t_bc = r->timing.compress;
    const std::string input = inputs_text(files);
    if (o.json) {
        nlohmann::ordered_json j;
        j["input"] = shown_inputs(files, o.paths_base);
        j["width"] = r->width;
        j["height"] = r->height;
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
    std::printf("%s: %dx%d texels, %zu audited (every %d-th), quality %s, %d thread(s)\n", input.c_str(), r->width, r->height,
                a.texels_sampled, o.stride, o.quality.c_str(), o.threads);
    std::printf("hemispherical irradiance RMSE vs SH3 (mean irradiance at normal %.5g):\n", a.mean_iz);
    std::printf("  old way (optimal linear direction, spherical Gram)  %.6g  (%.2f%%)\n", a.rmse_old, 100 * a.rmse_old / a.mean_iz);
    std::printf("  fit (hemispherical Gram, Newton on d)               %.6g  (%.2f%%)\n", a.rmse_search, 100 * a.rmse_search / a.mean_iz);
    std::printf("  fit after BC6H + BC5 + BC4                          %.6g  (%.2f%%)\n", a.rmse_after_bc, 100 * a.rmse_after_bc / a.mean_iz);
    std::printf("PSNR per texture: I_z BC6H %.2f dB (log2), w_a BC4 %.2f dB, d BC5 %.2f dB (angle mean %.3f deg, max %.2f deg)\n",
                a.psnr_iz_log2, a.psnr_wa, a.psnr_d, a.d_mean_deg, a.d_max_deg);
    std::printf("speed: IrradZ fit %.2f Mtexel/s, block compression %.2f Mtexel/s\n", texels / t_fit / 1e6, texels / t_bc / 1e6);
    return kExitOk;
}

int run_synth(const Options& o) {
    if (int rc = refuse_output_over_input("-o", o.output, {o.input}); rc != kExitOk) return rc;
    EnvmapReadOptions ro;
    ro.part = o.part;
    ro.latlong = o.latlong;
    auto img = read_envmap(o.input, ro);
    if (!img) return report(img.error());
    const Sh3Radiance world = project_envmap(*img, o.threads);
    Progress progress("zhc lightmap synth", "rows", o.progress);
    lightmap_stream::ProgressFn fn;
    if (progress.enabled()) fn = [&](std::uint64_t d, std::uint64_t t) { progress.update(d, t); };
    const int height = o.height > 0 ? o.height : o.size;
    const Status s = lightmap_stream::synth(world, o.size, height, o.output, o.half, o.threads, o.band_rows, fn);
    progress.finish();
    if (!s) return report_output(s.error());
    std::printf("%s -> %s: %dx%d SH lightmap of a sphere lit by the map's SH3 (channels sh0.R .. sh8.B)\n", o.input.c_str(),
                o.output.c_str(), o.size, height);
    return kExitOk;
}

const VerbRegistration registration(60, [](CLI::App& app) -> std::function<int()> {
    auto o = std::make_shared<Options>();
    CLI::App* lm = app.add_subcommand("lightmap", "IrradZ directional lightmaps: encode/decode/audit/synth");
    lm->require_subcommand(1);
    auto quality = [&](CLI::App* s) {
        s->add_option("--quality", o->quality, "block compression: " + choices_help(lightmap::quality_presets()))
            ->check(CLI::IsMember(choice_names(lightmap::quality_presets())));
        add_threads_option(s, o->threads, "output identical for any count");
    };
    auto band = [&](CLI::App* s) {
        s->add_option("--band-rows", o->band_rows, "rows per streamed band (rounded up to whole rows of blocks: 4, and the ASTC footprint height; default: about 2^18 texels; output identical for any value)")
            ->check(CLI::Range(1, 1 << 20));
        add_progress_flags(s, o->progress);
        add_depfile_option(s);
    };
    CLI::App* enc = lm->add_subcommand("encode", "SH lightmap EXR -> PREFIX.iz.ktx2 (BC6H) + PREFIX.d.ktx2 (BC5) + PREFIX.wa.ktx2 (BC4), or .dds");
    enc->add_option("IN", o->inputs,
                    "SH lightmap EXR (sh0.R .. sh8.B, or linear SH sh0.R .. sh3.B), or 4 / 9 EXRs one per coefficient "
                    "(R, G, B), or one name with {i} for the coefficient index")
        ->required();
    enc->add_option("-o,--output", o->output,
                    "output prefix; the other target's planes under it are removed (bc: PREFIX.dwa.ktx2; astc: PREFIX.{d,wa}.ktx2 and "
                    "PREFIX.{iz,d,wa}.dds; docs/lightmap-formats.md)")
        ->required();
    enc->add_option("--container", o->container, "ktx2 (default) | dds (DX10 header): PREFIX.{iz,d,wa}.ktx2 or .dds")
        ->check(CLI::IsMember({"ktx2", "dds"}));
    enc->add_option("--target", o->target,
                    "bc (default: BC6H + BC5 + BC4, 2.5 B/texel) | astc (ASTC HDR I_z + ASTC LDR d,w_a; KTX2 only) | "
                    "astc-ldr (I_z in ASTC LDR by a per-texture log2 range, for GPUs without ASTC HDR); ASTC effort from --quality: "
                    "fast, default = medium, slow = thorough")
        ->check(CLI::IsMember({"bc", "astc", "astc-ldr"}));
    enc->add_option("--footprint", o->footprint, "ASTC block footprint, with --target astc or astc-ldr only: 4x4 (default, 2 B/texel), 5x5, 6x6 (0.89 B/texel), 8x8")
        ->check(CLI::IsMember({"4x4", "5x5", "6x6", "8x8"}));
    std::string solve_help = "IrradZ fit: " + choices_help(lightmap::fits());
    std::vector<std::string> solve_names = choice_names(lightmap::fits());
    for (const lightmap::FitAlias& a : lightmap::fit_aliases()) {
        solve_help += "; " + std::string(a.alias) + ": alias of " + std::string(a.name);
        solve_names.emplace_back(a.alias);
    }
    enc->add_option("--solve", o->solve, solve_help)->check(CLI::IsMember(solve_names));
    quality(enc);
    band(enc);
    CLI::App* dec = lm->add_subcommand("decode", "PREFIX.{iz,d,wa}.ktx2 or .dds -> IrradZ EXR (Iz.R Iz.G Iz.B wa d.X d.Y d.Z)");
    dec->add_option("PREFIX", o->input, "prefix given to encode")->required();
    dec->add_option("--container", o->container, "auto (default: .ktx2 if PREFIX.iz.ktx2 exists, else .dds) | ktx2 | dds")
        ->check(CLI::IsMember({"auto", "ktx2", "dds"}));
    dec->add_option("-o,--output", o->output, "output EXR")->required();
    band(dec);
    CLI::App* aud = lm->add_subcommand("audit", "hemispherical error before/after block compression, PSNR per texture, speed");
    aud->add_option("IN", o->inputs, "SH lightmap EXR(s), as for encode")->required();
    aud->add_option("--targets", o->targets,
                    "compare texture targets side by side (comma-separated): bc, astc[:NxN], astc-ldr[:NxN], astc-split[:NxN] "
                    "(d and w_a in two textures), plain-astc[:NxN] (Godot-style irradiance only); NxN 4x4 (default), 5x5, 6x6, 8x8")
        ->delimiter(',');
    aud->add_option("--stride", o->stride, "audit every N-th texel")->check(CLI::Range(1, 1 << 20));
    add_json_flag(aud, o->json);
    add_paths_relative_to_option(aud, o->paths_base);
    aud->add_option("--html", o->html, "also write one self-contained HTML report (pictures before/after block compression, error map, tables; reads the whole lightmap)");
    quality(aud);
    band(aud);
    CLI::App* syn = lm->add_subcommand("synth", "synthetic SH lightmap: a sphere lit by an environment map's SH3");
    syn->add_option("ENVMAP", o->input, "EXR (lat-long or cube) or .hdr environment map")->required();
    add_envmap_read_options(syn, nullptr, o->part);
    add_latlong_option(syn, o->latlong, nullptr, "default openexr");
    syn->add_option("-o,--output", o->output, "output SH lightmap EXR")->required();
    syn->add_option("--size", o->size, "width (and height, unless --height) in texels")->check(CLI::Range(4, 16384));
    syn->add_option("--height", o->height, "height in texels (default: --size)")->check(CLI::Range(4, 16384));
    add_threads_option(syn, o->threads, "output identical for any count");
    syn->add_flag("--half", o->half, "HALF channels (half the file size) instead of FLOAT");
    band(syn);
    return [o, enc, dec, aud, syn] {
        o->threads = resolve_threads(o->threads);  // 0 = all cores
        if (enc->parsed()) {
            o->footprint_given = enc->get_option("--footprint")->count() > 0;
            return run_encode(*o);
        }
        if (dec->parsed()) return run_decode(*o);
        if (aud->parsed()) return run_audit(*o);
        if (syn->parsed()) return run_synth(*o);
        return static_cast<int>(kExitUsage);
    };
});

}  // namespace
}  // namespace cmd_lightmap
}  // namespace zhc::cli
