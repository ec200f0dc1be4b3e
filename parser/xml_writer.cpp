#include "parser/xml_writer.h"

#include <cstdio>
#include <unordered_set>

#include "core/xml_escape.h"
#include "parser/def_names.h"
#include "parser/writer.h"
#include "parser/x3d_xml.h"

namespace vr {
namespace {

// X3D 4.0 additions among the interfaces in grammar/x3d.nodes (which lists the 4.0 field sets).
bool x3d_4_node(std::string_view type) {
    return type == "PhysicalMaterial" || type == "UnlitMaterial" || type == "AcousticProperties" ||
           type == "HAnimMotion";
}

bool x3d_4_field(std::string_view type, std::string_view field) {
    // Fields 4.0 added to whole families of nodes (bounded objects, URL objects, lights).
    if (field == "visible" || field == "bboxDisplay" || field == "autoRefresh" ||
        field == "autoRefreshTimeLimit" || field == "shadows" || field == "shadowIntensity")
        return true;
    if (type == "Material")
        return field.ends_with("Texture") || field.ends_with("TextureMapping") ||
               field == "normalScale" || field == "occlusionStrength";
    if (type == "Appearance")
        return field == "acousticProperties" || field == "alphaCutoff" || field == "alphaMode" ||
               field == "backMaterial" || field == "pointProperties";
    if (type == "Shape") return field == "castShadow";
    if (type == "Viewpoint" || type == "OrthoViewpoint")
        return field == "farDistance" || field == "nearDistance" || field == "navigationInfo" ||
               field == "viewAll";
    if (type == "Inline") return field == "description" || field == "global";
    if (field == "description")
        return type == "ImageTexture" || type == "PixelTexture" || type == "MultiTexture" ||
               type == "Script" || type == "ShaderPart" || type == "ShaderProgram" ||
               type == "PackagedShader" || type == "Collision";
    return false;
}

// Text fit for an XML document: valid UTF-8 (bytes that are not are read as Latin-1, which is what
// old exporters wrote), without the control characters XML 1.0 cannot hold.
std::string clean_utf8(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (size_t i = 0; i < s.size();) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        size_t len = c < 0x80           ? 1
                     : (c >> 5) == 0x6  ? 2
                     : (c >> 4) == 0xE  ? 3
                     : (c >> 3) == 0x1E ? 4
                                        : 0;
        bool valid = len > 0 && i + len <= s.size() && !(len == 2 && c < 0xC2);
        for (size_t k = 1; valid && k < len; ++k)
            valid = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
        if (valid) {
            if (len > 1 || c >= 0x20 || c == '\t' || c == '\n' || c == '\r') out.append(s, i, len);
            i += len;
        } else {
            out += static_cast<char>(0xC0 | (c >> 6));
            out += static_cast<char>(0x80 | (c & 0x3F));
            ++i;
        }
    }
    return out;
}

// Escapes text for an attribute value written between single quotes (after clean_utf8, which
// leaves no control character but tab, newline and carriage return).
void append_attr_text(std::string& out, std::string_view s) {
    append_xml_escaped(out, clean_utf8(s), XmlEscape::kSingleQuotedAttribute);
}

class XmlWriter {
  public:
    XmlWriter(const NodeTree& tree, bool compact) : tree_(tree), names_(tree), compact_(compact) {}

    std::string run() {
        const char* version = needs_x3d_4(tree_) ? "4.0" : "3.3";
        out_ += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
        out_ += std::string("<!DOCTYPE X3D PUBLIC \"ISO//Web3D//DTD X3D ") + version +
                "//EN\" \"https://www.web3d.org/specifications/x3d-" + version + ".dtd\">\n";
        out_ += std::string("<X3D profile='Full' version='") + version +
                "' xmlns:xsd='http://www.w3.org/2001/XMLSchema-instance' "
                "xsd:noNamespaceSchemaLocation='https://www.web3d.org/specifications/x3d-" +
                version + ".xsd'>\n";
        out_ += "  <head>\n";
        // The read file's lengths are still in its UNIT (parser/units.h); angles are radians now.
        if (tree_.root_length_scale != 1.0)
            out_ += "    <unit category='length' name='unit' conversionFactor='" +
                    format_number(tree_.root_length_scale) + "'/>\n";
        out_ += "    <meta name='generator' content='vrmlray convert'/>\n  </head>\n";
        out_ += "  <Scene>\n";
        for (NodeId root : tree_.roots) write_node(root, 2, kNoName);
        write_routes();
        out_ += "  </Scene>\n</X3D>\n";
        return std::move(out_);
    }

  private:
    void indent(int depth) {
        if (!compact_) out_.append(static_cast<size_t>(depth) * 2, ' ');
    }

    // The ROUTEs between written nodes, as the classic writer writes them (parser/writer.cpp).
    void write_routes() {
        for (const Route& r : tree_.routes) {
            if (r.from_import != Route::kNoImport || r.to_import != Route::kNoImport) continue;
            if (!written_.count(r.from) || !written_.count(r.to)) continue;
            const std::string from = names_.name(r.from), to = names_.name(r.to);
            if (from.empty() || to.empty()) continue;
            out_ += "    <ROUTE fromNode='" + from + "' fromField='" +
                    std::string(name_text(r.from_event)) + "' toNode='" + to + "' toField='" +
                    std::string(name_text(r.to_event)) + "'/>\n";
        }
    }

