// X3D XML reader. libxml2's SAX2 interface streams the elements (no DOM is built); each element's
// attribute values are found in the file's own text, so the classic value parser reads them in
// place and every message points at the attribute's bytes. ProtoBody contents are recorded as
// element events and replayed per ProtoInstance, the XML counterpart of the classic reader
// re-reading a PROTO body's tokens.
//
// Safety: entity declarations are refused (so no entity is ever expanded: no billion laughs, no
// external entity), the external-entity loader refuses everything, DTDs are never loaded and the
// network is off. Because no entity can expand, XML_PARSE_HUGE is safe and lifts libxml2's 10 MB
// limit on one attribute value, which large meshes exceed; nesting depth is bounded by LoadLimits
// instead.
//
// This file: libxml2 glue and attribute values. x3d_xml_tree.cpp: elements to nodes.
#include "parser/x3d_xml.h"

#include <libxml/parserInternals.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <optional>
#include <thread>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/x3d_xml_reader.h"

namespace vr {

std::string_view x3d_default_container_field(std::string_view type) {
    static const std::unordered_map<std::string_view, std::string_view> table = [] {
        std::unordered_map<std::string_view, std::string_view> t;
        auto add = [&](std::string_view field, std::initializer_list<std::string_view> types) {
            for (std::string_view type : types) t.emplace(type, field);
        };
        add("metadata", {"MetadataBoolean", "MetadataDouble", "MetadataFloat", "MetadataInteger",
                         "MetadataSet", "MetadataString"});
        add("geometry", {"Arc2D",
                         "ArcClose2D",
                         "Box",
                         "Circle2D",
                         "Cone",
                         "Cylinder",
                         "Disk2D",
                         "ElevationGrid",
                         "Extrusion",
                         "IndexedFaceSet",
                         "IndexedLineSet",
                         "IndexedQuadSet",
                         "IndexedTriangleFanSet",
                         "IndexedTriangleSet",
                         "IndexedTriangleStripSet",
                         "LineSet",
                         "PointSet",
                         "Polyline2D",
                         "Polypoint2D",
                         "QuadSet",
                         "Rectangle2D",
                         "Sphere",
                         "Text",
                         "TriangleFanSet",
                         "TriangleSet",
                         "TriangleSet2D",
                         "TriangleStripSet",
                         "GeoElevationGrid",
                         "NurbsCurve",
                         "NurbsPatchSurface",
                         "NurbsTrimmedSurface",
                         "NurbsSweptSurface",
                         "NurbsSwungSurface"});
        add("appearance", {"Appearance"});
        add("material", {"Material", "PhysicalMaterial", "UnlitMaterial", "TwoSidedMaterial"});
        add("texture",
            {"ImageTexture", "MovieTexture", "PixelTexture", "MultiTexture", "ComposedTexture3D",
             "ImageTexture3D", "PixelTexture3D", "ComposedCubeMapTexture",
             "GeneratedCubeMapTexture", "ImageCubeMapTexture"});
        add("textureTransform", {"TextureTransform", "MultiTextureTransform", "TextureTransform3D",
                                 "TextureTransformMatrix3D"});
        add("coord", {"Coordinate", "CoordinateDouble", "GeoCoordinate"});
        add("normal", {"Normal"});
        add("color", {"Color", "ColorRGBA"});
        add("texCoord", {"TextureCoordinate", "TextureCoordinateGenerator",
                         "MultiTextureCoordinate", "TextureCoordinate3D", "TextureCoordinate4D"});
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
        // X3D 4.0 components read but not modelled (grammar/x3d.nodes, their last block).
        add("physics", {"BoundedPhysicsModel", "ForcePhysicsModel", "WindPhysicsModel"});
        add("emitter", {"ConeEmitter", "ExplosionEmitter", "PointEmitter", "PolylineEmitter",
                        "SurfaceEmitter", "VolumeEmitter"});
        add("joints", {"BallJoint", "DoubleAxisHingeJoint", "MotorJoint", "SingleAxisHingeJoint",
                       "SliderJoint", "UniversalJoint"});
        add("collider", {"CollisionCollection"});
        add("contacts", {"Contact"});
        add("bodies", {"RigidBody"});
        add("periodicWave", {"PeriodicWave"});
        add("renderStyle",
            {"BlendedVolumeStyle", "BoundaryEnhancementVolumeStyle", "CartoonVolumeStyle",
             "ComposedVolumeStyle", "EdgeEnhancementVolumeStyle", "OpacityMapVolumeStyle",
             "ProjectionVolumeStyle", "ShadedVolumeStyle", "SilhouetteEnhancementVolumeStyle",
             "ToneMappedVolumeStyle"});
        // X3D Layering and Layout (clauses 35, 36)
        add("layers", {"Layer", "LayoutLayer"});
        add("viewport", {"Viewport"});
        add("layout", {"Layout"});
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

namespace x3d_xml_detail {

// ---- libxml2 glue -------------------------------------------------------------------------------

static void silent_generic_error(void*, const char*, ...) {}

bool XmlReader::start_parser(uint32_t file) {
    std::string why;
    xml_ = libxml(why);  // loaded on first use; external entities refused from the start
    if (!xml_) {
        scene_.diagnostics.error({file, 0}, "cannot read X3D XML: " + why);
        return false;
    }
    xml_->SetGenericErrorFunc(nullptr,
                              silent_generic_error);  // per thread: the library never prints

    main_file_ = file;
    text_ = scene_.sources.file(file).text;
    auto top = std::make_unique<Frame>();
    top->file = file;
    top->protos = std::make_shared<ProtoScope>();
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
    sax.characters = sax_text;
    sax.cdataBlock = sax_text;
    sax.entityDecl = sax_entity_decl;
    sax.unparsedEntityDecl = sax_unparsed_entity_decl;
    // getEntity, resolveEntity, externalSubset stay null: nothing is looked up or loaded.

    // The push parser holds only the part of the text it has not consumed yet; the text itself
    // stays in the SourceManager, where the attribute values are read. The user data is `this`,
    // not the context, so libxml2 never falls back to looking entities up itself.
    ctxt_ = xml_->CreatePushParserCtxt(&sax, this, nullptr, 0, nullptr);
    if (!ctxt_) {
        scene_.diagnostics.error({file, 0}, "cannot start the XML parser (out of memory)");
        return false;
    }
    xml_->CtxtUseOptions(ctxt_, XML_PARSE_NONET | XML_PARSE_HUGE | XML_PARSE_RECOVER);
    return true;
}

void XmlReader::feed(std::string_view bytes, bool last) {
    xml_->ParseChunk(ctxt_, bytes.data(), static_cast<int>(bytes.size()), last ? 1 : 0);
}

void XmlReader::finish_parser() {
    // libxml2 makes a document of its own to hold entity declarations for SAX users; it is ours to
    // free.
    if (ctxt_->myDoc) xml_->FreeDoc(ctxt_->myDoc);
    xml_->FreeParserCtxt(ctxt_);
    ctxt_ = nullptr;
}

ClassicResult XmlReader::read(uint32_t file) {
    ClassicResult result;
    if (!start_parser(file)) {
        if (ctxt_) finish_parser();
        result.ok = false;
        return result;
    }
    result.protos = frames_.back()->protos;
    XmlPiecePlan plan = plan_xml_pieces(text_, piece_bytes());
    prefix_end_ = plan.prefix_end;
    PieceScheduler pieces(
        std::move(plan.pieces),
        [this, file](Piece& p) {
            static const ExternProtoResolver kNone;  // a piece never declares an EXTERNPROTO
            XmlReader reader({scene_.sources, p.diagnostics, p.tree, p.stats}, limits_, kNone);
            reader.read_piece(file, prefix_end_, p, consumer_);
        },
        piece_workers(limits_.read_threads));
    // 1 MB chunks, cut where a piece begins; while a chunk completes no element (one huge start
    // tag, e.g. a mesh's coordIndex), the next is twice as large: libxml2 rescans the pending start
    // tag on every chunk it is given.
    constexpr size_t kChunk = size_t(1) << 20;
    size_t chunk = kChunk;
    for (size_t pos = 0;;) {
        take_pieces(pieces, pos);
        size_t limit = text_.size();
        if (next_piece_ < pieces.size()) limit = std::max<size_t>(pos, pieces.begin(next_piece_));
        const size_t n = std::min({chunk, limit - pos, static_cast<size_t>(1) << 30});
        const bool last = pos + n >= text_.size();
        const uint64_t events = events_;
        feed(text_.substr(pos, n), last);
        // libxml2 copied what it still needs; attribute values before this chunk are read again
        // only for PROTO bodies, which a mapped file brings back from the page cache.
        scene_.sources.release_before(file, static_cast<uint32_t>(pos));
        pos += n;
        if (last || stopped_) break;
        chunk = events_ == events ? chunk * 2 : kChunk;
    }
    pieces.stop();
    scene_.sources.release_all(file);  // the last chunk too: the scene build comes next
    finish_parser();
    if (!failed_ && scenes_ == 0) {
        // Nothing to render: an error, not a picture of the background with exit 0.
        scene_.diagnostics.error({file, x3d_offset_},
                                 "no <Scene> in this X3D document: nothing to render");
        failed_ = true;
    }
    result.ok = !failed_;
    result.roots = std::move(roots_);
    result.units = units_;
    result.x3d_version = version_;
    result.consumed = std::move(consumed_);
    return result;
}

uint32_t XmlReader::offset_at(int line, int column) {
    if (line_starts_.empty()) build_line_starts();
    line = file_line(line);
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
    if (!in->buf || in->buf->encoder)
        return offset_at(in->line, in->col);  // transcoded: bytes differ
    const uint64_t stream =
        static_cast<uint64_t>(in->consumed) + static_cast<uint64_t>(in->cur - in->base);
    return std::min(file_offset(stream), static_cast<uint32_t>(text_.size()));
}

void XmlReader::on_xml_error(xmlErrorPtr error) {
    if (!error || stopped_) return;
    std::string message = error->message ? error->message : "XML error";
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
        message.pop_back();
    message = file_lines_in(std::move(message));
    uint32_t offset = offset_at(error->line, error->int2);
    // A line number in a piece reader's message counts the piece's lines, not the file's: the
    // main reader reads such a piece itself.
    if (piece_content_ && message.find(" line ") != std::string::npos)
        return stop(main_file_, offset, "XML: " + message);
    // Slips real exporters make that leave the document's meaning clear: warnings. The parser runs
    // in recovery mode so that it continues after them; any other error stops it here.
    const bool tolerated = error->level == XML_ERR_WARNING || error->domain == XML_FROM_NAMESPACE ||
                           error->code == XML_ERR_HYPHEN_IN_COMMENT;
    if (tolerated) {
        warn(main_file_, offset, "XML: " + message, "xml:" + message);
        return;
    }
    stop(main_file_, offset, "XML: " + message);
}

// libxml2's dictionary strings live as long as the parser: a name is spelt out, interned and put in
// X3D's case (`to_x3d`) once per address.
Name XmlReader::cached(const xmlChar* text, uint32_t offset,
                       std::unordered_map<const xmlChar*, Name>& cache,
                       Name (XmlReader::*to_x3d)(Name, uint32_t)) {
    const bool stable = ctxt_->dict && xml_->DictOwns(ctxt_->dict, text) == 1;
    if (stable) {
        auto it = cache.find(text);
        if (it != cache.end()) return it->second;
    }
    const Name name = (this->*to_x3d)(intern(reinterpret_cast<const char*>(text)), offset);
    if (stable) cache.emplace(text, name);
    return name;
}

void XmlReader::on_start(const xmlChar* local, int nb_attrs, int nb_defaulted,
                         const xmlChar** attrs, bool foreign) {
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
        const void* lt = memrchr(text_.data(), '<', tag_end);
        if (lt) {
            offset = static_cast<uint32_t>(static_cast<const char*>(lt) - text_.data()) + 1;
            const uint32_t end = tag_end;
            uint32_t q = offset;
            auto space = [&](uint32_t i) {
                return i < end && static_cast<unsigned char>(text_[i]) <= ' ';
            };
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
                const char quote = text_[q++];
                const uint32_t value_begin = q;
                const void* close = std::memchr(text_.data() + q, quote, end - q);
                if (!close) {
                    raw = false;
                    break;
                }
                q = static_cast<uint32_t>(static_cast<const char*>(close) - text_.data());
                if (qname != "xmlns" && qname.rfind("xmlns:", 0) != 0)
                    raw_scratch_.push_back({qname, name_begin, value_begin, q});
                ++q;
            }
            if (raw && raw_scratch_.size() != static_cast<size_t>(count)) raw = false;
            for (int i = 0; raw && i < count; ++i) {
                std::string_view qname = raw_scratch_[static_cast<size_t>(i)].qname;
                size_t colon = qname.find(':');
                std::string_view local_name =
                    colon == std::string_view::npos ? qname : qname.substr(colon + 1);
                if (local_name != reinterpret_cast<const char*>(attrs[i * 5])) raw = false;
            }
        }
    }
    if (!raw) offset = offset_at(in->line, in->col);
    for (int i = 0; i < count; ++i) {
        if (attrs[i * 5 + 1])
            continue;  // namespace-qualified (xsd:..., xml:...): never an X3D field
        XmlAttr a;
        a.name = cached(attrs[i * 5], offset, name_cache_, &XmlReader::attribute_in_x3d_case);
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
    e.tag = cached(local, offset, tag_cache_, &XmlReader::tag_in_x3d_case);
    e.file = main_file_;
    e.offset = offset;
    e.attrs = attr_scratch_;
    e.strings = &string_scratch_;
    e.foreign = foreign;
    start_element(e);
}

// ---- values -------------------------------------------------------------------------------------

// The attribute's value as XML defines it: references decoded, each tab, line break or CR LF one
// space.
std::string XmlReader::attr_text(const XmlElement& e, const XmlAttr& a) const {
    if (a.decoded >= 0) return (*e.strings)[static_cast<size_t>(a.decoded)];
    std::string_view raw =
        std::string_view(scene_.sources.file(e.file).text).substr(a.begin, a.end - a.begin);
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
    if (!a)
        fail(
            e.file, e.offset,
            std::string("<") + what + "> needs a '" + std::string(name_text(attr)) + "' attribute");
    return attr_text(e, *a);
}

void XmlReader::read_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                           const What& what) {
    entry.type = type;
    entry.loc = {e.file, a.begin};
    if (type.kind == ValueKind::Node) {
        std::string text(trim(attr_text(e, a)));
        if (!text.empty() && text != "NULL")
            fail(e.file, a.begin,
                 what.text() +
                     " holds nodes, which are given as child elements, not as an attribute");
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
            warn(e.file, a.begin,
                 what.text() + ": MFString items in single quotes; read as quoted strings",
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
            // One word unquoted (Jmol's type='EXAMINE', url='a.png') can only mean that word: read
            // silently. Words with white space between them might have meant several strings.
            if (t.find_first_of(" \t\r\n") != std::string_view::npos)
                warn(e.file, a.begin,
                     what.text() + ": MFString value is not quoted; read as one string",
                     "xml-mfstring-unquoted");
            tree_.strings.emplace_back(t);
        }
        entry.count = static_cast<uint32_t>(tree_.strings.size() - entry.begin);
        return;
    }
    lex_value(e, a, type, entry, what);
}

// Numbers and quoted strings: the classic value parser, over the attribute's bytes in the file when
// they are the value (so messages point into the attribute), else over the decoded value.
void XmlReader::lex_value(const XmlElement& e, const XmlAttr& a, FieldType type, FieldEntry& entry,
                          const What& what) {
    const std::string_view file_text = scene_.sources.file(e.file).text;
    std::string decoded;
    const bool raw = a.decoded < 0;
    if (!raw) decoded = (*e.strings)[static_cast<size_t>(a.decoded)];
    Lexer lexer = raw ? Lexer(file_text, a.begin, a.end) : Lexer(decoded);
    std::optional<Diagnostics> local;
    if (!raw) local.emplace();
    ValueContext ctx{tree_, lexer, raw ? &scene_.diagnostics : &*local, e.file,
                     limits_.max_mf_values};
    ctx.xml = true;
    auto where = [&](uint32_t offset) { return raw ? offset : a.begin; };
    if (!type.multi && lexer.peek().kind == TokenKind::End)
        fail(e.file, a.begin, what.text() + " is empty");
    try {
        read_field_value(ctx, type, entry);
        const Token extra = lexer.peek();
        if (extra.kind != TokenKind::End)
            fail(e.file, where(static_cast<uint32_t>(extra.offset)),
                 what.text() + ": more values than one " + std::string(type_name(type)) + " holds");
    } catch (const SyntaxError& s) {
        fail(e.file, where(static_cast<uint32_t>(s.offset)), what.text() + ": " + s.message);
    }
    entry.loc = {e.file, a.begin};
    if (local)
        for (const Diagnostic& d : local->all())
            for (uint32_t i = 0; i < d.count; ++i)
                warn(e.file, a.begin, d.message, "xml-value:" + d.message);
}

// An attribute's value ends at its closing quote, so unlike a classic-encoding value one that does
// not parse leaves a point to resume: browsers (X_ITE) keep the field's default and read the rest.
bool XmlReader::read_value_or_warn(const XmlElement& e, const XmlAttr& a, FieldType type,
                                   FieldEntry& entry, const What& what) {
    try {
        read_value(e, a, type, entry, what);
        return true;
    } catch (const XmlFailure& f) {
        warn(f.file, f.offset, f.message + "; the field keeps its default",
             "xml-bad-value:" + what.text());
        return false;
    }
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
    for (int i = 0; i < n; ++i)
        tree_.numbers.push_back(type.kind == ValueKind::Rotation && i == 2 ? 1.0 : 0.0);
    entry.count = static_cast<uint32_t>(n);
}

// A node-valued entry from the child nodes collected since `mark` (SFNode: the last, or NULL).
void XmlReader::node_entry(FieldType type, size_t mark, FieldEntry& entry, uint32_t file,
                           uint32_t offset, const std::string& what) {
    entry.type = type;
    entry.loc = {file, offset};
    entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
    size_t count = children_.size() - mark;
    if (!type.multi) {
        if (count > 1)
            warn(file, offset,
                 what + " holds one node but was given " + std::to_string(count) +
                     "; the last is used",
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
        if (scratch_[i].name ==
            entry.name) {  // IS after an attribute, or two connects: the last wins
            scratch_[i] = entry;
            return;
        }
    }
    scratch_.push_back(entry);
}

NodeId XmlReader::make_node(const NodeTypeDecl* decl, Name type, uint32_t file, uint32_t offset,
                            size_t mark) {
    // Ids from kFirstOuterNode on stand for a piece's outer USEs: the limit stays below them.
    const size_t limit = std::min<size_t>(limits_.max_nodes, kFirstOuterNode);
    if (tree_.nodes.size() + consumed_nodes_ >= limit)
        fail(file, offset, "more than " + std::to_string(limit) + " nodes (limit)");
    Node n;
    n.kind = tree_.kind_of(decl, type);
    n.loc = {file, offset};
    n.first_field = static_cast<uint32_t>(tree_.fields.size());
    const uint32_t field_count = static_cast<uint32_t>(scratch_.size() - mark);
    tree_.fields.insert(tree_.fields.end(), scratch_.begin() + static_cast<ptrdiff_t>(mark),
                        scratch_.end());
    scratch_.resize(mark);
    tree_.add_node(n, field_count);
    return static_cast<NodeId>(tree_.nodes.size() - 1);
}

}  // namespace x3d_xml_detail

ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits,
                           const ExternProtoResolver& resolve_externproto,
                           PieceConsumer* consumer) {
    x3d_xml_detail::XmlReader reader({scene.sources, scene.diagnostics, scene.tree, scene.stats},
                                     limits, resolve_externproto, consumer);
    return reader.read(file);
}

ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits) {
    return read_x3d_xml(scene, file, limits, ExternProtoResolver());
}

}  // namespace vr
