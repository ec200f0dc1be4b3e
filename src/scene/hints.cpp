#include "scene/hints.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

namespace vr {

bool sg::Hints::any() const {
    return sphere_mode != SphereHint::Unset || density >= 0.0 || reflectivity >= 0.0 ||
           ior >= 0.0 || albedo.x >= 0.0 || emission.x >= 0.0 || source_radius >= 0.0 ||
           angular_radius >= 0.0;
}

void sg::Hints::override_with(const Hints& h) {
    if (h.sphere_mode != SphereHint::Unset) sphere_mode = h.sphere_mode;
    if (h.density >= 0.0) density = h.density;
    if (h.reflectivity >= 0.0) reflectivity = h.reflectivity;
    if (h.ior >= 0.0) ior = h.ior;
    if (h.albedo.x >= 0.0) albedo = h.albedo;
    if (h.emission.x >= 0.0) emission = h.emission;
    if (h.source_radius >= 0.0) source_radius = h.source_radius;
    if (h.angular_radius >= 0.0) angular_radius = h.angular_radius;
}

namespace {

struct HintNames {
    Name metadata_set = intern("MetadataSet");
    Name metadata_string = intern("MetadataString");
    Name name = intern("name");
    Name value = intern("value");
};
const HintNames& names() {
    static const HintNames n;
    return n;
}

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return out;
}

// The numbers of a Metadata value: numeric fields as they are, MetadataString values parsed.
std::vector<double> numbers_of(const FieldView& value) {
    std::vector<double> out(value.numbers.begin(), value.numbers.end());
    for (const std::string& s : value.strings) {
        const char* p = s.data();
        const char* end = s.data() + s.size();
        while (p < end) {
            while (p < end && (*p == ' ' || *p == ',' || *p == '\t')) ++p;
            if (p == end) break;
            double d = 0.0;
            auto [next, ec] = std::from_chars(p, end, d);
            if (ec != std::errc()) return {};
            out.push_back(d);
            p = next;
        }
    }
    return out;
}

class HintReader {
  public:
    HintReader(const NodeTree& tree, Diagnostics& diagnostics)
        : tree_(tree), diagnostics_(diagnostics) {}

    void read_set(NodeId set, sg::Hints& hints) {
        for (NodeId value : tree_.get(set, names().value).nodes)
            if (value != kNullNode) read_value(value, hints);
    }

    // Finds the "vrmlray" MetadataSet at or below `node` (bounded depth: metadata may nest).
    NodeId find_set(NodeId node, int depth) {
        if (node == kNullNode || depth > 8 || tree_.type(node) != names().metadata_set)
            return kNullNode;
        const FieldView name = tree_.get(node, names().name);
        if (!name.strings.empty() && name.strings[0] == "vrmlray") return node;
        for (NodeId child : tree_.get(node, names().value).nodes) {
            const NodeId found = find_set(child, depth + 1);
            if (found != kNullNode) return found;
        }
        return kNullNode;
    }

  private:
    void warn(NodeId node, const std::string& message, const std::string& cause) {
        diagnostics_.warning(tree_.nodes[node].loc, message, "hint:" + cause);
    }

    void read_value(NodeId node, sg::Hints& hints) {
        const FieldView name_field = tree_.get(node, names().name);
        if (name_field.strings.empty()) return;
        const std::string& name = name_field.strings[0];
        const FieldView value = tree_.get(node, names().value);
        if (name == "sphereMode") {
            const std::string mode =
                value.strings.empty() ? std::string() : lower(value.strings[0]);
            if (mode == "gas")
                hints.sphere_mode = sg::SphereHint::Gas;
            else if (mode == "opaque")
                hints.sphere_mode = sg::SphereHint::Opaque;
            else
                warn(node, "vrmlray hint sphereMode must be \"opaque\" or \"gas\"; ignored",
                     "sphereMode");
            return;
        }
        const std::vector<double> v = numbers_of(value);
        const bool all_finite =
            std::all_of(v.begin(), v.end(), [](double d) { return std::isfinite(d); });
        auto scalar = [&](double& out, double lo, double hi, bool open_lo, const char* range) {
            if (v.size() == 1 && all_finite && (open_lo ? v[0] > lo : v[0] >= lo) && v[0] <= hi)
                out = v[0];
            else
                warn(node, "vrmlray hint " + name + " must be one number in " + range + "; ignored",
                     name);
        };
        auto colour = [&](Vec3& out) {
            const bool ok = all_finite && (v.size() == 1 || v.size() == 3) &&
                            std::all_of(v.begin(), v.end(), [](double d) { return d >= 0.0; });
            if (ok)
                out = v.size() == 1 ? Vec3(v[0]) : Vec3(v[0], v[1], v[2]);
            else
                warn(node,
                     "vrmlray hint " + name + " must be an RGB colour (3 numbers >= 0); ignored",
                     name);
        };
        if (name == "density")
            scalar(hints.density, 0.0, kInf, false, "[0,inf)");
        else if (name == "reflectivity")
            scalar(hints.reflectivity, 0.0, 1.0, false, "[0,1]");
        else if (name == "ior")
            scalar(hints.ior, 0.0, kInf, true, "(0,inf)");
        else if (name == "sourceRadius")
            scalar(hints.source_radius, 0.0, kInf, false, "[0,inf)");
        else if (name == "angularRadius")
            scalar(hints.angular_radius, 0.0, 0.5 * kPi, false, "[0,pi/2]");
        else if (name == "albedo")
            colour(hints.albedo);
        else if (name == "emission")
            colour(hints.emission);
        else
            warn(node, "unknown vrmlray hint '" + name + "'; ignored", "unknown:" + name);
    }

    const NodeTree& tree_;
    Diagnostics& diagnostics_;
};

}  // namespace

sg::Hints read_hints(const NodeTree& tree, NodeId metadata, Diagnostics& diagnostics) {
    sg::Hints hints;
    if (metadata == kNullNode) return hints;
    HintReader reader(tree, diagnostics);
    const NodeId set = reader.find_set(metadata, 0);
    if (set != kNullNode) reader.read_set(set, hints);
    return hints;
}

}  // namespace vr
