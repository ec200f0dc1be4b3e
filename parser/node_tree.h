// The generic node tree both readers produce: an arena of nodes whose field values live in shared
// pools. DEF/USE is a shared NodeId (instancing, not copying). PROTO instances are already
// expanded: a PROTO instance appears as the first node of its body, with IS fields filled in.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "parser/field_type.h"
#include "parser/name.h"
#include "parser/pool.h"
#include "parser/source.h"

namespace vr {

struct NodeTypeDecl;
class Registry;

using NodeId = uint32_t;
constexpr NodeId kNullNode = UINT32_MAX;

// One field value set in a file. `begin`/`count` index the pool that fits the type: numbers for
// numeric kinds (count = number of doubles, i.e. values * components), strings for String,
// node_refs for Node. 20 bytes (type and place packed): a 100 MB scene holds some 3 million.
struct FieldEntry {
    Name name = kNoName;
    FieldType type;
    PackedLoc loc;  // where the value starts
    uint32_t begin = 0;
    uint32_t count = 0;
};
static_assert(sizeof(FieldEntry) == 20);

// What a node was read as: its interface and its type name. Nodes keep an index into
// NodeTree::kinds instead of the pair, since a large scene holds millions of nodes of a few kinds.
struct NodeKind {
    const NodeTypeDecl* decl = nullptr;  // the interface the node was read with
    Name type = kNoName;                 // node type name, e.g. "Transform"
};

struct Node {
    uint32_t kind = 0;         // into NodeTree::kinds
    Name def_name = kNoName;   // DEF name, if any
    uint32_t first_field = 0;  // into NodeTree::fields
    PackedLoc loc;             // where the node's type name stands
    // The number of fields set, when below kManyFields; else NodeTree::many_fields has it (one
    // byte here keeps a node at 20 bytes; only Scripts and PROTOs can declare that many fields).
    uint8_t few_fields = 0;
    static constexpr uint8_t kManyFields = 255;
};
static_assert(sizeof(Node) == 20, "a large scene holds millions of nodes");

// A read-only view of one field's value: the value set in the file, or the grammar default.
struct FieldView {
    FieldType type;
    std::span<const double> numbers;       // numeric kinds (Bool is 0/1, Int32 exact)
    std::span<const std::string> strings;  // String kind
    std::span<const NodeId> nodes;         // Node kind (kNullNode for NULL)
    SourceLoc loc;                         // invalid for defaults
    bool is_default = true;
    bool found = false;  // false: the node type has no such field

    // Number of values (for MF fields), e.g. 3 numbers of an MFVec3f make 1 value.
    size_t size() const;
};

// A ROUTE as written. Its nodes are resolved in the DEF scope it stands in (the file, or one PROTO
// instance's body, so that a PROTO's internal ROUTEs connect that instance's nodes); its event
// names are kept as written (set_x, x_changed), for the evaluator (src/anim/) to match to fields.
struct Route {
    NodeId from = kNullNode;
    Name from_event = kNoName;
    NodeId to = kNullNode;
    Name to_event = kNoName;
    PackedLoc loc;  // the ROUTE keyword
    // An end that names an IMPORTed node: the index into NodeTree::imports; the loader puts the
    // exported node into from/to once the Inline is read.
    static constexpr uint32_t kNoImport = UINT32_MAX;
    uint32_t from_import = kNoImport, to_import = kNoImport;
};

// X3D 4.4.6: `EXPORT localDEF AS name` in a file offers its node to the file that inlines it;
// `IMPORT inlineDEF.name AS local` there lets that file's ROUTEs name it `local`.
struct Export {
    uint32_t file = 0;    // the source file the EXPORT stands in
    Name name = kNoName;  // the AS name (else the DEF name)
    NodeId node = kNullNode;
};
struct Import {
    NodeId inline_node = kNullNode;
    Name exported = kNoName;
    Name local = kNoName;
    PackedLoc loc;            // the IMPORT statement
    NodeId node = kNullNode;  // the exported node, once resolved
};

// `field IS protoField` inside a PROTO body, kept for events: what is routed to the instance's
// protoField reaches node.field, and what node.field sends leaves as the instance's protoField.
// `instance` is the node that stands for the instance (the first node of its body).
struct IsLink {
    NodeId instance = kNullNode;
    Name proto_field = kNoName;
    NodeId node = kNullNode;
    Name field = kNoName;
};

// One field, eventIn or eventOut a Script node declares itself (VRML97 6.40, X3D 29.4.1), kept for
// src/script/. A field's value lives in the pools like any field's (`value`; count 0 when the file
// gives none, which is the type's initial value); events have none.
struct ScriptField {
    Name name = kNoName;
    FieldType type;
    Access access = Access::Field;
    FieldEntry value;
};
struct ScriptInterface {
    std::vector<ScriptField> fields;  // in declaration order
    std::string source;  // X3D XML: the element's text (CDATA); the url field's forms are in `url`
    const ScriptField* find(Name name) const {
        for (const ScriptField& f : fields)
            if (f.name == name) return &f;
        return nullptr;
    }
};

struct NodeTree {
    Pool<Node> nodes;
    std::vector<NodeKind> kinds{NodeKind{}};  // distinct (decl, type) pairs; 0 is (none, no name)
    Pool<FieldEntry> fields;
    Pool<double> numbers;
    std::vector<std::string> strings;
    Pool<NodeId> node_refs;

