#include "geometry/fill.h"

#include <algorithm>
#include <cmath>

namespace vr {

namespace {

// An edge from its lower to its upper end; `winding` +1 if the contour runs upwards along it.
struct Edge {
    Vec2 lo, hi;
    int winding = 0;
    // x where the edge meets height y (lo.y <= y <= hi.y); the ends are returned exactly, so
    // slabs meeting at an end agree on its position.
    double x_at(double y) const {
        if (y <= lo.y) return lo.x;
        if (y >= hi.y) return hi.x;
        return lo.x + (y - lo.y) * ((hi.x - lo.x) / (hi.y - lo.y));
    }
};

std::vector<Edge> edges_of(const std::vector<std::vector<Vec2>>& contours) {
    std::vector<Edge> edges;
    for (const auto& c : contours) {
        const bool finite = std::all_of(c.begin(), c.end(), [](const Vec2& p) {
            return std::isfinite(p.x) && std::isfinite(p.y);
        });
        if (!finite || c.size() < 3) continue;
        for (size_t i = 0; i < c.size(); ++i) {
            const Vec2 a = c[i], b = c[(i + 1) % c.size()];
            if (a.y == b.y) continue;  // horizontal edges bound no slab's side
            edges.push_back(a.y < b.y ? Edge{a, b, 1} : Edge{b, a, -1});
        }
    }
    return edges;
}

// Every vertex height, and the heights where two edges cross strictly inside both.
std::vector<double> slab_heights(const std::vector<Edge>& edges) {
    std::vector<double> ys;
    for (const Edge& e : edges) {
        ys.push_back(e.lo.y);
        ys.push_back(e.hi.y);
    }
    for (size_t i = 0; i < edges.size(); ++i) {
        for (size_t j = i + 1; j < edges.size(); ++j) {
            const Edge &a = edges[i], &b = edges[j];
            const double y0 = std::max(a.lo.y, b.lo.y), y1 = std::min(a.hi.y, b.hi.y);
            if (!(y0 < y1)) continue;
            const double d0 = a.x_at(y0) - b.x_at(y0), d1 = a.x_at(y1) - b.x_at(y1);
            if ((d0 < 0.0 && d1 > 0.0) || (d0 > 0.0 && d1 < 0.0))
                ys.push_back(y0 + (y1 - y0) * (d0 / (d0 - d1)));
        }
    }
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    return ys;
}

void add_trapezoid(FlatTriangles& out, const Edge& l, const Edge& r, double y0, double y1) {
    const Vec2 l0(l.x_at(y0), y0), r0(r.x_at(y0), y0), r1(r.x_at(y1), y1), l1(l.x_at(y1), y1);
    auto tri = [&](Vec2 a, Vec2 b, Vec2 c) {
        if ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) <= 0.0) return;  // no area
        const uint32_t base = static_cast<uint32_t>(out.points.size());
        out.points.insert(out.points.end(), {a, b, c});
        out.triangles.insert(out.triangles.end(), {base, base + 1, base + 2});
    };
    tri(l0, r0, r1);
    tri(l0, r1, l1);
}

}  // namespace

FlatTriangles fill_nonzero(const std::vector<std::vector<Vec2>>& contours) {
    FlatTriangles out;
    const std::vector<Edge> edges = edges_of(contours);
    const std::vector<double> ys = slab_heights(edges);
    std::vector<std::pair<double, const Edge*>> active;
    for (size_t s = 0; s + 1 < ys.size(); ++s) {
        const double y0 = ys[s], y1 = ys[s + 1], mid = 0.5 * (y0 + y1);
        active.clear();
        for (const Edge& e : edges)
            if (e.lo.y <= y0 && e.hi.y >= y1) active.emplace_back(e.x_at(mid), &e);
        std::sort(active.begin(), active.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        int winding = 0;
        const Edge* left = nullptr;
        for (const auto& [x, e] : active) {
            const int before = winding;
            winding += e->winding;
            if (before == 0 && winding != 0) left = e;
            if (before != 0 && winding == 0) add_trapezoid(out, *left, *e, y0, y1);
        }
    }
    return out;
}

}  // namespace vr
