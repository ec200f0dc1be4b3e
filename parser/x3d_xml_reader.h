// Internals of the X3D XML reader (parser/x3d_xml.cpp: libxml2 glue; parser/x3d_xml_tree.cpp:
// elements to nodes). Not part of the parser's interface. Its byte offsets are 32-bit (libxml2
// places elements by line and column in int): parser/load.cpp refuses an XML file over 4 GiB.
#pragma once
#include <libxml/parser.h>
#include <libxml/xmlerror.h>

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "parser/classic.h"
#include "parser/classic_pieces.h"
#include "parser/libxml.h"
#include "parser/load.h"
#include "parser/proto.h"

namespace vr::x3d_xml_detail {

inline bool is_xml_text(std::string_view text) {
    size_t p = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    p = text.find_first_not_of(" \t\r\n", p);
    return p != std::string_view::npos && text[p] == '<';
}

inline std::string_view trim(std::string_view s) {
    while (!s.empty() && static_cast<unsigned char>(s.front()) <= ' ') s.remove_prefix(1);
    while (!s.empty() && static_cast<unsigned char>(s.back()) <= ' ') s.remove_suffix(1);
    return s;
}

// One attribute: the byte range of its raw value in the file, and the decoded value when the raw
// text is not the value (character or entity references, or a file libxml2 transcoded).
struct XmlAttr {
    Name name = kNoName;
    uint32_t name_offset = 0;
    uint32_t begin = 0;
    uint32_t end = 0;
    int32_t decoded = -1;  // index into the element's string pool; -1: the raw text is the value
};

// An element as the handlers see it: live from libxml2, or replayed from a recorded ProtoBody.
struct XmlElement {
    Name tag = kNoName;
    uint32_t file = 0;
    uint32_t offset = 0;  // of the element name
    std::span<const XmlAttr> attrs;
    const std::vector<std::string>* strings = nullptr;
    // In another XML namespace (a prefix bound to anything but X3D's): an exporter's own element.
    bool foreign = false;
    const XmlAttr* find(Name name) const {
        for (const XmlAttr& a : attrs)
            if (a.name == name) return &a;
        return nullptr;
    }
};

// One element start (with its attributes, attrs[first_attr, first_attr + attr_count)) or end of a
// ProtoBody.
struct RecordedEvent {
    Name tag;
    uint32_t offset;
    uint32_t first_attr;
    uint32_t attr_count;
    bool start;
};

// A ProtoDeclare of an XML file: its ProtoBody as the events that make it up.
struct XmlProtoDecl : ProtoDecl {
    bool has_body = false;
    std::vector<RecordedEvent> events;
    std::vector<XmlAttr> attrs;
    std::vector<std::string> strings;
};

// What a value belongs to, for messages: "attribute 'translation' of Transform". Built only for a
// message.
struct What {
    const char* kind;
    std::string_view name;
    std::string_view owner = {};
    What(const char* kind, std::string_view name, std::string_view owner = {})
        : kind(kind), name(name), owner(owner) {}
    What(const char* kind, Name name, Name owner) : kind(kind), name_id(name), owner_id(owner) {}
    Name name_id = kNoName, owner_id = kNoName;  // names not yet looked up
    std::string text() const {
        std::string_view n = name_id != kNoName ? name_text(name_id) : name;
        std::string_view o = owner_id != kNoName ? name_text(owner_id) : owner;
        std::string s = std::string(kind) + " '" + std::string(n) + "'";
        if (!o.empty()) s += " of " + std::string(o);
        return s;
    }
};

// A reader error: stops the reader; becomes one Diagnostic.
struct XmlFailure {
    uint32_t file;
    uint32_t offset;
    std::string message;
};

// Attribute names the reader looks for, interned once per reader.
struct Names {
    Name def = intern("DEF"), use = intern("USE"), container = intern("containerField"),
         cls = intern("class"), id = intern("id"), style = intern("style"), name = intern("name"),
         type = intern("type"), access = intern("accessType"), value = intern("value"),
         url = intern("url"), node_field = intern("nodeField"), proto_field = intern("protoField"),
         from_node = intern("fromNode"), from_field = intern("fromField"),
         to_node = intern("toNode"), to_field = intern("toField"), inline_def = intern("inlineDEF"),
         imported_def = intern("importedDEF"), exported_def = intern("exportedDEF"),
         local_def = intern("localDEF"), as = intern("AS"), version = intern("version"),
         category = intern("category"), conversion_factor = intern("conversionFactor");
    // Elements of the encoding.
    Name x3d = intern("X3D"), scene = intern("Scene"), head = intern("head"), unit = intern("unit"),
         proto_interface = intern("ProtoInterface"), proto_body = intern("ProtoBody"),
         field = intern("field"), field_value = intern("fieldValue"), is = intern("IS"),
         connect = intern("connect"), proto_declare = intern("ProtoDeclare"),
         extern_proto_declare = intern("ExternProtoDeclare"),
         proto_instance = intern("ProtoInstance"), route = intern("ROUTE"),
         import = intern("IMPORT"), export_ = intern("EXPORT");
    // Nodes and fields with VRML97 names (x3d_field_name) or a declared interface.
    Name switch_ = intern("Switch"), lod = intern("LOD"), collision = intern("Collision"),
         choice = intern("choice"), level = intern("level"), collide = intern("collide"),
         children = intern("children"), enabled = intern("enabled"), script = intern("Script"),
         composed_shader = intern("ComposedShader"), packaged_shader = intern("PackagedShader"),
         shader_program = intern("ShaderProgram");
};

// How a large X3D XML file is cut (x3d_xml_pieces.cpp): the <Scene> content at lines that look like
// the start of a top-level element. Every piece is read on its own after the file's text up to
// and including the <Scene> start tag (the prefix: XML declaration, DOCTYPE, <X3D> with its
// namespaces, <head>), so that it sees what the main reader sees there. Only a guess: the main
// reader checks every cut when it arrives at it.
struct XmlPiecePlan {
    uint32_t prefix_end = 0;  // just past the '>' of <Scene ...>; 0: no pieces
    std::vector<Piece> pieces;
};
XmlPiecePlan plan_xml_pieces(std::string_view text, size_t piece);

// Where a reader puts what it reads: the scene, or one piece of the main file read on another
// thread (classic_pieces.h).
struct XmlTarget {
    const SourceManager& sources;
    Diagnostics& diagnostics;
    NodeTree& tree;
    ReadStats& stats;
};

class XmlReader {
  public:
    XmlReader(XmlTarget target, const LoadLimits& limits, const ExternProtoResolver& resolver,
              PieceConsumer* consumer = nullptr)
        : scene_(target),
          tree_(target.tree),
          registry_(Registry::builtin()),
          limits_(limits),
          resolver_(resolver),
          consumer_(consumer) {}