    // `field`: the X3D name of the parent's field that holds the node (kNoName at the top level).
    void write_node(NodeId id, int depth, Name field) {
        if (id == kNullNode) return;
        const std::string_view type = tree_.type_name(id);
        std::string container;
        if (field != kNoName && name_text(field) != x3d_default_container_field(type))
            container = std::string(name_text(field));
        indent(depth);
        out_ += '<';
        out_ += type;
        if (written_.count(id)) {
            attribute("USE", names_.name(id));
            if (!container.empty()) attribute("containerField", container);
            out_ += "/>\n";
            return;
        }
        written_.insert(id);
        const std::string& def = names_.name(id);
        if (!def.empty()) attribute("DEF", def);
        if (!container.empty()) attribute("containerField", container);
        bool has_children = false;
        // A VRML97 node's both faces, as vrmlray draws them (parser/writer.h).
        const bool solid_false = needs_solid_false_in_x3d(tree_, id);
        static const Name solid = intern("solid");
        for (const FieldEntry& e : tree_.set_fields(id)) {
            if (e.type.kind == ValueKind::Node) {
                has_children = has_children || has_nodes(e);
                continue;
            }
            if (solid_false && e.name == solid) continue;
            out_ += ' ';
            out_ += x3d_field_name(type, name_text(e.name));
            out_ += "='";
            write_value(e, depth + 1);
            out_ += '\'';
        }
        if (solid_false) out_ += " solid='false'";
        if (!has_children) {
            out_ += "/>\n";
            return;
        }
        out_ += ">\n";
        for (const FieldEntry& e : tree_.set_fields(id)) {
            if (e.type.kind != ValueKind::Node) continue;
            const Name x3d_name = intern(x3d_field_name(type, name_text(e.name)));
            FieldView v = tree_.view(e);
            for (NodeId child : v.nodes) write_node(child, depth + 1, x3d_name);
        }
        indent(depth);
        out_ += "</";
        out_ += type;
        out_ += ">\n";
    }

    bool has_nodes(const FieldEntry& e) const {
        for (uint32_t i = 0; i < e.count; ++i)
            if (tree_.node_refs[e.begin + i] != kNullNode) return true;
        return false;
    }

    void attribute(std::string_view name, std::string_view value) {
        out_ += ' ';
        out_ += name;
        out_ += "='";
        append_attr_text(out_, value);
        out_ += '\'';
    }

    void line_break(int depth) {
        out_ += '\n';
        indent(depth + 1);
    }

    void write_value(const FieldEntry& e, int depth) {
        FieldView v = tree_.view(e);
        const FieldType t = e.type;
        if (t.kind == ValueKind::String) {
            if (!t.multi) {
                if (!v.strings.empty()) append_attr_text(out_, v.strings[0]);
                return;
            }
            // MFString: each item quoted, '"' and '\' escaped as in the classic encoding.
            for (size_t i = 0; i < v.strings.size(); ++i) {
                if (i) out_ += ' ';
                std::string quoted = "\"";
                for (char c : v.strings[i]) {
                    if (c == '"' || c == '\\') quoted += '\\';
                    quoted += c;
                }
                quoted += '"';
                append_attr_text(out_, quoted);
            }
            return;
        }
        if (t.kind == ValueKind::Image) {
            size_t i = 0;
            while (i + 3 <= v.numbers.size()) {
                if (i) out_ += ", ";
                const size_t n = static_cast<size_t>(v.numbers[i] * v.numbers[i + 1]);
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
            return;
        }
        const size_t n = static_cast<size_t>(components(t.kind));
        for (size_t i = 0; i < v.numbers.size(); ++i) {
            if (i) {
                const bool value_break = i % n == 0;
                if (value_break && t.multi && (i / n) % 8 == 0) {
                    if (n > 1) out_ += ',';
                    line_break(depth);
                } else {
                    out_ += value_break && t.multi && n > 1 ? ", " : " ";
                }
            }
            if (t.kind == ValueKind::Bool)
                out_ += v.numbers[i] != 0.0 ? "true" : "false";
            else
                out_ +=
                    compact_ ? format_number_compact(v.numbers[i]) : format_number(v.numbers[i]);
        }
    }

    const NodeTree& tree_;
    DefNames names_;
    bool compact_ = false;
    std::string out_;
    std::unordered_set<NodeId> written_;
};

}  // namespace

bool needs_x3d_4(const NodeTree& tree) {
    std::vector<NodeId> stack(tree.roots.begin(), tree.roots.end());
    std::unordered_set<NodeId> seen;
    while (!stack.empty()) {
        NodeId id = stack.back();
        stack.pop_back();
        if (id == kNullNode || !seen.insert(id).second) continue;
        const std::string_view type = tree.type_name(id);
        if (x3d_4_node(type)) return true;
        for (const FieldEntry& e : tree.set_fields(id)) {
            if (x3d_4_field(type, name_text(e.name))) return true;
            if (e.type.kind != ValueKind::Node) continue;
            for (uint32_t i = 0; i < e.count; ++i) stack.push_back(tree.node_refs[e.begin + i]);
        }
    }
    return false;
}

std::string write_x3d_xml(const NodeTree& tree, bool compact) {
    return XmlWriter(tree, compact).run();
}

}  // namespace vr
