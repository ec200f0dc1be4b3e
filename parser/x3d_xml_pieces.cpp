// Reading one large X3D XML file on all cores, the way the classic reader reads one
// (classic_pieces.h). The <Scene> content is cut at lines that look like the start of a top-level
// element; each piece but the first is parsed on a worker thread by a libxml2 context of its own,
// given the file's text up to and including the <Scene> start tag, a line break, then the piece's
// bytes, so that it sees the XML declaration, namespaces and nesting the main reader sees there.
// The main reader gives libxml2 the file up to a piece's first byte; when it then stands between
// two top-level elements of the Scene with nothing but white space pending, and the file declared
// no prototype so far, it appends the piece's tree, DEF names, counts and warnings, and gives
// libxml2 the bytes after the piece next, counting the skipped bytes and lines into every offset
// and line libxml2 reports later. A USE of a DEF before the piece stands as an outer node
// (piece_consumer.h), resolved where the piece joins. A piece that failed, needs more of what
// came before it (ProtoDeclare, ProtoInstance, ROUTE, IMPORT, EXPORT, a USE as another type than
// its DEF's node), closed its <Scene>, or was cut anywhere but between top-level elements is read
// again by the main reader, so the result and every message equal a single-thread read.
#include <algorithm>
#include <cctype>
#include <cstring>

#include "parser/x3d_xml_reader.h"

namespace vr::x3d_xml_detail {

namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// A CR not followed by LF: libxml2 counts it as a line break, the line tables do not.
bool has_lone_cr(std::string_view text) {
    for (size_t p = text.find('\r'); p != std::string_view::npos; p = text.find('\r', p + 1))
        if (p + 1 >= text.size() || text[p + 1] != '\n') return true;
    return false;
}

// The encoding the XML declaration names, lower case ("" when it names none).
std::string declared_encoding(std::string_view text) {
    size_t p = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    if (text.compare(p, 5, "<?xml") != 0) return "";
    const size_t end = text.find("?>", p);
    const std::string_view decl = text.substr(p, end == std::string_view::npos ? 0 : end - p);
    size_t at = decl.find("encoding");
    if (at == std::string_view::npos) return "";
    at = decl.find_first_of("'\"", at);
    if (at == std::string_view::npos) return "?";
    const size_t close = decl.find(decl[at], at + 1);
    if (close == std::string_view::npos) return "?";
    std::string name(decl.substr(at + 1, close - at - 1));
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return name;
}

// Just past the '>' of the first "<Scene" start tag, 0 when there is none or it closes itself.
// A guess too ("<Scene" in a comment of the head): the main reader compares it with the tag it
// read.
uint32_t scene_tag_end(std::string_view text) {
    for (size_t at = text.find("<Scene"); at != std::string_view::npos;
         at = text.find("<Scene", at + 6)) {
        if (at + 6 >= text.size()) return 0;
        const char next = text[at + 6];
        if (next != '>' && next != '/' && !blank(next)) continue;  // <SceneX...>
        char quote = 0;
        for (size_t p = at + 6; p < text.size(); ++p) {
            const char c = text[p];
            if (quote) {
                quote = c == quote ? 0 : quote;
            } else if (c == '\'' || c == '"') {
                quote = c;
            } else if (c == '>') {
                return text[p - 1] == '/' ? 0 : static_cast<uint32_t>(p + 1);
            }
        }
        return 0;
    }
    return 0;
}

}  // namespace