    ClassicResult read(uint32_t file);
    // Reads `piece` of the main file on its own, on a worker thread (x3d_xml_pieces.cpp), into
    // this reader's target (the piece's own tree, messages and counts); hands it to `consumer`
    // when that may take it. Any failure only leaves the piece unusable.
    void read_piece(uint32_t file, uint32_t prefix_end, Piece& piece, PieceConsumer* consumer);

  private:
    // What an open element is to the reader. Skip: ignored with all it contains; Leaf: takes no
    // children (ROUTE, IMPORT, EXPORT, connect); ReplayRoot: collects the top-level nodes of a
    // ProtoBody being replayed.
    enum class Role : uint8_t {
        Document,
        X3d,
        Head,  // <head>: meta, component, unit
        Scene,
        Skip,
        Leaf,
        Node,
        Use,
        ProtoDeclare,
        ProtoInterface,
        InterfaceField,
        ProtoBody,
        ExternProto,
        ExternField,
        Instance,
        FieldValue,
        DynamicField,
        Is,
        ReplayRoot,
    };
    struct Instance {
        // Owned: a ProtoDeclare among the instance's field values may replace the scope's entry.
        std::shared_ptr<const ProtoDecl> proto;
        std::unordered_map<Name, FieldEntry> values;
        std::vector<std::pair<Name, Name>> events;  // (field, enclosing PROTO field) of IS events
    };
    // An element that has started and not yet ended; the members used depend on the role.
    struct Open {
        Role role = Role::Skip;
        Name tag = kNoName;
        uint32_t file = 0;
        uint32_t offset = 0;
        const NodeTypeDecl* decl = nullptr;
        Name def = kNoName;
        Name container = kNoName;  // explicit containerField
        uint32_t container_offset = 0;
        size_t field_mark = 0;  // into scratch_
        size_t child_mark = 0;  // into children_
        bool dynamic = false;
        bool value_given = false;
        NodeId use = kNullNode;
        ProtoField field;  // field, fieldValue
        std::shared_ptr<XmlProtoDecl> proto;
        std::vector<std::string> urls;
        std::unique_ptr<Instance> instance;
        std::vector<std::pair<Name, Name>> events;  // a node's IS events: (field, PROTO field)
        std::vector<ScriptField> script_fields;     // a Script's own interface
        std::string script_text;                    // a Script's text (CDATA) content
    };
    // A scope of DEF names and PROTOs: the file, one PROTO instance, or one interface default
    // value.
    struct Frame {
        uint32_t file = 0;
        std::unordered_map<Name, NodeId> defs;
        const std::unordered_map<Name, NodeId>* outer_defs = nullptr;
        std::shared_ptr<ProtoScope> protos;
        const std::unordered_map<Name, FieldEntry>* is_values = nullptr;
        const ProtoDecl* proto = nullptr;
        size_t proto_depth = 0;
    };
    struct Child {
        Name field;
        NodeId id;
    };

