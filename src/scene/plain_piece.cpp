#include "scene/plain_piece.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <unordered_map>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "scene/build_internal.h"
#include "scene/transform.h"
#include "scene/translated_shape.h"

namespace vr {

namespace {

using detail::FirstIndexMap;
using detail::MaterialKey;

// ---- the node types and the fields the scene build reads of them -----------------------------

enum class Type : uint8_t {
    Transform,
    Group,
    Shape,
    Appearance,
    Material,
    Sphere,
    Box,
    Cylinder,
    Cone
};
constexpr size_t kTypes = 9;
constexpr std::string_view kTypeNames[kTypes] = {
    "Transform", "Group", "Shape", "Appearance", "Material", "Sphere", "Box", "Cylinder", "Cone"};
bool is_child(Type t) { return t == Type::Transform || t == Type::Group || t == Type::Shape; }
bool is_geometry(Type t) { return t >= Type::Sphere; }

// The node fields the pattern has; any other node field makes the reader give up.
enum class NodeField : uint8_t { None, Children, Appearance, Geometry, Material };

// A field the scene build reads (detail::Builder's make_group, make_shape, material and
// make_geometry): its values go to slots [slot, slot + count) of the node's values.
struct BuildField {
    std::string_view name;
    uint8_t slot;
    // Numbers: 1 for SFFloat and SFBool, 3 for SFVec3f and SFColor, 4 for SFRotation.
    uint8_t count;
};
constexpr size_t kSlots = 17;  // Transform's five fields
const std::vector<BuildField>& build_fields(Type t) {
    static const std::vector<BuildField> kFields[kTypes] = {
        {{"translation", 0, 3},
         {"rotation", 3, 4},
         {"scale", 7, 3},
         {"scaleOrientation", 10, 4},
         {"center", 14, 3}},
        {},
        {{"visible", 0, 1}},
        {},
        {{"ambientIntensity", 0, 1},
         {"diffuseColor", 1, 3},
         {"specularColor", 4, 3},
         {"shininess", 7, 1},
         {"emissiveColor", 8, 3},
         {"transparency", 11, 1}},
        {{"radius", 0, 1}},
        {{"size", 0, 3}},
        {{"radius", 0, 1}, {"height", 1, 1}, {"side", 2, 1}, {"top", 3, 1}, {"bottom", 4, 1}},
        {{"bottomRadius", 0, 1}, {"height", 1, 1}, {"side", 2, 1}, {"bottom", 3, 1}},
    };
    return kFields[static_cast<size_t>(t)];
}

// A field a file may give: read into its slots, or read and dropped (slot < 0).
struct FieldInfo {
    std::string_view name;
    ValueKind kind = ValueKind::Float;
    int8_t slot = -1;
    NodeField node = NodeField::None;
    bool readable = false;  // false: a kind this reader does not take (it gives up)
};

struct TypeInfo {
    Name name = kNoName;
    std::vector<FieldInfo> fields;  // the node's interface
    std::array<double, kSlots> defaults{};
    // Geometry: the ranges the build checks (Sphere radius; Box size; Cylinder radius, height;
    // Cone bottomRadius, height).
    std::array<const NumericRange*, 2> ranges{};
};

struct Grammar {
    std::array<TypeInfo, kTypes> types;
    bool usable = false;
};

NodeField node_field(Type t, std::string_view name) {
    if ((t == Type::Transform || t == Type::Group) && name == "children")
        return NodeField::Children;
    if (t == Type::Shape && name == "appearance") return NodeField::Appearance;
    if (t == Type::Shape && name == "geometry") return NodeField::Geometry;
    if (t == Type::Appearance && name == "material") return NodeField::Material;
    return NodeField::None;
}

bool numeric(ValueKind k) {
    switch (k) {
        case ValueKind::Bool:
        case ValueKind::Float:
        case ValueKind::Double:
        case ValueKind::Time:
        case ValueKind::Vec2f:
        case ValueKind::Vec3f:
        case ValueKind::Vec4f:
        case ValueKind::Vec2d:
        case ValueKind::Vec3d:
        case ValueKind::Vec4d:
        case ValueKind::Rotation:
        case ValueKind::Color:
        case ValueKind::ColorRGBA:
            return true;
        default:
            return false;
    }
}

// The type's interface and defaults as the tree's reading and build see them (the reader takes a
// field of the node's own table; the build reads a value or the default lookup_field gives).
bool describe(const Registry& registry, Spec spec, Type t, TypeInfo& info) {
    const Name name = intern(kTypeNames[static_cast<size_t>(t)]);
    const NodeTypeDecl* decl = registry.lookup(spec, name);
    if (!decl || decl->name != name) return false;
    // The build dispatches on the role: these types must be what their names say.
    if ((is_child(t) || is_geometry(t)) && decl->role != name) return false;
    info.name = name;
    for (const FieldDecl& f : decl->fields) {
        FieldInfo field;
        field.name = name_text(f.name);
        field.kind = f.type.kind;
        field.node = node_field(t, field.name);
        const bool node_ok = f.type.kind == ValueKind::Node && field.node != NodeField::None &&
                             f.type.multi == (field.node == NodeField::Children);
        field.readable = has_value(f.access) && !f.extension &&
                         (node_ok || (!f.type.multi && numeric(f.type.kind)));
        info.fields.push_back(field);
    }
    size_t range = 0;
    for (const BuildField& b : build_fields(t)) {
        const FieldDecl* f = registry.lookup_field(decl->spec, *decl, intern(b.name));
        if (!f || f->default_field == UINT32_MAX || f->type.multi) return false;
        const FieldView v = f->default_tree->view(f->default_tree->fields[f->default_field]);
        if (v.numbers.size() != b.count) return false;
        std::copy(v.numbers.begin(), v.numbers.end(), info.defaults.begin() + b.slot);
        for (FieldInfo& field : info.fields)
            if (field.name == b.name) field.slot = static_cast<int8_t>(b.slot);
        if (is_geometry(t) && f->type.kind != ValueKind::Bool && range < 2)
            info.ranges[range++] = &f->numeric_range;
    }
    // The fields files give are looked up first.
    std::stable_partition(info.fields.begin(), info.fields.end(), [](const FieldInfo& f) {
        return f.slot >= 0 || f.node != NodeField::None;
    });
    return true;
}

const Grammar& grammar(Spec spec) {
    static const auto make = [](Spec s) {
        Grammar g;
        g.usable = true;
        for (size_t t = 0; t < kTypes; ++t)
            g.usable = g.usable && describe(Registry::builtin(), s, Type(t), g.types[t]);
        return g;
    };
    static const Grammar vrml97 = make(Spec::Vrml97), x3d = make(Spec::X3d), none;
    return spec == Spec::Vrml97 ? vrml97 : spec == Spec::X3d ? x3d : none;
}

// ---- reading ----------------------------------------------------------------------------------

struct GiveUp {};  // the piece is not plain: it is read into a tree instead
[[noreturn]] void give_up() { throw GiveUp{}; }

constexpr uint32_t kNoNode = UINT32_MAX;

// One node of the top-level subtree being read.
struct PlainNode {
    Type type = Type::Group;
    SourceOffset offset = 0;  // of its type name, as the tree's node location
    uint64_t given = 0;       // fields the file gave, by index in TypeInfo::fields
    uint32_t first_child = 0, child_count = 0;  // into Subtree::children
    // Nodes of the subtree, kNoNode for none; an appearance may be an outer node (a USE of a DEF
    // before the piece: kFirstOuterNode + k).
    uint32_t appearance = kNoNode, geometry = kNoNode, material = kNoNode;
    std::array<double, kSlots> values{};  // the build's fields, defaults where not given
};

struct Subtree {
    std::vector<PlainNode> nodes;
    std::vector<uint32_t> children;  // each node's children, one block a node
};

class PlainReader {
  public:
    PlainReader(const Grammar& grammar, const PieceText& text)
        : grammar_(grammar),
          text_(text),
          lexer_(text.source, text.begin, text.end),
          depth_limit_(std::min<size_t>(text.max_depth, 100)) {}

