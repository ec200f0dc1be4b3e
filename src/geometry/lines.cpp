#include "geometry/lines.h"

#include <cmath>

#include "geometry/nurbs.h"

namespace vr {

namespace {

struct Corner {
    int64_t coord = -1, color = -1;
};

// Polylines as (coordinate, colour) index lists, before any check.
std::vector<std::vector<Corner>> corners_of(const sg::LineSet& l, NodeReport& report) {
    std::vector<std::vector<Corner>> out;
    const bool colored = !l.colors.empty();
    if (l.kind == sg::LineKind::Points) {
        for (size_t i = 0; i < l.coords.size(); ++i)
            out.push_back({{int64_t(i), colored ? int64_t(i) : -1}});
        return out;
    }
    if (l.kind == sg::LineKind::Strips) {
        size_t next = 0;
        for (int32_t count : l.vertex_count) {
            if (count < 2) {
                report.warn("vertex-count", "vertexCount values below 2 are skipped");
                continue;
            }
            if (next + size_t(count) > l.coords.size()) {
                report.warn("vertex-count",
                            "vertexCount asks for more coordinates than there are; the rest is "
                            "not drawn");
                break;
            }
            out.emplace_back();
            for (int32_t k = 0; k < count; ++k, ++next)
                out.back().push_back({int64_t(next), colored ? int64_t(next) : -1});
        }
        return out;
    }
    out.emplace_back();
    size_t polyline = 0;
    for (size_t j = 0; j < l.coord_index.size(); ++j) {
        if (l.coord_index[j] < 0) {
            if (!out.back().empty()) ++polyline;
            out.emplace_back();
            continue;
        }
        Corner c{l.coord_index[j], -1};
        if (colored && l.color_per_vertex)
            c.color = l.color_index.empty()      ? c.coord
                      : j < l.color_index.size() ? l.color_index[j]
                                                 : l.colors.size();  // too few: out of range
        if (colored && !l.color_per_vertex)
            c.color = l.color_index.empty()             ? int64_t(polyline)
                      : polyline < l.color_index.size() ? l.color_index[polyline]
                                                        : l.colors.size();
        out.back().push_back(c);
    }
    return out;
}

}  // namespace

Polylines line_geometry(const sg::LineSet& l, NodeReport& report) {
    Polylines out;
    if (l.kind == sg::LineKind::Curve) {  // NurbsCurve: one polyline, the material's colour
        if (l.curve) out.positions = curve_polyline(*l.curve, report, "NurbsCurve");
        if (out.positions.size() >= 2)
            out.starts.push_back(0);
        else
            out.positions.clear();
        return out;
    }
    out.points = l.kind == sg::LineKind::Points;
    const std::vector<std::vector<Corner>> polylines = corners_of(l, report);
    bool colors_ok = !l.colors.empty();
    for (const auto& p : polylines)
        for (const Corner& c : p)
            if (colors_ok && (c.color < 0 || c.color >= int64_t(l.colors.size()))) {
                report.warn("color-index-range",
                            "colour indices out of range or too few; the material's colour is "
                            "used");
                colors_ok = false;
            }
    auto usable = [&](const Corner& c) {
        if (c.coord < 0 || c.coord >= int64_t(l.coords.size())) {
            report.warn("coord-index-range",
                        "coordinate index out of range; the polyline is broken there");
            return false;
        }
        const Vec3& p = l.coords[size_t(c.coord)];
        return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    };
    for (const auto& p : polylines) {
        bool open = false;  // a polyline has been started and not broken since
        for (const Corner& c : p) {
            if (!usable(c)) {
                open = false;
                continue;
            }
            if (!open && !out.points) out.starts.push_back(uint32_t(out.positions.size()));
            open = true;
            out.positions.push_back(l.coords[size_t(c.coord)]);
            if (colors_ok) out.colors.push_back(l.colors[size_t(c.color)]);
            if (colors_ok && l.alphas.size() == l.colors.size())
                out.alphas.push_back(l.alphas[size_t(c.color)]);
        }
    }
    return out;
}

}  // namespace vr