XmlPiecePlan plan_xml_pieces(std::string_view text, size_t piece) {
    XmlPiecePlan plan;
    if (piece == 0 || text.size() <= piece) return plan;
    // Byte offsets, lines and columns of a piece must count as the main reader's: encodings whose
    // characters are one byte each (or UTF-8, not transcoded at all) and line breaks that both
    // count alike.
    const std::string encoding = declared_encoding(text);
    if (!encoding.empty() && encoding != "utf-8" && encoding != "utf8" &&
        encoding != "iso-8859-1" && encoding != "latin1" && encoding != "us-ascii" &&
        encoding != "ascii")
        return plan;
    // Every piece parses the prefix again: a head of megabytes is read by one thread.
    constexpr uint32_t kMaxPrefix = uint32_t(1) << 20;
    const uint32_t prefix_end = scene_tag_end(text.substr(0, kMaxPrefix));
    if (prefix_end == 0 || has_lone_cr(text.substr(0, prefix_end))) return plan;
    // The last piece ends where the line of the last </Scene> begins: the main reader reads that.
    size_t content_end = text.rfind("</Scene");
    if (content_end == std::string_view::npos || content_end < prefix_end)
        content_end = text.size();
    const size_t line = text.rfind('\n', content_end == 0 ? 0 : content_end - 1);
    if (content_end != text.size() && line != std::string_view::npos && line >= prefix_end)
        content_end = line + 1;
    // Exporters indent nested elements: a cut is a line indented as the first element line of the
    // Scene, then '<' and a letter.
    auto element_at = [&](size_t line_start, size_t& indent) {
        size_t p = line_start;
        while (p < content_end && (text[p] == ' ' || text[p] == '\t')) ++p;
        indent = p - line_start;
        if (p + 1 >= content_end || text[p] != '<') return false;
        const unsigned char c = static_cast<unsigned char>(text[p + 1]);
        return (c | 0x20) >= 'a' && (c | 0x20) <= 'z';
    };
    size_t top_indent = 0;
    for (size_t nl = text.find('\n', prefix_end); nl != std::string_view::npos && nl < content_end;
         nl = text.find('\n', nl + 1))
        if (element_at(nl + 1, top_indent)) break;
    std::vector<uint32_t> starts;
    for (size_t at = size_t(prefix_end) + piece; at < content_end;) {
        const size_t nl = text.find('\n', at - 1);  // a line start at or after `at`
        if (nl == std::string_view::npos || nl + 1 >= content_end) break;
        size_t indent = 0;
        if (element_at(nl + 1, indent) && indent == top_indent) {
            starts.push_back(static_cast<uint32_t>(nl + 1));
            at = nl + 1 + piece;
        } else {
            at = nl + 2;
        }
    }
    for (size_t k = 0; k < starts.size(); ++k) {
        Piece& p = plan.pieces.emplace_back();
        p.index = static_cast<uint32_t>(k);
        p.begin = starts[k];
        p.end = k + 1 < starts.size() ? starts[k + 1] : static_cast<uint32_t>(content_end);
    }
    if (!plan.pieces.empty()) plan.prefix_end = prefix_end;
    return plan;
}

void XmlReader::read_piece(uint32_t file, uint32_t prefix_end, Piece& piece,
                           PieceConsumer* consumer) {
    in_piece_ = true;
    prefix_end_ = prefix_end;
    piece_begin_ = static_cast<uint32_t>(piece.begin);
    piece_end_ = static_cast<uint32_t>(piece.end);
    piece_stream_ = uint64_t(prefix_end) + 1;  // after the prefix and the line break
    if (!start_parser(file)) {
        if (ctxt_) finish_parser();
        return;
    }
    feed(text_.substr(0, prefix_end), false);
    feed("\n", false);
    if (stopped_ || stack_.back().role != Role::Scene || !pending_is_blank() ||
        !tree_.nodes.empty() || has_lone_cr(text_.substr(piece.begin, piece.end - piece.begin))) {
        finish_parser();
        return;
    }
    // What the prefix said (a warning of the head, say) the main reader says itself.
    piece_depth_ = stack_.size();
    piece_content_ = true;
    piece.diagnostics = Diagnostics{};
    piece.stats = ReadStats{};
    constexpr size_t kChunk = size_t(1) << 20;
    for (size_t pos = piece.begin; pos < piece.end && !stopped_; pos += kChunk)
        feed(text_.substr(pos, std::min<size_t>(kChunk, piece.end - pos)), false);
    // Ended between two top-level elements, as the main reader must stand where it joins.
    const bool whole = !stopped_ && stack_.size() == piece_depth_ && pending_is_blank();
    finish_parser();
    if (!whole || piece.diagnostics.error_count() > 0) return;
    piece.roots = std::move(roots_);
    piece.defs = std::move(frames_.front()->defs);
    piece.outer_uses = std::move(outer_uses_);
    piece.outer_tags = std::move(outer_tags_);
    piece.lines = static_cast<uint32_t>(
        std::count(text_.begin() + piece.begin, text_.begin() + piece.end, '\n'));
    piece.usable = true;
    const NodeTree& t = tree_;
    // What the main reader must see (DEF names) or what lives outside the nodes stays a tree; so
    // does a piece of a file whose UNIT angle converts the nodes after reading.
    if (!consumer || units_.angle != 1.0 || !piece.defs.empty() || !t.routes.empty() ||
        !t.is_links.empty() || !t.exports.empty() || !t.imports.empty() ||
        !t.inline_roots.empty() || !t.many_fields.empty())
        return;
    if (!consumer->consume(piece.index, t, piece.roots)) return;
    piece.consumed = true;
    piece.nodes = static_cast<uint32_t>(t.nodes.size());
    piece.root_count = static_cast<uint32_t>(piece.roots.size());
    piece.tree = NodeTree{};
}