    // The next top-level node into `tree` (its root is the last node); false at the piece's end.
    bool next(Subtree& tree) {
        tree.nodes.clear();
        tree.children.clear();
        stack_.clear();
        const Token t = lexer_.next();
        if (t.kind == TokenKind::End) return false;
        if (t.kind != TokenKind::Word || !is_child(node(t, 0, tree).type)) give_up();
        return true;
    }

    TextConsumed& counts() { return counts_; }

  private:
    const PlainNode& node(const Token& type_token, size_t depth, Subtree& tree) {
        if (depth > depth_limit_ || ++counts_.nodes >= text_.max_nodes) give_up();
        const Type type = type_of(lexer_.text(type_token));
        const TypeInfo& info = grammar_.types[static_cast<size_t>(type)];
        if (lexer_.next().kind != TokenKind::LBrace) give_up();
        PlainNode n;
        n.type = type;
        n.offset = type_token.offset;
        n.values = info.defaults;
        for (;;) {
            const Token t = lexer_.next();
            if (t.kind == TokenKind::RBrace) break;
            if (t.kind != TokenKind::Word) give_up();
            const std::string_view word = lexer_.text(t);
            size_t k = 0;
            while (k < info.fields.size() && !same_word(info.fields[k].name, word)) ++k;
            if (k == info.fields.size() || !info.fields[k].readable || k >= 64 ||
                (n.given >> k & 1))
                give_up();  // another node's field, an event, a kind not read here, or twice
            n.given |= uint64_t(1) << k;
            const FieldInfo& field = info.fields[k];
            if (field.name == "solid") give_up();  // the build reads it (back-face culling)
            if (field.node == NodeField::None)
                value(field, n.values);
            else
                node_value(field.node, depth, tree, n);
        }
        tree.nodes.push_back(n);
        return tree.nodes.back();
    }

