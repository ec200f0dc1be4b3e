#include "support/tree_compare.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <unordered_map>

#include "parser/def_names.h"
#include "parser/registry.h"
#include "parser/writer.h"
#include "parser/x3d_xml.h"

namespace vr {
namespace {

class Comparer {
  public:
    Comparer(const NodeTree& a, const NodeTree& b, const TreeCompareOptions& options)
        : a_(a), b_(b), options_(options), names_(a) {}

    std::string run() {
        if (a_.roots.size() != b_.roots.size())
            return "different numbers of top-level nodes: " + std::to_string(a_.roots.size()) +
                   " vs " + std::to_string(b_.roots.size());
        for (size_t i = 0; i < a_.roots.size(); ++i) {
            std::string d = node(a_.roots[i], b_.roots[i], "roots[" + std::to_string(i) + "]");
            if (!d.empty()) return d;
        }
        return {};
    }

  private:
    std::string node(NodeId x, NodeId y, const std::string& path) {
        if (x == kNullNode || y == kNullNode)
            return x == y ? std::string() : path + ": NULL vs a node";
        auto seen_a = a_to_b_.find(x);
        auto seen_b = b_to_a_.find(y);
        if (seen_a != a_to_b_.end() || seen_b != b_to_a_.end()) {
            if (seen_a != a_to_b_.end() && seen_a->second == y) return {};
            return path + ": DEF/USE sharing differs (" + describe(a_, x) + " vs " +
                   describe(b_, y) + ")";
        }
        a_to_b_[x] = y;
        b_to_a_[y] = x;
        const std::string_view type = a_.type_name(x);
        if (type != b_.type_name(y))
            return path + ": node type " + describe(a_, x) + " vs " + describe(b_, y);
        const std::string expected_def =
            options_.names_as_written ? names_.name(x) : std::string(a_.def_name(x));
        if (expected_def != b_.def_name(y))
            return path + " " + std::string(type) + ": DEF name '" + expected_def + "' vs '" +
                   std::string(b_.def_name(y)) + "'";
        // Set fields of either node, by their X3D names, in a's order then b's.
        std::vector<std::string> fields;
        auto add = [&](const NodeTree& t, NodeId id) {
            for (const FieldEntry& e : t.set_fields(id)) {
                std::string name(x3d_field_name(type, name_text(e.name)));
                if (std::find(fields.begin(), fields.end(), name) == fields.end())
                    fields.push_back(name);
            }
        };
        add(a_, x);
        add(b_, y);
        // A VRML97 node written as X3D says `solid FALSE` (both faces drawn, as vrmlray draws the
        // VRML97 node: parser/writer.h).
        const NodeTypeDecl* b_decl = b_.decl(y);
        if (options_.names_as_written && b_decl && b_decl->spec == Spec::X3d &&
            needs_solid_false_in_x3d(a_, x)) {
            if (b_.get_bool(y, intern("solid")))
                return path + " " + std::string(type) + ".solid: TRUE where X3D needs FALSE";
            std::erase(fields, std::string("solid"));
        }
        for (const std::string& field : fields) {
            FieldView u = value(a_, x, field), v = value(b_, y, field);
            const std::string where = path + " " + std::string(type) + "." + field;
            if (!u.found || !v.found) return where + ": field unknown to one of the nodes";
            if (u.type != v.type)
                return where + ": type " + std::string(type_name(u.type)) + " vs " +
                       std::string(type_name(v.type));
            if (u.type.kind == ValueKind::Node) {
                if (u.nodes.size() != v.nodes.size())
                    return where + ": " + std::to_string(u.nodes.size()) + " vs " +
                           std::to_string(v.nodes.size()) + " nodes";
                for (size_t i = 0; i < u.nodes.size(); ++i) {
                    std::string d =
                        node(u.nodes[i], v.nodes[i], where + "[" + std::to_string(i) + "]");
                    if (!d.empty()) return d;
                }
            } else if (u.type.kind == ValueKind::String) {
                if (!std::equal(u.strings.begin(), u.strings.end(), v.strings.begin(),
                                v.strings.end()))
                    return where + ": strings differ";
            } else if (!numbers_equal(u.numbers, v.numbers)) {
                return where + ": " + numbers_text(u.numbers) + " vs " + numbers_text(v.numbers);
            }
        }
        return {};
    }

    // The node's value of a field named by its X3D name: set under either name, else the default.
    static FieldView value(const NodeTree& t, NodeId id, const std::string& x3d_name) {
        const std::string_view type = t.type_name(id);
        for (const FieldEntry& e : t.set_fields(id))
            if (x3d_field_name(type, name_text(e.name)) == x3d_name) return t.view(e);
        return t.get(id, x3d_name);
    }

    bool numbers_equal(std::span<const double> u, std::span<const double> v) const {
        if (u.size() != v.size()) return false;
        for (size_t i = 0; i < u.size(); ++i) {
            if (u[i] == v[i]) continue;
            const double scale = std::max(std::abs(u[i]), std::abs(v[i]));
            if (!(std::abs(u[i] - v[i]) <= options_.relative_tolerance * scale)) return false;
        }
        return true;
    }

    static std::string numbers_text(std::span<const double> n) {
        std::string s;
        for (size_t i = 0; i < n.size() && i < 12; ++i) {
            if (i) s += ' ';
            s += format_number(n[i]);
        }
        if (n.size() > 12) s += " ... (" + std::to_string(n.size()) + " numbers)";
        return s;
    }

    static std::string describe(const NodeTree& t, NodeId id) {
        std::string s(t.type_name(id));
        if (!t.def_name(id).empty()) s = "DEF " + std::string(t.def_name(id)) + " " + s;
        return s;
    }

    const NodeTree& a_;
    const NodeTree& b_;
    const TreeCompareOptions& options_;
    DefNames names_;
    std::unordered_map<NodeId, NodeId> a_to_b_, b_to_a_;
};

}  // namespace

std::string compare_trees(const NodeTree& a, const NodeTree& b, const TreeCompareOptions& options) {
    return Comparer(a, b, options).run();
}

}  // namespace vr