    // ---- libxml2 glue ---------------------------------------------------------------------------
    static void sax_start(void* self, const xmlChar* local, const xmlChar* prefix,
                          const xmlChar* uri, int, const xmlChar**, int nb_attrs, int nb_defaulted,
                          const xmlChar** attrs) {
        auto* r = static_cast<XmlReader*>(self);
        ++r->events_;
        const bool foreign = prefix != nullptr && !is_x3d_namespace(uri);
        r->guarded([&] { r->on_start(local, nb_attrs, nb_defaulted, attrs, foreign); });
    }
    static void sax_end(void* self, const xmlChar*, const xmlChar*, const xmlChar*) {
        auto* r = static_cast<XmlReader*>(self);
        ++r->events_;
        r->guarded([&] { r->end_element(); });
    }
    // Text inside a Script element is its ECMAScript source (X3D 29.4.1: a CDATA section).
    static void sax_text(void* self, const xmlChar* text, int length) {
        auto* r = static_cast<XmlReader*>(self);
        if (r->stopped_ || r->stack_.empty() || length <= 0) return;
        if (r->recording_)
            return r->record_text(reinterpret_cast<const char*>(text), size_t(length));
        Open& o = r->stack_.back();
        if (o.role == Role::Node && o.tag == r->n_.script && length > 0)
            o.script_text.append(reinterpret_cast<const char*>(text), size_t(length));
    }
    static void sax_error(void* self, xmlErrorPtr error) {
        static_cast<XmlReader*>(self)->on_xml_error(error);
    }
    static void sax_entity_decl(void* self, const xmlChar* name, int, const xmlChar*,
                                const xmlChar*, xmlChar*) {
        auto* r = static_cast<XmlReader*>(self);
        r->guarded([&] {
            throw XmlFailure{
                r->main_file_, r->current_offset(),
                "the document declares the entity '" +
                    std::string(reinterpret_cast<const char*>(name)) +
                    "': entity declarations are refused (vrmlray never expands DTD entities)"};
        });
    }
    static void sax_unparsed_entity_decl(void* self, const xmlChar* name, const xmlChar*,
                                         const xmlChar*, const xmlChar*) {
        sax_entity_decl(self, name, 0, nullptr, nullptr, nullptr);
    }

    template <class F>
    void guarded(F&& f) {
        if (stopped_) return;
        try {
            f();
        } catch (const XmlFailure& e) {
            stop(e.file, e.offset, e.message);
        } catch (const std::exception& e) {
            stop(main_file_, current_offset(),
                 std::string("cannot read the document: ") + e.what());
        }
    }
    void stop(uint32_t file, uint32_t offset, const std::string& message) {
        if (!stopped_) scene_.diagnostics.error({file, offset}, message);
        stopped_ = true;
        failed_ = true;
        xml_->StopParser(ctxt_);
    }

    bool start_parser(uint32_t file);
    void finish_parser();
    void feed(std::string_view bytes, bool last);
    void on_start(const xmlChar* local, int nb_attrs, int nb_defaulted, const xmlChar** attrs,
                  bool foreign);
    // A prefixed element's namespace is X3D's when its URI is the X3D namespace (any version's
    // schema folder under web3d.org), or unknown (an undeclared prefix, which libxml2 reports).
    static bool is_x3d_namespace(const xmlChar* uri) {
        if (uri == nullptr) return true;
        const std::string_view u = reinterpret_cast<const char*>(uri);
        return u.find("web3d.org") != std::string_view::npos;
    }
    void on_xml_error(xmlErrorPtr error);
    uint32_t current_offset();
    uint32_t offset_at(int line, int column);
    // An element's or attribute's name, in X3D's spelling when the file spells it in another case
    // (X3DOM pages do: HTML ignores case), cached by address.
    Name cached(const xmlChar* text, uint32_t offset,
                std::unordered_map<const xmlChar*, Name>& cache,
                Name (XmlReader::*to_x3d)(Name, uint32_t));
    Name tag_in_x3d_case(Name tag, uint32_t offset);
    Name attribute_in_x3d_case(Name name, uint32_t offset);  // DEF, USE, containerField
    const FieldDecl* field_in_x3d_case(const XmlElement& e, const NodeTypeDecl& decl,
                                       const XmlAttr& a);

