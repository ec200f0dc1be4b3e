// X3D XML reader. libxml2's SAX2 interface streams the elements (no DOM is built); each element's attribute
// values are found in the file's own text, so the classic value parser reads them in place and every message
// points at the attribute's bytes. ProtoBody contents are recorded as element events and replayed per
// ProtoInstance, the XML counterpart of the classic reader re-reading a PROTO body's tokens.
//
// Safety: entity declarations are refused (so no entity is ever expanded: no billion laughs, no external
// entity), the external-entity loader refuses everything, DTDs are never loaded and the network is off.
// Because no entity can expand, XML_PARSE_HUGE is safe and lifts libxml2's 10 MB limit on one attribute
// value, which large meshes exceed; nesting depth is bounded by LoadLimits instead.
#include "parser/x3d_xml.h"

#include <libxml/parser.h>
#include <libxml/parserInternals.h>
#include <libxml/xmlerror.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <mutex>
#include <span>
#include <unordered_map>

#include "parser/field_value.h"
#include "parser/lexer.h"

namespace vr {

std::string_view x3d_default_container_field(std::string_view type) {
    static const std::unordered_map<std::string_view, std::string_view> table = [] {
        std::unordered_map<std::string_view, std::string_view> t;
        auto add = [&](std::string_view field, std::initializer_list<std::string_view> types) {
            for (std::string_view type : types) t.emplace(type, field);
        };
        add("metadata", {"MetadataBoolean", "MetadataDouble", "MetadataFloat", "MetadataInteger", "MetadataSet",
                         "MetadataString"});
        add("geometry", {"Arc2D", "ArcClose2D", "Box", "Circle2D", "Cone", "Cylinder", "Disk2D", "ElevationGrid",
                         "Extrusion", "IndexedFaceSet", "IndexedLineSet", "IndexedQuadSet", "IndexedTriangleFanSet",
                         "IndexedTriangleSet", "IndexedTriangleStripSet", "LineSet", "PointSet", "Polyline2D",
                         "Polypoint2D", "QuadSet", "Rectangle2D", "Sphere", "Text", "TriangleFanSet", "TriangleSet",
                         "TriangleSet2D", "TriangleStripSet", "GeoElevationGrid", "NurbsCurve", "NurbsPatchSurface",
                         "NurbsTrimmedSurface", "NurbsSweptSurface", "NurbsSwungSurface"});
        add("appearance", {"Appearance"});
        add("material", {"Material", "PhysicalMaterial", "UnlitMaterial", "TwoSidedMaterial"});
        add("texture", {"ImageTexture", "MovieTexture", "PixelTexture", "MultiTexture", "ComposedTexture3D",
                        "ImageTexture3D", "PixelTexture3D", "ComposedCubeMapTexture", "GeneratedCubeMapTexture",
                        "ImageCubeMapTexture"});
        add("textureTransform", {"TextureTransform", "MultiTextureTransform", "TextureTransform3D",
                                 "TextureTransformMatrix3D"});
        add("coord", {"Coordinate", "CoordinateDouble", "GeoCoordinate"});
        add("normal", {"Normal"});
        add("color", {"Color", "ColorRGBA"});
        add("texCoord", {"TextureCoordinate", "TextureCoordinateGenerator", "MultiTextureCoordinate",
                         "TextureCoordinate3D", "TextureCoordinate4D"});
        add("fogCoord", {"FogCoordinate"});
        add("attrib", {"FloatVertexAttribute", "Matrix3VertexAttribute", "Matrix4VertexAttribute"});
        add("fontStyle", {"FontStyle", "ScreenFontStyle"});
        add("fillProperties", {"FillProperties"});
        add("lineProperties", {"LineProperties"});
        add("pointProperties", {"PointProperties"});
        add("acousticProperties", {"AcousticProperties"});
        add("textureProperties", {"TextureProperties"});
        add("shaders", {"ComposedShader", "PackagedShader", "ProgramShader"});
        add("parts", {"ShaderPart"});
        add("programs", {"ShaderProgram"});
        add("source", {"AudioClip"});
        add("displacers", {"HAnimDisplacer"});
        add("motions", {"HAnimMotion"});
        return t;
    }();
    auto it = table.find(type);
    return it == table.end() ? std::string_view("children") : it->second;
}

std::string_view x3d_field_name(std::string_view type, std::string_view field) {
    if (type == "Switch" && field == "choice") return "children";
    if (type == "LOD" && field == "level") return "children";
    if (type == "Collision" && field == "collide") return "enabled";
    return field;
}

namespace {

bool has_dynamic_interface(std::string_view type) {
    return type == "Script" || type == "ComposedShader" || type == "PackagedShader" || type == "ShaderProgram";
}

bool is_xml_text(std::string_view text) {
    size_t p = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    p = text.find_first_not_of(" \t\r\n", p);
    return p != std::string_view::npos && text[p] == '<';
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && static_cast<unsigned char>(s.front()) <= ' ') s.remove_prefix(1);
    while (!s.empty() && static_cast<unsigned char>(s.back()) <= ' ') s.remove_suffix(1);
    return s;
}

// One attribute: the byte range of its raw value in the file, and the decoded value when the raw text is not
// the value (character or entity references, or a file libxml2 transcoded).
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
    const XmlAttr* find(Name name) const {
        for (const XmlAttr& a : attrs)
            if (a.name == name) return &a;
        return nullptr;
    }
};

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

// A reader error: stops the reader; becomes one Diagnostic.
struct XmlFailure {
    uint32_t file;
    uint32_t offset;
    std::string message;
};

struct Names {
    Name def = intern("DEF"), use = intern("USE"), container = intern("containerField"), cls = intern("class"),
         id = intern("id"), style = intern("style"), name = intern("name"), type = intern("type"),
         access = intern("accessType"), value = intern("value"), url = intern("url"),
         node_field = intern("nodeField"), proto_field = intern("protoField");
};

class XmlReader {
public:
    XmlReader(LoadedScene& scene, const LoadLimits& limits, const ExternProtoResolver& resolver)
        : scene_(scene), tree_(scene.tree), registry_(Registry::builtin()), limits_(limits), resolver_(resolver) {}

