// Compact classic output's atom kinds (`vrmlray convert --recover-spheres`, docs/manual.md
// "convert"): a molecular scene is thousands of Transforms that differ only by their translation,
// each holding the same small Shape (an Appearance and a Sphere or Cylinder). Each such kind is
// declared once as a PROTO whose one field is the translation, and every atom becomes an instance
// of it, `A{t 1.2 3.4 5.6}`: about 25 bytes where the Transform took 75. PROTO is VRML97 (and X3D
// classic), so every browser reads the result; expanding the instances gives back the same
// Transforms with the same field values, so the scene renders the same.
#pragma once
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "parser/def_names.h"
#include "parser/node_tree.h"

namespace vr {

struct ProtoKinds {
    // Per kind: the PROTO's name and one Transform of that kind (any one: they differ only by
    // their translation), whose fields and child are the PROTO body.
    std::vector<std::string> names;
    std::vector<NodeId> bodies;
    std::unordered_map<NodeId, uint32_t> kind_of;  // every Transform written as an instance
};

// The kinds of at least two Transforms each. A Transform qualifies when it is reached once, has
// no DEF name, sets no field but translation, rotation, scale, scaleOrientation, center and
// children, and holds one Shape whose nodes are all Appearance, Material, TwoSidedMaterial,
// Sphere, Cylinder, Cone or Box (nothing that a copy per instance would make heavy, nothing with
// a URL). Nodes that a ROUTE, a PROTO interface, an EXPORT or an IMPORT names are left alone.
ProtoKinds find_proto_kinds(const NodeTree& tree, const DefNames& names);

// What writing kind k costs in a file's bytes: declared (the declaration and every member as an
// instance) or not (every member as a Transform).
struct KindCost {
    double declared = 0.0, plain = 0.0;
};

// Keeps the kinds that make the file smaller (`cost(k, members, name)`, name the one the kind
// gets if kept), renamed A, B, ... in order.
void keep_kinds_that_pay(
    ProtoKinds& kinds,
    const std::function<KindCost(size_t kind, size_t members, const std::string& name)>& cost);

// The k-th kind's PROTO name: A, B, ... Z, then A1, B1, ... (never a node type of either standard,
// whose names are longer words).
std::string proto_kind_name(size_t k);

}  // namespace vr
