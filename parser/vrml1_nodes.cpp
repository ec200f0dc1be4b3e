// The VRML 1.0 upgrade's plumbing: interned names, reading V1 field values (or their VRML 1.0
// defaults), and making VRML97 nodes whose fields differ from the VRML97 defaults.
#include <algorithm>

#include "parser/vrml1_upgrade.h"

namespace vr::vrml1 {

Names::Names()
    : translation(intern("translation")),
      rotation(intern("rotation")),
      scaleFactor(intern("scaleFactor")),
      scaleOrientation(intern("scaleOrientation")),
      center(intern("center")),
      matrix(intern("matrix")),
      scale(intern("scale")),
      ambientColor(intern("ambientColor")),
      diffuseColor(intern("diffuseColor")),
      specularColor(intern("specularColor")),
      emissiveColor(intern("emissiveColor")),
      shininess(intern("shininess")),
      transparency(intern("transparency")),
      ambientIntensity(intern("ambientIntensity")),
      value(intern("value")),
      point(intern("point")),
      vector(intern("vector")),
      coordIndex(intern("coordIndex")),
      materialIndex(intern("materialIndex")),
      normalIndex(intern("normalIndex")),
      textureCoordIndex(intern("textureCoordIndex")),
      texCoordIndex(intern("texCoordIndex")),
      colorIndex(intern("colorIndex")),
      vertexOrdering(intern("vertexOrdering")),
      shapeType(intern("shapeType")),
      faceType(intern("faceType")),
      creaseAngle(intern("creaseAngle")),
      ccw(intern("ccw")),
      solid(intern("solid")),
      convex(intern("convex")),
      colorPerVertex(intern("colorPerVertex")),
      normalPerVertex(intern("normalPerVertex")),
      radius(intern("radius")),
      width(intern("width")),
      height(intern("height")),
      depth(intern("depth")),
      parts(intern("parts")),
      bottomRadius(intern("bottomRadius")),
      size(intern("size")),
      side(intern("side")),
      top(intern("top")),
      bottom(intern("bottom")),
      on(intern("on")),
      intensity(intern("intensity")),
      color(intern("color")),
      direction(intern("direction")),
      location(intern("location")),
      dropOffRate(intern("dropOffRate")),
      cutOffAngle(intern("cutOffAngle")),
      beamWidth(intern("beamWidth")),
      global(intern("global")),
      position(intern("position")),
      orientation(intern("orientation")),
      heightAngle(intern("heightAngle")),
      fieldOfView(intern("fieldOfView")),
      description(intern("description")),
      filename(intern("filename")),
      image(intern("image")),
      wrapS(intern("wrapS")),
      wrapT(intern("wrapT")),
      repeatS(intern("repeatS")),
      repeatT(intern("repeatT")),
      url(intern("url")),
      name(intern("name")),
      bboxSize(intern("bboxSize")),
      bboxCenter(intern("bboxCenter")),
      whichChild(intern("whichChild")),
      whichChoice(intern("whichChoice")),
      choice(intern("choice")),
      range(intern("range")),
      level(intern("level")),
      startIndex(intern("startIndex")),
      numPoints(intern("numPoints")),
      children(intern("children")),
      material(intern("material")),
      texture(intern("texture")),
      textureTransform(intern("textureTransform")),
      appearance(intern("appearance")),
      geometry(intern("geometry")),
      coord(intern("coord")),
      normal(intern("normal")),
      texCoord(intern("texCoord")) {}

const Names& names() {
    static const Names n;
    return n;
}

size_t StateKeyHash::operator()(const StateKey& k) const {
    uint64_t h = 1469598103934665603ull ^ k.node;
    auto mix = [&](uint64_t v) { h = (h ^ v) * 1099511628211ull; };
    for (uint32_t p : k.props) mix(p);
    mix(k.material_binding | (uint32_t(k.normal_binding) << 8) | (uint32_t(k.in_separator) << 16));
    return static_cast<size_t>(h);
}

// ---- field access ----

FieldView Upgrader::get(uint32_t id, Name field) const {
    const V1Node& n = file_.nodes[id];
    for (uint32_t i = 0; i < n.field_count; ++i) {
        const FieldEntry& e = file_.fields[n.first_field + i];
        if (e.name == field) return tree_.view(e);
    }
    return get_default(n.type, field);
}

FieldView Upgrader::get_default(Name type, Name field) const {
    const NodeTypeDecl* decl = registry_.find(Spec::Vrml1, type);
    const FieldDecl* f = decl ? decl->find(field) : nullptr;
    if (!f || f->default_field == UINT32_MAX) return {};
    const NodeTree& defaults = *f->default_tree;
    FieldView v = defaults.view(defaults.fields[f->default_field]);
    v.is_default = true;
    return v;
}

const FieldEntry* Upgrader::set_entry(uint32_t id, Name field) const {
    const V1Node& n = file_.nodes[id];
    for (uint32_t i = 0; i < n.field_count; ++i)
        if (file_.fields[n.first_field + i].name == field) return &file_.fields[n.first_field + i];
    return nullptr;
}

std::vector<double> Upgrader::values(uint32_t id, Name field) const {
    FieldView v = get(id, field);
    return {v.numbers.begin(), v.numbers.end()};
}

double Upgrader::number(uint32_t id, Name field) const {
    FieldView v = get(id, field);
    return v.numbers.empty() ? 0.0 : v.numbers[0];
}

Vec3d Upgrader::vec3(uint32_t id, Name field) const {
    FieldView v = get(id, field);
    if (v.numbers.size() < 3) return {0, 0, 0};
    return {v.numbers[0], v.numbers[1], v.numbers[2]};
}

std::string Upgrader::word(uint32_t id, Name field) const {
    FieldView v = get(id, field);
    return v.strings.empty() ? std::string() : v.strings[0];
}

// ---- making VRML97 nodes ----

Fields Upgrader::begin(std::string_view type) const {
    Fields f;
    f.decl = registry_.find(Spec::Vrml97, type);
    if (!f.decl) f.decl = registry_.find(Spec::X3d, type);
    return f;
}

void Upgrader::set(Fields& f, Name field, std::span<const double> values) {
    const FieldDecl* fd = registry_.lookup_field(f.decl->spec, *f.decl, field);
    if (fd->default_field != UINT32_MAX) {
        const NodeTree& defaults = *fd->default_tree;
        FieldView d = defaults.view(defaults.fields[fd->default_field]);
        if (std::equal(values.begin(), values.end(), d.numbers.begin(), d.numbers.end())) return;
    }
    FieldEntry e;
    e.name = field;
    e.type = fd->type;
    e.begin = static_cast<uint32_t>(tree_.numbers.size());
    e.count = static_cast<uint32_t>(values.size());
    // The values may live in the pool being appended to: copy them out first.
    const double* pool = tree_.numbers.data();
    if (values.data() >= pool && values.data() < pool + tree_.numbers.size()) {
        std::vector<double> copy(values.begin(), values.end());
        tree_.numbers.insert(tree_.numbers.end(), copy.begin(), copy.end());
    } else {
        tree_.numbers.insert(tree_.numbers.end(), values.begin(), values.end());
    }
    f.list.push_back(e);
}

void Upgrader::set_strings(Fields& f, Name field, std::vector<std::string> values) {
    const FieldDecl* fd = registry_.lookup_field(f.decl->spec, *f.decl, field);
    FieldEntry e;
    e.name = field;
    e.type = fd->type;
    e.begin = static_cast<uint32_t>(tree_.strings.size());
    e.count = static_cast<uint32_t>(values.size());
    for (std::string& s : values) tree_.strings.push_back(std::move(s));
    f.list.push_back(e);
}

void Upgrader::set_node(Fields& f, Name field, NodeId node) {
    if (node == kNullNode) return;
    set_nodes(f, field, std::span<const NodeId>(&node, 1));
}

void Upgrader::set_nodes(Fields& f, Name field, std::span<const NodeId> nodes) {
    const FieldDecl* fd = registry_.lookup_field(f.decl->spec, *f.decl, field);
    FieldEntry e;
    e.name = field;
    e.type = fd->type;
    e.begin = static_cast<uint32_t>(tree_.node_refs.size());
    e.count = static_cast<uint32_t>(nodes.size());
    tree_.node_refs.insert(tree_.node_refs.end(), nodes.begin(), nodes.end());
    f.list.push_back(e);
}

void Upgrader::reuse(Fields& f, Name field, uint32_t id, Name v1_field) {
    if (const FieldEntry* src = set_entry(id, v1_field)) {
        FieldEntry e = *src;
        e.name = field;
        f.list.push_back(e);
        return;
    }
    FieldView d = get(id, v1_field);  // the VRML 1.0 default, copied into the tree
    set(f, field, d.numbers);
}

NodeId Upgrader::make(Fields& f, SourceLoc loc, Name def) {
    if (tree_.nodes.size() >= limits_.max_nodes)
        throw SyntaxError{loc.offset,
                          "more than " + std::to_string(limits_.max_nodes) + " nodes (limit)"};
    Node n;
    n.kind = tree_.kind_of(f.decl, f.decl->name);
    n.def_name = def;
    n.loc = loc;
    n.first_field = static_cast<uint32_t>(tree_.fields.size());
    const uint32_t field_count = static_cast<uint32_t>(f.list.size());
    tree_.fields.insert(tree_.fields.end(), f.list.begin(), f.list.end());
    tree_.add_node(n, field_count);
    f.list.clear();
    return static_cast<NodeId>(tree_.nodes.size() - 1);
}

void Upgrader::fail(uint32_t id, std::string message) const {
    throw SyntaxError{file_.nodes[id].loc.offset, std::move(message)};
}

void Upgrader::warn(uint32_t id, std::string message, const std::string& cause) {
    scene_.diagnostics.warning(file_.nodes[id].loc, std::move(message), cause);
}

StateKey Upgrader::key(uint32_t id, const State& s) const {
    StateKey k;
    k.node = id;
    k.props = {s.material,          s.coords,      s.normals,   s.texcoords, s.texture,
               s.texture_transform, s.shape_hints, s.font_style};
    k.material_binding = static_cast<uint8_t>(s.material_binding);
    k.normal_binding = static_cast<uint8_t>(s.normal_binding);
    k.in_separator = s.in_separator;
    return k;
}

}  // namespace vr::vrml1