    ClassicResult read(uint32_t file);

private:
    enum class Role : uint8_t {
        Document, X3d, Scene, Skip, Leaf, Node, Use, ProtoDeclare, ProtoInterface, InterfaceField, ProtoBody,
        ExternProto, ExternField, Instance, FieldValue, DynamicField, Is, ReplayRoot,
    };
    struct Instance {
        const ProtoDecl* proto = nullptr;
        std::unordered_map<Name, FieldEntry> values;
    };
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
    };
    // A scope of DEF names and PROTOs: the file, one PROTO instance, or one interface default value.
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
    static void sax_start(void* self, const xmlChar* local, const xmlChar*, const xmlChar*, int, const xmlChar**,
                          int nb_attrs, int nb_defaulted, const xmlChar** attrs) {
        auto* r = static_cast<XmlReader*>(self);
        r->guarded([&] { r->on_start(local, nb_attrs, nb_defaulted, attrs); });
    }
    static void sax_end(void* self, const xmlChar*, const xmlChar*, const xmlChar*) {
        auto* r = static_cast<XmlReader*>(self);
        r->guarded([&] { r->end_element(); });
    }
    static void sax_error(void* self, xmlErrorPtr error) { static_cast<XmlReader*>(self)->on_xml_error(error); }
    static void sax_entity_decl(void* self, const xmlChar* name, int, const xmlChar*, const xmlChar*, xmlChar*) {
        auto* r = static_cast<XmlReader*>(self);
        r->guarded([&] {
            throw XmlFailure{r->main_file_, r->current_offset(),
                             "the document declares the entity '" + std::string(reinterpret_cast<const char*>(name)) +
                                 "': entity declarations are refused (vrmlray never expands DTD entities)"};
        });
    }
    static void sax_unparsed_entity_decl(void* self, const xmlChar* name, const xmlChar*, const xmlChar*,
                                         const xmlChar*) {
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
            stop(main_file_, current_offset(), std::string("cannot read the document: ") + e.what());
        }
    }
    void stop(uint32_t file, uint32_t offset, const std::string& message) {
        if (!stopped_) scene_.diagnostics.error({file, offset}, message);
        stopped_ = true;
        failed_ = true;
        xmlStopParser(ctxt_);
    }

    void on_start(const xmlChar* local, int nb_attrs, int nb_defaulted, const xmlChar** attrs);
    void on_xml_error(xmlErrorPtr error);
    uint32_t current_offset();
    uint32_t offset_at(int line, int column);
    Name cached_name(const xmlChar* text);

    // ---- elements -------------------------------------------------------------------------------
    void start_element(const XmlElement& e);
    void end_element();
    void content_element(const XmlElement& e);
    void node_start(const XmlElement& e, const NodeTypeDecl* decl);
    void use_start(const XmlElement& e, const XmlAttr& use, bool instance);
    void node_end(Open& o);
    void attach(NodeId id, const Open& child);
    void instance_start(const XmlElement& e);
    void field_value_start(const XmlElement& e);
    void connect(const XmlElement& e);
    void field_start(const XmlElement& e, Role role);
    void field_end(Open& o);
    void proto_declare_start(const XmlElement& e);
    void extern_start(const XmlElement& e);
    void record(const XmlElement& e);
    NodeId expand(const Instance& inst, uint32_t file, uint32_t offset);
    NodeId builtin_instance(const NodeTypeDecl& decl, const std::unordered_map<Name, FieldEntry>& values,
                            uint32_t file, uint32_t offset);

    // ---- values ---------------------------------------------------------------------------------
    std::string attr_text(const XmlElement& e, const XmlAttr& a) const;
    std::string required(const XmlElement& e, Name attr, const char* what);
    void read_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                    const std::string& what);
    void lex_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                   const std::string& what);
    void type_default(FieldType type, FieldEntry& entry);
    void node_entry(FieldType type, size_t mark, FieldEntry& entry, uint32_t file, uint32_t offset,
                    const std::string& what);
    void push_field(size_t mark, const FieldEntry& entry);
    NodeId make_node(const NodeTypeDecl* decl, Name type, uint32_t file, uint32_t offset, size_t mark);

    [[noreturn]] void fail(uint32_t file, uint32_t offset, std::string message) {
        throw XmlFailure{file, offset, std::move(message)};
    }
    void warn(uint32_t file, uint32_t offset, std::string message, const std::string& cause) {
        scene_.diagnostics.warning({file, offset}, std::move(message), cause);
    }
    Frame& frame() { return *frames_.back(); }
    std::string tag_of(const Open& o) const { return std::string(name_text(o.tag)); }
    void push(Open o) {
        if (stack_.size() > limits_.max_nesting_depth + 2)
            fail(o.file, o.offset, "elements nested deeper than " + std::to_string(limits_.max_nesting_depth) +
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

    LoadedScene& scene_;
    NodeTree& tree_;
    const Registry& registry_;
    const LoadLimits& limits_;
    const ExternProtoResolver& resolver_;
    const Names n_;
    xmlParserCtxtPtr ctxt_ = nullptr;
    uint32_t main_file_ = 0;
    std::string_view text_;  // the main file's text
    std::vector<uint32_t> line_starts_;
    bool stopped_ = false;
    bool failed_ = false;

    std::vector<Open> stack_;
    std::vector<std::unique_ptr<Frame>> frames_;
    std::vector<FieldEntry> scratch_;  // fields of the open nodes, innermost last
    std::vector<Child> children_;      // child nodes of the open elements, innermost last
    std::vector<NodeId> roots_;
    XmlProtoDecl* recording_ = nullptr;  // the ProtoBody being recorded
    size_t record_depth_ = 0;

    std::unordered_map<const xmlChar*, Name> name_cache_;  // libxml2's dictionary strings are stable
    std::vector<XmlAttr> attr_scratch_;
    std::vector<std::string> string_scratch_;
    struct RawAttr {
        std::string_view qname;
        uint32_t name_offset, begin, end;
    };
    std::vector<RawAttr> raw_scratch_;
};

// ---- libxml2 glue -------------------------------------------------------------------------------

xmlParserInputPtr refuse_external_entity(const char*, const char*, xmlParserCtxtPtr) { return nullptr; }
void silent_generic_error(void*, const char*, ...) {}

ClassicResult XmlReader::read(uint32_t file) {
    static std::once_flag once;
    std::call_once(once, [] {
        xmlInitParser();
        xmlSetExternalEntityLoader(refuse_external_entity);
    });
    xmlSetGenericErrorFunc(nullptr, silent_generic_error);  // per thread: the library never prints

    ClassicResult result;
    main_file_ = file;
    text_ = scene_.sources.file(file).text;
    if (text_.size() > static_cast<size_t>(INT_MAX)) {
        scene_.diagnostics.error({file, 0}, "X3D XML files larger than 2 GB are not supported");
        result.ok = false;
        return result;
    }
    auto top = std::make_unique<Frame>();
    top->file = file;
    top->protos = std::make_shared<ProtoScope>();
    result.protos = top->protos;
    frames_.push_back(std::move(top));
    Open document;
    document.role = Role::Document;
    document.file = file;
    stack_.push_back(std::move(document));

    xmlSAXHandler sax;
    std::memset(&sax, 0, sizeof sax);
    sax.initialized = XML_SAX2_MAGIC;
    sax.startElementNs = sax_start;
    sax.endElementNs = sax_end;
    sax.serror = sax_error;
    sax.entityDecl = sax_entity_decl;
    sax.unparsedEntityDecl = sax_unparsed_entity_decl;
    // getEntity, resolveEntity, externalSubset stay null: nothing is looked up or loaded.

    // The push parser holds only the part of the text it has not consumed yet; the text itself stays in
    // the SourceManager, where the attribute values are read.
    ctxt_ = xmlCreatePushParserCtxt(&sax, this, nullptr, 0, nullptr);  // user data `this`, not the context:
    if (!ctxt_) {                                                      // libxml2 then never looks entities up
        scene_.diagnostics.error({file, 0}, "cannot start the XML parser (out of memory)");
        result.ok = false;
        return result;
    }
    xmlCtxtUseOptions(ctxt_, XML_PARSE_NONET | XML_PARSE_HUGE | XML_PARSE_RECOVER);
    constexpr size_t kChunk = size_t(1) << 20;
    for (size_t pos = 0;;) {
        const size_t n = std::min(kChunk, text_.size() - pos);
        const bool last = pos + n >= text_.size();
        xmlParseChunk(ctxt_, text_.data() + pos, static_cast<int>(n), last ? 1 : 0);
        pos += n;
        if (last || stopped_) break;
    }
    xmlFreeParserCtxt(ctxt_);
    ctxt_ = nullptr;
    result.ok = !failed_;
    result.roots = std::move(roots_);
    return result;
}

uint32_t XmlReader::offset_at(int line, int column) {
    if (line_starts_.empty()) {
        line_starts_.push_back(0);
        for (size_t i = 0; i < text_.size(); ++i)
            if (text_[i] == '\n') line_starts_.push_back(static_cast<uint32_t>(i + 1));
    }
    if (line < 1) return 0;
    if (static_cast<size_t>(line) > line_starts_.size()) return static_cast<uint32_t>(text_.size());
    size_t p = line_starts_[static_cast<size_t>(line) - 1];
    // libxml2 counts columns in characters; step over whole UTF-8 sequences.
    for (int c = 1; c < column && p < text_.size() && text_[p] != '\n'; ++c) {
        ++p;
        while (p < text_.size() && (static_cast<unsigned char>(text_[p]) & 0xC0) == 0x80) ++p;
    }
    return static_cast<uint32_t>(p);
}

uint32_t XmlReader::current_offset() {
    const xmlParserInputPtr in = ctxt_ ? ctxt_->input : nullptr;
    if (!in) return 0;
    if (!in->buf || in->buf->encoder) return offset_at(in->line, in->col);  // transcoded: bytes differ
    size_t offset = static_cast<size_t>(in->consumed) + static_cast<size_t>(in->cur - in->base);
    return static_cast<uint32_t>(std::min(offset, text_.size()));
}

void XmlReader::on_xml_error(xmlErrorPtr error) {
    if (!error || stopped_) return;
    std::string message = error->message ? error->message : "XML error";
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    uint32_t offset = offset_at(error->line, error->int2);
    // Slips real exporters make that leave the document's meaning clear: warnings. The parser runs in
    // recovery mode so that it continues after them; any other error stops it here.
    const bool tolerated = error->level == XML_ERR_WARNING || error->domain == XML_FROM_NAMESPACE ||
                           error->code == XML_ERR_HYPHEN_IN_COMMENT;
    if (tolerated) {
        warn(main_file_, offset, "XML: " + message, "xml:" + message);
        return;
    }
    stop(main_file_, offset, "XML: " + message);
}

Name XmlReader::cached_name(const xmlChar* text) {
    // Names libxml2 keeps in its dictionary live as long as the parser: cache them by address.
    const bool stable = ctxt_->dict && xmlDictOwns(ctxt_->dict, text) == 1;
    if (stable) {
        auto it = name_cache_.find(text);
        if (it != name_cache_.end()) return it->second;
    }
    Name name = intern(reinterpret_cast<const char*>(text));
    if (stable) name_cache_.emplace(text, name);
    return name;
}

void XmlReader::on_start(const xmlChar* local, int nb_attrs, int nb_defaulted, const xmlChar** attrs) {
    attr_scratch_.clear();
    string_scratch_.clear();
    raw_scratch_.clear();
    const int count = nb_attrs - nb_defaulted;  // attributes defaulted by an ATTLIST are ignored
    const xmlParserInputPtr in = ctxt_->input;
    const bool same_bytes = in->buf && !in->buf->encoder;
    bool raw = false;
    uint32_t offset = 0;
    const uint32_t tag_end = current_offset();
    if (same_bytes && tag_end < text_.size() && (text_[tag_end] == '>' || text_[tag_end] == '/')) {
        // libxml2 stops at the '>' or '/>' that ends the start tag; '<' cannot occur inside it.
        uint32_t p = tag_end;
        while (p > 0 && text_[p] != '<') --p;
        if (text_[p] == '<') {
            offset = p + 1;
            const uint32_t end = tag_end;
            uint32_t q = offset;
            auto space = [&](uint32_t i) { return i < end && static_cast<unsigned char>(text_[i]) <= ' '; };
            while (q < end && !space(q) && text_[q] != '/' && text_[q] != '>') ++q;
            raw = true;
            for (;;) {
                while (space(q)) ++q;
                if (q >= end || text_[q] == '/' || text_[q] == '>') break;
                uint32_t name_begin = q;
                while (q < end && !space(q) && text_[q] != '=') ++q;
                std::string_view qname = text_.substr(name_begin, q - name_begin);
                while (space(q)) ++q;
                if (q >= end || text_[q] != '=') {
                    raw = false;
                    break;
                }
                ++q;
                while (space(q)) ++q;
                if (q >= end || (text_[q] != '"' && text_[q] != '\'')) {
                    raw = false;
                    break;
                }
                char quote = text_[q++];
                uint32_t value_begin = q;
                while (q < end && text_[q] != quote) ++q;
                if (q >= end) {
                    raw = false;
                    break;
                }
                if (qname != "xmlns" && qname.rfind("xmlns:", 0) != 0)
                    raw_scratch_.push_back({qname, name_begin, value_begin, q});
                ++q;
            }
            if (raw && raw_scratch_.size() != static_cast<size_t>(count)) raw = false;
            for (int i = 0; raw && i < count; ++i) {
                std::string_view qname = raw_scratch_[static_cast<size_t>(i)].qname;
                size_t colon = qname.find(':');
                std::string_view local_name = colon == std::string_view::npos ? qname : qname.substr(colon + 1);
                if (local_name != reinterpret_cast<const char*>(attrs[i * 5])) raw = false;
            }
        }
    }
    if (!raw) offset = offset_at(in->line, in->col);
    for (int i = 0; i < count; ++i) {
        if (attrs[i * 5 + 1]) continue;  // namespace-qualified (xsd:..., xml:...): never an X3D field
        XmlAttr a;
        a.name = cached_name(attrs[i * 5]);
        const char* value = reinterpret_cast<const char*>(attrs[i * 5 + 3]);
        const char* value_end = reinterpret_cast<const char*>(attrs[i * 5 + 4]);
        bool use_raw = false;
        if (raw) {
            const RawAttr& r = raw_scratch_[static_cast<size_t>(i)];
            a.name_offset = r.name_offset;
            a.begin = r.begin;
            a.end = r.end;
            use_raw = text_.substr(r.begin, r.end - r.begin).find('&') == std::string_view::npos;
        } else {
            a.name_offset = a.begin = a.end = offset;
        }
        if (!use_raw) {
            // SAX2 without entity substitution spells a decoded '&' as "&#38;".
            std::string decoded;
            decoded.reserve(static_cast<size_t>(value_end - value));
            for (const char* p = value; p < value_end;) {
                if (value_end - p >= 5 && std::memcmp(p, "&#38;", 5) == 0) {
                    decoded += '&';
                    p += 5;
                } else {
                    decoded += *p++;
                }
            }
            a.decoded = static_cast<int32_t>(string_scratch_.size());
            string_scratch_.push_back(std::move(decoded));
        }
        attr_scratch_.push_back(a);
    }
    XmlElement e;
    e.tag = cached_name(local);
    e.file = main_file_;
    e.offset = offset;
    e.attrs = attr_scratch_;
    e.strings = &string_scratch_;
    start_element(e);
}

// ---- elements -----------------------------------------------------------------------------------

void XmlReader::start_element(const XmlElement& e) {
    if (recording_) {
        record(e);
        ++record_depth_;
        return;
    }
    const Role parent = stack_.back().role;
    std::string_view tag = name_text(e.tag);
    switch (parent) {
        case Role::Skip:
        case Role::Leaf:
            push(make_open(Role::Skip, e));
            return;
        case Role::Use:
            warn(e.file, e.offset, "elements inside a USE element are ignored", "xml-use-children");
            push(make_open(Role::Skip, e));
            return;
        case Role::Document:
            if (tag == "X3D") return push(make_open(Role::X3d, e));
            if (tag == "Scene") return push(make_open(Role::Scene, e));
            fail(e.file, e.offset, "not an X3D document: the root element is <" + std::string(tag) + ">, expected <X3D>");
        case Role::X3d:
            if (tag == "Scene") return push(make_open(Role::Scene, e));
            if (tag != "head")
                warn(e.file, e.offset, "element <" + std::string(tag) + "> outside <Scene> ignored",
                     "xml-outside-scene:" + std::string(tag));
            return push(make_open(Role::Skip, e));
        case Role::ProtoDeclare:
            if (tag == "ProtoInterface") return push(make_open(Role::ProtoInterface, e));
            if (tag == "ProtoBody") {
                XmlProtoDecl& decl = *stack_.back().proto;
                if (decl.has_body) fail(e.file, e.offset, "a ProtoDeclare has only one ProtoBody");
                decl.has_body = true;
                decl.file = e.file;
                push(make_open(Role::ProtoBody, e));
                recording_ = &decl;
                record_depth_ = 0;
                return;
            }
            fail(e.file, e.offset, "<" + std::string(tag) + "> inside <ProtoDeclare>: expected <ProtoInterface> or <ProtoBody>");
        case Role::ProtoInterface:
            if (tag == "field") return field_start(e, Role::InterfaceField);
            fail(e.file, e.offset, "<" + std::string(tag) + "> inside <ProtoInterface>: expected <field>");
        case Role::ExternProto:
            if (tag == "field") return field_start(e, Role::ExternField);
            fail(e.file, e.offset, "<" + std::string(tag) + "> inside <ExternProtoDeclare>: expected <field>");
        case Role::Instance:
            if (tag == "fieldValue") return field_value_start(e);
            if (tag == "IS") {
                if (!frame().is_values) fail(e.file, e.offset, "<IS> may only be used inside a <ProtoBody>");
                return push(make_open(Role::Is, e));
            }
            warn(e.file, e.offset, "<" + std::string(tag) + "> inside <ProtoInstance> ignored (expected <fieldValue>)",
                 "xml-instance-child:" + std::string(tag));
            return push(make_open(Role::Skip, e));
        case Role::Is:
            if (tag == "connect") {
                connect(e);
                return push(make_open(Role::Leaf, e));
            }
            fail(e.file, e.offset, "<" + std::string(tag) + "> inside <IS>: expected <connect>");
        case Role::ExternField:
        case Role::ProtoBody:
            break;
        default:
            return content_element(e);
    }
    fail(e.file, e.offset, "<" + std::string(tag) + "> is not allowed here");
}

// An element where nodes may stand: the Scene, a ProtoBody being replayed, a node, a field's default value.
void XmlReader::content_element(const XmlElement& e) {
    std::string_view tag = name_text(e.tag);
    if (tag == "ProtoDeclare") return proto_declare_start(e);
    if (tag == "ExternProtoDeclare") return extern_start(e);
    if (tag == "ProtoInstance") return instance_start(e);
    if (tag == "ROUTE" || tag == "IMPORT" || tag == "EXPORT") {
        if (tag == "ROUTE") ++scene_.stats.routes;
        return push(make_open(Role::Leaf, e));
    }
    Open& parent = stack_.back();
    if (tag == "IS") {
        if (parent.role != Role::Node) fail(e.file, e.offset, "<IS> may only stand inside a node or <ProtoInstance>");
        if (!frame().is_values) fail(e.file, e.offset, "<IS> may only be used inside a <ProtoBody>");
        return push(make_open(Role::Is, e));
    }
    if (tag == "field") {
        if (parent.role == Role::Node && parent.dynamic) return field_start(e, Role::DynamicField);
        fail(e.file, e.offset, "<field> may only stand in <ProtoInterface>, <ExternProtoDeclare>, Script and shader nodes");
    }
    if (tag == "fieldValue" || tag == "connect" || tag == "ProtoInterface" || tag == "ProtoBody" || tag == "Scene" ||
        tag == "X3D")
        fail(e.file, e.offset, "<" + std::string(tag) + "> is not allowed inside <" + tag_of(parent) + ">");
    if (const NodeTypeDecl* decl = registry_.lookup(Spec::X3d, e.tag)) return node_start(e, decl);
    std::string type(tag);
    std::string hint = frame().protos->find(e.tag) ? " (to instantiate the prototype, use <ProtoInstance name='" + type + "'>)" : "";
    warn(e.file, e.offset, "unknown node type '" + type + "' skipped" + hint, "unknown-node:" + type);
    ++scene_.stats.skipped_nodes[type];
    push(make_open(Role::Skip, e));
}

void XmlReader::node_start(const XmlElement& e, const NodeTypeDecl* decl) {
    if (const XmlAttr* use = e.find(n_.use)) return use_start(e, *use, false);
    Open o = make_open(Role::Node, e);
    o.decl = decl;
    const std::string_view type = name_text(e.tag);
    o.dynamic = has_dynamic_interface(type);
    for (const XmlAttr& a : e.attrs) {
        if (a.name == n_.def) {
            o.def = intern(trim(attr_text(e, a)));
            continue;
        }
        if (a.name == n_.container) {
            o.container = intern(trim(attr_text(e, a)));
            o.container_offset = a.begin;
            continue;
        }
        if (a.name == n_.cls || a.name == n_.id || a.name == n_.style) continue;
        Name field_name = intern(x3d_field_name(type, name_text(a.name)));
        const FieldDecl* field = registry_.lookup_field(Spec::X3d, *decl, field_name);
        if (!field)
            fail(e.file, a.name_offset, "unknown attribute '" + std::string(name_text(a.name)) + "' of node " +
                                            std::string(type));
        if (field->extension)
            warn(e.file, a.name_offset, "non-standard field '" + std::string(name_text(a.name)) + "' of " +
                                            std::string(type) + " (a browser extension) read and ignored",
                 "extension-field:" + std::string(type) + "." + std::string(name_text(a.name)));
        if (!has_value(field->access))
            fail(e.file, a.name_offset, "'" + std::string(name_text(a.name)) + "' is an event of " + std::string(type) +
                                            " and takes no value");
        FieldEntry entry;
        entry.name = field->name;
        read_value(e, a, field->type, entry, "attribute '" + std::string(name_text(a.name)) + "' of " + std::string(type));
        push_field(o.field_mark, entry);
    }
    push(std::move(o));
}

void XmlReader::use_start(const XmlElement& e, const XmlAttr& use, bool instance) {
    Open o = make_open(Role::Use, e);
    std::string name(trim(attr_text(e, use)));
    Name key = intern(name);
    Frame& f = frame();
    auto it = f.defs.find(key);
    if (it != f.defs.end()) {
        o.use = it->second;
    } else if (f.outer_defs && f.outer_defs->count(key)) {
        o.use = f.outer_defs->at(key);
    } else {
        fail(e.file, use.begin, "USE of '" + name + "', which no DEF before it names" +
                                    (f.is_values ? " in this ProtoBody" : ""));
    }
    ++scene_.stats.use_count;
    for (const XmlAttr& a : e.attrs) {
        if (a.name == n_.container) {
            o.container = intern(trim(attr_text(e, a)));
            o.container_offset = a.begin;
        } else if (a.name != n_.use && a.name != n_.cls && a.name != n_.id && a.name != n_.style &&
                   !(instance && a.name == n_.name)) {
            warn(e.file, a.name_offset, "attribute '" + std::string(name_text(a.name)) + "' of a USE element ignored",
                 "xml-use-attribute");
        }
    }
    if (!instance && o.use != kNullNode && tree_.nodes[o.use].type != e.tag)
        warn(e.file, e.offset, "USE '" + name + "' names a " + std::string(tree_.type_name(o.use)) + ", not a " +
                                   std::string(name_text(e.tag)),
             "xml-use-type:" + name);
    push(std::move(o));
}

void XmlReader::end_element() {
    if (recording_) {
        if (record_depth_ > 0) {
            --record_depth_;
            recording_->events.push_back({kNoName, 0, 0, 0, false});
            return;
        }
        recording_ = nullptr;  // this is </ProtoBody>
    }
    Open o = std::move(stack_.back());
    stack_.pop_back();
    switch (o.role) {
        case Role::Node: return node_end(o);
        case Role::Use: return attach(o.use, o);
        case Role::Instance: {
            ++scene_.stats.proto_instances;
            NodeId id = expand(*o.instance, o.file, o.offset);
            if (o.def != kNoName) {
                if (id != kNullNode && tree_.nodes[id].def_name == kNoName) tree_.nodes[id].def_name = o.def;
                frame().defs[o.def] = id;
                ++scene_.stats.def_count;
            }
            return attach(id, o);
        }
        case Role::FieldValue: {
            FieldEntry entry;
            entry.name = o.field.name;
            node_entry(o.field.type, o.child_mark, entry, o.file, o.offset,
                       "fieldValue '" + std::string(name_text(o.field.name)) + "'");
            stack_.back().instance->values[o.field.name] = entry;
            return;
        }
        case Role::InterfaceField:
        case Role::ExternField:
        case Role::DynamicField: return field_end(o);
        case Role::ProtoDeclare: {
            auto& scope = *frame().protos;
            if (!o.proto->has_body)
                warn(o.file, o.offset, "ProtoDeclare '" + std::string(name_text(o.proto->name)) +
                                           "' has no ProtoBody; its instances are empty",
                     "xml-no-protobody");
            if (!scope.protos.count(o.proto->name)) scope.order.push_back(o.proto->name);
            scope.protos[o.proto->name] = o.proto;
            ++scene_.stats.proto_declarations;
            return;
        }
        case Role::ExternProto: {
            auto& scope = *frame().protos;
            if (resolver_) o.proto->implementation = resolver_(o.urls, o.file, {o.file, o.offset}, o.proto->name);
            if (!scope.protos.count(o.proto->name)) scope.order.push_back(o.proto->name);
            scope.protos[o.proto->name] = o.proto;
            ++scene_.stats.externproto_declarations;
            return;
        }
        default: return;
    }
}

void XmlReader::node_end(Open& o) {
    // Child elements become MFNode/SFNode fields, one entry per field in order of first appearance.
    for (size_t i = o.child_mark; i < children_.size(); ++i) {
        const Name field = children_[i].field;
        bool seen = false;
        for (size_t k = o.child_mark; k < i && !seen; ++k) seen = children_[k].field == field;
        if (seen) continue;
        const FieldDecl* decl = registry_.lookup_field(Spec::X3d, *o.decl, field);
        FieldEntry entry;
        entry.name = field;
        entry.type = decl->type;
        entry.loc = tree_.nodes[children_[i].id].loc;
        entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
        for (size_t k = i; k < children_.size(); ++k)
            if (children_[k].field == field) tree_.node_refs.push_back(children_[k].id);
        entry.count = static_cast<uint32_t>(tree_.node_refs.size() - entry.begin);
        if (!decl->type.multi && entry.count > 1) {
            warn(entry.loc.file, entry.loc.offset, "field '" + std::string(name_text(field)) + "' of " + tag_of(o) +
                                                       " holds one node but was given " + std::to_string(entry.count) +
                                                       "; the last is used",
                 "xml-sfnode-twice:" + std::string(name_text(field)));
            tree_.node_refs[entry.begin] = tree_.node_refs.back();
            tree_.node_refs.resize(entry.begin + 1);
            entry.count = 1;
        }
        push_field(o.field_mark, entry);
    }
    children_.resize(o.child_mark);
    NodeId id = make_node(o.decl, o.tag, o.file, o.offset, o.field_mark);
    if (o.def != kNoName) {
        tree_.nodes[id].def_name = o.def;
        frame().defs[o.def] = id;
        ++scene_.stats.def_count;
    }
    attach(id, o);
}

// Places a finished node (or USE, or PROTO instance) into the element that contains it.
void XmlReader::attach(NodeId id, const Open& child) {
    if (id == kNullNode) return;
    Open& parent = stack_.back();
    switch (parent.role) {
        case Role::Scene: roots_.push_back(id); return;
        case Role::ReplayRoot:
        case Role::InterfaceField:
        case Role::FieldValue:
        case Role::DynamicField: children_.push_back({kNoName, id}); return;
        case Role::Node: break;
        default: return;
    }
    const std::string_view parent_type = name_text(parent.tag);
    const std::string_view type = tree_.type_name(id);
    if (child.container != kNoName) {
        std::string_view wanted = x3d_field_name(parent_type, name_text(child.container));
        const FieldDecl* field = registry_.lookup_field(Spec::X3d, *parent.decl, intern(wanted));
        if (!field || field->type.kind != ValueKind::Node)
            fail(child.file, child.container_offset,
                 "containerField '" + std::string(name_text(child.container)) + "' of " + std::string(type) +
                     " is not a node field of its parent " + std::string(parent_type));
        if (!has_value(field->access))
            fail(child.file, child.container_offset, "containerField '" + std::string(wanted) + "' is an event of " +
                                                         std::string(parent_type) + " and takes no nodes");
        children_.push_back({field->name, id});
        return;
    }
    std::string_view wanted = x3d_default_container_field(type);
    const FieldDecl* field = registry_.lookup_field(Spec::X3d, *parent.decl, intern(wanted));
    if (!field || field->type.kind != ValueKind::Node || !has_value(field->access)) {
        warn(child.file, child.offset,
             std::string(type) + " ignored: its parent " + std::string(parent_type) + " has no field '" +
                 std::string(wanted) + "' (the default containerField of " + std::string(type) +
                 "); give a containerField attribute",
             "xml-container:" + std::string(parent_type) + "." + std::string(wanted));
        return;
    }
    children_.push_back({field->name, id});
}

void XmlReader::instance_start(const XmlElement& e) {
    if (const XmlAttr* use = e.find(n_.use)) return use_start(e, *use, true);
    std::string name = required(e, n_.name, "ProtoInstance");
    Open o = make_open(Role::Instance, e);
    const ProtoDecl* proto = frame().protos->find(intern(name));
    if (!proto) {
        warn(e.file, e.offset, "ProtoInstance of '" + name + "', which no ProtoDeclare or ExternProtoDeclare before it declares; skipped",
             "unknown-proto:" + name);
        ++scene_.stats.skipped_nodes[name];
        return push(make_open(Role::Skip, e));
    }
    o.instance = std::make_unique<Instance>();
    o.instance->proto = proto;
    for (const XmlAttr& a : e.attrs) {
        if (a.name == n_.def) o.def = intern(trim(attr_text(e, a)));
        if (a.name == n_.container) {
            o.container = intern(trim(attr_text(e, a)));
            o.container_offset = a.begin;
        }
    }
    push(std::move(o));
}

void XmlReader::field_value_start(const XmlElement& e) {
    Instance& inst = *stack_.back().instance;
    std::string name = required(e, n_.name, "fieldValue");
    const ProtoField* pf = inst.proto->find(intern(name));
    if (!pf)
        fail(e.file, e.find(n_.name)->begin, "ProtoInstance of " + std::string(name_text(inst.proto->name)) +
                                                 " has no field '" + name + "'");
    if (!has_value(pf->access))
        fail(e.file, e.offset, "field '" + name + "' of " + std::string(name_text(inst.proto->name)) +
                                   " is an event and takes no value");
    if (const XmlAttr* value = e.find(n_.value)) {
        FieldEntry entry;
        entry.name = pf->name;
        read_value(e, *value, pf->type, entry, "fieldValue '" + name + "'");
        inst.values[pf->name] = entry;
        return push(make_open(Role::Skip, e));
    }
    if (pf->type.kind != ValueKind::Node) return push(make_open(Role::Skip, e));  // no value: the default stays
    Open o = make_open(Role::FieldValue, e);
    o.field = *pf;
    push(std::move(o));
}

// <connect nodeField protoField>: the enclosing node (or PROTO instance) field takes the instance's value.
void XmlReader::connect(const XmlElement& e) {
    Open& owner = stack_[stack_.size() - 2];
    Frame& f = frame();
    const std::string node_field = required(e, n_.node_field, "connect");
    const std::string proto_field = required(e, n_.proto_field, "connect");
    const ProtoField* outer = f.proto->find(intern(proto_field));
    if (!outer)
        fail(e.file, e.find(n_.proto_field)->begin, "connect names '" + proto_field + "', which is not a field of " +
                                                        std::string(name_text(f.proto->name)));
    auto bound = f.is_values->find(outer->name);
    if (owner.role == Role::Instance) {
        Instance& inst = *owner.instance;
        const ProtoField* inner = inst.proto->find(intern(node_field));
        if (!inner)
            fail(e.file, e.find(n_.node_field)->begin, "connect names '" + node_field + "', which is not a field of " +
                                                           std::string(name_text(inst.proto->name)));
        if (inner->type != outer->type) fail(e.file, e.offset, "connect joins fields of different types");
        if (bound != f.is_values->end()) {
            inst.values[inner->name] = bound->second;
            inst.values[inner->name].name = inner->name;
        }
        return;
    }
    const std::string_view type = name_text(owner.tag);
    const FieldDecl* field = registry_.lookup_field(Spec::X3d, *owner.decl, intern(x3d_field_name(type, node_field)));
    if (!field) {
        if (owner.dynamic) return;  // a Script's own field: dropped with the Script's interface
        fail(e.file, e.find(n_.node_field)->begin, "connect names '" + node_field + "', which is not a field of " +
                                                       std::string(type));
    }
    if (field->type != outer->type)
        fail(e.file, e.offset, "connect joins " + std::string(type) + "." + node_field + " (" +
                                   std::string(type_name(field->type)) + ") to " + proto_field + " of type " +
                                   std::string(type_name(outer->type)));
    if (!has_value(field->access) || bound == f.is_values->end()) return;  // events carry no value at time 0
    FieldEntry entry = bound->second;
    entry.name = field->name;
    push_field(owner.field_mark, entry);
}

void XmlReader::field_start(const XmlElement& e, Role role) {
    Open o = make_open(role, e);
    const std::string name = required(e, n_.name, "field");
    const std::string type_text = required(e, n_.type, "field");
    auto type = parse_type_name(trim(type_text));
    if (!type) fail(e.file, e.find(n_.type)->begin, "unknown field type '" + type_text + "'");
    Access access = Access::Field;
    if (const XmlAttr* a = e.find(n_.access)) {
        std::string text(trim(attr_text(e, *a)));
        auto parsed = parse_access(text);
        if (!parsed) fail(e.file, a->begin, "unknown accessType '" + text + "'");
        access = *parsed;
    }
    o.field.name = intern(name);
    o.field.type = *type;
    o.field.access = access;
    o.field.default_value.name = o.field.name;
    const XmlAttr* value = e.find(n_.value);
    if (value && role != Role::ExternField && has_value(access)) {
        read_value(e, *value, *type, o.field.default_value, "field '" + name + "'");
        o.value_given = true;
    }
    if (role == Role::InterfaceField) {
        o.field.has_default = has_value(access);
        // A default value is a DEF scope of its own that may USE the enclosing scope's names.
        auto scope = std::make_unique<Frame>();
        Frame& f = frame();
        scope->file = f.file;
        scope->outer_defs = &f.defs;
        scope->protos = f.protos;
        scope->is_values = f.is_values;
        scope->proto = f.proto;
        scope->proto_depth = f.proto_depth;
        frames_.push_back(std::move(scope));
    }
    push(std::move(o));
}

void XmlReader::field_end(Open& o) {
    if (o.role == Role::DynamicField) {
        children_.resize(o.child_mark);
        return;
    }
    if (o.role == Role::InterfaceField) {
        frames_.pop_back();
        if (o.field.has_default && !o.value_given) {
            if (o.field.type.kind == ValueKind::Node) {
                node_entry(o.field.type, o.child_mark, o.field.default_value, o.file, o.offset,
                           "field '" + std::string(name_text(o.field.name)) + "'");
            } else {
                type_default(o.field.type, o.field.default_value);  // X3D: the type's initial value
            }
        }
    }
    children_.resize(o.child_mark);
    XmlProtoDecl& decl = *stack_[stack_.size() - (o.role == Role::InterfaceField ? 2 : 1)].proto;
    if (decl.find(o.field.name))
        fail(o.file, o.offset, "field '" + std::string(name_text(o.field.name)) + "' declared twice in " +
                                   std::string(name_text(decl.name)));
    decl.fields.push_back(o.field);
}

void XmlReader::proto_declare_start(const XmlElement& e) {
    Open o = make_open(Role::ProtoDeclare, e);
    o.proto = std::make_shared<XmlProtoDecl>();
    o.proto->name = intern(trim(required(e, n_.name, "ProtoDeclare")));
    o.proto->spec = Spec::X3d;
    o.proto->file = e.file;
    o.proto->body_begin = o.proto->body_end = e.offset;  // the body is kept as events, not as text
    o.proto->scope = frame().protos;
    push(std::move(o));
}

void XmlReader::extern_start(const XmlElement& e) {
    Open o = make_open(Role::ExternProto, e);
    o.proto = std::make_shared<XmlProtoDecl>();
    o.proto->name = intern(trim(required(e, n_.name, "ExternProtoDeclare")));
    o.proto->spec = Spec::X3d;
    o.proto->file = e.file;
    o.proto->external = true;
    o.proto->scope = frame().protos;
    if (const XmlAttr* url = e.find(n_.url)) {
        FieldEntry urls;
        read_value(e, *url, FieldType{ValueKind::String, true}, urls, "attribute 'url' of ExternProtoDeclare");
        o.urls.assign(tree_.strings.begin() + urls.begin, tree_.strings.begin() + urls.begin + urls.count);
    }
    push(std::move(o));
}

void XmlReader::record(const XmlElement& e) {
    XmlProtoDecl& decl = *recording_;
    RecordedEvent event{e.tag, e.offset, static_cast<uint32_t>(decl.attrs.size()),
                        static_cast<uint32_t>(e.attrs.size()), true};
    for (XmlAttr a : e.attrs) {
        if (a.decoded >= 0) {
            decl.strings.push_back((*e.strings)[static_cast<size_t>(a.decoded)]);
            a.decoded = static_cast<int32_t>(decl.strings.size() - 1);
        }
        decl.attrs.push_back(a);
    }
    decl.events.push_back(event);
}

NodeId XmlReader::expand(const Instance& inst, uint32_t file, uint32_t offset) {
    const ProtoDecl& proto = *inst.proto;
    const std::string name(name_text(proto.name));
    const ProtoDecl* impl = &proto;
    if (proto.external) {
        impl = proto.implementation.get();
        if (!impl) {
            warn(file, offset, "instance of ExternProtoDeclare " + name + " skipped: it was not resolved",
                 "unresolved-externproto:" + name);
            ++scene_.stats.skipped_nodes[name];
            return kNullNode;
        }
    }
    if (impl->builtin) return builtin_instance(*impl->builtin, inst.values, file, offset);
    if (!is_xml_text(scene_.sources.file(impl->file).text)) {
        warn(file, offset, "instance of " + name + " skipped: its implementation is a classic-encoding PROTO, which an X3D XML file cannot instantiate",
             "classic-externproto:" + name);
        ++scene_.stats.skipped_nodes[name];
        return kNullNode;
    }
    const auto& body = static_cast<const XmlProtoDecl&>(*impl);
    // Every field of the implementation gets a value: the instance's, else the declared default.
    std::unordered_map<Name, FieldEntry> bound;
    for (const ProtoField& pf : impl->fields) {
        auto it = inst.values.find(pf.name);
        if (it != inst.values.end()) {
            if (it->second.type != pf.type)
                fail(file, offset, "field '" + std::string(name_text(pf.name)) + "' of " + name +
                                       " has another type in its implementation");
            bound[pf.name] = it->second;
        } else if (pf.has_default) {
            bound[pf.name] = pf.default_value;
        }
    }
    if (frame().proto_depth + 1 > limits_.max_proto_depth)
        fail(file, offset, "ProtoInstances nested deeper than " + std::to_string(limits_.max_proto_depth) +
                               " (limit; a prototype that instantiates itself?)");
    auto scope = std::make_unique<Frame>();
    scope->file = body.file;
    scope->protos = std::make_shared<ProtoScope>();
    scope->protos->parent = impl->scope;
    scope->is_values = &bound;
    scope->proto = impl;
    scope->proto_depth = frame().proto_depth + 1;
    frames_.push_back(std::move(scope));
    Open root;
    root.role = Role::ReplayRoot;
    root.file = body.file;
    root.offset = offset;
    root.child_mark = children_.size();
    const size_t depth = stack_.size();
    push(std::move(root));
    for (const RecordedEvent& ev : body.events) {
        if (!ev.start) {
            end_element();
            continue;
        }
        XmlElement e;
        e.tag = ev.tag;
        e.file = body.file;
        e.offset = ev.offset;
        e.attrs = std::span<const XmlAttr>(body.attrs.data() + ev.first_attr, ev.attr_count);
        e.strings = &body.strings;
        start_element(e);
    }
    if (stack_.size() != depth + 1 || recording_)
        fail(file, offset, "the ProtoBody of " + name + " is not balanced");  // cannot happen for recorded XML
    // The first node of the body is the instance; the others are built but not part of the scene.
    NodeId first = children_.size() > stack_.back().child_mark ? children_[stack_.back().child_mark].id : kNullNode;
    children_.resize(stack_.back().child_mark);
    stack_.pop_back();
    frames_.pop_back();
    return first;
}

NodeId XmlReader::builtin_instance(const NodeTypeDecl& decl, const std::unordered_map<Name, FieldEntry>& values,
                                   uint32_t file, uint32_t offset) {
    const size_t mark = scratch_.size();
    for (const auto& [name, entry] : values) {
        const FieldDecl* field = decl.find(name);
        if (!field || field->type != entry.type || !has_value(field->access)) {
            warn(file, offset, "field '" + std::string(name_text(name)) + "' does not match built-in node " +
                                   std::string(name_text(decl.name)) + "; ignored",
                 "builtin-proto-field:" + std::string(name_text(name)));
            continue;
        }
        scratch_.push_back(entry);
    }
    return make_node(&decl, decl.name, file, offset, mark);
}

// ---- values -------------------------------------------------------------------------------------

// The attribute's value as XML defines it: references decoded, each tab, line break or CR LF one space.
std::string XmlReader::attr_text(const XmlElement& e, const XmlAttr& a) const {
    if (a.decoded >= 0) return (*e.strings)[static_cast<size_t>(a.decoded)];
    std::string_view raw = std::string_view(scene_.sources.file(e.file).text).substr(a.begin, a.end - a.begin);
    std::string out;
    out.reserve(raw.size());
    for (size_t i = 0; i < raw.size(); ++i) {
        char c = raw[i];
        if (c == '\r' && i + 1 < raw.size() && raw[i + 1] == '\n') continue;
        out += (c == '\t' || c == '\n' || c == '\r') ? ' ' : c;
    }
    return out;
}

std::string XmlReader::required(const XmlElement& e, Name attr, const char* what) {
    const XmlAttr* a = e.find(attr);
    if (!a) fail(e.file, e.offset, std::string("<") + what + "> needs a '" + std::string(name_text(attr)) + "' attribute");
    return attr_text(e, *a);
}

void XmlReader::read_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                           const std::string& what) {
    entry.type = type;
    entry.loc = {e.file, a.begin};
    if (type.kind == ValueKind::Node) {
        std::string text(trim(attr_text(e, a)));
        if (!text.empty() && text != "NULL")
            fail(e.file, a.begin, what + " holds nodes, which are given as child elements, not as an attribute");
        entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
        if (!type.multi) tree_.node_refs.push_back(kNullNode);
        entry.count = type.multi ? 0 : 1;
        return;
    }
    if (type.kind == ValueKind::String && !type.multi) {
        // An SFString attribute is the string itself, without quotes.
        entry.begin = static_cast<uint32_t>(tree_.strings.size());
        tree_.strings.push_back(attr_text(e, a));
        entry.count = 1;
        return;
    }
    if (type.kind == ValueKind::String) {
        std::string text = attr_text(e, a);
        std::string_view t = trim(text);
        if (t.empty() || t.front() == '"') return lex_value(e, a, type, entry, what);
        // Not quoted: X3D requires "a" "b", but exporters write url='a.png' or X3DOM-style 'a','b'.
        entry.begin = static_cast<uint32_t>(tree_.strings.size());
        if (t.front() == '\'') {
            warn(e.file, a.begin, what + ": MFString items in single quotes; read as quoted strings",
                 "xml-mfstring-single-quotes");
            size_t p = 0;
            while (p < t.size()) {
                size_t open = t.find('\'', p);
                if (open == std::string_view::npos) break;
                size_t close = t.find('\'', open + 1);
                if (close == std::string_view::npos) close = t.size();
                tree_.strings.emplace_back(t.substr(open + 1, close - open - 1));
                p = close + 1;
            }
        } else {
            warn(e.file, a.begin, what + ": MFString value is not quoted; read as one string",
                 "xml-mfstring-unquoted");
            tree_.strings.emplace_back(t);
        }
        entry.count = static_cast<uint32_t>(tree_.strings.size() - entry.begin);
        return;
    }
    lex_value(e, a, type, entry, what);
}

