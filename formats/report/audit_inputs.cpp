#include "formats/report/audit_inputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "formats/envmap/envmap.h"
#include "formats/envmap/envmap_cube.h"
#include "formats/io/file_io.h"
#include "formats/io/json_depth.h"
#include "formats/probes/probe_file.h"
#include "codec/probe/probe_set.h"
#include "formats/report/raster.h"

namespace zhc {

namespace fs = std::filesystem;

namespace {
bool audit_extension(const std::string& ext) { return ext == ".exr" || ext == ".hdr" || ext == ".zhp" || ext == ".json"; }
}  // namespace

namespace {
// Why a JSON file found in a folder is not a probe list ("" when it may be one): a document with a
// "format" other than zhc-probes (a zhc-scene file), a glTF file ("asset"), or no "probes" array.
// A file that does not parse is kept: the loader names what is wrong with it.
std::string not_a_probe_list(const std::string& path) {
    auto bytes = read_file_bytes(path, std::uint64_t(2) << 30);
    if (!bytes || !check_json_depth(*bytes, path)) return "";
    const auto doc = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (!doc.is_object()) return "";
    if (doc.contains("format") && doc["format"].is_string() && doc["format"] != "zhc-probes")
        return "a " + doc["format"].get<std::string>() + " file, not a probe list";
    if (doc.contains("asset") && doc["asset"].is_object()) return "a glTF file, not a probe list";
    if (!doc.contains("probes") || !doc["probes"].is_array()) return "no \"probes\" array: not a probe list";
    return "";
}
}  // namespace

Result<std::vector<std::string>> expand_audit_inputs(const std::vector<std::string>& paths, std::vector<std::string>* skipped) {
    std::vector<std::string> out;
    for (const std::string& p : paths) {
        std::error_code ec;
        if (fs::is_directory(p, ec)) {
            std::vector<std::string> found;
            for (const auto& e : fs::directory_iterator(p, ec))
                if (e.is_regular_file() && audit_extension(file_extension(e.path().string())))
                    found.push_back(e.path().string());
            if (ec) return make_error(ErrorCode::kIoError, p + ": cannot list folder (" + ec.message() + ")");
            std::sort(found.begin(), found.end());
            for (const std::string& f : found) {
                if (file_extension(f) == ".json") {
                    if (const std::string why = not_a_probe_list(f); !why.empty()) {
                        if (skipped) skipped->push_back(f + ": " + why);
                        continue;
                    }
                }
                out.push_back(f);
            }
        } else if (fs::exists(p, ec)) {
            out.push_back(p);
        } else {
            return make_error(ErrorCode::kIoError, p + ": no such file or folder");
        }
    }
    return out;
}

Result<AuditInput> load_audit_input(const std::string& path, const std::vector<Vec3>& dirs,
                                    const AuditLoadOptions& options) {
    AuditInput in;
    in.path = path;
    auto bytes = read_file_bytes(path, std::uint64_t(2) << 30);
    if (!bytes) return bytes.error();
    if (looks_like_envmap(*bytes)) {
        EnvmapReadOptions ro;
        if (options.replace_non_finite) ro.non_finite = NonFinitePolicy::kReplaceZero;
        ro.part = options.part;
        ro.latlong = options.latlong;
        ro.ldr = options.ldr;
        auto img = read_envmap_memory(*bytes, path, ro);
        if (!img) return img.error();
        in.kind = "envmap";
        in.probes.push_back(project_envmap(*img, options.threads));
        // The reference integrates lat-long pixels: a cube map is resampled to a lat-long of 4N x 2N
        // (N the face size; at least the audit's 512 x 256).
        const Image ll = envmap_as_latlong(*img, std::max(512, 4 * img->width), std::max(256, 2 * img->width));
        in.map = downsample_for_audit({ll.rgb.data(), ll.width, ll.height, ll.latlong});
        in.map_reference = integrate_irradiance(in.map.view(), dirs, options.threads);
        in.description = std::string(img->layout != EnvmapLayout::kLatLong ? "cube " : "") + "environment map " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                         (img->layout == EnvmapLayout::kLatLong && img->latlong != LatLongConvention::kOpenExr
                              ? std::string(" (lat-long as ") + latlong_convention_name(img->latlong) + ")"
                              : std::string()) +
                         ", reference: the map integrated at " + std::to_string(in.map.width) + "x" +
                         std::to_string(in.map.height);
        in.reference = "the map's irradiance, integrated over each pixel's exact footprint at " + std::to_string(in.map.width) + "x" +
                       std::to_string(in.map.height);
        return in;
    }
    // Probe files: the reference is each probe's SH3 (decoded from whatever the file stores, so a
    // quantised file is audited against its own decoded hub).
    if (looks_like_probe_file(*bytes)) {
        auto file = parse_and_decode_probe_set(*bytes, path);
        if (!file) return file.error();
        in.kind = "probes";
        in.probes = std::move(file->hub);
        in.description = std::to_string(in.probes.size()) + " probes stored as " + file->set.representation +
                         ", reference: their SH3";
        const Codec* stored = file->set.codec();
        in.reference = stored && stored->traits.exact
                           ? "the probes' SH3 irradiance (stored exactly as " + file->set.representation + ")"
                           : "the stored data: the probes as decoded from " + file->set.representation +
                                 ", not the lighting they were made from (" + file->set.representation +
                                 " itself shows 0 error)";
        return in;
    }
    if (looks_like_json(*bytes)) {
        auto list = parse_probe_json(*bytes, path);
        if (!list) return list.error();
        in.kind = "probes";
        in.probes = std::move(list->probes);
        in.description = std::to_string(in.probes.size()) + " probes (JSON), reference: their SH3";
        in.reference = "the probes' SH3 irradiance (JSON float SH3)";
        return in;
    }
    return unknown_probe_input(path, *bytes);
}

Error unknown_probe_input(const std::string& path, std::span<const std::uint8_t> bytes) {
    // A KTX2, KTX 1 or DDS texture that is not a cube map: the cube reader's own reason (exit 5, as
    // `zhc project` says it: "KTX 1 numberOfFaces 1 (byte 52): a 2-D texture, not a cube map").
    if (is_ktx2(bytes) || is_ktx1(bytes) || is_dds(bytes)) {
        auto img = read_envmap_memory(bytes, path, {});
        if (!img) return img.error();
    }
    return Error{ErrorCode::kBadFormat, path + ": not an environment map (EXR/.hdr, KTX2/KTX 1/DDS cube map), .zhp probe file or JSON probe list" +
                                            git_lfs_hint(bytes)};
}

Result<AuditedFiles> audit_files(const std::vector<std::string>& files, const std::vector<Vec3>& dirs,
                                 const std::vector<const Codec*>& codecs, const AuditOptions& options,
                                 const AuditLoadOptions& load, const AuditFileHook& after_input) {
    AuditedFiles out;
    std::vector<InputAudit> audited;
    for (size_t i = 0; i < files.size(); ++i) {
        auto input = load_audit_input(files[i], dirs, load);
        if (!input) return input.error();
        audited.push_back(audit_input(*input, dirs, codecs, options));
        if (after_input) {
            if (Status s = after_input(*input, audited.back(), i); !s) return s.error();
        }
        out.inputs.push_back(std::move(input).value());
    }
    out.run = summarize_audit(std::move(audited));
    return out;
}

Status write_audit_images(const std::string& dir, const AuditInput& input, const std::vector<Vec3>&,
                          const std::vector<const Codec*>& codecs, const CodecOptions& options) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return make_error(ErrorCode::kIoError, dir + ": cannot create folder (" + ec.message() + ")");
    if (input.probes.empty()) return Ok{};
    // Strips: a lat-long picture of irradiance, one pixel per normal direction.
    const int sw = 256, sh = 128;
    std::vector<Vec3> pixel_dirs;
    for (int y = 0; y < sh; ++y)
        for (int x = 0; x < sw; ++x) pixel_dirs.push_back(latlong_direction(x, y, sw, sh));
    // Reference picture: the map integrated at 64x32 (irradiance is smooth; the audit numbers
    // use the finer reference), or the probe's SH3 for probe files.
    std::vector<Rgb> ref;
    if (input.kind == "envmap") {
        const LatLongImage coarse = downsample_for_audit(input.map.view(), 64, 32);
        ref = integrate_irradiance(coarse.view(), pixel_dirs, 2);
    } else {
        ref = sh3_irradiance(input.probes[0], pixel_dirs);
    }
    double mean = 0;
    for (const Rgb& c : ref) mean += (double(c.r) + c.g + c.b) / 3.0;
    mean = std::max(mean / static_cast<double>(ref.size()), 1e-12);
    std::vector<std::vector<Rgb>> recs;
    for (const Codec* codec : codecs) {
        std::vector<std::uint8_t> stored(codec->size_bytes);
        codec->encode(input.probes[0], options, stored.data(), nullptr);
        recs.push_back(codec_irradiance(*codec, stored.data(), options, pixel_dirs));
    }
    // Relative error per pixel (max over channels of |E - E_ref| / mean reference), on one
    // logarithmic scale shared by every representation (as in the HTML report).
    auto error_of = [&](const std::vector<Rgb>& rec, size_t i) {
        double err = 0;
        for (int k = 0; k < 3; ++k) err = std::max(err, std::fabs(double(rec[i][k]) - ref[i][k]));
        return std::isfinite(err) ? err / mean : 1e30;
    };
    std::vector<std::vector<double>> errors;
    for (const auto& rec : recs) {
        errors.emplace_back(rec.size());
        for (size_t i = 0; i < rec.size(); ++i) errors.back()[i] = error_of(rec, i);
    }
    const ErrorScale scale = ErrorScale::from_percentile(errors);

