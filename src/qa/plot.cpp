// Line plots into an Image (see plot.h): axis ranges and ticks, coverage-based anti-aliased
// drawing, and a 5x7 bitmap font.
#include "qa/plot.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace vr {
namespace {

using Rgb = std::array<float, 3>;

// Glyphs for ASCII 32..126: seven rows, top first, five bits a row (bit 4 = leftmost column).
constexpr uint8_t kFont[95][7] = {
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},  // space
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04},  // !
    {0x0A, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00},  // "
    {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A},  // #
    {0x04, 0x0F, 0x14, 0x0E, 0x05, 0x1E, 0x04},  // $
    {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03},  // %
    {0x0C, 0x12, 0x14, 0x08, 0x15, 0x12, 0x0D},  // &
    {0x04, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00},  // '
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02},  // (
    {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08},  // )
    {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00},  // *
    {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00},  // +
    {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08},  // ,
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00},  // -
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C},  // .
    {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00},  // /
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E},  // 0
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},  // 1
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F},  // 2
    {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},  // 3
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},  // 4
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},  // 5
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E},  // 6
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},  // 7
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E},  // 8
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},  // 9
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00},  // :
    {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08},  // ;
    {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02},  // <
    {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00},  // =
    {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08},  // >
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04},  // ?
    {0x0E, 0x11, 0x01, 0x0D, 0x15, 0x15, 0x0E},  // @
    {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11},  // A
    {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E},  // B
    {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E},  // C
    {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C},  // D
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F},  // E
    {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10},  // F
    {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F},  // G
    {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},  // H
    {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E},  // I
    {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C},  // J
    {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11},  // K
    {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},  // L
    {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11},  // M
    {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11},  // N
    {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},  // O
    {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10},  // P
    {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D},  // Q
    {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},  // R
    {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E},  // S
    {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},  // T
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E},  // U
    {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04},  // V
    {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A},  // W
    {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11},  // X
    {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04},  // Y
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F},  // Z
    {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E},  // [
    {0x00, 0x10, 0x08, 0x04, 0x02, 0x01, 0x00},  // backslash
    {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E},  // ]
    {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00},  // ^
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F},  // _
    {0x08, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00},  // `
    {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F},  // a
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E},  // b
    {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E},  // c
    {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F},  // d
    {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E},  // e
    {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08},  // f
    {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E},  // g
    {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11},  // h
    {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E},  // i
    {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C},  // j
    {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12},  // k
    {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E},  // l
    {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11},  // m
    {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11},  // n
    {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E},  // o
    {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10},  // p
    {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01},  // q
    {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10},  // r
    {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E},  // s
    {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06},  // t
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D},  // u
    {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04},  // v
    {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A},  // w
    {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11},  // x
    {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E},  // y
    {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F},  // z
    {0x02, 0x04, 0x04, 0x08, 0x04, 0x04, 0x02},  // {
    {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},  // |
    {0x08, 0x04, 0x04, 0x02, 0x04, 0x04, 0x08},  // }
    {0x00, 0x00, 0x08, 0x15, 0x02, 0x00, 0x00},  // ~
};
constexpr int kCellW = 6, kCellH = 8;

// Distinct colours for series without their own.
constexpr Rgb kPalette[] = {{0.12f, 0.40f, 0.75f}, {0.90f, 0.45f, 0.05f}, {0.15f, 0.60f, 0.20f},
                            {0.80f, 0.12f, 0.15f}, {0.55f, 0.35f, 0.75f}, {0.50f, 0.30f, 0.25f},
                            {0.85f, 0.40f, 0.70f}, {0.40f, 0.40f, 0.40f}, {0.65f, 0.65f, 0.10f},
                            {0.10f, 0.70f, 0.75f}};

const Rgb kBlack{0, 0, 0};
const Rgb kWhite{1, 1, 1};
const Rgb kMajorGrid{0.82f, 0.82f, 0.82f};
const Rgb kMinorGrid{0.93f, 0.93f, 0.93f};

struct Rect {
    int x0, y0, x1, y1;  // inclusive-exclusive pixel bounds
};

// Mixes `color` into a pixel with the given coverage in [0,1].
void blend(Image& im, int x, int y, const Rgb& color, double coverage) {
    if (x < 0 || y < 0 || x >= im.width || y >= im.height || coverage <= 0) return;
    const float a = float(std::min(1.0, coverage));
    float* p = im.pixel(x, y);
    for (int c = 0; c < 3; ++c) p[c] = (1 - a) * p[c] + a * color[c];
}

