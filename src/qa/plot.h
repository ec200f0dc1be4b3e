// Line plots drawn into an Image, for `vrmlray bench` (docs/manual.md, bench: error against time,
// log-log). Self-contained: a built-in 5x7 bitmap font, anti-aliased lines and markers, no system
// fonts.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "image/image.h"

namespace vr {

struct PlotSeries {
    std::string label;                       // shown in the legend; empty = not listed
    std::vector<double> x, y;                // same length; points are joined in the given order
    std::array<float, 3> color{-1, -1, -1};  // RGB in [0,1]; negative = the next palette colour
};

struct PlotOptions {
    int width = 800;
    int height = 600;
    std::string title;
    std::string x_label = "time (s)";
    std::string y_label = "RMSE";
    bool log_x = true;
    bool log_y = true;
};

// Draws the series on a white background with axes, grid, tick labels (whole decades on log axes),
// axis labels, title and a legend (in the corner that hides the least of the series). Points that
// are not finite, or not positive on a log axis, are left out and break the line there. Log axes
// span whole decades around the data, linear axes "nice" 1-2-5 steps. The image is opaque (alpha 1)
// and holds display values: write it without
// --srgb. Empty or invalid data still gives a plot with default ranges.
Image plot_series(const std::vector<PlotSeries>& series, const PlotOptions& options);

// Text drawing with the built-in font (ASCII 32..126; other bytes show as '?'). Each character is a
// 6x8 cell (5x7 glyph and spacing) times `scale`; (x, y) is the top left corner. Returns the width
// in pixels. Pixels outside the image are skipped.
int draw_text(Image& image, int x, int y, const std::string& text, int scale,
              const std::array<float, 3>& color);
int text_width(const std::string& text, int scale);

}  // namespace vr