// Numbers and quoted strings: the classic value parser, over the attribute's bytes in the file when they are
// the value (so messages point into the attribute), else over the decoded value.
void XmlReader::lex_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                          const std::string& what) {
    const std::string& file_text = scene_.sources.file(e.file).text;
    std::string decoded;
    const bool raw = a.decoded < 0;
    if (!raw) decoded = (*e.strings)[static_cast<size_t>(a.decoded)];
    Lexer lexer = raw ? Lexer(file_text, a.begin, a.end) : Lexer(decoded);
    Diagnostics local;
    ValueContext ctx{tree_, lexer, raw ? &scene_.diagnostics : &local, e.file, limits_.max_mf_values};
    ctx.xml = true;
    auto where = [&](uint32_t offset) { return raw ? offset : a.begin; };
    if (!type.multi && lexer.peek().kind == TokenKind::End) fail(e.file, a.begin, what + " is empty");
    try {
        read_field_value(ctx, type, entry);
        const Token extra = lexer.peek();
        if (extra.kind != TokenKind::End)
            fail(e.file, where(extra.offset), what + ": more values than one " + std::string(type_name(type)) + " holds");
    } catch (const SyntaxError& s) {
        fail(e.file, where(s.offset), what + ": " + s.message);
    }
    entry.loc = {e.file, a.begin};
    for (const Diagnostic& d : local.all())
        for (uint32_t i = 0; i < d.count; ++i) warn(e.file, a.begin, d.message, "xml-value:" + d.message);
}