    // ---- pieces (x3d_xml_pieces.cpp)
    // ------------------------------------------------------------- Offsets and lines as libxml2
    // counts them in the bytes it was given, which skip the pieces the main reader joined (a piece
    // reader's: its prefix, a line break, then the piece), mapped to the file's.
    uint32_t file_offset(uint64_t stream) const;
    int file_line(int stream_line) const;
    std::string file_lines_in(std::string message) const;
    void build_line_starts();
    bool pending_is_blank() const;
    bool at_piece_boundary() const;
    void take_pieces(PieceScheduler& pieces, size_t& pos);
    void join(Piece& piece, std::vector<NodeId>& outer, size_t& pos);
    void drop_piece(PieceScheduler& pieces);
    void not_in_piece(const XmlElement& e) { not_in_piece(e.file, e.offset); }
    void not_in_piece(uint32_t file, uint32_t offset);
    NodeId outer_node(Name name, const XmlElement& use);
    bool resolve_outer(const Piece& piece, std::vector<NodeId>& nodes) const;
    void scene_start(const XmlElement& e);

    // ---- elements -------------------------------------------------------------------------------
    void start_element(const XmlElement& e);
    void unit(const XmlElement& e);
    // An element of an exporter's own namespace (x3d_xml_foreign.cpp): what it says of the view
    // (Chimera's WindowSize, DepthCue) into the stats; anything else ignored silently.
    void foreign_element(const XmlElement& e);
    void end_element();
    void content_element(const XmlElement& e);
    void node_start(const XmlElement& e, const NodeTypeDecl* decl);
    void use_start(const XmlElement& e, const XmlAttr& use, bool instance);
    void node_end(Open& o);
    void attach(NodeId id, const Open& child);
    void instance_start(const XmlElement& e);
    void field_value_start(const XmlElement& e);
    void connect(const XmlElement& e);
    void script_connect(Open& owner, const std::string& node_field, const ProtoField& outer,
                        std::unordered_map<Name, FieldEntry>::const_iterator bound);
    void field_start(const XmlElement& e, Role role);
    void field_end(Open& o);
    void proto_declare_start(const XmlElement& e);
    void extern_start(const XmlElement& e);
    void record(const XmlElement& e);
    void record_text(const char* text, size_t length);
    NodeId expand(const Instance& inst, uint32_t file, uint32_t offset);
    NodeId builtin_instance(const NodeTypeDecl& decl,
                            const std::unordered_map<Name, FieldEntry>& values, uint32_t file,
                            uint32_t offset);