// The bytes libxml2 holds but has not parsed are white space only (it keeps the white space
// before the next '<' until it sees one).
bool XmlReader::pending_is_blank() const {
    const xmlParserInputPtr in = ctxt_->input;
    if (!in || ctxt_->inputNr != 1) return false;
    for (const xmlChar* p = in->cur; p < in->end; ++p)
        if (!blank(static_cast<char>(*p))) return false;
    return true;
}

// The main reader, having given libxml2 the bytes before a piece: may the piece stand here?
bool XmlReader::at_piece_boundary() const {
    return !stopped_ && !recording_ && scenes_ == 1 && scene_end_ == prefix_end_ &&
           stack_.back().role == Role::Scene && frames_.size() == 1 &&
           frames_.front()->protos->protos.empty() && ctxt_->instate == XML_PARSER_CONTENT &&
           pending_is_blank();
}

void XmlReader::take_pieces(PieceScheduler& pieces, size_t& pos) {
    while (next_piece_ < pieces.size()) {
        const uint32_t begin = static_cast<uint32_t>(pieces.begin(next_piece_));
        if (begin > pos) return;
        if (begin < pos || !at_piece_boundary()) {
            drop_piece(pieces);  // cut inside an element, or after a prototype
            continue;
        }
        Piece& piece = pieces.get(next_piece_++);
        const size_t nodes = piece.consumed ? piece.nodes : piece.tree.nodes.size();
        std::vector<NodeId> outer;
        if (!piece.usable || tree_.nodes.size() + consumed_nodes_ + nodes > limits_.max_nodes ||
            !resolve_outer(piece, outer)) {
            if (piece.consumed) consumer_->discard(piece.index);
            return;  // read here: the same messages, the same limit error
        }
        join(piece, outer, pos);
    }
}

void XmlReader::join(Piece& piece, std::vector<NodeId>& outer, size_t& pos) {
    // A node field whose first node is an outer one starts where that node does.
    if (!piece.consumed)
        for (FieldEntry& e : piece.tree.fields)
            if (e.type.kind == ValueKind::Node && !e.loc.valid() && e.count > 0 &&
                is_outer_node(piece.tree.node_refs[e.begin]))
                e.loc = tree_.nodes[outer[piece.tree.node_refs[e.begin] - kFirstOuterNode]].loc;
    const auto begin = static_cast<uint32_t>(piece.begin), end = static_cast<uint32_t>(piece.end);
    const uint32_t lines = piece.lines;
    join_piece(piece, std::move(outer),
               {tree_, roots_, frames_.front()->defs, consumed_, consumed_nodes_, scene_.stats,
                scene_.diagnostics});
    // libxml2 goes on after the piece: what it counts from here on lacks the piece's bytes and
    // lines. The white space it holds still has its line breaks to count.
    const xmlParserInputPtr in = ctxt_->input;
    const Skip before = skips_.empty() ? Skip{} : skips_.back();
    Skip skip;
    skip.stream = uint64_t(begin) - before.bytes;
    skip.bytes = before.bytes + (end - begin);
    skip.stream_line = in->line + static_cast<int>(std::count(in->cur, in->end, '\n'));
    skip.lines = before.lines + static_cast<int>(lines);
    skips_.push_back(skip);
    pos = end;
    scene_.sources.release_before(main_file_, end);
}

void XmlReader::drop_piece(PieceScheduler& pieces) {
    const size_t k = next_piece_++;
    pieces.drop(k);
    if (consumer_) consumer_->discard(k);
}

void XmlReader::not_in_piece(uint32_t file, uint32_t offset) {
    if (piece_content_) fail(file, offset, "needs the rest of the file");
}