// The initial value of a field type, for an X3D interface field declared without a value.
void XmlReader::type_default(FieldType type, FieldEntry& entry) {
    entry.type = type;
    entry.loc = {};
    entry.count = 0;
    if (type.kind == ValueKind::String) {
        entry.begin = static_cast<uint32_t>(tree_.strings.size());
        if (!type.multi) {
            tree_.strings.emplace_back();
            entry.count = 1;
        }
        return;
    }
    entry.begin = static_cast<uint32_t>(tree_.numbers.size());
    if (type.multi) return;
    int n = type.kind == ValueKind::Image ? 3 : components(type.kind);
    for (int i = 0; i < n; ++i) tree_.numbers.push_back(type.kind == ValueKind::Rotation && i == 2 ? 1.0 : 0.0);
    entry.count = static_cast<uint32_t>(n);
}

// A node-valued entry from the child nodes collected since `mark` (SFNode: the last, or NULL).
void XmlReader::node_entry(FieldType type, size_t mark, FieldEntry& entry, uint32_t file, uint32_t offset,
                           const std::string& what) {
    entry.type = type;
    entry.loc = {file, offset};
    entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
    size_t count = children_.size() - mark;
    if (!type.multi) {
        if (count > 1)
            warn(file, offset, what + " holds one node but was given " + std::to_string(count) + "; the last is used",
                 "xml-sfnode-twice:" + what);
        tree_.node_refs.push_back(count ? children_.back().id : kNullNode);
    } else {
        for (size_t i = mark; i < children_.size(); ++i) tree_.node_refs.push_back(children_[i].id);
    }
    entry.count = static_cast<uint32_t>(tree_.node_refs.size() - entry.begin);
    children_.resize(mark);
}