void fill_rect(Image& im, Rect r, const Rgb& color) {
    for (int y = std::max(0, r.y0); y < std::min(im.height, r.y1); ++y)
        for (int x = std::max(0, r.x0); x < std::min(im.width, r.x1); ++x)
            blend(im, x, y, color, 1);
}

// A segment of the given width in pixel coordinates (pixel centres at +0.5); coverage falls off
// over one pixel at the edge. Only pixels inside `clip` are touched.
void draw_segment(Image& im, double ax, double ay, double bx, double by, double width,
                  const Rgb& color, Rect clip) {
    if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(bx) || !std::isfinite(by) ||
        std::max({std::fabs(ax), std::fabs(ay), std::fabs(bx), std::fabs(by)}) > 1e8)
        return;  // degenerate axis ranges; nothing sensible to draw
    const double half = 0.5 * width;
    const int x0 = std::max(clip.x0, int(std::floor(std::min(ax, bx) - half - 1)));
    const int x1 = std::min(clip.x1, int(std::ceil(std::max(ax, bx) + half + 1)));
    const int y0 = std::max(clip.y0, int(std::floor(std::min(ay, by) - half - 1)));
    const int y1 = std::min(clip.y1, int(std::ceil(std::max(ay, by) + half + 1)));
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const double px = x + 0.5 - ax, py = y + 0.5 - ay;
            const double t = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
            const double ex = px - t * dx, ey = py - t * dy;
            blend(im, x, y, color, half + 0.5 - std::sqrt(ex * ex + ey * ey));
        }
}

void draw_disc(Image& im, double cx, double cy, double radius, const Rgb& color, Rect clip) {
    draw_segment(im, cx, cy, cx, cy, 2 * radius, color, clip);
}

// One plot axis: the data range in plot space (log10 of the value on a log axis) mapped to pixels.
struct Axis {
    bool log = true;
    double lo = 0, hi = 1;      // plot-space range
    double p_lo = 0, p_hi = 1;  // pixel coordinates of lo and hi

    bool valid(double v) const { return std::isfinite(v) && (!log || v > 0); }
    double to_plot(double v) const { return log ? std::log10(v) : v; }
    double to_pixel(double v) const { return p_lo + (to_plot(v) - lo) / (hi - lo) * (p_hi - p_lo); }
    // The pixel of a plot-space value (a tick's).
    double plot_to_pixel(double plot_v) const {
        return p_lo + (plot_v - lo) / (hi - lo) * (p_hi - p_lo);
    }
};

// Where a legend of w x h pixels goes: the corner of the plot area (`margin` in from its edges)
// that covers the fewest of 50 points along each segment of the series and their markers; the top
// right when none covers fewer.
Rect legend_box(const std::vector<PlotSeries>& series, const Axis& ax, const Axis& ay,
                const Rect& area, int w, int h, int margin) {
    Rect best{};
    int hidden_least = INT_MAX;
    for (const auto& [right, top] : {std::pair{true, true}, std::pair{false, true},
                                     std::pair{true, false}, std::pair{false, false}}) {
        const int x0 = right ? area.x1 - margin - w : area.x0 + margin;
        const int y0 = top ? area.y0 + margin : area.y1 - margin - h;
        const Rect box{x0, y0, x0 + w, y0 + h};
        int hidden = 0;
        for (const PlotSeries& ser : series) {
            const size_t n = std::min(ser.x.size(), ser.y.size());
            for (size_t i = 0; i < n; ++i) {
                if (!ax.valid(ser.x[i]) || !ay.valid(ser.y[i])) continue;
                const double x = ax.to_pixel(ser.x[i]), y = ay.to_pixel(ser.y[i]);
                const bool next = i + 1 < n && ax.valid(ser.x[i + 1]) && ay.valid(ser.y[i + 1]);
                const double dx = next ? ax.to_pixel(ser.x[i + 1]) - x : 0.0;
                const double dy = next ? ay.to_pixel(ser.y[i + 1]) - y : 0.0;
                for (int k = 0; k < (next ? 50 : 1); ++k) {
                    const double px = x + k / 50.0 * dx, py = y + k / 50.0 * dy;
                    hidden += px >= box.x0 && px <= box.x1 && py >= box.y0 && py <= box.y1;
                }
            }
        }
        if (hidden < hidden_least) hidden_least = hidden, best = box;
    }
    return best;
}

// 1, 2 or 5 times a power of ten, the nearest at or above `raw`.
double nice_step(double raw) {
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0})
        if (m * p >= raw * (1 - 1e-12)) return m * p;
    return 10 * p;
}

