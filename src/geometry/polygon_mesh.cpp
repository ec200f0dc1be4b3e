#include "geometry/polygon_mesh.h"

#include <cmath>
#include <string>

#include "geometry/triangulate.h"

namespace vr {

DefaultTexMapping DefaultTexMapping::from_bounds(const Vec3& lo, const Vec3& hi) {
    DefaultTexMapping m;
    m.lo = lo;
    const Vec3 size = hi - lo;
    // Largest dimension first; a stable order keeps ties in X, Y, Z preference.
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j + 1 < 3 - i; ++j)
            if (size[order[j + 1]] > size[order[j]]) std::swap(order[j], order[j + 1]);
    m.s_axis = order[0];
    m.t_axis = order[1];
    m.size = size[order[0]];
    return m;
}

Vec2 DefaultTexMapping::operator()(const Vec3& p) const {
    if (!(size > 0.0)) return Vec2(0.0);
    return Vec2((p[s_axis] - lo[s_axis]) / size, (p[t_axis] - lo[t_axis]) / size);
}

namespace {

bool finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

struct Face {
    uint32_t begin = 0;  // first corner in the corner arrays
    uint32_t count = 0;
    uint32_t number = 0;  // the face's number in the file (per-face attributes count every face)
    Vec3 normal{0.0};     // unit, of the (possibly reversed) corner order
};

// Where an attribute's value for a corner comes from, following the IndexedFaceSet rules.
struct AttributeSource {
    const char* name;        // "normal", "color", "texCoord" (messages)
    size_t value_count = 0;  // values in the attribute node
    const std::vector<int32_t>* index = nullptr;
    bool per_vertex = true;
    bool usable = false;

