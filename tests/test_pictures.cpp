// The PNG pictures: text in DejaVu Sans rendered with stb_truetype (proportional and anti-aliased),
// PNGs through libpng that decode (stb_image) to the canvas's pixels and are smaller than
// stb_image_write's for the same pixels; `zhc audit --images` and the demo's images.
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <set>

#include "formats/report/html_report.h"
#include "formats/report/raster.h"
#include "support.h"

namespace fs = std::filesystem;
using namespace zhc;

namespace {

struct Ink {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  // bounding box of non-background pixels
    size_t partial = 0, full = 0;                     // pixels between background and ink; pure ink
    int height() const { return y1 >= y0 ? y1 - y0 + 1 : 0; }
    int width() const { return x1 >= x0 ? x1 - x0 + 1 : 0; }
};

// Black text on white: where the ink is and how many pixels are anti-aliased.
Ink ink_of(const Canvas& c) {
    Ink k;
    const auto& px = c.pixels();
    for (int y = 0; y < c.height(); ++y)
        for (int x = 0; x < c.width(); ++x) {
            const std::uint8_t v = px[(static_cast<size_t>(y) * c.width() + x) * 3];
            EXPECT_EQ(v, px[(static_cast<size_t>(y) * c.width() + x) * 3 + 1]);  // grey: text colour over background
            if (v == 255) continue;
            k.x0 = std::min(k.x0, x), k.y0 = std::min(k.y0, y), k.x1 = std::max(k.x1, x), k.y1 = std::max(k.y1, y);
            (v == 0 ? k.full : k.partial)++;
        }
    return k;
}

Ink render(const std::string& s, int size) {
    Canvas c(400, 3 * size, {255, 255, 255});
    c.text(10, size / 2, s, size, {0, 0, 0});
    return ink_of(c);
}

std::vector<std::uint8_t> stb_png(const Canvas& c) {
    std::vector<std::uint8_t> out;
    auto sink = [](void* ctx, void* data, int n) {
        auto* o = static_cast<std::vector<std::uint8_t>*>(ctx);
        o->insert(o->end(), static_cast<std::uint8_t*>(data), static_cast<std::uint8_t*>(data) + n);
    };
    stbi_write_png_to_func(sink, &out, c.width(), c.height(), 3, c.pixels().data(), c.width() * 3);
    return out;
}

}  // namespace

TEST(Pictures, TextIsDejaVuSansNotThe3x5Font) {
    // A capital H at 24 px: DejaVu's cap height is 0.729 em and 24 px spans ascender to descender
    // (1.164 em), so the H is about 15 px tall; the 3x5 font drew 5 rows per scale step.
    const Ink h = render("H", 24);
    EXPECT_GE(h.height(), 14);
    EXPECT_LE(h.height(), 16);
    // Lower case is lower case (the 3x5 font drew it as upper case): x-height 0.547 em < cap 0.729 em.
    const Ink x = render("x", 24), X = render("X", 24);
    EXPECT_LT(x.height() + 3, X.height());
    // Anti-aliased: a round letter has many partial-coverage pixels (the 3x5 font had none).
    const Ink o = render("O", 24);
    EXPECT_GT(o.partial, 20u);
    EXPECT_GT(o.full, 10u);
    // Proportional: four i's are much narrower than four M's (a monospaced font fails this).
    EXPECT_LT(Canvas::text_width("iiii", 20) * 2, Canvas::text_width("MMMM", 20));
    // The advance text() returns is text_width's, and it grows with the size.
    Canvas c(300, 40);
    EXPECT_EQ(c.text(0, 0, "zhc audit 12.5%", 17, {0, 0, 0}), Canvas::text_width("zhc audit 12.5%", 17));
    EXPECT_GT(Canvas::text_width("zhc audit", 34), Canvas::text_width("zhc audit", 17) * 3 / 2);
    // Descenders go below the baseline: "g" reaches lower than "a".
    EXPECT_GT(render("g", 24).y1, render("a", 24).y1 + 3);
    // Deterministic, and total on bad input (invalid UTF-8, empty, huge or zero size, off-canvas).
    Canvas a(120, 30), b(120, 30);
    a.text(3, 3, "sh3_q28 \xC3\xA9 \xFF\xFE \xE2\x82", 16, {10, 20, 30});
    b.text(3, 3, "sh3_q28 \xC3\xA9 \xFF\xFE \xE2\x82", 16, {10, 20, 30});
    EXPECT_EQ(a.pixels(), b.pixels());
    EXPECT_EQ(a.text(0, 0, "", 16, {}), 0);
    EXPECT_EQ(a.text(0, 0, "x", 0, {}), 0);
    EXPECT_EQ(a.text(0, 0, "x", 100000, {}), 0);
    a.text(-500, -500, "off the canvas", 40, {});
    a.text(100, 25, "partly off", 40, {});
}