// Sets lo/hi around the valid values of `values`.
void fit_axis(Axis& axis, const std::vector<double>& values) {
    double vmin = INFINITY, vmax = -INFINITY;
    for (double v : values)
        if (axis.valid(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    if (axis.log) {
        if (!(vmin <= vmax)) vmin = 1, vmax = 10;
        axis.lo = std::floor(std::log10(vmin));
        axis.hi = std::ceil(std::log10(vmax));
        if (axis.hi <= axis.lo) axis.hi = axis.lo + 1;
    } else {
        if (!(vmin <= vmax)) vmin = 0, vmax = 1;
        if (!std::isfinite(vmax - vmin)) vmin = -1e300, vmax = 1e300;
        if (vmin == vmax) {
            const double pad = vmin == 0 ? 1.0 : 0.1 * std::fabs(vmin);
            vmin -= pad, vmax += pad;
        }
        const double step = nice_step((vmax - vmin) / 5);
        axis.lo = std::floor(vmin / step) * step;
        axis.hi = std::ceil(vmax / step) * step;
    }
}

struct Tick {
    double value;  // plot space
    bool major;
};

std::vector<Tick> axis_ticks(const Axis& axis) {
    std::vector<Tick> ticks;
    if (axis.log) {
        const int decades = int(std::lround(axis.hi - axis.lo));
        const int every = std::max(1, (decades + 9) / 10);  // at most ~10 labelled decades
        for (int k = int(axis.lo); k <= int(axis.hi); ++k) {
            if ((k - int(axis.lo)) % every == 0) ticks.push_back({double(k), true});
            if (decades <= 6 && k < int(axis.hi))
                for (int m = 2; m <= 9; ++m) ticks.push_back({k + std::log10(double(m)), false});
        }
    } else {
        const double step = nice_step((axis.hi - axis.lo) / 5);
        const double n = std::round((axis.hi - axis.lo) / step);
        if (!(n >= 1 && n <= 100)) return {{axis.lo, true}, {axis.hi, true}};
        for (int i = 0; i <= int(n); ++i) {
            const double v = axis.lo + i * step;
            ticks.push_back({std::fabs(v) < step * 1e-9 ? 0.0 : v, true});
        }
    }
    return ticks;
}

std::string tick_label(const Axis& axis, double plot_value) {
    char buf[32];
    if (axis.log) {
        const int k = int(std::lround(plot_value));
        if (k >= -3 && k <= 4)
            std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, k));
        else
            std::snprintf(buf, sizeof buf, "1e%d", k);
    } else {
        std::snprintf(buf, sizeof buf, "%g", plot_value);
    }
    return buf;
}

// Vertical text reading upwards; (x, y) is the bottom left corner of the first character.
void draw_text_up(Image& im, int x, int y, const std::string& text, int scale, const Rgb& color) {
    int pen = 0;
    for (unsigned char ch : text) {
        const int g = (ch >= 32 && ch <= 126) ? ch - 32 : '?' - 32;
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col)
                if (kFont[g][row] & (0x10 >> col))
                    for (int sy = 0; sy < scale; ++sy)
                        for (int sx = 0; sx < scale; ++sx)
                            blend(im, x + row * scale + sy, y - (pen + col * scale + sx) - 1, color,
                                  1);
        pen += kCellW * scale;
    }
}

}  // namespace

int text_width(const std::string& text, int scale) {
    return text.empty() ? 0 : int(text.size()) * kCellW * scale - scale;
}

int draw_text(Image& image, int x, int y, const std::string& text, int scale, const Rgb& color) {
    int pen = x;
    for (unsigned char ch : text) {
        const int g = (ch >= 32 && ch <= 126) ? ch - 32 : '?' - 32;
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col)
                if (kFont[g][row] & (0x10 >> col))
                    for (int sy = 0; sy < scale; ++sy)
                        for (int sx = 0; sx < scale; ++sx)
                            blend(image, pen + col * scale + sx, y + row * scale + sy, color, 1);
        pen += kCellW * scale;
    }
    return text_width(text, scale);
}