    // `k` is the corner's position in coordIndex, `face` the face number.
    int64_t source(const std::vector<int32_t>& coord_index, size_t k, uint32_t face) const {
        if (per_vertex) {
            if (index->empty()) return coord_index[k];
            return k < index->size() ? (*index)[k] : -2;
        }
        if (index->empty()) return face;
        return face < index->size() ? (*index)[face] : -2;
    }
};

// The valid faces of an IndexedFaceSet, their corners in output order.
struct FaceList {
    std::vector<Face> faces;
    std::vector<int32_t> corner_coord;  // coordinate index of each corner of the valid faces
    std::vector<uint32_t> corner_k;     // its position in coordIndex
    size_t degenerate = 0;              // faces with fewer than 3 corners (so far)
};

// Pass 1: faces and their validity; warns of the faces skipped for bad indices or numbers.
FaceList collect_faces(const sg::IndexedFaceSet& ifs, NodeReport& report) {
    const std::vector<Vec3>& coords = ifs.data.coords;
    const std::vector<int32_t>& coord_index = ifs.coord_index;
    FaceList list;
    size_t bad_index = 0, bad_number = 0;
    uint32_t face_number = 0;
    for (size_t begin = 0; begin < coord_index.size();) {
        size_t end = begin;
        while (end < coord_index.size() && coord_index[end] != -1) ++end;
        const size_t count = end - begin;
        bool ok = count >= 3;
        if (!ok && count > 0) ++list.degenerate;
        for (size_t k = begin; k < end && ok; ++k) {
            const int32_t c = coord_index[k];
            if (c < 0 || static_cast<size_t>(c) >= coords.size()) {
                ok = false;
                ++bad_index;
            } else if (!finite(coords[c])) {
                ok = false;
                ++bad_number;
            }
        }
        if (ok) {
            Face f;
            f.begin = static_cast<uint32_t>(list.corner_coord.size());
            f.count = static_cast<uint32_t>(count);
            f.number = face_number;
            for (size_t j = 0; j < count; ++j) {
                // ccw FALSE: the vertices run clockwise seen from the front; reverse them once
                // here.
                const size_t k = ifs.ccw ? begin + j : end - 1 - j;
                list.corner_coord.push_back(coord_index[k]);
                list.corner_k.push_back(static_cast<uint32_t>(k));
            }
            list.faces.push_back(f);
        }
        if (count > 0) ++face_number;
        begin = end + 1;
    }
    if (bad_index)
        report.warn("coord-index-range",
                    std::to_string(bad_index) + " face(s) use a coordIndex outside 0.." +
                        std::to_string(coords.size() - 1) + "; those faces are skipped");
    if (bad_number)
        report.warn("non-finite",
                    std::to_string(bad_number) +
                        " face(s) use a NaN or infinite coordinate; those faces are skipped");
    return list;
}

// Clears `a.usable` (with a warning) unless every index of the valid faces is in range.
void check_attribute(AttributeSource& a, const std::vector<int32_t>& coord_index,
                     const FaceList& list, NodeReport& report) {
    if (!a.usable) return;
    auto in_range = [&](int64_t s) { return s >= 0 && static_cast<size_t>(s) < a.value_count; };
    if (a.per_vertex) {
        for (size_t c = 0; c < list.corner_coord.size() && a.usable; ++c)
            a.usable = in_range(a.source(coord_index, list.corner_k[c], 0));
    } else {
        for (size_t fi = 0; fi < list.faces.size() && a.usable; ++fi)
            a.usable = in_range(a.source(coord_index, 0, list.faces[fi].number));
    }
    if (!a.usable)
        report.warn(std::string(a.name) + "-index",
                    std::string(a.name) + " index out of range or missing (" +
                        std::to_string(a.value_count) + " values); the " + a.name +
                        " values are ignored for this node");
}

// Face normals (unit) of the valid faces, in the corner order used for output.
void face_normals(const std::vector<Vec3>& coords, FaceList& list) {
    std::vector<Vec3> points;
    for (Face& f : list.faces) {
        points.assign(f.count, Vec3(0.0));
        for (uint32_t j = 0; j < f.count; ++j) points[j] = coords[list.corner_coord[f.begin + j]];
        const Vec3 n = newell_normal(points);
        const double length = glm::length(n);
        f.normal = length > 0.0 ? n / length : Vec3(0.0);
    }
}

// Crease-angle normals per corner: the faces around its vertex within the crease angle, averaged.
std::vector<Vec3> crease_normals(const sg::IndexedFaceSet& ifs, const FaceList& list) {
    const std::vector<Face>& faces = list.faces;
    const std::vector<int32_t>& corner_coord = list.corner_coord;
    const size_t vertex_count = ifs.data.coords.size();
    // Vertex -> faces around it (compressed rows).
    std::vector<uint32_t> start(vertex_count + 1, 0);
    for (int32_t c : corner_coord) ++start[c + 1];
    for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> around(corner_coord.size());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t fi = 0; fi < faces.size(); ++fi)
        for (uint32_t j = 0; j < faces[fi].count; ++j)
            around[fill[corner_coord[faces[fi].begin + j]]++] = fi;
    const double cos_crease = ifs.smooth_all ? -2.0 : std::cos(std::min(ifs.crease_angle, kPi));
    std::vector<Vec3> corner_normal(corner_coord.size());
    for (uint32_t fi = 0; fi < faces.size(); ++fi) {
        const Vec3 nf = faces[fi].normal;
        for (uint32_t j = 0; j < faces[fi].count; ++j) {
            const int32_t v = corner_coord[faces[fi].begin + j];
            Vec3 sum(0.0);
            for (uint32_t a = start[v]; a < start[v + 1]; ++a) {
                const Vec3& ng = faces[around[a]].normal;
                if (around[a] == fi || glm::dot(nf, ng) > cos_crease) sum += ng;
            }
            const double length = glm::length(sum);
            corner_normal[faces[fi].begin + j] = length > 1e-12 ? sum / length : nf;
        }
    }
    return corner_normal;
}

DefaultTexMapping default_mapping_of(const std::vector<Vec3>& coords, const FaceList& list) {
    Vec3 lo(kInf), hi(-kInf);
    for (int32_t c : list.corner_coord) {
        lo = glm::min(lo, coords[c]);
        hi = glm::max(hi, coords[c]);
    }
    return DefaultTexMapping::from_bounds(lo, hi);
}

// What pass 2 writes for each corner besides its position.
struct CornerAttributes {
    const AttributeSource& normal;
    const AttributeSource& color;
    const AttributeSource& texcoord;
    const std::vector<Vec3>& corner_normal;  // crease-angle normals; empty: none
    const DefaultTexMapping& default_mapping;
    bool want_uvs;
};