    // Most names differ in length or first letter: no call to memcmp for them (it showed in a
    // large file's profile: bench/README.md, "Figures behind the comments").
    static bool same_word(std::string_view a, std::string_view b) {
        return a.size() == b.size() && a[0] == b[0] &&
               std::memcmp(a.data(), b.data(), a.size()) == 0;
    }

    Type type_of(std::string_view word) const {
        for (size_t t = 0; t < kTypes; ++t)
            if (same_word(kTypeNames[t], word)) return Type(t);
        give_up();  // DEF, USE, PROTO, ROUTE, another node type ...
    }

    // A numeric or boolean field, converted exactly as the tree's reader converts it.
    void value(const FieldInfo& field, std::array<double, kSlots>& values) {
        // Straight to the slots (a copy afterwards compiled to `rep movsq`: 22% of this reader).
        std::array<double, 4> dropped;
        double* v = field.slot >= 0 ? values.data() + field.slot : dropped.data();
        const int count = components(field.kind);
        for (int i = 0; i < count; ++i) {
            if (field.kind == ValueKind::Bool) {
                const Token t = lexer_.next();
                const std::string_view w = lexer_.text(t);
                if (t.kind != TokenKind::Word || (w != "TRUE" && w != "FALSE")) give_up();
                v[i] = w == "TRUE" ? 1.0 : 0.0;
                continue;
            }
            Decimal d;
            const Token t = lexer_.next_number(d);
            if (!d.to_double(v[i]) &&
                (t.kind != TokenKind::Word || !parse_double(lexer_.text(t), v[i])))
                give_up();
        }
        if (field.kind == ValueKind::Rotation && !normalise_rotation(v))
            give_up();  // the reader warns about a zero axis
    }

