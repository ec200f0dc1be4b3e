#include "parser/writer.h"

#include <charconv>
#include <unordered_map>
#include <unordered_set>

#include "parser/def_names.h"
#include "parser/proto_kinds.h"
#include "parser/registry.h"

namespace vr {

std::string format_number(double v) {
    if (v == 0.0) return "0";
    char buf[32];
    auto r = std::to_chars(buf, buf + sizeof(buf), v);
    return std::string(buf, r.ptr);
}

std::string format_number_compact(double v) {
    std::string text = format_number(v);
    // ".5" and "-.5" are numbers in both grammars; the zero in front is a byte a value.
    if (text.starts_with("0.")) text.erase(0, 1);
    if (text.starts_with("-0.")) text.erase(1, 1);
    return text;
}

bool needs_solid_false_in_x3d(const NodeTree& tree, NodeId id) {
    const NodeTypeDecl* own = tree.decl(id);
    if (!own || own->spec == Spec::X3d) return false;
    const NodeTypeDecl* x3d = Registry::builtin().find(Spec::X3d, tree.type(id));
    const FieldDecl* solid = x3d ? x3d->find(std::string_view("solid")) : nullptr;
    // get() gives X3D's default where VRML97's interface has no `solid` (registry lookup_field).
    return solid && tree.get_bool(id, solid->name);
}

namespace {

class Writer {
  public:
    Writer(const NodeTree& tree, Encoding target, bool compact)
        : tree_(tree), target_(target), compact_(compact), names_(tree) {
        if (compact_) {
            kinds_ = find_proto_kinds(tree_, names_);
            keep_kinds_that_pay();
        }
    }

    std::string run() {
        out_ += target_ == Encoding::X3dClassic ? "#X3D V3.3 utf8\nPROFILE Full\n\n"
                                                : "#VRML V2.0 utf8\n\n";
        // The read file's lengths are still in its UNIT (parser/units.h; angles are radians now):
        // X3D says so with a UNIT statement, VRML97, which has none, with a scale around it all.
        const double length = tree_.root_length_scale;
        const bool scaled = length != 1.0 && target_ != Encoding::X3dClassic;
        if (length != 1.0 && !scaled) out_ += "UNIT length unit " + format_number(length) + "\n\n";
        write_proto_kinds();
        if (scaled) {
            const std::string s = format_number(length);
            out_ += "Transform {\n  scale " + s + " " + s + " " + s + "\n  children [\n";
        }
        for (NodeId root : tree_.roots) {
            if (scaled) indent(2);
            write_node(root, scaled ? 2 : 0);
            out_ += "\n";
        }
        if (scaled) out_ += "  ]\n}\n";
        write_routes();
        return std::move(out_);
    }

  private:
    // Each kind's declaration (proto_kinds.h), before any statement, at the top level where both
    // grammars allow a PROTO: its body is a copy of one Transform of the kind, with the
    // translation an instance gives (default 0 0 0: an instance without one leaves it unset).
    // The body is a scope of its own: its nodes are written out, with no DEF or USE.
    void write_proto_kinds() {
        const char* access = target_ == Encoding::X3dClassic ? "initializeOnly" : "field";
        for (size_t k = 0; k < kinds_.bodies.size(); ++k) {
            out_ += "PROTO " + kinds_.names[k] + "[" + access + " SFVec3f t 0 0 0]{";
            out_ += body_text(kinds_.bodies[k], true);
            out_ += "}\n";
        }
        if (!kinds_.bodies.empty()) out_ += "\n";
    }