namespace {

// A plot being drawn: the image, its axes, the plot area and the text scale.
struct Canvas {
    Image& im;
    Axis ax, ay;
    Rect area{};
    int s = 1;       // text scale
    int line_h = 0;  // a line of text's height
};

// Sets the axes' plot-space ranges around the series' valid points.
void fit_axes(const std::vector<PlotSeries>& series, Axis& ax, Axis& ay) {
    std::vector<double> xs, ys;
    for (const PlotSeries& ser : series) {
        const size_t n = std::min(ser.x.size(), ser.y.size());
        for (size_t i = 0; i < n; ++i)
            if (ax.valid(ser.x[i]) && ay.valid(ser.y[i]))
                xs.push_back(ser.x[i]), ys.push_back(ser.y[i]);
    }
    fit_axis(ax, xs);
    fit_axis(ay, ys);
}

void draw_grid(Canvas& c, const std::vector<Tick>& xticks, const std::vector<Tick>& yticks) {
    // Minor first.
    for (int pass = 0; pass < 2; ++pass) {
        const bool major = pass == 1;
        const Rgb& color = major ? kMajorGrid : kMinorGrid;
        for (const Tick& t : xticks)
            if (t.major == major)
                draw_segment(c.im, c.ax.plot_to_pixel(t.value), c.area.y0,
                             c.ax.plot_to_pixel(t.value), c.area.y1, 1, color, c.area);
        for (const Tick& t : yticks)
            if (t.major == major)
                draw_segment(c.im, c.area.x0, c.ay.plot_to_pixel(t.value), c.area.x1,
                             c.ay.plot_to_pixel(t.value), 1, color, c.area);
    }
}

// Each series' colour: its own, or the palette's next.
std::vector<Rgb> series_colors(const std::vector<PlotSeries>& series) {
    std::vector<Rgb> colors;
    size_t next_palette = 0;
    for (const PlotSeries& ser : series) {
        if (ser.color[0] >= 0 && ser.color[1] >= 0 && ser.color[2] >= 0)
            colors.push_back(ser.color);
        else
            colors.push_back(kPalette[next_palette++ % std::size(kPalette)]);
    }
    return colors;
}

// Lines, then markers on top.
void draw_series(Canvas& c, const std::vector<PlotSeries>& series, const std::vector<Rgb>& colors) {
    const Axis &ax = c.ax, &ay = c.ay;
    const int s = c.s;
    const Rect inside{c.area.x0 + 1, c.area.y0, c.area.x1, c.area.y1 - 1};
    for (size_t k = 0; k < series.size(); ++k) {
        const PlotSeries& ser = series[k];
        const size_t n = std::min(ser.x.size(), ser.y.size());
        for (size_t i = 0; i + 1 < n; ++i) {
            if (!ax.valid(ser.x[i]) || !ay.valid(ser.y[i]) || !ax.valid(ser.x[i + 1]) ||
                !ay.valid(ser.y[i + 1]))
                continue;
            draw_segment(c.im, ax.to_pixel(ser.x[i]), ay.to_pixel(ser.y[i]),
                         ax.to_pixel(ser.x[i + 1]), ay.to_pixel(ser.y[i + 1]), 1.5 * s, colors[k],
                         inside);
        }
        for (size_t i = 0; i < n; ++i)
            if (ax.valid(ser.x[i]) && ay.valid(ser.y[i]))
                draw_disc(c.im, ax.to_pixel(ser.x[i]), ay.to_pixel(ser.y[i]), 3.0 * s, colors[k],
                          inside);
    }
}

// Frame, ticks and their labels.
void draw_frame(Canvas& c, const std::vector<Tick>& xticks, const std::vector<Tick>& yticks) {
    Image& im = c.im;
    const Rect& area = c.area;
    const int s = c.s;
    const Rect all{0, 0, im.width, im.height};
    draw_segment(im, area.x0, area.y0, area.x1, area.y0, s, kBlack, all);
    draw_segment(im, area.x0, area.y1, area.x1, area.y1, s, kBlack, all);
    draw_segment(im, area.x0, area.y0, area.x0, area.y1, s, kBlack, all);
    draw_segment(im, area.x1, area.y0, area.x1, area.y1, s, kBlack, all);
    for (const Tick& t : xticks) {
        const double x = c.ax.plot_to_pixel(t.value);
        const int len = (t.major ? 6 : 3) * s;
        draw_segment(im, x, area.y1, x, area.y1 - len, s, kBlack, all);
        if (t.major) {
            const std::string label = tick_label(c.ax, t.value);
            draw_text(im, int(std::lround(x)) - text_width(label, s) / 2, area.y1 + 4 * s, label, s,
                      kBlack);
        }
    }
    for (const Tick& t : yticks) {
        const double y = c.ay.plot_to_pixel(t.value);
        const int len = (t.major ? 6 : 3) * s;
        draw_segment(im, area.x0, y, area.x0 + len, y, s, kBlack, all);
        if (t.major) {
            const std::string label = tick_label(c.ay, t.value);
            draw_text(im, area.x0 - 5 * s - text_width(label, s), int(std::lround(y)) - 7 * s / 2,
                      label, s, kBlack);
        }
    }
}

// Axis labels and title, centred on the plot area.
void draw_titles(Canvas& c, const PlotOptions& options) {
    const Rect& area = c.area;
    const int s = c.s;
    if (!options.x_label.empty())
        draw_text(c.im, (area.x0 + area.x1 - text_width(options.x_label, s)) / 2,
                  area.y1 + 4 * s + c.line_h + 2 * s, options.x_label, s, kBlack);
    if (!options.y_label.empty())
        draw_text_up(c.im, 4 * s, (area.y0 + area.y1 + text_width(options.y_label, s)) / 2,
                     options.y_label, s, kBlack);
    if (!options.title.empty())
        draw_text(c.im, (area.x0 + area.x1 - text_width(options.title, s)) / 2, 6 * s,
                  options.title, s, kBlack);
}

// The legend, in the corner where it hides the least of the series.
void draw_legend(Canvas& c, const std::vector<PlotSeries>& series, const std::vector<Rgb>& colors) {
    Image& im = c.im;
    const int s = c.s;
    const Rect all{0, 0, im.width, im.height};
    int legend_w = 0, entries = 0;
    for (const PlotSeries& ser : series)
        if (!ser.label.empty()) legend_w = std::max(legend_w, text_width(ser.label, s)), ++entries;
    if (entries == 0) return;
    const int sample_w = 20 * s, pad = 4 * s, row_h = c.line_h + 3 * s;
    const int box_w = legend_w + sample_w + 3 * pad, box_h = entries * row_h + 2 * pad - 3 * s;
    const Rect box = legend_box(series, c.ax, c.ay, c.area, box_w, box_h, 6 * s);
    fill_rect(im, box, kWhite);
    draw_segment(im, box.x0, box.y0, box.x1, box.y0, 1, kMajorGrid, all);
    draw_segment(im, box.x0, box.y1, box.x1, box.y1, 1, kMajorGrid, all);
    draw_segment(im, box.x0, box.y0, box.x0, box.y1, 1, kMajorGrid, all);
    draw_segment(im, box.x1, box.y0, box.x1, box.y1, 1, kMajorGrid, all);
    int row = 0;
    for (size_t k = 0; k < series.size(); ++k) {
        if (series[k].label.empty()) continue;
        const int top = box.y0 + pad + row * row_h;
        const double mid = top + 3.5 * s;
        draw_segment(im, box.x0 + pad, mid, box.x0 + pad + sample_w, mid, 1.5 * s, colors[k], all);
        draw_disc(im, box.x0 + pad + sample_w / 2.0, mid, 3.0 * s, colors[k], all);
        draw_text(im, box.x0 + 2 * pad + sample_w, top, series[k].label, s, kBlack);
        ++row;
    }
}

}  // namespace