    // A node field: children (one node or a bracketed list), or one node, NULL or a USE.
    void node_value(NodeField field, size_t depth, Subtree& tree, PlainNode& n) {
        if (field == NodeField::Children) {
            const size_t mark = stack_.size();
            Token t = lexer_.next();
            if (t.kind == TokenKind::LBracket) {
                for (t = lexer_.next(); t.kind != TokenKind::RBracket; t = lexer_.next()) {
                    stack_.push_back(child(t, depth, tree));
                    if (stack_.size() - mark > text_.max_values) give_up();  // the reader fails
                }
            } else {
                stack_.push_back(child(t, depth, tree));
            }
            n.first_child = static_cast<uint32_t>(tree.children.size());
            n.child_count = static_cast<uint32_t>(stack_.size() - mark);
            tree.children.insert(tree.children.end(), stack_.begin() + std::ptrdiff_t(mark),
                                 stack_.end());
            stack_.resize(mark);
            return;
        }
        const Token t = lexer_.next();
        if (t.kind != TokenKind::Word) give_up();
        const std::string_view w = lexer_.text(t);
        uint32_t value = kNoNode;
        if (w == "USE" && field == NodeField::Appearance) {
            value = outer_use();
        } else if (w != "NULL") {
            const Type type = node(t, depth + 1, tree).type;
            const bool fits = field == NodeField::Appearance ? type == Type::Appearance
                              : field == NodeField::Material ? type == Type::Material
                                                             : is_geometry(type);
            if (!fits) give_up();  // the build warns about a node of the wrong type
            value = static_cast<uint32_t>(tree.nodes.size() - 1);
        }
        (field == NodeField::Appearance ? n.appearance
         : field == NodeField::Material ? n.material
                                        : n.geometry) = value;
    }

    uint32_t child(const Token& t, size_t depth, Subtree& tree) {
        if (t.kind != TokenKind::Word || !is_child(node(t, depth + 1, tree).type)) give_up();
        return static_cast<uint32_t>(tree.nodes.size() - 1);
    }

    // USE of a name no DEF in the piece gave (a piece with a DEF is not plain): an outer node.
    uint32_t outer_use() {
        const Token name = lexer_.next();
        if (name.kind != TokenKind::Word) give_up();
        ++counts_.uses;
        const Name n = intern(lexer_.text(name));
        const auto [it, added] = outer_index_.try_emplace(
            n, kFirstOuterNode + static_cast<uint32_t>(counts_.outer_uses.size()));
        if (added) counts_.outer_uses.push_back(n);
        return it->second;
    }

    const Grammar& grammar_;
    const PieceText& text_;
    Lexer lexer_;
    size_t depth_limit_;
    TextConsumed counts_;
    std::vector<uint32_t> stack_;  // children of the lists being read, innermost last
    std::unordered_map<Name, uint32_t> outer_index_;
};

// ---- building: detail::Builder's steps for these node types, in its order ---------------------

class FragmentWriter {
  public:
    FragmentWriter(const Grammar& grammar, uint32_t file) : grammar_(grammar), file_(file) {
        groups_.emplace_back();  // the root
        groups_[Scene::kRoot].origin.type = intern("(root)");
    }

    // One top-level node: a slot of the root's block, filled if it draws.
    void add_root(const Subtree& tree) {
        tree_ = &tree;
        root_refs_.emplace_back();
        if (const auto ref = child(static_cast<uint32_t>(tree.nodes.size() - 1)))
            root_refs_[root_count_++] = *ref;
    }

    // The fragment: the root's block first (the tree's build claims it before any top-level node
    // is built), then the other groups' blocks.
    Scene finish() && {
        const auto shift = static_cast<uint32_t>(root_refs_.size());
        groups_[Scene::kRoot].first_child = 0;
        groups_[Scene::kRoot].child_count = root_count_;
        for (size_t g = 1; g < groups_.size(); ++g) groups_[g].first_child += shift;
        root_refs_.insert(root_refs_.end(), refs_.begin(), refs_.end());
        scene_.groups.adopt(std::move(groups_));
        scene_.child_refs.adopt(std::move(root_refs_));
        scene_.translations.adopt(std::move(translations_));
        scene_.shapes.adopt(std::move(shapes_));
        scene_.translated_shapes.adopt(std::move(translated_shapes_));
        return std::move(scene_);
    }

  private:
    const PlainNode& at(uint32_t n) const { return tree_->nodes[n]; }
    sg::Origin origin(const PlainNode& n) const {
        return sg::Origin{grammar_.types[static_cast<size_t>(n.type)].name, kNoName,
                          SourceLoc{file_, n.offset}};
    }