    // A kind is declared when that makes the file smaller (PyMOL's sticks and RasMol's bonds
    // come in kinds of a few, by their rotations). Declared: `PROTO A[field SFVec3f t 0 0 0]{`,
    // the body (every node written out) and `}` once, then `A{t }` around each translation. Not:
    // each member's Transform around its translation and `USE name` of the child, which the
    // first member writes out with `DEF name` instead (its shared nodes USEd: they are written
    // out once in the file either way).
    void keep_kinds_that_pay() {
        const double is_t = double(std::string_view("translation IS t ").size());
        vr::keep_kinds_that_pay(kinds_, [&](size_t k, size_t members, const std::string& name) {
            const NodeId body = kinds_.bodies[k];
            const double n = double(members), text = double(body_text(body, true).size());
            const NodeId child = tree_.get_node(body, intern("children"));
            const double child_text = double(body_text(child, false).size());
            estimating_ = child;
            const double child_plain = double(body_text(child, false).size());
            estimating_ = kNullNode;
            const double use = double(4 + names_.name(child).size());  // "USE name" or "DEF name "
            KindCost c;
            c.declared = double(24 + 2 * name.size()) + text + n * double(name.size() + 4);
            c.plain = n * (text - is_t - child_text) + child_plain + n * use;
            return c;
        });
    }

    // The node's text as a PROTO body holds it (no DEF or USE); `is_body`: the node is the
    // body's Transform, whose translation is the instance's.
    std::string body_text(NodeId id, bool is_body) {
        std::string saved = std::move(out_);
        out_.clear();
        in_body_ = true;
        body_ = is_body ? id : kNullNode;
        write_node(id, 0);
        in_body_ = false;
        body_ = kNullNode;
        std::string text = std::move(out_);
        out_ = std::move(saved);
        return text;
    }

    // An instance of the Transform's kind: its translation alone.
    void write_instance(NodeId id, uint32_t kind) {
        written_.insert(id);
        out_ += kinds_.names[kind] + "{";
        for (const FieldEntry& e : tree_.set_fields(id))
            if (name_text(e.name) == "translation") {
                out_ += "t ";
                write_value(e, 0);
            }
        out_ += "}";
    }

    // The ROUTEs between written nodes (those into or out of an Inline's file or an IMPORT stay
    // with that file), after the nodes they name.
    void write_routes() {
        for (const Route& r : tree_.routes) {
            if (r.from_import != Route::kNoImport || r.to_import != Route::kNoImport) continue;
            if (!written_.count(r.from) || !written_.count(r.to)) continue;
            const std::string from = names_.name(r.from), to = names_.name(r.to);
            if (from.empty() || to.empty()) continue;
            out_ += "ROUTE " + from + "." + std::string(name_text(r.from_event)) + " TO " + to +
                    "." + std::string(name_text(r.to_event)) + "\n";
        }
    }

    void indent(int depth) {
        if (!compact_) out_.append(static_cast<size_t>(depth) * 2, ' ');
    }

    std::string_view field_name(NodeId id, Name field) {
        std::string_view type = tree_.type_name(id);
        std::string_view name = name_text(field);
        if (target_ == Encoding::X3dClassic) {
            if (type == "Switch" && name == "choice") return "children";
            if (type == "LOD" && name == "level") return "children";
        } else {
            if (type == "Switch" && name == "children") return "choice";
            if (type == "LOD" && name == "children") return "level";
        }
        return name;
    }

    void write_node(NodeId id, int depth) {
        if (id == kNullNode) {
            out_ += "NULL";
            return;
        }
        if (estimating_ != kNullNode && id != estimating_ && names_.references(id) > 1) {
            out_ += "USE " + names_.name(id);
            return;
        }
        if (!in_body_) {
            if (auto kind = kinds_.kind_of.find(id); kind != kinds_.kind_of.end())
                return write_instance(id, kind->second);
            if (written_.count(id)) {
                out_ += "USE " + names_.name(id);
                return;
            }
            written_.insert(id);
            std::string def = names_.name(id);
            if (!def.empty()) out_ += "DEF " + def + " ";
        }
        out_ += tree_.type_name(id);
        auto fields = tree_.set_fields(id);
        const bool solid_false =
            target_ == Encoding::X3dClassic && needs_solid_false_in_x3d(tree_, id);
        if (fields.empty() && !solid_false) {
            out_ += " {}";
            return;
        }
        out_ += compact_ ? " { " : " {\n";
        if (id == body_) out_ += "translation IS t ";  // compact only: no indentation
        static const Name solid = intern("solid");
        for (const FieldEntry& e : fields) {
            if (id == body_ && name_text(e.name) == "translation") continue;
            if (solid_false && e.name == solid) continue;
            indent(depth + 1);
            out_ += field_name(id, e.name);
            out_ += " ";
            write_value(e, depth + 1);
            out_ += compact_ ? " " : "\n";
        }
        if (solid_false) {
            indent(depth + 1);
            out_ += compact_ ? "solid FALSE " : "solid FALSE\n";
        }
        indent(depth);
        out_ += "}";
    }