TEST(Pictures, PngDecodesToTheCanvasAndIsSmallerThanStb) {
    // A picture like the audit strips: a smooth gradient, banded heat map, text.
    Canvas c(320, 200, {32, 32, 36});
    for (int y = 0; y < 100; ++y)
        for (int x = 0; x < 320; ++x)
            c.set(x, y, {tonemap_srgb8(0.2 + x / 200.0), tonemap_srgb8(0.3 + y / 150.0), tonemap_srgb8(0.5)});
    ErrorScale s;
    s.top = 0.3;
    for (int y = 100; y < 170; ++y)
        for (int x = 0; x < 320; ++x) c.set(x, y, s.colour(0.3 * std::exp(-0.02 * std::hypot(x - 160.0, y - 135.0))));
    c.text(6, 172, "reference  sh2  zh3_lum  12.5%", 18, {235, 235, 235});
    const std::vector<std::uint8_t> png = png_bytes_rgb8(c.pixels().data(), c.pixels().size(), c.width(), c.height());
    ASSERT_FALSE(png.empty());
    auto back = decode_image_rgb8(png);  // stb_image: an independent decoder
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->width, 320);
    EXPECT_EQ(back->height, 200);
    EXPECT_EQ(back->rgb, c.pixels());
    const std::vector<std::uint8_t> stb = stb_png(c);
    EXPECT_LT(png.size(), stb.size()) << "libpng " << png.size() << " vs stb " << stb.size();
    // Bad sizes are refused, not read out of bounds.
    EXPECT_TRUE(png_bytes_rgb8(c.pixels().data(), c.pixels().size() - 1, 320, 200).empty());
    EXPECT_TRUE(png_bytes_rgb8(nullptr, 0, 0, 0).empty());
    EXPECT_TRUE(png_bytes_rgb8(c.pixels().data(), c.pixels().size(), 1 << 15, 1).empty());
}

TEST(Pictures, AuditImagesAreReadableAndCompact) {
    const std::string dir = zhc::test::fresh_dir("pictures_audit");
    const auto r = zhc::test::run_zhc({"audit", std::string(ZHC_ENVMAP_DIR) + "/city.exr", "--representations", "sh3,sh2,zh3_lum",
                                       "--no-timing", "--directions", "256", "--images", dir});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::vector<std::uint8_t> png = zhc::test::read_bytes(dir + "/city.png");
    auto img = decode_image_rgb8(png);
    ASSERT_TRUE(img.ok());
    // Four rows (reference + 3) of 128-pixel strips plus title and legend.
    EXPECT_GT(img->height, 4 * 128);
    EXPECT_GT(img->width, 2 * 256);
    // Text is anti-aliased: grey levels between the background (32,32,36) and the text (235) in the
    // label column, where only text is drawn.
    std::set<int> greys;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < 160; ++x) {
            const std::uint8_t* p = &img->rgb[(static_cast<size_t>(y) * img->width + x) * 3];
            if (p[0] == p[1] && p[0] > 40 && p[0] < 230) greys.insert(p[0]);
        }
    EXPECT_GT(greys.size(), 30u);
    // Smaller than stb_image_write's PNG of the same pixels.
    Canvas same(img->width, img->height);
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) {
            const std::uint8_t* p = &img->rgb[(static_cast<size_t>(y) * img->width + x) * 3];
            same.set(x, y, {p[0], p[1], p[2]});
        }
    EXPECT_LT(png.size(), stb_png(same).size() * 9 / 10);
    // The three error strips are told apart (a shared log scale with bands, not one saturated
    // colour): pixel by pixel, a good part of each pair differs in colour.
    const int label_w = 170, pad = 8, title_h = 34, sh = 128, sw = 256;
    auto error_px = [&](int row, int x, int y) {
        return &img->rgb[(static_cast<size_t>(title_h + row * (sh + pad) + y) * img->width + label_w + 2 * pad + sw + x) * 3];
    };
    for (int a = 1; a <= 3; ++a)
        for (int b = a + 1; b <= 3; ++b) {
            size_t differ = 0;
            for (int y = 0; y < sh; ++y)
                for (int x = 0; x < sw; ++x) {
                    const std::uint8_t *p = error_px(a, x, y), *q = error_px(b, x, y);
                    if (std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 30) ++differ;
                }
            EXPECT_GT(differ, static_cast<size_t>(sh * sw / 4)) << "error strips " << a << " and " << b << " look alike";
        }
}