Image plot_series(const std::vector<PlotSeries>& series, const PlotOptions& options) {
    const int w = std::max(64, options.width), h = std::max(64, options.height);
    Image im(w, h);
    for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
        for (int c = 0; c < 4; ++c) im.rgba[p * 4 + c] = 1.0f;

    Canvas c{im, Axis{}, Axis{}};
    c.s = std::max(1, int(std::lround(std::min(w, h) / 400.0)));
    c.line_h = kCellH * c.s;
    const int s = c.s, line_h = c.line_h;
    c.ax.log = options.log_x;
    c.ay.log = options.log_y;
    fit_axes(series, c.ax, c.ay);
    const std::vector<Tick> xticks = axis_ticks(c.ax), yticks = axis_ticks(c.ay);

    // Layout: room for the title above, tick labels and the axis label below and on the left.
    int ylabel_w = 0;
    for (const Tick& t : yticks)
        if (t.major) ylabel_w = std::max(ylabel_w, text_width(tick_label(c.ay, t.value), s));
    c.area = Rect{(options.y_label.empty() ? 0 : line_h + 4 * s) + ylabel_w + 10 * s,
                  options.title.empty() ? 8 * s : 2 * line_h + 4 * s, w - 12 * s,
                  h - (options.x_label.empty() ? 1 : 2) * line_h - 10 * s};
    if (c.area.x1 - c.area.x0 < 16 || c.area.y1 - c.area.y0 < 16) return im;
    c.ax.p_lo = c.area.x0, c.ax.p_hi = c.area.x1;
    c.ay.p_lo = c.area.y1, c.ay.p_hi = c.area.y0;  // up is smaller y

    draw_grid(c, xticks, yticks);
    const std::vector<Rgb> colors = series_colors(series);
    draw_series(c, series, colors);
    draw_frame(c, xticks, yticks);
    draw_titles(c, options);
    draw_legend(c, series, colors);
    return im;
}

}  // namespace vr
