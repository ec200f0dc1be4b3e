// Plot images for bench: sizes, what gets drawn, and robustness against bad data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "qa/plot.h"

namespace vr {
namespace {

// Pixels within 0.02 of `rgb` in every channel.
int count_color(const Image& im, const std::array<float, 3>& rgb) {
    int n = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const float* p = im.pixel(x, y);
            if (std::fabs(p[0] - rgb[0]) < 0.02f && std::fabs(p[1] - rgb[1]) < 0.02f &&
                std::fabs(p[2] - rgb[2]) < 0.02f)
                ++n;
        }
    return n;
}

TEST(ImagePlotTest, SizeBackgroundAndOpacity) {
    PlotOptions opt;
    opt.width = 320;
    opt.height = 200;
    opt.title = "title";
    const Image im = plot_series({}, opt);
    ASSERT_EQ(im.width, 320);
    ASSERT_EQ(im.height, 200);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(im.pixel(319, 199)[c], 1.0f);
    for (size_t i = 3; i < im.rgba.size(); i += 4) ASSERT_EQ(im.rgba[i], 1.0f);
    EXPECT_GT(count_color(im, {0, 0, 0}), 100);  // frame, ticks, labels
}

TEST(ImagePlotTest, SeriesAreDrawnInTheirColour) {
    PlotSeries s;
    s.label = "grid";
    s.x = {0.01, 0.1, 1.0};
    s.y = {0.1, 0.01, 0.001};
    s.color = {0.0f, 0.8f, 0.0f};
    const Image im = plot_series({s}, PlotOptions{});
    EXPECT_GT(count_color(im, s.color), 200);

    // Only invalid points on log axes: nothing of that colour but the legend sample.
    PlotSeries bad = s;
    bad.x = {-1.0, 0.0, std::numeric_limits<double>::quiet_NaN()};
    bad.label.clear();
    EXPECT_EQ(count_color(plot_series({bad}, PlotOptions{}), s.color), 0);
}

// Lines that end in the top right corner (bench/scale.sh's seconds against atoms) stay in view:
// the legend moves to a corner they leave empty.
TEST(ImagePlotTest, TheLegendHidesNoEndOfTheLines) {
    PlotSeries rising, flat;
    rising.label = "whole process";
    rising.x = {1e5, 1e6, 1e7};
    rising.y = {0.1, 1.0, 10.0};
    rising.color = {0.0f, 0.8f, 0.0f};
    flat.label = "render";
    flat.x = rising.x;
    flat.y = {0.3, 0.3, 0.3};
    flat.color = {0.8f, 0.0f, 0.8f};
    const Image im = plot_series({rising, flat}, PlotOptions{});
    // The rising line's pixels where a top right legend's labels would be (its colour sample is
    // further left).
    int top_right = 0;
    for (int y = 24; y < 45; ++y)
        for (int x = im.width - 70; x < im.width - 35; ++x) {
            const float* p = im.pixel(x, y);
            top_right += std::fabs(p[0]) < 0.02f && std::fabs(p[1] - 0.8f) < 0.02f && p[2] < 0.02f;
        }
    EXPECT_GT(top_right, 30);  // 69 here; 8 under a legend (the end of its colour sample)
    EXPECT_GT(count_color(im, flat.color), 200);
}

TEST(ImagePlotTest, LinearAxesAndPaletteColours) {
    PlotSeries a, b;
    a.x = {0, 1, 2};
    a.y = {5, 5, 5};  // a flat line: the range is padded
    b.x = {0, 2};
    b.y = {-1, 7};
    PlotOptions opt;
    opt.log_x = opt.log_y = false;
    const Image im = plot_series({a, b}, opt);
    ASSERT_EQ(im.width, opt.width);
    // Unlabelled series without a colour take the palette's first and second colours (plot.cpp),
    // and each is drawn as a line across the plot: an 800-pixel-wide plot gives hundreds of its
    // pixels.
    const std::array<float, 3> first{0.12f, 0.40f, 0.75f}, second{0.90f, 0.45f, 0.05f};
    EXPECT_GT(count_color(im, first), 200);
    EXPECT_GT(count_color(im, second), 200);
    // The flat line's range is padded, so it lies inside the plot, not on its top or bottom frame.
    int top = im.height, bottom = -1;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const float* p = im.pixel(x, y);
            if (std::fabs(p[0] - first[0]) < 0.02f && std::fabs(p[1] - first[1]) < 0.02f &&
                std::fabs(p[2] - first[2]) < 0.02f) {
                top = std::min(top, y);
                bottom = std::max(bottom, y);
            }
        }
    EXPECT_GT(top, im.height / 10);
    EXPECT_LT(bottom, im.height * 9 / 10);
    // One horizontal line: anti-aliased over a few rows, with the point markers (about 10 pixels
    // across) standing out of it.
    EXPECT_LE(bottom - top, 12);
}

TEST(ImagePlotTest, DegenerateInputsDoNotCrash) {
    PlotSeries s;
    s.x = {1e-300, 1e300, std::numeric_limits<double>::infinity(), 1.0};
    s.y = {1e-300, 1e300, 1.0};  // shorter than x
    PlotOptions opt;
    opt.width = 10;  // grown to the minimum size
    opt.height = 10;
    const Image im = plot_series({s}, opt);
    EXPECT_GE(im.width, 10);
    EXPECT_GE(im.height, 10);

    // Linear axes with ranges that defeat stepping: huge offsets, the whole double range.
    PlotOptions lin;
    lin.log_x = lin.log_y = false;
    PlotSeries far;
    far.x = {1e17, 1e17 + 64};
    far.y = {-1.7e308, 1.7e308};
    EXPECT_EQ(plot_series({far}, lin).width, lin.width);
}

TEST(ImagePlotTest, TextWidthAndClipping) {
    EXPECT_EQ(text_width("", 1), 0);
    EXPECT_EQ(text_width("abc", 1), 17);
    EXPECT_EQ(text_width("abc", 2), 34);
    Image im(40, 10);
    for (float& v : im.rgba) v = 1.0f;
    EXPECT_EQ(draw_text(im, 1, 1, "   ", 1, {0, 0, 0}), 17);
    EXPECT_EQ(count_color(im, {0, 0, 0}), 0);
    draw_text(im, 1, 1, "E", 1, {0, 0, 0});
    EXPECT_EQ(count_color(im, {0, 0, 0}), 5 + 1 + 1 + 4 + 1 + 1 + 5);
    draw_text(im, 35, 5, "WWWW\x01", 3, {0, 0, 0});  // off the edge: clipped, not a crash
}

}  // namespace
}  // namespace vr
