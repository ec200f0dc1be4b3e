// X3D layers (one flat scene each, docs/rendering.md "Layers"), Layout's rectangles, and the scopes
// of ClipPlane and LocalFog.
#include <algorithm>
#include <cmath>

#include "flatten/flattener.h"
#include "scene/transform.h"

namespace vr::flatten_detail {

namespace {

double in_units(double value, sg::LayoutUnits units, double parent, double pixel) {
    switch (units) {
        case sg::LayoutUnits::Fraction:
            return value * parent;
        case sg::LayoutUnits::Pixel:
            return value * pixel;
        case sg::LayoutUnits::World:
            break;
    }
    return value;
}

}  // namespace

void add_stats(FlattenStats& to, const FlattenStats& s) {
    to.spheres += s.spheres, to.quadrics += s.quadrics, to.meshes += s.meshes;
    to.triangles += s.triangles, to.materials += s.materials, to.lights += s.lights;
    to.textures += s.textures, to.instances += s.instances;
    to.skipped_shapes += s.skipped_shapes, to.recovery_candidates += s.recovery_candidates;
    to.recovered_spheres += s.recovered_spheres;
    to.recovered_ellipsoids += s.recovered_ellipsoids;
    to.recovered_cylinders += s.recovered_cylinders;
    for (size_t i = 0; i < to.recovery_misses.size(); ++i)
        to.recovery_misses[i] += s.recovery_misses[i];
}

// X3D 36.4.2: the rectangle's size and offset in their units (FRACTION of the parent's, PIXEL, or
// the parent's WORLD units); align puts it at the parent's left/centre/right (bottom/centre/top)
// and the children's origin at its centre; scaleMode sets the children's unit (NONE: the
// parent's, FRACTION: the rectangle's size, PIXEL: a pixel, STRETCH: the other axis's scale).
Mat4 layout_matrix(const sg::Layout& layout, const LayoutRect& parent, LayoutRect& child) {
    Vec2 size, centre, scale;
    for (int i = 0; i < 2; ++i) {
        size[i] = in_units(layout.size[i], layout.size_units[i], parent.size[i], parent.pixel[i]);
        const double offset =
            in_units(layout.offset[i], layout.offset_units[i], parent.size[i], parent.pixel[i]);
        centre[i] = layout.align[i] * 0.5 * (parent.size[i] - size[i]) + offset;
        switch (layout.scale_mode[i]) {
            case sg::LayoutScale::Fraction:
                scale[i] = size[i];
                break;
            case sg::LayoutScale::Pixel:
                scale[i] = parent.pixel[i];
                break;
            default:
                scale[i] = 1.0;
                break;
        }
    }
    for (int i = 0; i < 2; ++i)
        if (layout.scale_mode[i] == sg::LayoutScale::Stretch)
            scale[i] = layout.scale_mode[1 - i] == sg::LayoutScale::Stretch ? 1.0 : scale[1 - i];
    for (int i = 0; i < 2; ++i)
        if (!(std::fabs(scale[i]) > 0.0) || !std::isfinite(scale[i])) scale[i] = 1.0;
    child.size = size / scale;
    child.pixel = parent.pixel / scale;
    Mat4 m(1.0);
    m[0][0] = scale.x;
    m[1][1] = scale.y;
    m[2][2] = std::min(scale.x, scale.y);  // depth keeps the smaller unit: shading stays sane
    m[3] = Vec4(centre.x, centre.y, 0.0, 1.0);
    return m;
}

uint32_t Flattener::enter_scope(std::span<const sg::ChildRef> children, const Mat4& m) {
    ShadingScope scope = out_.scopes[scope_];
    const Mat3 linear = linear_part(m);
    const Mat3 normal_map = glm::transpose(glm::inverse(linear));  // planes map by A^-T
    const Vec3 t(m[3]);
    for (const sg::ChildRef& c : children) {
        if (c.kind == sg::NodeKind::ClipPlane) {
            const Vec4& p = scene_.clip_planes[c.index].plane;
            const Vec3 n = normal_map * Vec3(p);
            const double length = glm::length(n);
            if (!(length > 0.0) || !std::isfinite(length)) continue;  // singular: build warned
            // n.(A^-1 (x - t)) + w >= 0  <=>  (A^-T n).x - (A^-T n).t + w >= 0
            scope.clip_planes.push_back(Vec4(n / length, (p.w - glm::dot(n, t)) / length));
        } else if (c.kind == sg::NodeKind::LocalFog) {
            out_.local_fogs.push_back(make_fog(scene_.fogs[c.index], m));
            scope.local_fog = int32_t(out_.local_fogs.size() - 1);
        }
    }
    out_.scopes.push_back(std::move(scope));
    return uint32_t(out_.scopes.size() - 1);
}

void Flattener::start_layer() {
    // A LayoutLayer's default OrthoViewpoint (X3D 36.4.3) spans -1..1 across the viewport's
    // smaller side: its WORLD units, and the size of its pixels in them.
    const Vec2 px = frame_.viewport_pixels;
    const double unit = px.x > 0.0 && px.y > 0.0 ? 2.0 / std::min(px.x, px.y) : 1.0;
    layout_rect_.pixel = Vec2(unit);
    layout_rect_.size = px.x > 0.0 && px.y > 0.0 ? px * unit : Vec2(2.0);
    if (frame_.layout && main_.viewpoints.empty() && inlined_.viewpoints.empty()) {
        Viewpoint v;
        v.def_name = "(LayoutLayer)";
        v.ortho = true;
        main_.viewpoints.push_back(v);
    }
}

}  // namespace vr::flatten_detail

namespace vr {

// Each layer in `order` flattened from its own group; the active one is the scene returned (the
// user's camera options apply to it), holding the drawing order.
FlatScene flatten_layers(const Scene& scene, const FlattenOptions& options,
                         Diagnostics& diagnostics, FlattenStats& stats) {
    std::vector<uint32_t> drawn;
    for (const uint32_t k : scene.layer_order)
        if (scene.layers[k].group != sg::kNone &&
            std::find(drawn.begin(), drawn.end(), k) == drawn.end())
            drawn.push_back(k);
    if (drawn.empty()) return FlatScene{};
    const uint32_t active = std::find(drawn.begin(), drawn.end(), scene.active_layer) != drawn.end()
                                ? scene.active_layer
                                : drawn.front();
    FlatScene main;
    std::vector<FlatLayer> layers;
    for (const uint32_t k : drawn) {
        const sg::Layer& layer = scene.layers[k];
        flatten_detail::LayerFrame frame;
        frame.root = layer.group;
        frame.layout = layer.layout;
        frame.viewport_pixels = Vec2((layer.clip[1] - layer.clip[0]) * options.image_width,
                                     (layer.clip[3] - layer.clip[2]) * options.image_height);
        FlattenOptions o = options;
        if (k != active) o.viewpoint.clear();  // --viewpoint names one of the active layer's
        FlattenStats s;
        flatten_detail::Flattener flattener(scene, o, diagnostics, s, frame);
        FlatScene flat = flattener.run();
        flatten_detail::add_stats(stats, s);
        FlatLayer entry;
        std::copy(layer.clip.begin(), layer.clip.end(), entry.clip);
        if (k == active)
            main = std::move(flat);
        else
            entry.scene = std::make_shared<const FlatScene>(std::move(flat));
        layers.push_back(std::move(entry));
    }
    if (!(layers.size() == 1 && layers[0].full())) main.layers = std::move(layers);
    return main;
}

}  // namespace vr