    void write_string(const std::string& s) {
        out_ += '"';
        for (char c : s) {
            if (c == '"' || c == '\\') out_ += '\\';
            out_ += c;
        }
        out_ += '"';
    }

    void write_value(const FieldEntry& e, int depth) {
        FieldView v = tree_.view(e);
        const FieldType t = e.type;
        if (t.kind == ValueKind::Node) {
            if (!t.multi) return write_node(v.nodes.empty() ? kNullNode : v.nodes[0], depth);
            if (v.nodes.empty()) {
                out_ += "[]";
                return;
            }
            // One node needs no brackets (VRML97 grammar: mfnodeValue ::= nodeStatement | [...]).
            if (compact_ && v.nodes.size() == 1) return write_node(v.nodes[0], depth);
            out_ += "[\n";
            for (NodeId child : v.nodes) {
                indent(depth + 1);
                write_node(child, depth + 1);
                out_ += "\n";
            }
            indent(depth);
            out_ += "]";
            return;
        }
        if (t.kind == ValueKind::String) {
            if (t.multi) out_ += "[";
            for (size_t i = 0; i < v.strings.size(); ++i) {
                if (i) out_ += t.multi ? ", " : " ";
                write_string(v.strings[i]);
            }
            if (t.multi) out_ += "]";
            return;
        }
        if (t.kind == ValueKind::Image) {
            if (t.multi) out_ += "[";
            size_t i = 0;
            bool first = true;
            while (i + 3 <= v.numbers.size()) {
                if (!first) out_ += ", ";
                first = false;
                size_t n = static_cast<size_t>(v.numbers[i] * v.numbers[i + 1]);
                out_ += format_number(v.numbers[i]) + " " + format_number(v.numbers[i + 1]) + " " +
                        format_number(v.numbers[i + 2]);
                for (size_t k = 0; k < n && i + 3 + k < v.numbers.size(); ++k) {
                    char buf[16];
                    std::snprintf(buf, sizeof(buf), " 0x%X",
                                  static_cast<unsigned>(v.numbers[i + 3 + k]));
                    out_ += buf;
                }
                i += 3 + n;
            }
            if (t.multi) out_ += "]";
            return;
        }
        const size_t n = static_cast<size_t>(components(t.kind));
        if (t.multi) out_ += "[";
        for (size_t i = 0; i < v.numbers.size(); ++i) {
            if (i) {
                bool value_break = i % n == 0;
                if (value_break && t.multi && (i / n) % 8 == 0) {
                    out_ += compact_ ? "\n" : ",\n";  // commas are white space to a reader
                    indent(depth + 1);
                } else {
                    out_ += value_break && t.multi && !compact_ ? ", " : " ";
                }
            }
            if (t.kind == ValueKind::Bool) {
                out_ += v.numbers[i] != 0.0 ? "TRUE" : "FALSE";
            } else {
                out_ +=
                    compact_ ? format_number_compact(v.numbers[i]) : format_number(v.numbers[i]);
            }
        }
        if (t.multi) out_ += "]";
    }

    const NodeTree& tree_;
    Encoding target_;
    bool compact_ = false;
    std::string out_;
    DefNames names_;
    std::unordered_set<NodeId> written_;
    ProtoKinds kinds_;
    bool in_body_ = false;           // writing a PROTO body: a scope of its own, no DEF or USE
    NodeId estimating_ = kNullNode;  // sizing this node as written outside a body: shared ones USEd
    NodeId body_ = kNullNode;        // the Transform whose copy is the PROTO body being written
};

}  // namespace

std::string write_classic(const NodeTree& tree, Encoding target, bool compact) {
    return Writer(tree, target, compact).run();
}

}  // namespace vr
