// Node tree -> typed scene for X3D Layering (clause 35), Layout (clause 36), ClipPlane (11.4.1)
// and LocalFog (24.4.3); docs/rendering.md "Layers" and "ClipPlane" say how they are drawn.
#include <algorithm>
#include <cmath>

#include "scene/build_internal.h"

namespace vr::detail {

namespace {

sg::LayoutUnits units_of(const std::string& s) {
    if (s == "FRACTION") return sg::LayoutUnits::Fraction;
    if (s == "PIXEL") return sg::LayoutUnits::Pixel;
    return sg::LayoutUnits::World;
}

sg::LayoutScale scale_of(const std::string& s) {
    if (s == "FRACTION") return sg::LayoutScale::Fraction;
    if (s == "STRETCH") return sg::LayoutScale::Stretch;
    if (s == "PIXEL") return sg::LayoutScale::Pixel;
    return sg::LayoutScale::None;
}

// An MFString of one or two values (X3D 36.4.2: one value applies to both axes).
std::array<std::string, 2> two_of(const std::vector<std::string>& v, const char* fallback) {
    if (v.empty()) return {fallback, fallback};
    return {v[0], v.size() > 1 ? v[1] : v[0]};
}

Vec2 two_numbers(const std::vector<double>& v, double fallback) {
    if (v.empty()) return Vec2(fallback);
    return Vec2(v[0], v.size() > 1 ? v[1] : v[0]);
}

}  // namespace

void Builder::read_group_layout(NodeId id, sg::Group& group) {
    const NodeTypeDecl* decl = tree_.decl(id);
    if (!decl || !decl->find("layout"_n)) return;  // a Layer: no layout field
    const NodeId l = node(id, "layout"_n);
    if (l == kNullNode) return;
    if (type(l) != "Layout"_n) {
        warn(l, "layout-type", "is not a Layout; the group is not laid out");
        return;
    }
    sg::Layout out;
    // One align value names one axis by its word (X3D 36.4.2: "LEFT" alone is LEFT CENTER).
    std::vector<std::string> align = strings(l, "align"_n);
    if (align.size() == 1) {
        const std::string& a = align[0];
        align = a == "TOP" || a == "BOTTOM" ? std::vector<std::string>{"CENTER", a}
                                            : std::vector<std::string>{a, "CENTER"};
    }
    const auto a = two_of(align, "CENTER");
    out.align[0] = int8_t(a[0] == "LEFT" ? -1 : a[0] == "RIGHT" ? 1 : 0);
    out.align[1] = int8_t(a[1] == "BOTTOM" ? -1 : a[1] == "TOP" ? 1 : 0);
    out.offset = two_numbers(numbers(l, "offset"_n), 0.0);
    out.size = two_numbers(numbers(l, "size"_n), 1.0);
    const auto ou = two_of(strings(l, "offsetUnits"_n), "WORLD");
    const auto su = two_of(strings(l, "sizeUnits"_n), "WORLD");
    const auto sm = two_of(strings(l, "scaleMode"_n), "NONE");
    for (int i = 0; i < 2; ++i) {
        out.offset_units[i] = units_of(ou[i]);
        out.size_units[i] = units_of(su[i]);
        out.scale_mode[i] = scale_of(sm[i]);
    }
    if (!std::isfinite(out.offset.x + out.offset.y + out.size.x + out.size.y)) {
        warn(l, "layout-value", "has a NaN or infinite offset or size; the group is not laid out");
        return;
    }
    group.transform_kind = sg::GroupTransform::Layout;
    group.transform = static_cast<sg::Index>(scene_.layouts.size());
    scene_.layouts.push_back(out);
}

void Builder::make_layer_set(NodeId id) {
    if (!scene_.layers.empty()) {
        warn(id, "second-layer-set", "is a second LayerSet; only the first is drawn");
        return;
    }
    sg::Layer root;
    root.origin = origin(id);
    root.group = Scene::kRoot;
    std::vector<sg::Layer> layers{root};
    for (const NodeId l : nodes(id, "layers"_n)) {
        sg::Layer layer;
        if (l != kNullNode && (type(l) == "Layer"_n || type(l) == "LayoutLayer"_n)) {
            layer.origin = origin(l);
            layer.layout = type(l) == "LayoutLayer"_n;
            if (boolean(l, "visible"_n)) layer.group = make_group(l);
            const NodeId v = node(l, "viewport"_n);
            if (v != kNullNode && type(v) == "Viewport"_n) {
                const std::vector<double> c = numbers(v, "clipBoundary"_n);
                const bool ok = c.size() == 4 &&
                                std::all_of(c.begin(), c.end(),
                                            [](double x) { return x >= 0.0 && x <= 1.0; }) &&
                                c[0] < c[1] && c[2] < c[3];
                if (ok)
                    layer.clip = {c[0], c[1], c[2], c[3]};
                else
                    warn(v, "clip-boundary",
                         "clipBoundary is not 4 values 0 <= left < right <= 1, 0 <= bottom < "
                         "top <= 1; the layer is not clipped");
            } else if (v != kNullNode) {
                warn(v, "viewport-type", "is not a Viewport; the layer is not clipped");
            }
        } else if (l != kNullNode) {
            warn(l, "layer-type", "is not a Layer or LayoutLayer; nothing drawn for it");
        }
        layers.push_back(layer);  // kept, so that `order` indices count it
    }
    for (const int32_t k : integers(id, "order"_n)) {
        if (k >= 0 && size_t(k) < layers.size()) {
            scene_.layer_order.push_back(uint32_t(k));
        } else {
            warn(id, "layer-order",
                 "order names layer " + std::to_string(k) + ", which does not exist (0 to " +
                     std::to_string(layers.size() - 1) + "); skipped");
        }
    }
    const int32_t active = integer(id, "activeLayer"_n);
    scene_.active_layer = active >= 0 && size_t(active) < layers.size() ? uint32_t(active) : 0;
    scene_.layers = std::move(layers);
}

std::optional<sg::ChildRef> Builder::make_clip_plane(NodeId id) {
    if (!boolean(id, "enabled"_n)) return std::nullopt;
    const FieldView v = read(id, "plane"_n, Many::SF, {ValueKind::Vec4f, ValueKind::Vec4d});
    if (v.numbers.size() < 4) return std::nullopt;
    const Vec4 plane(v.numbers[0], v.numbers[1], v.numbers[2], v.numbers[3]);
    const double n = std::sqrt(plane.x * plane.x + plane.y * plane.y + plane.z * plane.z);
    if (!(n > 0.0) || !std::isfinite(n) || !std::isfinite(plane.w)) {
        warn(id, "plane", "plane has a zero or non-finite normal; the ClipPlane is ignored");
        return std::nullopt;
    }
    scene_.clip_planes.push_back(sg::ClipPlane{origin(id), plane});
    return sg::ChildRef{sg::NodeKind::ClipPlane, sg::Index(scene_.clip_planes.size() - 1)};
}

std::optional<sg::ChildRef> Builder::make_local_fog(NodeId id) {
    if (!boolean(id, "enabled"_n)) return std::nullopt;
    return sg::ChildRef{sg::NodeKind::LocalFog, make_fog(id)};
}

}  // namespace vr::detail