    std::optional<sg::ChildRef> child(uint32_t n) {
        if (at(n).type == Type::Shape) return shape(n);
        return translated_or_group(group(n));
    }

    // detail::Builder::translated_or_group's question, asked of the group just built.
    sg::ChildRef translated_or_group(sg::Index g) {
        const sg::ChildRef as_group{sg::NodeKind::Group, g};
        const sg::Group group = groups_[g];
        if (g + 1 != groups_.size() || group.child_count != 1 ||
            group.transform_kind != sg::GroupTransform::Translation ||
            group.transform + 1 != translations_.size())
            return as_group;
        const sg::ChildRef only = refs_[group.first_child];
        if (only.kind != sg::NodeKind::Shape || only.index + 1 != shapes_.size()) return as_group;
        const std::optional<sg::TranslatedShape> t =
            translated_shape(group, translations_[group.transform], shapes_[only.index]);
        if (!t) return as_group;
        groups_.pop_back();
        translations_.pop_back();
        shapes_.pop_back();
        refs_.resize(group.first_child);
        const auto index = static_cast<sg::Index>(translated_shapes_.size());
        translated_shapes_.push_back(*t);
        return sg::ChildRef{sg::NodeKind::TranslatedShape, index};
    }

    sg::Index group(uint32_t id) {
        const PlainNode& n = at(id);
        const auto index = static_cast<sg::Index>(groups_.size());
        groups_.emplace_back();
        sg::Group g;
        g.origin = origin(n);
        if (n.type == Type::Transform) {
            const auto& v = n.values;
            TransformFields f;
            f.translation = Vec3(v[0], v[1], v[2]);
            f.rotation = Vec4(v[3], v[4], v[5], v[6]);
            f.scale = Vec3(v[7], v[8], v[9]);
            f.scale_orientation = Vec4(v[10], v[11], v[12], v[13]);
            f.center = Vec3(v[14], v[15], v[16]);
            const Mat4 m = transform_matrix(f);
            // [I | t] with a finite t (every number read is finite) is never singular: the
            // build's order of the two tests gives the same answer, and most atoms skip one.
            if (is_translation(m)) {
                g.transform_kind = sg::GroupTransform::Translation;
                g.transform = static_cast<sg::Index>(translations_.size());
                translations_.push_back(Vec3(m[3]));
            } else if (is_singular(m)) {
                give_up();  // warned about by the build
            } else {
                g.transform_kind = sg::GroupTransform::Matrix;
                g.transform = static_cast<sg::Index>(scene_.matrices.size());
                scene_.matrices.push_back(m);
            }
        }
        // The block is claimed before the children are built (theirs follow it).
        const size_t first = refs_.size();
        refs_.resize(first + n.child_count);
        uint32_t count = 0;
        for (uint32_t c = 0; c < n.child_count; ++c)
            if (const auto ref = child(tree_->children[n.first_child + c]))
                refs_[first + count++] = *ref;
        g.first_child = static_cast<uint32_t>(first);
        g.child_count = count;
        groups_[index] = g;
        return index;
    }

    std::optional<sg::ChildRef> shape(uint32_t id) {
        const PlainNode& n = at(id);
        if (n.values[0] == 0.0) return std::nullopt;  // visible FALSE
        sg::Shape s;
        s.origin = origin(n);
        if (is_outer_node(n.appearance))
            s.appearance = n.appearance;  // resolved by the splice
        else if (n.appearance != kNoNode)
            s.appearance = appearance(n.appearance);
        if (n.geometry != kNoNode) s.geometry = geometry(n.geometry);
        if (s.geometry == sg::kNone) return std::nullopt;
        const auto index = static_cast<sg::Index>(shapes_.size());
        shapes_.push_back(s);
        return sg::ChildRef{sg::NodeKind::Shape, index};
    }