void XmlReader::push_field(size_t mark, const FieldEntry& entry) {
    for (size_t i = mark; i < scratch_.size(); ++i) {
        if (scratch_[i].name == entry.name) {  // IS after an attribute, or two connects: the last wins
            scratch_[i] = entry;
            return;
        }
    }
    scratch_.push_back(entry);
}

NodeId XmlReader::make_node(const NodeTypeDecl* decl, Name type, uint32_t file, uint32_t offset, size_t mark) {
    if (tree_.nodes.size() >= limits_.max_nodes)
        fail(file, offset, "more than " + std::to_string(limits_.max_nodes) + " nodes (limit)");
    Node n;
    n.decl = decl;
    n.type = type;
    n.loc = {file, offset};
    n.first_field = static_cast<uint32_t>(tree_.fields.size());
    n.field_count = static_cast<uint32_t>(scratch_.size() - mark);
    tree_.fields.insert(tree_.fields.end(), scratch_.begin() + static_cast<ptrdiff_t>(mark), scratch_.end());
    scratch_.resize(mark);
    tree_.nodes.push_back(n);
    return static_cast<NodeId>(tree_.nodes.size() - 1);
}

}  // namespace

ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits,
                           const ExternProtoResolver& resolve_externproto) {
    XmlReader reader(scene, limits, resolve_externproto);
    return reader.read(file);
}

ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits) {
    return read_x3d_xml(scene, file, limits, ExternProtoResolver());
}

}  // namespace vr
