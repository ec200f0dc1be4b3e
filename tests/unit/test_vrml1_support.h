// Helpers for the VRML 1.0 tests: loading text, and flattening a node tree into shapes with world
// matrices computed here independently of the upgrade's own matrix code.
#pragma once
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "parser/load.h"

namespace vrml1_test {

using Mat = std::array<std::array<double, 4>, 4>;  // column vectors: p' = M·p

inline Mat identity() {
    Mat m{};
    for (int i = 0; i < 4; ++i) m[i][i] = 1;
    return m;
}

inline Mat mul(const Mat& a, const Mat& b) {
    Mat r{};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) r[i][j] += a[i][k] * b[k][j];
    return r;
}

inline Mat translate(double x, double y, double z) {
    Mat m = identity();
    m[0][3] = x;
    m[1][3] = y;
    m[2][3] = z;
    return m;
}

inline Mat scale(double x, double y, double z) {
    Mat m = identity();
    m[0][0] = x;
    m[1][1] = y;
    m[2][2] = z;
    return m;
}

// Rodrigues' formula.
inline Mat rotate(double x, double y, double z, double angle) {
    const double len = std::sqrt(x * x + y * y + z * z);
    Mat m = identity();
    if (len == 0) return m;
    x /= len, y /= len, z /= len;
    const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    const double r[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                            {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                            {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[i][j] = r[i][j];
    return m;
}

inline double max_difference(const Mat& a, const Mat& b) {
    double d = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) d = std::max(d, std::abs(a[i][j] - b[i][j]));
    return d;
}

struct FlatShape {
    Mat world;
    vr::NodeId shape = vr::kNullNode;
    vr::NodeId geometry = vr::kNullNode;
    vr::NodeId material = vr::kNullNode;
};

// The VRML97 Transform: T·C·R·SR·S·SR⁻¹·C⁻¹.
inline Mat transform_of(const vr::NodeTree& t, vr::NodeId id) {
    auto v = [&](const char* f) { return t.get(id, f).numbers; };
    auto tr = v("translation"), c = v("center"), r = v("rotation"), s = v("scale"),
         so = v("scaleOrientation");
    return mul(mul(mul(mul(mul(mul(translate(tr[0], tr[1], tr[2]), translate(c[0], c[1], c[2])),
                               rotate(r[0], r[1], r[2], r[3])),
                           rotate(so[0], so[1], so[2], so[3])),
                       scale(s[0], s[1], s[2])),
                   rotate(so[0], so[1], so[2], -so[3])),
               translate(-c[0], -c[1], -c[2]));
}

// Shapes in traversal order (Switch: the chosen child; LOD: the first level).
inline void flatten(const vr::NodeTree& t, vr::NodeId id, const Mat& parent,
                    std::vector<FlatShape>& out) {
    if (id == vr::kNullNode) return;
    const std::string_view type = t.type_name(id);
    auto kids = [&](const char* field) {
        for (vr::NodeId c : t.get(id, field).nodes) flatten(t, c, parent, out);
    };
    if (type == "Group" || type == "Anchor") {
        kids("children");
    } else if (type == "Transform") {
        const Mat m = mul(parent, transform_of(t, id));
        for (vr::NodeId c : t.get(id, "children").nodes) flatten(t, c, m, out);
    } else if (type == "Switch") {
        auto choice = t.get(id, "choice").nodes;
        const int which = t.get_int(id, vr::intern("whichChoice"));
        if (which >= 0 && static_cast<size_t>(which) < choice.size())
            flatten(t, choice[which], parent, out);
    } else if (type == "LOD") {
        auto level = t.get(id, "level").nodes;
        if (!level.empty()) flatten(t, level[0], parent, out);
    } else if (type == "Shape") {
        FlatShape s;
        s.world = parent;
        s.shape = id;
        s.geometry = t.get_node(id, vr::intern("geometry"));
        const vr::NodeId app = t.get_node(id, vr::intern("appearance"));
        if (app != vr::kNullNode) s.material = t.get_node(app, vr::intern("material"));
        out.push_back(s);
    }
}

inline std::vector<FlatShape> flatten(const vr::LoadedScene& scene) {
    std::vector<FlatShape> out;
    for (vr::NodeId r : scene.tree.roots) flatten(scene.tree, r, identity(), out);
    return out;
}

inline vr::LoadedScene load(const std::string& text, const std::string& name = "test.wrl") {
    return vr::load_scene_text(text, "/tmp/vrmlray_vrml1_tests/" + name);
}

inline std::string errors(const vr::LoadedScene& s) { return s.diagnostics.format(s.sources); }

}  // namespace vrml1_test
