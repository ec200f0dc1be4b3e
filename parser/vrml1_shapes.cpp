// VRML 1.0 shapes and their appearance: the traversal state's Material (with MaterialBinding),
// textures, coordinates, normals and shape hints, turned into VRML97 Shape nodes. Nodes made from
// values alone (Material, Sphere, Appearance, Shape, ...) are shared, so a RasMol file's thousands
// of atoms of a few colours and radii become a few Shape nodes placed by one Transform each.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "parser/vrml1_upgrade.h"

namespace vr::vrml1 {
namespace {

// Bindings that give each part (Cylinder: sides, top, bottom; Cone: sides, bottom; Cube: its six
// faces) or each face of an indexed shape its own material.
bool per_part(Binding b) {
    return b == Binding::PerPart || b == Binding::PerPartIndexed || b == Binding::PerFace ||
           b == Binding::PerFaceIndexed;
}

// The words of an SFBitMask value ("SIDES|TOP").
bool has_part(const std::string& parts, std::string_view part) {
    if (parts == "ALL") return true;
    size_t start = 0;
    while (start <= parts.size()) {
        size_t bar = parts.find('|', start);
        std::string_view w = std::string_view(parts).substr(
            start, bar == std::string::npos ? std::string::npos : bar - start);
        if (w == part || w == "ALL") return true;
        start = bar == std::string::npos ? parts.size() + 1 : bar + 1;
    }
    return false;
}

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

}  // namespace

// ---- materials ----

// A Material whose ambient, diffuse and specular colours are given as empty lists and whose
// emissive colours are given holds precomputed lighting (as Open Inventor writers use it): it is
// drawn unlit.
bool Upgrader::pure_emissive(uint32_t mat) {
    if (mat == kNone) return false;
    const Names& n = names();
    auto empty = [&](Name f) {
        const FieldEntry* e = set_entry(mat, f);
        return e && e->count == 0;
    };
    return empty(n.ambientColor) && empty(n.diffuseColor) && empty(n.specularColor) &&
           get(mat, n.emissiveColor).numbers.size() >= 3;
}

// The number of colours a per-face or per-vertex binding can choose from (the Color node's length).
size_t Upgrader::material_count(uint32_t mat) {
    if (mat == kNone) return 1;
    const Names& n = names();
    return std::max<size_t>(get(mat, pure_emissive(mat) ? n.emissiveColor : n.diffuseColor).size(),
                            1);
}

NodeId Upgrader::material(uint32_t mat, size_t index) {
    const uint64_t id_key = (uint64_t(mat) << 32) | std::min<size_t>(index, UINT32_MAX);
    auto cached = materials_.find(id_key);
    if (cached != materials_.end()) return cached->second;
    const Names& n = names();
    static const Name kMaterial = intern("Material");
    // Value `index` of one field; an empty list means the VRML 1.0 default; short lists repeat
    // their last.
    auto pick = [&](Name field, int components, double* out) {
        FieldView v = mat == kNone ? get_default(kMaterial, field) : get(mat, field);
        if (v.numbers.empty()) v = get_default(kMaterial, field);
        const size_t count = v.numbers.size() / components;
        const size_t i = std::min(index, count - 1);
        for (int c = 0; c < components; ++c) out[c] = v.numbers[i * components + c];
    };
    double diffuse[3], specular[3], emissive[3], ambient[3], shininess, transparency;
    pick(n.diffuseColor, 3, diffuse);
    pick(n.specularColor, 3, specular);
    pick(n.emissiveColor, 3, emissive);
    pick(n.ambientColor, 3, ambient);
    pick(n.shininess, 1, &shininess);
    pick(n.transparency, 1, &transparency);
    // VRML97 has no ambient colour, only an intensity applied to the diffuse colour; the mean of
    // the VRML 1.0 ambient colour maps the VRML 1.0 default (0.2) to the VRML97 default (0.2).
    const bool grey = ambient[0] == ambient[1] && ambient[1] == ambient[2];
    double ambient_intensity =
        clamp01(grey ? ambient[0] : (ambient[0] + ambient[1] + ambient[2]) / 3);
    if (pure_emissive(mat)) {
        std::fill(diffuse, diffuse + 3, 0.0);
        std::fill(specular, specular + 3, 0.0);
        ambient_intensity = 0;
    }
    const Name def = mat != kNone && index == 0 ? file_.nodes[mat].def_name : kNoName;
    std::vector<double> key = {1,
                               diffuse[0],
                               diffuse[1],
                               diffuse[2],
                               specular[0],
                               specular[1],
                               specular[2],
                               emissive[0],
                               emissive[1],
                               emissive[2],
                               ambient_intensity,
                               clamp01(shininess),
                               clamp01(transparency),
                               static_cast<double>(def)};
    auto found = values_.find(key);
    NodeId node;
    if (found != values_.end()) {
        node = found->second;
    } else {
        Fields f = begin("Material");
        for (double* c : {diffuse, specular, emissive})
            for (int k = 0; k < 3; ++k) c[k] = clamp01(c[k]);
        set(f, n.diffuseColor, std::span<const double>(diffuse, 3));
        set(f, n.specularColor, std::span<const double>(specular, 3));
        set(f, n.emissiveColor, std::span<const double>(emissive, 3));
        set(f, n.ambientIntensity, {ambient_intensity});
        set(f, n.shininess, {clamp01(shininess)});
        set(f, n.transparency, {clamp01(transparency)});
        node = make(f, mat == kNone ? SourceLoc{} : file_.nodes[mat].loc, def);
        values_[key] = node;
    }
    materials_[id_key] = node;
    return node;
}

NodeId Upgrader::color_node(uint32_t mat) {
    auto cached = colors_.find(mat);
    if (cached != colors_.end()) return cached->second;
    const Names& n = names();
    Fields f = begin("Color");
    const Name source = pure_emissive(mat) ? n.emissiveColor : n.diffuseColor;
    const FieldEntry* e = set_entry(mat, source);
    if (e && e->count > 0) {
        reuse(f, n.color, mat, source);
    } else {
        static const Name kMaterial = intern("Material");
        set(f, n.color, get_default(kMaterial, source).numbers);
    }
    NodeId node = make(f, file_.nodes[mat].loc);
    colors_[mat] = node;
    return node;
}

NodeId Upgrader::texture(uint32_t id) {
    auto cached = textures_.find(id);
    if (cached != textures_.end()) return cached->second;
    const Names& n = names();
    const std::string filename = word(id, n.filename);
    Fields f = begin(filename.empty() ? "PixelTexture" : "ImageTexture");
    if (filename.empty())
        reuse(f, n.image, id, n.image);
    else
        set_strings(f, n.url, {filename});
    set(f, n.repeatS, {word(id, n.wrapS) == "CLAMP" ? 0.0 : 1.0});
    set(f, n.repeatT, {word(id, n.wrapT) == "CLAMP" ? 0.0 : 1.0});
    NodeId node = make(f, file_.nodes[id].loc, file_.nodes[id].def_name);
    textures_[id] = node;
    return node;
}

// VRML 1.0 applies scale, rotation and translation about the centre in that order, VRML97's
// TextureTransform another order: the fields map one to one, which is exact when one of them is
// set.
NodeId Upgrader::texture_transform(uint32_t id) {
    auto cached = texture_transforms_.find(id);
    if (cached != texture_transforms_.end()) return cached->second;
    const Names& n = names();
    Fields f = begin("TextureTransform");
    set(f, n.translation, get(id, n.translation).numbers);
    set(f, n.rotation, get(id, n.rotation).numbers);
    set(f, n.scale, get(id, n.scaleFactor).numbers);
    set(f, n.center, get(id, n.center).numbers);
    NodeId node = make(f, file_.nodes[id].loc, file_.nodes[id].def_name);
    texture_transforms_[id] = node;
    return node;
}

NodeId Upgrader::appearance(const State& s, NodeId material_node) {
    const NodeId tex = s.texture != kNone ? texture(s.texture) : kNullNode;
    const NodeId tt = tex != kNullNode && s.texture_transform != kNone
                          ? texture_transform(s.texture_transform)
                          : kNullNode;
    std::vector<double> key = {2, double(material_node), double(tex), double(tt)};
    auto it = values_.find(key);
    if (it != values_.end()) return it->second;
    const Names& n = names();
    Fields f = begin("Appearance");
    set_node(f, n.material, material_node);
    set_node(f, n.texture, tex);
    set_node(f, n.textureTransform, tt);
    const SourceLoc loc =
        material_node != kNullNode ? tree_.nodes[material_node].loc.get() : SourceLoc{};
    NodeId node = make(f, loc);
    values_[key] = node;
    return node;
}

// ---- shared helpers ----

NodeId Upgrader::coordinate(uint32_t id) {
    auto cached = coordinates_.find(id);
    if (cached != coordinates_.end()) return cached->second;
    const Names& n = names();
    Fields f = begin("Coordinate");
    SourceLoc loc;
    if (id == kNone) {
        static const Name kCoordinate3 = intern("Coordinate3");
        set(f, n.point, get_default(kCoordinate3, n.point).numbers);
    } else {
        reuse(f, n.point, id, n.point);
        loc = file_.nodes[id].loc;
    }
    NodeId node = make(f, loc, id == kNone ? kNoName : file_.nodes[id].def_name);
    coordinates_[id] = node;
    return node;
}

// Nodes made from field values alone are shared between all shapes that have the same values.
NodeId Upgrader::primitive(Fields& f, SourceLoc loc) {
    std::vector<double> key = {3, static_cast<double>(f.decl->name)};
    for (const FieldEntry& e : f.list) {
        key.push_back(static_cast<double>(e.name));
        key.insert(key.end(), tree_.numbers.begin() + e.begin,
                   tree_.numbers.begin() + e.begin + e.count);
    }
    auto it = values_.find(key);
    if (it != values_.end()) {
        f.list.clear();  // the values stay in the pool unused; they are a few numbers
        return it->second;
    }
    NodeId node = make(f, loc);
    values_[key] = node;
    return node;
}

NodeId Upgrader::shape_node(uint32_t id, NodeId app, NodeId geometry) {
    const Name def = file_.nodes[id].def_name;
    std::vector<double> key = {4, double(app), double(geometry), double(def)};
    auto found = values_.find(key);
    if (found != values_.end()) return found->second;
    const Names& n = names();
    Fields f = begin("Shape");
    set_node(f, n.appearance, app);
    set_node(f, n.geometry, geometry);
    NodeId node = make(f, file_.nodes[id].loc, def);
    values_[key] = node;
    return node;
}

void Upgrader::emit_shape(uint32_t id, const State& s, OutList& out, NodeId app, NodeId geometry) {
    emit(shape_node(id, app, geometry), s, out);
}

bool Upgrader::cached_shape(uint32_t id, const State& s, OutList& out) {
    if (!shared_[id]) return false;
    auto it = shapes_.find(key(id, s));
    if (it == shapes_.end()) return false;
    for (NodeId shape : it->second) emit(shape, s, out);
    return true;
}

void Upgrader::cache_shape(uint32_t id, const State& s, std::vector<NodeId> made) {
    if (shared_[id]) shapes_[key(id, s)] = std::move(made);
}

// VRML 1.0 ShapeHints (or their defaults, when no ShapeHints node came before) as VRML97 fields.
// Back faces may be culled only when the shape is SOLID and its vertex order is known.
void Upgrader::shape_hints(const State& s, Fields& f) {
    const Names& n = names();
    static const Name kShapeHints = intern("ShapeHints");
    auto hint = [&](Name field) {
        FieldView v =
            s.shape_hints == kNone ? get_default(kShapeHints, field) : get(s.shape_hints, field);
        return v;
    };
    const std::string ordering =
        hint(n.vertexOrdering).strings.empty() ? "" : hint(n.vertexOrdering).strings[0];
    const std::string type = hint(n.shapeType).strings.empty() ? "" : hint(n.shapeType).strings[0];
    const std::string face = hint(n.faceType).strings.empty() ? "" : hint(n.faceType).strings[0];
    set(f, n.ccw, {ordering == "CLOCKWISE" ? 0.0 : 1.0});
    set(f, n.solid, {type == "SOLID" && ordering != "UNKNOWN_ORDERING" ? 1.0 : 0.0});
    set(f, n.convex, {face == "UNKNOWN_FACE_TYPE" ? 0.0 : 1.0});
    set(f, n.creaseAngle, hint(n.creaseAngle).numbers);
}

// Builds colorIndex/normalIndex/texCoordIndex for `binding` (DEFAULT already resolved by the
// caller). `count`: values available; `given`: the VRML 1.0 index field (used by the _INDEXED
// bindings when set). Indices out of range are clamped (`clamp`, materials: with a warning) or make
// the mapping unusable.
IndexMapping Upgrader::map_indices(Binding binding, size_t count, std::span<const double> given,
                                   bool given_set, std::span<const double> coord_index, bool clamp,
                                   uint32_t node, const char* what) {
    IndexMapping m;
    if (count == 0 || binding == Binding::Overall || binding == Binding::Default) return m;
    size_t faces = 0, corners = 0;
    bool open = false;
    double largest = -1;
    for (double v : coord_index) {
        if (v == -1) {
            if (open) ++faces;
            open = false;
        } else {
            ++corners;
            open = true;
            largest = std::max(largest, v);
        }
    }
    if (open) ++faces;
    bool bad = false;
    auto fix = [&](double v) {
        if (v >= 0 && v < static_cast<double>(count)) return v;
        bad = true;
        return std::clamp(v, 0.0, static_cast<double>(count - 1));
    };
    m.use = true;
    switch (binding) {
        case Binding::PerPartIndexed:
        case Binding::PerFaceIndexed:
            if (given_set && !given.empty()) {
                m.per_vertex = false;
                m.explicit_index = true;
                for (size_t i = 0; i < faces; ++i)
                    m.index.push_back(fix(given[std::min(i, given.size() - 1)]));
                break;
            }
            [[fallthrough]];
        case Binding::PerPart:
        case Binding::PerFace:
            m.per_vertex = false;
            if (count < faces) {
                m.explicit_index = true;
                for (size_t i = 0; i < faces; ++i) m.index.push_back(fix(static_cast<double>(i)));
            }
            break;
        case Binding::PerVertex: {
            m.explicit_index = true;
            double k = 0;
            for (double v : coord_index) m.index.push_back(v == -1 ? -1.0 : fix(k++));
            break;
        }
        case Binding::PerVertexIndexed:
            if (!given_set || given.empty()) {
                if (largest < static_cast<double>(count)) break;  // coordIndex serves as the index
                m.explicit_index = true;
                for (double v : coord_index) m.index.push_back(v == -1 ? -1.0 : fix(v));
                break;
            }
            m.explicit_index = true;
            if (given.size() ==
                coord_index.size()) {  // written parallel to coordIndex, -1 included
                for (size_t i = 0; i < coord_index.size(); ++i)
                    m.index.push_back(coord_index[i] == -1 ? -1.0 : fix(given[i]));
            } else {  // one index per corner, -1 left out or misplaced
                size_t j = 0;
                for (double v : coord_index) {
                    if (v == -1) {
                        m.index.push_back(-1.0);
                        continue;
                    }
                    while (j < given.size() && given[j] == -1) ++j;
                    m.index.push_back(fix(j < given.size() ? given[j++] : (bad = true, 0.0)));
                }
            }
            break;
        default:
            break;
    }
    if (bad && !clamp) return IndexMapping{};
    if (m.explicit_index && m.per_vertex &&
        std::equal(m.index.begin(), m.index.end(), coord_index.begin(), coord_index.end()))
        m.explicit_index =
            false;  // the same as coordIndex, which VRML97 uses when the index is empty
    if (bad)
        warn(node,
             std::string(what) + " indices out of range (the state holds " + std::to_string(count) +
                 "); the nearest valid index is used",
             std::string("vrml1-index-range:") + what);
    return m;
}

// ---- shapes ----

void Upgrader::sphere(uint32_t id, const State& s, OutList& out) {
    const Names& n = names();
    Fields f = begin("Sphere");
    set(f, n.radius, get(id, n.radius).numbers);
    const NodeId geometry = primitive(f, file_.nodes[id].loc);
    emit_shape(id, s, out, appearance(s, material(s.material, 0)), geometry);
}

void Upgrader::cylinder_or_cone(uint32_t id, const State& s, OutList& out, bool cone) {
    const Names& n = names();
    const std::string parts = word(id, n.parts);
    // Part order of the VRML 1.0 specification: Cylinder sides, top, bottom; Cone sides, bottom.
    const bool present[3] = {has_part(parts, "SIDES"), !cone && has_part(parts, "TOP"),
                             has_part(parts, "BOTTOM")};
    const Name part_field[3] = {n.side, n.top, n.bottom};
    const bool split = per_part(s.material_binding) && material_count(s.material) > 1;
    auto make_part = [&](int only) {  // only: -1 for all present parts
        Fields f = begin(cone ? "Cone" : "Cylinder");
        set(f, cone ? n.bottomRadius : n.radius, get(id, cone ? n.bottomRadius : n.radius).numbers);
        set(f, n.height, get(id, n.height).numbers);
        for (int p = 0; p < 3; ++p) {
            if (cone && p == 1) continue;
            set(f, part_field[p], {present[p] && (only < 0 || only == p) ? 1.0 : 0.0});
        }
        return primitive(f, file_.nodes[id].loc);
    };
    if (!present[0] && !present[1] && !present[2]) return;
    if (!split) {
        emit_shape(id, s, out, appearance(s, material(s.material, 0)), make_part(-1));
        return;
    }
    size_t index = 0;  // material index of the part
    for (int p = 0; p < 3; ++p) {
        if (cone && p == 1) continue;
        if (present[p])
            emit_shape(id, s, out, appearance(s, material(s.material, index)), make_part(p));
        ++index;
    }
}

// A Cube with one material per face becomes an IndexedFaceSet with a colour per face (faces in the
// VRML 1.0 order front, back, left, right, top, bottom; texture coordinates as on a VRML97 Box).
void Upgrader::cube(uint32_t id, const State& s, OutList& out) {
    const Names& n = names();
    const double a = number(id, n.width) / 2, b = number(id, n.height) / 2,
                 c = number(id, n.depth) / 2;
    if (!(per_part(s.material_binding) && material_count(s.material) > 1)) {
        Fields f = begin("Box");
        set(f, n.size, {2 * a, 2 * b, 2 * c});
        emit_shape(id, s, out, appearance(s, material(s.material, 0)),
                   primitive(f, file_.nodes[id].loc));
        return;
    }
    const double corners[6][4][3] = {
        {{-a, -b, c}, {a, -b, c}, {a, b, c}, {-a, b, c}},      // front  (+z)
        {{a, -b, -c}, {-a, -b, -c}, {-a, b, -c}, {a, b, -c}},  // back   (-z)
        {{-a, -b, -c}, {-a, -b, c}, {-a, b, c}, {-a, b, -c}},  // left   (-x)
        {{a, -b, c}, {a, -b, -c}, {a, b, -c}, {a, b, c}},      // right  (+x)
        {{-a, b, c}, {a, b, c}, {a, b, -c}, {-a, b, -c}},      // top    (+y)
        {{-a, -b, -c}, {a, -b, -c}, {a, -b, c}, {-a, -b, c}},  // bottom (-y)
    };
    std::vector<double> points, coord_index, tex_index;
    for (int face = 0; face < 6; ++face) {
        for (int k = 0; k < 4; ++k) {
            points.insert(points.end(), corners[face][k], corners[face][k] + 3);
            coord_index.push_back(face * 4 + k);
            tex_index.push_back(k);
        }
        coord_index.push_back(-1);
        tex_index.push_back(-1);
    }
    Fields coord = begin("Coordinate");
    set(coord, n.point, points);
    Fields ifs = begin("IndexedFaceSet");
    set_node(ifs, n.coord, make(coord, file_.nodes[id].loc));
    set(ifs, n.coordIndex, coord_index);
    const size_t colors = material_count(s.material);
    IndexMapping m =
        map_indices(Binding::PerFace, colors, {}, false, coord_index, true, id, "material");
    set_node(ifs, n.color, color_node(s.material));
    set(ifs, n.colorPerVertex, {0.0});
    if (m.explicit_index) set(ifs, n.colorIndex, m.index);
    if (s.texture != kNone) {
        Fields tc = begin("TextureCoordinate");
        set(tc, n.point, {0, 0, 1, 0, 1, 1, 0, 1});
        set_node(ifs, n.texCoord, make(tc, file_.nodes[id].loc));
        set(ifs, n.texCoordIndex, tex_index);
    }
    const NodeId geometry = make(ifs, file_.nodes[id].loc);
    // Precomputed (emissive-only) colours are drawn unlit: no Material, the Color node as is.
    const NodeId mat = pure_emissive(s.material) ? kNullNode : material(s.material, 0);
    emit_shape(id, s, out, appearance(s, mat), geometry);
}

// The Material of an indexed set, and its colours as a Color node with colorIndex/colorPerVertex
// when the binding asks for several (then the Material itself is dropped if it only carried
// emission).
NodeId Upgrader::indexed_colors(uint32_t id, const State& s, Fields& f,
                                const std::vector<double>& coord_index) {
    const Names& n = names();
    NodeId mat = material(s.material, 0);
    const size_t colors = material_count(s.material);
    if (colors > 1) {
        const FieldEntry* given = set_entry(id, n.materialIndex);
        IndexMapping m = map_indices(s.material_binding, colors, values(id, n.materialIndex),
                                     given != nullptr, coord_index, true, id, "material");
        if (m.use) {
            set_node(f, n.color, color_node(s.material));
            set(f, n.colorPerVertex, {m.per_vertex ? 1.0 : 0.0});
            if (m.explicit_index) set(f, n.colorIndex, m.index);
            if (pure_emissive(s.material)) mat = kNullNode;
        }
    }
    return mat;
}

void Upgrader::face_set(uint32_t id, const State& s, OutList& out) {
    if (cached_shape(id, s, out)) return;
    const Names& n = names();
    // Copies: making nodes appends to the pools these values live in.
    const std::vector<double> coord_index = values(id, n.coordIndex);
    Fields f = begin("IndexedFaceSet");
    set_node(f, n.coord, coordinate(s.coords));
    reuse(f, n.coordIndex, id, n.coordIndex);

    // Materials: a colour per face or vertex when the binding asks and the Material has several
    // values.
    NodeId mat = indexed_colors(id, s, f, coord_index);
    // Normals: used when the state holds enough of them; otherwise the renderer generates them
    // (VRML 1.0 says the same). OVERALL has no VRML97 form.
    if (s.normals != kNone) {
        const Binding b =
            s.normal_binding == Binding::Default ? Binding::PerVertexIndexed : s.normal_binding;
        if (b == Binding::Overall) {
            warn(id,
                 "NormalBinding OVERALL has no VRML97 equivalent; normals are generated instead",
                 "vrml1-normal-overall");
        } else {
            const FieldEntry* given = set_entry(id, n.normalIndex);

            const size_t count = get(s.normals, n.vector).size();
            IndexMapping m = map_indices(b, count, values(id, n.normalIndex), given != nullptr,
                                         coord_index, false, id, "normal");
            if (m.use) {
                auto it = normals_.find(s.normals);
                NodeId normal;
                if (it != normals_.end()) {
                    normal = it->second;
                } else {
                    Fields nf = begin("Normal");
                    reuse(nf, n.vector, s.normals, n.vector);
                    normal = normals_[s.normals] =
                        make(nf, file_.nodes[s.normals].loc, file_.nodes[s.normals].def_name);
                }
                set_node(f, n.normal, normal);
                set(f, n.normalPerVertex, {m.per_vertex ? 1.0 : 0.0});
                if (m.explicit_index) set(f, n.normalIndex, m.index);
            }
        }
    }
    // Texture coordinates, when a texture is in use (without them the renderer maps the bounding
    // box, as VRML 1.0 does).
    if (s.texture != kNone && s.texcoords != kNone) {
        const FieldEntry* given = set_entry(id, n.textureCoordIndex);

        const size_t count = get(s.texcoords, n.point).size();
        IndexMapping m =
            map_indices(Binding::PerVertexIndexed, count, values(id, n.textureCoordIndex),
                        given != nullptr, coord_index, false, id, "texture coordinate");
        if (m.use) {
            auto it = texcoords_.find(s.texcoords);
            NodeId tc;
            if (it != texcoords_.end()) {
                tc = it->second;
            } else {
                Fields tf = begin("TextureCoordinate");
                reuse(tf, n.point, s.texcoords, n.point);
                tc = texcoords_[s.texcoords] =
                    make(tf, file_.nodes[s.texcoords].loc, file_.nodes[s.texcoords].def_name);
            }
            set_node(f, n.texCoord, tc);
            if (m.explicit_index) set(f, n.texCoordIndex, m.index);
        }
    }
    shape_hints(s, f);
    const NodeId shape = shape_node(id, appearance(s, mat), make(f, file_.nodes[id].loc));
    cache_shape(id, s, {shape});
    emit(shape, s, out);
}

void Upgrader::line_set(uint32_t id, const State& s, OutList& out) {
    if (cached_shape(id, s, out)) return;
    const Names& n = names();
    // Copies: making nodes appends to the pools these values live in.
    const std::vector<double> coord_index = values(id, n.coordIndex);
    Fields f = begin("IndexedLineSet");
    set_node(f, n.coord, coordinate(s.coords));
    reuse(f, n.coordIndex, id, n.coordIndex);
    // PER_PART (one material per segment) becomes one colour per polyline.
    NodeId mat = indexed_colors(id, s, f, coord_index);
    const NodeId shape = shape_node(id, appearance(s, mat), make(f, file_.nodes[id].loc));
    cache_shape(id, s, {shape});
    emit(shape, s, out);
}

// PointSet draws numPoints of the current coordinates from startIndex: a VRML97 PointSet of those
// points.
void Upgrader::point_set(uint32_t id, const State& s, OutList& out) {
    if (cached_shape(id, s, out)) return;
    const Names& n = names();
    static const Name kCoordinate3 = intern("Coordinate3");
    FieldView points =
        s.coords == kNone ? get_default(kCoordinate3, n.point) : get(s.coords, n.point);
    const size_t total = points.size();
    const double start_value = number(id, n.startIndex), count_value = number(id, n.numPoints);
    const size_t start = start_value > 0 ? std::min(static_cast<size_t>(start_value), total) : 0;
    const size_t count =
        count_value < 0 ? total - start : std::min(static_cast<size_t>(count_value), total - start);
    std::vector<double> subset(points.numbers.begin() + 3 * start,
                               points.numbers.begin() + 3 * (start + count));
    Fields coord = begin("Coordinate");
    set(coord, n.point, subset);
    Fields f = begin("PointSet");
    set_node(f, n.coord, make(coord, file_.nodes[id].loc));
    NodeId mat = material(s.material, 0);
    const size_t colors = material_count(s.material);
    if (colors > 1 && s.material_binding != Binding::Overall && count > 0) {
        // One colour per point: _INDEXED bindings by coordinate index, the others in order.
        const bool indexed = s.material_binding == Binding::PerPartIndexed ||
                             s.material_binding == Binding::PerFaceIndexed ||
                             s.material_binding == Binding::PerVertexIndexed;
        const bool emissive = pure_emissive(s.material);
        FieldView list = get(s.material, emissive ? n.emissiveColor : n.diffuseColor);
        std::vector<double> rgb;
        for (size_t i = 0; i < count; ++i) {
            const size_t k = std::min(indexed ? start + i : i, colors - 1);
            rgb.insert(rgb.end(), list.numbers.begin() + 3 * k, list.numbers.begin() + 3 * k + 3);
        }
        Fields cf = begin("Color");
        set(cf, n.color, rgb);
        set_node(f, n.color, make(cf, file_.nodes[s.material].loc));
        if (emissive) mat = kNullNode;
    }
    const NodeId shape = shape_node(id, appearance(s, mat), make(f, file_.nodes[id].loc));
    cache_shape(id, s, {shape});
    emit(shape, s, out);
}

// VRML 1.0 AsciiText (VRML 1.0 spec 4.1) under the current FontStyle: a VRML97 Text.
void Upgrader::ascii_text(uint32_t id, const State& s, OutList& out) {
    if (cached_shape(id, s, out)) return;
    static const Name kFontStyle = intern("FontStyle"), kString = intern("string"),
                      kSpacing = intern("spacing"), kJustification = intern("justification"),
                      kWidth = intern("width"), kSize = intern("size"), kFamily = intern("family"),
                      kStyle = intern("style"), kJustify = intern("justify"),
                      kLength = intern("length"), kFontStyleField = intern("fontStyle");
    const uint32_t fs = s.font_style;
    auto font = [&](Name field) {
        return fs == kNone ? get_default(kFontStyle, field) : get(fs, field);
    };
    const std::string style_word = font(kStyle).strings.empty() ? "" : font(kStyle).strings[0];
    const bool bold = has_part(style_word, "BOLD"), italic = has_part(style_word, "ITALIC");
    const std::string justification = word(id, kJustification);
    Fields style = begin("FontStyle");
    set(style, kSize, font(kSize).numbers);
    set_strings(style, kFamily,
                {font(kFamily).strings.empty() ? "SERIF" : font(kFamily).strings[0]});
    set_strings(style, kStyle,
                {bold && italic ? "BOLDITALIC"
                 : bold         ? "BOLD"
                 : italic       ? "ITALIC"
                                : "PLAIN"});
    set(style, kSpacing, get(id, kSpacing).numbers);
    set_strings(style, kJustify,
                {justification == "CENTER"  ? "MIDDLE"
                 : justification == "RIGHT" ? "END"
                                            : "BEGIN"});
    const SourceLoc loc = file_.nodes[id].loc;
    const NodeId style_node = make(style, loc);
    const FieldView strings = get(id, kString);
    Fields text = begin("Text");
    set_strings(text, kString, {strings.strings.begin(), strings.strings.end()});
    set(text, kLength, get(id, kWidth).numbers);
    set_node(text, kFontStyleField, style_node);
    const NodeId geometry = make(text, loc);
    const NodeId shape = shape_node(id, appearance(s, material(s.material, 0)), geometry);
    emit(shape, s, out);
    cache_shape(id, s, {shape});
}

}  // namespace vr::vrml1