    // ---- values ---------------------------------------------------------------------------------
    std::string attr_text(const XmlElement& e, const XmlAttr& a) const;
    std::string required(const XmlElement& e, Name attr, const char* what);
    void route(const XmlElement& e);
    void import_export(const XmlElement& e);
    std::string imported_def(const XmlElement& e);
    void read_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                    const What& what);
    void lex_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                   const What& what);
    // read_value, but a value that does not parse is a warning and false (the field unset).
    bool read_value_or_warn(const XmlElement& e, const XmlAttr& a, FieldType type,
                            FieldEntry& entry, const What& what);
    Name default_container(Name type);
    void type_default(FieldType type, FieldEntry& entry);
    void node_entry(FieldType type, size_t mark, FieldEntry& entry, uint32_t file, uint32_t offset,
                    const std::string& what);
    void push_field(size_t mark, const FieldEntry& entry);
    NodeId make_node(const NodeTypeDecl* decl, Name type, uint32_t file, uint32_t offset,
                     size_t mark);

    [[noreturn]] void fail(uint32_t file, uint32_t offset, std::string message) {
        throw XmlFailure{file, offset, std::move(message)};
    }
    void warn(uint32_t file, uint32_t offset, std::string message, const std::string& cause) {
        scene_.diagnostics.warning({file, offset}, std::move(message), cause);
    }
    Frame& frame() { return *frames_.back(); }
    std::string tag_of(const Open& o) const { return std::string(name_text(o.tag)); }
    static std::string tag_text(const XmlElement& e) { return std::string(name_text(e.tag)); }
    // x3d_field_name() on names: the X3D name of a field VRML97 named differently.
    Name x3d_field(Name type, Name field) const {
        if (field == n_.choice && type == n_.switch_) return n_.children;
        if (field == n_.level && type == n_.lod) return n_.children;
        if (field == n_.collide && type == n_.collision) return n_.enabled;
        return field;
    }
    bool dynamic_type(Name type) const {
        return type == n_.script || type == n_.composed_shader || type == n_.packaged_shader ||
               type == n_.shader_program;
    }
    void push(Open o) {
        if (stack_.size() > limits_.max_nesting_depth + 2)
            fail(o.file, o.offset,
                 "elements nested deeper than " + std::to_string(limits_.max_nesting_depth) +
                     " (limit)");
        stack_.push_back(std::move(o));
    }
    Open make_open(Role role, const XmlElement& e) {
        Open o;
        o.role = role;
        o.tag = e.tag;
        o.file = e.file;
        o.offset = e.offset;
        o.child_mark = children_.size();
        o.field_mark = scratch_.size();
        return o;
    }

    XmlTarget scene_;
    NodeTree& tree_;
    const Registry& registry_;
    const LoadLimits& limits_;
    const ExternProtoResolver& resolver_;
    PieceConsumer* consumer_ = nullptr;  // the main file's, if any (never a piece reader's own)
    const Names n_;
    const LibXml* xml_ = nullptr;  // set by read()
    xmlParserCtxtPtr ctxt_ = nullptr;
    uint32_t main_file_ = 0;
    std::string_view text_;  // the main file's text
    std::vector<uint32_t> line_starts_;
    bool stopped_ = false;
    bool failed_ = false;
    uint64_t events_ = 0;  // elements started or ended, to size the chunks given to libxml2

    // A piece reader: the piece and where its first byte stands in what libxml2 was given.
    bool in_piece_ = false;
    bool piece_content_ = false;  // past the prefix: what needs the rest of the file fails
    size_t piece_depth_ = 0;      // open elements at the piece's start (its <Scene> the last)
    uint32_t prefix_end_ = 0, piece_begin_ = 0, piece_end_ = 0;
    uint64_t piece_stream_ = 0;
    // The main reader: the pieces it joined instead of giving their bytes to libxml2. From stream
    // offset `stream` (line `stream_line`) on, `bytes` bytes and `lines` lines were skipped in all.
    struct Skip {
        uint64_t stream = 0;
        uint64_t bytes = 0;
        int stream_line = 0;
        int lines = 0;
    };
    std::vector<Skip> skips_;
    uint32_t scene_end_ = 0;   // just past the <Scene ...> start tag, as the main reader read it
    int scenes_ = 0;           // <Scene> elements started
    uint32_t x3d_offset_ = 0;  // where <X3D> starts
    size_t next_piece_ = 0;    // the first piece not yet joined or dropped
    std::vector<ConsumedPiece> consumed_;
    size_t consumed_nodes_ = 0;  // nodes of consumed pieces, counted against the node limit
    // A piece reader's USEs of DEFs before the piece (piece_consumer.h: outer nodes).
    std::vector<Name> outer_uses_, outer_tags_;
    std::unordered_map<Name, NodeId> outer_index_;

    std::vector<Open> stack_;
    std::vector<std::unique_ptr<Frame>> frames_;
    std::vector<FieldEntry> scratch_;  // fields of the open nodes, innermost last
    std::vector<Child> children_;      // child nodes of the open elements, innermost last
    std::vector<NodeId> roots_;
    XmlProtoDecl* recording_ = nullptr;            // the ProtoBody being recorded
    std::unordered_map<Name, uint32_t> imported_;  // IMPORT AS names -> tree.imports
    FileUnits units_;                              // the <unit> elements of <head>
    std::string version_;                          // <X3D version>
    size_t record_depth_ = 0;

    std::unordered_map<const xmlChar*, Name>
        name_cache_;                                      // libxml2's dictionary strings are stable
    std::unordered_map<const xmlChar*, Name> tag_cache_;  // the same for element names
    std::unordered_map<Name, Name> container_cache_;      // node type -> default containerField
    std::vector<XmlAttr> attr_scratch_;
    std::vector<std::string> string_scratch_;
    struct RawAttr {
        std::string_view qname;
        uint32_t name_offset, begin, end;
    };
    std::vector<RawAttr> raw_scratch_;
};

}  // namespace vr::x3d_xml_detail