    sg::Index appearance(uint32_t id) {
        const PlainNode& n = at(id);
        sg::Appearance a;
        a.origin = origin(n);
        if (n.material != kNoNode) a.material = material(n.material);
        auto index = static_cast<sg::Index>(scene_.appearances.size());
        if (uint64_t key; detail::appearance_key(a, key))
            index = same_appearance_.find_or_add(key, index);
        if (index == scene_.appearances.size()) scene_.appearances.push_back(a);
        return index;
    }

    sg::Index material(uint32_t id) {
        const PlainNode& n = at(id);
        const auto& v = n.values;
        sg::Material m;
        m.origin = origin(n);
        m.model = sg::MaterialModel::Phong;
        m.ambient_intensity = v[0];
        m.diffuse_color = Vec3(v[1], v[2], v[3]);
        m.specular_color = Vec3(v[4], v[5], v[6]);
        m.shininess = v[7];
        m.emissive_color = Vec3(v[8], v[9], v[10]);
        m.transparency = v[11];
        auto index = static_cast<sg::Index>(scene_.materials.size());
        MaterialKey key;
        if (detail::material_key(m, key))
            index = same_material_.try_emplace(key, index).first->second;
        if (index == scene_.materials.size()) scene_.materials.push_back(m);
        return index;
    }

    sg::Index geometry(uint32_t id) {
        const PlainNode& n = at(id);
        const TypeInfo& info = grammar_.types[static_cast<size_t>(n.type)];
        const auto& v = n.values;
        sg::Geometry g;
        g.origin = origin(n);
        // An X3D primitive's `solid` is TRUE here (a piece that gives it is read as a tree).
        g.cull_back_faces = &grammar_ == &grammar(Spec::X3d);
        const auto in_range = [&](size_t r, std::initializer_list<double> x) {
            if (!info.ranges[r]->contains({x.begin(), x.size()})) give_up();  // warned about
        };
        switch (n.type) {
            case Type::Sphere:
                in_range(0, {v[0]});
                g.shape = sg::Sphere{v[0]};
                break;
            case Type::Box:
                in_range(0, {v[0], v[1], v[2]});
                g.shape = sg::Box{Vec3(v[0], v[1], v[2])};
                break;
            case Type::Cylinder:
                in_range(0, {v[0]});
                in_range(1, {v[1]});
                g.shape = sg::Cylinder{v[0], v[1], v[2] != 0.0, v[3] != 0.0, v[4] != 0.0};
                break;
            default:  // Cone
                in_range(0, {v[0]});
                in_range(1, {v[1]});
                g.shape = sg::Cone{v[0], v[1], v[2] != 0.0, v[3] != 0.0};
                break;
        }
        auto index = static_cast<sg::Index>(scene_.geometries.size());
        if (n.type == Type::Sphere)
            index = same_sphere_.find_or_add(std::bit_cast<uint64_t>(v[0]), index);
        if (index == scene_.geometries.size()) scene_.geometries.push_back(std::move(g));
        return index;
    }

    const Grammar& grammar_;
    uint32_t file_;
    const Subtree* tree_ = nullptr;
    Scene scene_;  // matrices, geometries, appearances, materials; the rest below until finish()
    std::vector<sg::Group> groups_;
    std::vector<sg::ChildRef> root_refs_, refs_;
    uint32_t root_count_ = 0;
    std::vector<Vec3> translations_;
    std::vector<sg::Shape> shapes_;
    std::vector<sg::TranslatedShape> translated_shapes_;
    std::unordered_map<MaterialKey, sg::Index, detail::MaterialKeyHash> same_material_;
    FirstIndexMap same_appearance_, same_sphere_;
};

}  // namespace

std::optional<PlainPiece> read_plain_piece(const PieceText& text) {
    const Grammar& g = grammar(text.spec);
    if (!g.usable) return std::nullopt;
    try {
        PlainReader reader(g, text);
        FragmentWriter writer(g, text.file);
        Subtree tree;
        while (reader.next(tree)) {
            writer.add_root(tree);
            ++reader.counts().roots;
        }
        return PlainPiece{std::move(writer).finish(), std::move(reader.counts())};
    } catch (const GiveUp&) {
        return std::nullopt;
    }
}

}  // namespace vr