// Pass 2: triangulate the valid faces and emit their corners (faces without area emit none).
void emit_faces(const sg::IndexedFaceSet& ifs, FaceList& list, const CornerAttributes& at,
                TriMesh& mesh) {
    const std::vector<Vec3>& coords = ifs.data.coords;
    const std::vector<int32_t>& coord_index = ifs.coord_index;
    std::vector<int32_t> remap(coords.size(), -1);
    std::vector<uint32_t> local;
    std::vector<Vec3> points;
    const bool out_normals = at.normal.usable || !at.corner_normal.empty();
    for (const Face& f : list.faces) {
        points.assign(f.count, Vec3(0.0));
        for (uint32_t j = 0; j < f.count; ++j) points[j] = coords[list.corner_coord[f.begin + j]];
        local.clear();
        // A face with no area shows nothing and hides nothing: skipped silently, as browsers do
        // (Jmol's cartoons hold such faces where a ribbon narrows to a line).
        if (!triangulate_polygon(points, local)) continue;
        for (uint32_t corner_local : local) {
            const uint32_t corner = f.begin + corner_local;
            const int32_t c = list.corner_coord[corner];
            if (remap[c] < 0) {
                remap[c] = static_cast<int32_t>(mesh.positions.size());
                mesh.positions.push_back(coords[c]);
            }
            mesh.triangles.push_back(static_cast<uint32_t>(remap[c]));
            const size_t k = list.corner_k[corner];
            if (out_normals) {
                Vec3 n = f.normal;
                if (at.normal.usable) {
                    const Vec3 given = ifs.data.normals[at.normal.source(coord_index, k, f.number)];
                    const double length = glm::length(given);
                    if (length > 0.0 && std::isfinite(length)) n = given / length;
                } else {
                    n = at.corner_normal[corner];
                }
                mesh.normals.push_back(n);
            }
            if (at.color.usable) {
                const size_t source = at.color.source(coord_index, k, f.number);
                mesh.colors.push_back(ifs.data.colors[source]);
                if (!ifs.data.alphas.empty()) mesh.alphas.push_back(ifs.data.alphas[source]);
            }
            if (!ifs.data.fog_depths.empty()) {
                // A depth per coordinate; a shorter list repeats its last depth (as
                // view3dscene reads fog_coordinate.x3dv's `depth 0.5`).
                const std::vector<double>& d = ifs.data.fog_depths;
                mesh.fog_depths.push_back(d[std::min<size_t>(size_t(c), d.size() - 1)]);
            }
            if (at.want_uvs) {
                mesh.uvs.push_back(
                    at.texcoord.usable
                        ? ifs.data.texcoords[at.texcoord.source(coord_index, k, f.number)]
                        : at.default_mapping(coords[c]));
            }
        }
    }
}

}  // namespace

TriMesh triangulate_face_set(const sg::IndexedFaceSet& ifs, bool want_uvs, NodeReport& report) {
    TriMesh mesh;
    mesh.solid = ifs.solid;
    const std::vector<Vec3>& coords = ifs.data.coords;
    const std::vector<int32_t>& coord_index = ifs.coord_index;
    if (coords.empty() || coord_index.empty()) {
        report.warn("empty", "has no coordinates or no coordIndex; nothing to render");
        return mesh;
    }

    AttributeSource normal{"normal", ifs.data.normals.size(), &ifs.normal_index,
                           ifs.normal_per_vertex, !ifs.data.normals.empty()};
    AttributeSource color{"color", ifs.data.colors.size(), &ifs.color_index, ifs.color_per_vertex,
                          !ifs.data.colors.empty()};
    AttributeSource texcoord{"texCoord", ifs.data.texcoords.size(), &ifs.texcoord_index, true,
                             !ifs.data.texcoords.empty()};

    FaceList list = collect_faces(ifs, report);
    for (AttributeSource* a : {&normal, &color, &texcoord})
        check_attribute(*a, coord_index, list, report);
    face_normals(coords, list);
    // Crease-angle normals per corner, when no usable explicit normals are given.
    std::vector<Vec3> corner_normal;
    if (!normal.usable && (ifs.smooth_all || ifs.crease_angle > 0.0))
        corner_normal = crease_normals(ifs, list);
    const DefaultTexMapping default_mapping =
        want_uvs && !texcoord.usable ? default_mapping_of(coords, list) : DefaultTexMapping();

    emit_faces(ifs, list, {normal, color, texcoord, corner_normal, default_mapping, want_uvs},
               mesh);
    if (list.degenerate)
        report.warn("degenerate",
                    std::to_string(list.degenerate) +
                        " face(s) have fewer than 3 vertices; those faces are skipped");
    if (mesh.triangles.empty() && list.faces.empty() == false)
        report.warn("no-triangles", "no face has an area; nothing to render");
    return mesh;
}
}  // namespace vr