NodeId XmlReader::outer_node(Name name, const XmlElement& use) {
    const auto [it, added] =
        outer_index_.try_emplace(name, kFirstOuterNode + static_cast<NodeId>(outer_uses_.size()));
    if (added) {
        if (outer_uses_.size() >= kNullNode - kFirstOuterNode - 1) throw std::bad_alloc();
        outer_uses_.push_back(name);
        outer_tags_.push_back(use.tag);
    } else if (outer_tags_[it->second - kFirstOuterNode] != use.tag) {
        not_in_piece(use);  // USEd as two types: one of them draws a warning
    }
    return it->second;
}

// The nodes a piece's outer USEs name, as the file's DEFs stand where it begins; false if one
// names no DEF (an error there), a skipped node, or a node of another type than its USE element
// (a warning there): the main reader reads the piece itself.
bool XmlReader::resolve_outer(const Piece& piece, std::vector<NodeId>& nodes) const {
    const auto& defs = frames_.front()->defs;
    for (size_t k = 0; k < piece.outer_uses.size(); ++k) {
        const auto it = defs.find(piece.outer_uses[k]);
        if (it == defs.end() || it->second == kNullNode ||
            tree_.type(it->second) != piece.outer_tags[k])
            return false;
        nodes.push_back(it->second);
    }
    return true;
}

void XmlReader::scene_start(const XmlElement& e) {
    // Where the main reader's <Scene> start tag ends, for the pieces' prefix (libxml2 stands at its
    // '>' while it reports the element).
    const uint32_t gt = current_offset();
    scene_end_ = gt < text_.size() && text_[gt] == '>' ? gt + 1 : 0;
    ++scenes_;
    push(make_open(Role::Scene, e));
}

uint32_t XmlReader::file_offset(uint64_t stream) const {
    if (in_piece_)
        return static_cast<uint32_t>(
            stream < piece_stream_ ? stream : piece_begin_ + (stream - piece_stream_));
    if (skips_.empty() || stream < skips_.front().stream) return static_cast<uint32_t>(stream);
    // The last skip at or before `stream` (offsets asked for are nearly always the latest).
    auto it = skips_.back().stream <= stream
                  ? skips_.end() - 1
                  : std::upper_bound(skips_.begin(), skips_.end(), stream,
                                     [](uint64_t s, const Skip& k) { return s < k.stream; }) -
                        1;
    return static_cast<uint32_t>(stream + it->bytes);
}

int XmlReader::file_line(int stream_line) const {
    // A piece reader's line table is in the lines libxml2 counts (build_line_starts).
    if (in_piece_ || skips_.empty() || stream_line < skips_.front().stream_line) return stream_line;
    auto it = std::upper_bound(skips_.begin(), skips_.end(), stream_line,
                               [](int l, const Skip& k) { return l < k.stream_line; }) -
              1;
    return stream_line + it->lines;
}

// libxml2 names lines in some messages ("Opening and ending tag mismatch: Shape line 12 and
// Group"): those of the bytes it was given, which the main reader maps to the file's.
std::string XmlReader::file_lines_in(std::string message) const {
    if (skips_.empty()) return message;
    std::string out;
    size_t p = 0;
    for (size_t at = message.find(" line "); at != std::string::npos;
         at = message.find(" line ", at + 1)) {
        size_t q = at + 6, line = 0;
        while (q < message.size() && q < at + 15 &&
               std::isdigit(static_cast<unsigned char>(message[q])))
            line = line * 10 + static_cast<size_t>(message[q++] - '0');
        if (q == at + 6 || q == at + 15) continue;
        out.append(message, p, at + 6 - p);
        out += std::to_string(file_line(static_cast<int>(line)));
        p = q;
    }
    out.append(message, p, std::string::npos);
    return out;
}

// Where each line starts: the file's for the main reader; a piece reader's stream is its prefix, a
// line break and the piece, so its table holds the prefix's lines, then the piece's.
void XmlReader::build_line_starts() {
    line_starts_.push_back(0);
    const size_t prefix = in_piece_ ? prefix_end_ : text_.size();
    for (size_t i = 0; i < prefix; ++i)
        if (text_[i] == '\n') line_starts_.push_back(static_cast<uint32_t>(i + 1));
    if (!in_piece_) return;
    line_starts_.push_back(piece_begin_);
    for (size_t i = piece_begin_; i < piece_end_; ++i)
        if (text_[i] == '\n') line_starts_.push_back(static_cast<uint32_t>(i + 1));
}

}  // namespace vr::x3d_xml_detail