    std::vector<NodeId> roots;                         // top-level nodes of the main file, in order
    std::unordered_map<NodeId, uint32_t> many_fields;  // field counts of Node::kManyFields or more

    std::vector<Route> routes;     // in file order (PROTO bodies' where each instance stands)
    std::vector<IsLink> is_links;  // PROTO interface events, for routes into and out of instances
    std::vector<Export> exports;   // of every file read
    std::vector<Import> imports;
    std::unordered_map<NodeId, ScriptInterface> scripts;  // every Script node's own interface

    // Inline nodes that were resolved: the top-level nodes of the file they name.
    std::unordered_map<NodeId, std::vector<NodeId>> inline_roots;
    // UNIT length factors (parser/units.h), applied by the scene build as a uniform scale: metres
    // per length unit of the main file, and per resolved Inline the scale that takes its file's
    // lengths into those of the file holding the Inline (absent: 1).
    double root_length_scale = 1.0;
    std::unordered_map<NodeId, double> inline_length_scale;

    // Field access. `registry` supplies defaults for fields the file did not set.
    FieldView get(NodeId node, Name field) const;
    FieldView get(NodeId node, std::string_view field) const;  // convenience (interns the name)
    // Explicitly set fields of a node, in file order.
    std::span<const FieldEntry> set_fields(NodeId node) const {
        return {fields.data() + nodes[node].first_field, field_count(node)};
    }
    uint32_t field_count(NodeId node) const {
        const Node& n = nodes[node];
        return n.few_fields < Node::kManyFields ? n.few_fields : many_fields.at(node);
    }
    // Appends a node whose `field_count` fields start at n.first_field.
    NodeId add_node(Node n, uint32_t field_count);
    FieldView view(const FieldEntry& entry) const;

    // Typed helpers for the scene builder; they return the default when the field is not set.
    bool get_bool(NodeId node, Name field) const;
    int32_t get_int(NodeId node, Name field) const;
    double get_number(NodeId node, Name field) const;  // SFFloat, SFDouble, SFTime
    NodeId get_node(NodeId node, Name field) const;    // SFNode; kNullNode if NULL
    const NodeTypeDecl* decl(NodeId node) const { return kinds[nodes[node].kind].decl; }
    Name type(NodeId node) const { return kinds[nodes[node].kind].type; }
    std::string_view type_name(NodeId node) const { return name_text(type(node)); }
    std::string_view def_name(NodeId node) const { return name_text(nodes[node].def_name); }
    // The index in `kinds` of the pair, added if new.
    uint32_t kind_of(const NodeTypeDecl* decl, Name type);
    // Empties the tree for another piece of a file, keeping its pools' memory, which a new tree
    // would take from the kernel again, zeroed page by page.
    void clear_keeping_memory();

  private:
    // Recently used kinds by hash of the pair (readers ask once per node), then all of them.
    std::array<uint32_t, 64> kind_cache_{};
    std::unordered_map<uint64_t, std::vector<uint32_t>> kind_index_;
};

// What an exporter wrote about the view its user saw, in elements of its own XML namespace
// (UCSF Chimera's <chimera:WindowSize width height> and <chimera:DepthCue range color>): not
// nodes, so not in the tree; the command line takes them as defaults (docs/input.md "Exporters'
// own elements").
struct ExporterView {
    int window_width = 0, window_height = 0;           // pixels; 0: not given
    bool depth_cue = false;                            // a depth cue range was given
    double depth_cue_near = 0.0, depth_cue_far = 0.0;  // view depth, scene units
    bool depth_cue_has_color = false;
    std::array<double, 3> depth_cue_color{0.0, 0.0, 0.0};
};

// Statistics the readers keep for `vrmlray info`.
struct ReadStats {
    size_t def_count = 0;
    size_t use_count = 0;
    size_t proto_declarations = 0;
    size_t externproto_declarations = 0;
    size_t proto_instances = 0;
    size_t inline_files = 0;
    size_t routes = 0;
    size_t pieces = 0;  // parts of a file read on other threads and appended (classic_pieces.h)
    std::unordered_map<std::string, size_t>
        skipped_nodes;  // node type -> count (unknown or not modelled)
    // Elements of other XML namespaces: what they said, and how many were ignored.
    ExporterView exporter_view;
    size_t foreign_elements = 0;
};

}  // namespace vr