    // The label column is as wide as the longest label (at least 170 pixels, so that the strips
    // of pictures with short names line up); the canvas at least as wide as the title.
    const int text_px = 17, title_px = 20, pad = 8, title_h = 34, legend_h = 62;
    int widest = Canvas::text_width("reference", text_px);
    for (const Codec* codec : codecs) widest = std::max(widest, Canvas::text_width(std::string(codec->name), text_px));
    const int label_w = std::max(170, pad + widest + pad);
    const std::string title = fs::path(input.path).filename().string() + ": irradiance (tone-mapped) | error / mean";
    const int rows = 1 + static_cast<int>(codecs.size());
    Canvas canvas(std::max(label_w + 2 * sw + 3 * pad + 28, 2 * pad + Canvas::text_width(title, title_px)),
                  title_h + rows * (sh + pad) + legend_h, {32, 32, 36});
    const Rgb8 white{235, 235, 235}, magenta{255, 0, 255};
    canvas.text(pad, 7, title, title_px, white);
    auto draw_row = [&](int row, const std::string& label, const std::vector<Rgb>& rec, bool with_error) {
        const int y0 = title_h + row * (sh + pad);
        canvas.text(pad, y0 + sh / 2 - text_px / 2, label, text_px, white);
        for (int y = 0; y < sh; ++y)
            for (int x = 0; x < sw; ++x) {
                const size_t i = static_cast<size_t>(y) * sw + x;
                const Rgb& c = rec[i];
                const bool negative = c.r < 0 || c.g < 0 || c.b < 0;
                Rgb8 p = negative ? magenta
                                  : Rgb8{tonemap_srgb8(c.r / mean), tonemap_srgb8(c.g / mean), tonemap_srgb8(c.b / mean)};
                canvas.set(label_w + pad + x, y0 + y, p);
                if (with_error) canvas.set(label_w + 2 * pad + sw + x, y0 + y, negative ? magenta : scale.colour(error_of(rec, i)));
            }
    };
    draw_row(0, "reference", ref, false);
    for (size_t c = 0; c < codecs.size(); ++c) draw_row(static_cast<int>(c) + 1, std::string(codecs[c]->name), recs[c], true);
    // Legend: the error scale (three decades, four bands each) and the negative marker.
    const int ly = canvas.height() - legend_h + 8, bx = label_w + 2 * pad + sw;
    for (int x = 0; x < sw; ++x) canvas.fill_rect(bx + x, ly, 1, 12, ErrorScale::band_colour((x + 0.5) / sw));
    for (int d = 0; d <= 3; ++d) {
        const int x = bx + d * (sw - 1) / 3;
        canvas.fill_rect(x, ly + 12, 1, 5, white);
        const std::string t = percent_text(scale.top * std::pow(10.0, d - 3));
        const int w = Canvas::text_width(t, 14);
        canvas.text(std::min(x - w / 2, canvas.width() - 2 - w), ly + 18, t, 14, white);
    }
    canvas.text(bx, ly + 36, "error / mean irradiance, log scale", 14, white);
    canvas.fill_rect(label_w + pad, ly, 12, 12, magenta);
    canvas.text(label_w + pad + 18, ly - 3, "negative", text_px, white);
    const std::string out = (fs::path(dir) / (fs::path(input.path).stem().string() + ".png")).string();
    return write_png(out, canvas);
}

}  // namespace zhc