// Long representation names and file names fit: the label column widens to the longest label
// (zh3_solved_channel_q16 is wider than the 170-pixel default) and the canvas to the title, so no
// label runs under its strip and no title runs off the picture.
TEST(Pictures, AuditImagesFitLongLabelsAndTitles) {
    const std::string dir = zhc::test::fresh_dir("pictures_audit_labels");
    const std::string map = dir + "/a_map_with_a_rather_long_file_name_for_the_title_line.hdr";
    fs::copy_file(std::string(ZHC_TEST_DATA_DIR) + "/hdr/simple-rle.hdr", map);
    const auto r = zhc::test::run_zhc({"audit", map, "--representations", "sh3,zh3_solved_channel_q16,zh3_solved_channel", "--no-timing",
                                       "--directions", "64", "--images", dir + "/img"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    auto img = decode_image_rgb8(zhc::test::read_bytes(dir + "/img/a_map_with_a_rather_long_file_name_for_the_title_line.png"));
    ASSERT_TRUE(img.ok());
    const int text_px = 17, pad = 8, title_h = 34, sh = 128, sw = 256;
    const int widest = Canvas::text_width("zh3_solved_channel_q16", text_px);
    ASSERT_GT(pad + widest + pad, 170);  // the default column would clip it
    const int label_w = pad + widest + pad;
    auto px = [&](int x, int y) { return &img->rgb[(static_cast<size_t>(y) * img->width + x) * 3]; };
    auto background = [&](int x, int y) {
        const std::uint8_t* p = px(x, y);
        return p[0] == 32 && p[1] == 32 && p[2] == 36;
    };
    for (int row = 0; row < 4; ++row) {
        SCOPED_TRACE(row);
        const int y0 = title_h + row * (sh + pad);
        // The label's ink ends before the column does; the gap before the strip is empty.
        int right = -1;
        for (int y = y0; y < y0 + sh; ++y)
            for (int x = 0; x < label_w + pad; ++x)
                if (!background(x, y)) right = std::max(right, x);
        EXPECT_GT(right, pad);           // a label is drawn
        EXPECT_LT(right, label_w - 1);   // and ends inside its column
        // The strip starts right after the gap.
        EXPECT_FALSE(background(label_w + pad, y0 + sh / 2));
        EXPECT_FALSE(background(label_w + pad + sw - 1, y0 + sh / 2));
    }
    // The title's ink stays inside the picture with room to spare.
    int title_right = -1;
    for (int y = 0; y < title_h; ++y)
        for (int x = 0; x < img->width; ++x)
            if (!background(x, y)) title_right = std::max(title_right, x);
    EXPECT_GT(title_right, label_w + sw);  // the long title is wider than the strips' start
    EXPECT_LT(title_right, img->width - pad / 2);
}
