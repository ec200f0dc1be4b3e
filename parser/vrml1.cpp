// Reading a VRML 1.0 file as written: node types from grammar/vrml1.nodes, values by the shared
// value parser, plus what VRML 1.0 adds to the classic syntax: children inside a node's braces
// after its fields, bare-word SFEnum/SFBitMask values (`parts (SIDES | TOP)`), unquoted SFString
// words, SFBool 0/1, and the `fields [ SFFloat a, ... ]` declaration of non-standard nodes.
#include "parser/vrml1.h"

#include <unordered_map>
#include <unordered_set>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/vrml1_internal.h"

namespace vr {
namespace vrml1 {

bool is_enum_field(const FieldDecl& field) {
    if (field.type.kind != ValueKind::String || field.type.multi || field.range.empty())
        return false;
    for (char c : field.range)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '|')) return false;
    return true;
}

std::string_view vrml97_counterpart(std::string_view t) {
    static const std::unordered_map<std::string_view, std::string_view> table = {
        {"Cube", "Box"},
        {"Coordinate3", "Coordinate"},
        {"Texture2", "ImageTexture"},
        {"Texture2Transform", "TextureTransform"},
        {"TextureCoordinate2", "TextureCoordinate"},
        {"WWWInline", "Inline"},
        {"WWWAnchor", "Anchor"},
        {"PerspectiveCamera", "Viewpoint"},
        {"OrthographicCamera", "OrthoViewpoint"},
        {"AsciiText", "Text"},
        {"Separator", "Group"},
        {"TransformSeparator", "Group"},
    };
    auto it = table.find(t);
    if (it != table.end()) return it->second;
    return t;  // same name in both (Material, Sphere, lights, IndexedFaceSet, ...)
}

namespace {

// VRML 1.0 nodes that take children inside their braces.
bool is_group(std::string_view type) {
    return type == "Separator" || type == "Group" || type == "Switch" ||
           type == "TransformSeparator" || type == "LOD" || type == "WWWAnchor";
}

// A field of a non-standard node, declared by `fields [ ... ]`.
struct DeclaredField {
    Name name = kNoName;
    FieldType type;
    bool words = false;  // SFEnum or SFBitMask: bare words, kept as text
};

class Reader {
  public:
    Reader(LoadedScene& scene, uint32_t file, const LoadLimits& limits, V1File& out)
        : scene_(scene),
          tree_(scene.tree),
          registry_(Registry::builtin()),
          limits_(limits),
          file_(file),
          lexer_(scene.sources.file(file).text),
          out_(out) {}

    bool run() {
        out_.file = file_;
        check_header();
        try {
            while (lexer_.peek().kind != TokenKind::End) {
                uint32_t id = statement(0);
                if (id != kNone) out_.roots.push_back(id);
            }
        } catch (const SyntaxError& e) {
            scene_.diagnostics.error({file_, e.offset}, e.message);
            return false;
        }
        return true;
    }

  private:
    // ---- tokens ---------------------------------------------------------------------------------

    [[noreturn]] void fail(const Token& t, std::string message) {
        throw SyntaxError{t.offset, std::move(message)};
    }

    std::string describe(const Token& t) { return lexer_.describe(t); }

    std::string_view expect_word(const char* what) {
        Token t = lexer_.next();
        if (t.kind != TokenKind::Word)
            fail(t, std::string("expected ") + what + ", found " + describe(t));
        return lexer_.text(t);
    }

    void expect(TokenKind kind, const char* what) {
        Token t = lexer_.next();
        if (t.kind != kind) fail(t, std::string("expected ") + what + ", found " + describe(t));
    }

    // The token after the next one.
    Token peek_second() {
        Lexer copy = lexer_;
        copy.next();
        return copy.peek();
    }

    void warn(SourceOffset offset, std::string message, const std::string& cause) {
        scene_.diagnostics.warning({file_, offset}, std::move(message), cause);
    }

    void check_header() {
        const std::string_view text = scene_.sources.file(file_).text;
        size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
        size_t end = text.find_first_of("\r\n", start);
        std::string_view line = std::string_view(text).substr(
            start, end == std::string::npos ? std::string::npos : end - start);
        std::string_view rest = line.size() > 10 ? line.substr(10) : std::string_view();
        while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t'))
            rest.remove_prefix(1);
        if (rest.substr(0, 5) != "ascii")
            warn(start, "header should say 'ascii' after the version: '" + std::string(line) + "'",
                 "header-ascii");
    }

    // ---- nodes ----------------------------------------------------------------------------------

    // DEF name node | USE name | node. Returns the node, or kNone for a node that was skipped.
    uint32_t statement(size_t depth) {
        Token t = lexer_.next();
        if (t.kind != TokenKind::Word) fail(t, "expected a node, found " + describe(t));
        std::string_view w = lexer_.text(t);
        if (w == "DEF") {
            Name def = intern(expect_word("a name after DEF"));
            Token type = lexer_.next();
            if (type.kind != TokenKind::Word)
                fail(type, "expected a node type after DEF " + std::string(name_text(def)) +
                               ", found " + describe(type));
            uint32_t id = node(type, depth);
            if (id != kNone && out_.nodes[id].def_name == kNoName) {
                out_.nodes[id].def_name = def;
                if (out_.nodes[id].vrml97 != kNullNode)
                    tree_.nodes[out_.nodes[id].vrml97].def_name = def;
            }
            // Registered after the node is complete: a node cannot USE itself, so the file is a
            // DAG.
            defs_[def] = id;
            ++scene_.stats.def_count;
            return id;
        }
        if (w == "USE") {
            Token nt = lexer_.next();
            if (nt.kind != TokenKind::Word)
                fail(nt, "expected a name after USE, found " + describe(nt));
            auto it = defs_.find(intern(lexer_.text(nt)));
            if (it == defs_.end())
                fail(nt,
                     "USE of '" + std::string(lexer_.text(nt)) + "', which no DEF before it names");
            ++scene_.stats.use_count;
            if (it->second != kNone) out_.nodes[it->second].shared = true;
            return it->second;
        }
        return node(t, depth);
    }

    uint32_t node(const Token& type_token, size_t depth) {
        if (depth > limits_.max_nesting_depth)
            fail(type_token, "nodes nested deeper than " +
                                 std::to_string(limits_.max_nesting_depth) + " (limit)");
        std::string_view type = lexer_.text(type_token);
        Name type_name = intern(type);
        const NodeTypeDecl* decl = registry_.find(Spec::Vrml1, type_name);
        if (!decl) {
            if (const NodeTypeDecl* d97 = registry_.lookup(Spec::Vrml97, type_name)) {
                NodeId id = vrml97_node(type_token, *d97, depth);
                V1Node n;
                n.type = type_name;
                n.loc = {file_, type_token.offset};
                n.vrml97 = id;
                return add(n, scratch_fields_.size(), scratch_children_.size(), type_token);
            }
            return unknown_node(type_token, depth);
        }
        Token open = lexer_.next();
        if (open.kind != TokenKind::LBrace)
            fail(open, "expected '{' after node type '" + std::string(type) + "', found " +
                           describe(open));
        const size_t field_mark = scratch_fields_.size();
        const size_t child_mark = scratch_children_.size();
        const bool group = is_group(type);
        for (;;) {
            Token t = lexer_.peek();
            if (t.kind == TokenKind::RBrace) {
                lexer_.next();
                break;
            }
            if (t.kind == TokenKind::End)
                fail(type_token,
                     std::string(type) + " is not closed: the file ends before its '}'");
            if (t.kind != TokenKind::Word)
                fail(t, "expected a field name, a child node or '}' in " + std::string(type) +
                            ", found " + describe(t));
            std::string_view w = lexer_.text(t);
            if (w == "fields" && peek_second().kind == TokenKind::LBracket) {
                lexer_.next();
                declarations();  // a standard node needs none; its fields are read by its own
                                 // interface
                continue;
            }
            const FieldDecl* field = find_field(*decl, type, intern(w));
            if (field) {
                lexer_.next();
                if (field->extension)
                    warn(t.offset,
                         "non-standard field '" + std::string(w) + "' of " + std::string(type) +
                             " (a browser extension) read and ignored",
                         "extension-field:" + std::string(type) + "." + std::string(w));
                FieldEntry entry;
                entry.name = field->name;
                if (value(field->type, is_enum_field(*field) ? field : nullptr, entry))
                    push_field(entry, field_mark);
                continue;
            }
            if (w == "DEF" || w == "USE" || peek_second().kind == TokenKind::LBrace) {
                if (!group)
                    fail(t, std::string(type) + " takes no child nodes, found " + describe(t) +
                                " (is a '}' missing before it?)");
                uint32_t child = statement(depth + 1);
                if (child != kNone) scratch_children_.push_back(child);
                continue;
            }
            fail(t, "unknown field '" + std::string(w) + "' in node " + std::string(type));
        }
        V1Node n;
        n.decl = decl;
        n.type = type_name;
        n.loc = {file_, type_token.offset};
        return add(n, field_mark, child_mark, type_token);
    }

    // A field of the node's VRML 1.0 interface, or a browser extension of it or of its VRML97
    // counterpart.
    const FieldDecl* find_field(const NodeTypeDecl& decl, std::string_view type, Name name) {
        if (const FieldDecl* f = registry_.lookup_field(Spec::Vrml1, decl, name)) return f;
        std::string_view counterpart = vrml97_counterpart(type);
        if (counterpart != type)
            if (const NodeTypeDecl* e = registry_.find(Spec::Extension, counterpart))
                return e->find(name);
        return nullptr;
    }

    // A later value of the same field replaces the earlier one.
    void push_field(const FieldEntry& entry, size_t mark) {
        for (size_t i = mark; i < scratch_fields_.size(); ++i) {
            if (scratch_fields_[i].name == entry.name) {
                scratch_fields_[i] = entry;
                return;
            }
        }
        scratch_fields_.push_back(entry);
    }

    uint32_t add(V1Node n, size_t field_mark, size_t child_mark, const Token& at) {
        if (out_.nodes.size() + tree_.nodes.size() >= limits_.max_nodes)
            fail(at, "more than " + std::to_string(limits_.max_nodes) + " nodes (limit)");
        n.first_field = static_cast<uint32_t>(out_.fields.size());
        n.field_count = static_cast<uint32_t>(scratch_fields_.size() - field_mark);
        out_.fields.insert(out_.fields.end(),
                           scratch_fields_.begin() + static_cast<ptrdiff_t>(field_mark),
                           scratch_fields_.end());
        scratch_fields_.resize(field_mark);
        n.first_child = static_cast<uint32_t>(out_.children.size());
        n.child_count = static_cast<uint32_t>(scratch_children_.size() - child_mark);
        out_.children.insert(out_.children.end(),
                             scratch_children_.begin() + static_cast<ptrdiff_t>(child_mark),
                             scratch_children_.end());
        scratch_children_.resize(child_mark);
        out_.nodes.push_back(n);
        return static_cast<uint32_t>(out_.nodes.size() - 1);
    }

    // ---- values ---------------------------------------------------------------------------------

    // Reads one field value into the tree's pools. `enum_decl`: the field is an SFEnum/SFBitMask
    // whose words are checked against its range. Returns false when the value is not kept (unknown
    // enum word).
    bool value(FieldType type, const FieldDecl* enum_decl, FieldEntry& entry) {
        entry.type = type;
        entry.loc = {file_, lexer_.peek().offset};
        if (type.kind == ValueKind::String && !type.multi && enum_decl)
            return enum_value(enum_decl, entry);
        if (type.kind == ValueKind::String) {
            string_value(type.multi, entry);
            return true;
        }
        if (type.kind == ValueKind::Bool && !type.multi) {
            Token t = lexer_.next();
            std::string_view w = t.kind == TokenKind::Word ? lexer_.text(t) : std::string_view();
            double v;
            if (w == "TRUE" || w == "true" || w == "1") {
                v = 1.0;
            } else if (w == "FALSE" || w == "false" || w == "0") {
                v = 0.0;
            } else {
                fail(t, "expected TRUE or FALSE, found " + describe(t));
            }
            entry.begin = static_cast<uint32_t>(tree_.numbers.size());
            entry.count = 1;
            tree_.numbers.push_back(v);
            return true;
        }
        if (type.kind == ValueKind::Node) fail(lexer_.peek(), "VRML 1.0 has no node-valued fields");
        ValueContext ctx{tree_, lexer_, &scene_.diagnostics, file_, limits_.max_mf_values};
        read_field_value(ctx, type, entry);
        return true;
    }

    // SFString/MFString: quoted strings, or (VRML 1.0) single words without white space.
    void string_value(bool multi, FieldEntry& entry) {
        entry.begin = static_cast<uint32_t>(tree_.strings.size());
        auto one = [&](const Token& t) {
            if (t.kind == TokenKind::String) {
                tree_.strings.push_back(Lexer::unescape(lexer_.text(t)));
            } else if (t.kind == TokenKind::Word) {
                tree_.strings.emplace_back(lexer_.text(t));
            } else if (t.kind == TokenKind::BadString) {
                fail(t, "string is not closed before the end of the file");
            } else {
                fail(t, "expected a string, found " + describe(t));
            }
        };
        Token first = lexer_.next();
        if (multi && first.kind == TokenKind::LBracket) {
            for (;;) {
                Token t = lexer_.next();
                if (t.kind == TokenKind::RBracket) break;
                if (t.kind == TokenKind::End)
                    fail(first, "'[' is not closed before the end of the file");
                one(t);
                if (tree_.strings.size() - entry.begin > limits_.max_mf_values)
                    fail(first, "field holds more than " + std::to_string(limits_.max_mf_values) +
                                    " values (limit)");
            }
        } else {
            one(first);
        }
        entry.count = static_cast<uint32_t>(tree_.strings.size() - entry.begin);
    }

    // SFEnum `WORD`, SFBitMask `WORD` or `(A | B)`; kept as "A|B". Unknown words: warning, default
    // kept.
    bool enum_value(const FieldDecl* decl, FieldEntry& entry) {
        std::string words = read_words();
        std::string_view allowed = decl->range;
        std::string kept;
        size_t start = 0;
        while (start <= words.size()) {
            size_t bar = words.find('|', start);
            std::string_view w = std::string_view(words).substr(
                start, bar == std::string::npos ? std::string::npos : bar - start);
            start = bar == std::string::npos ? words.size() + 1 : bar + 1;
            if (w.empty()) continue;
            bool known = false;
            for (size_t p = 0; p <= allowed.size();) {
                size_t q = allowed.find('|', p);
                if (allowed.substr(
                        p, q == std::string_view::npos ? std::string_view::npos : q - p) == w)
                    known = true;
                p = q == std::string_view::npos ? allowed.size() + 1 : q + 1;
            }
            if (!known) {
                warn(entry.loc.get().offset,
                     "'" + std::string(w) + "' is not a value of " +
                         std::string(name_text(decl->name)) + " (" + decl->range +
                         "); the default is used",
                     "vrml1-enum:" + std::string(name_text(decl->name)) + ":" + std::string(w));
                return false;
            }
            if (!kept.empty()) kept += '|';
            kept += w;
        }
        if (kept.empty()) {
            warn(entry.loc.get().offset,
                 "empty value for " + std::string(name_text(decl->name)) + "; the default is used",
                 "vrml1-enum-empty");
            return false;
        }
        entry.begin = static_cast<uint32_t>(tree_.strings.size());
        entry.count = 1;
        tree_.strings.push_back(std::move(kept));
        return true;
    }

    // The text of an enum or bit mask value without parentheses and blanks: "SIDES|TOP".
    std::string read_words() {
        Token t = lexer_.next();
        if (t.kind == TokenKind::String) return Lexer::unescape(lexer_.text(t));
        if (t.kind != TokenKind::Word) fail(t, "expected a value word, found " + describe(t));
        std::string text(lexer_.text(t));
        if (text.front() == '(') {
            for (int n = 0; text.back() != ')'; ++n) {
                Token more = lexer_.next();
                if (more.kind != TokenKind::Word || n > 64)
                    fail(t, "'(' of a bit mask value is not closed by ')'");
                text += lexer_.text(more);
            }
            text = text.substr(1, text.size() - 2);
        }
        return text;
    }

    // `fields [ SFFloat a, MFString isA ]` (the '[' is next).
    std::vector<DeclaredField> declarations() {
        expect(TokenKind::LBracket, "'[' after fields");
        std::vector<DeclaredField> out;
        for (;;) {
            Token t = lexer_.next();
            if (t.kind == TokenKind::RBracket) break;
            if (t.kind != TokenKind::Word)
                fail(t, "expected a field type or ']' in fields [...], found " + describe(t));
            std::string_view type = lexer_.text(t);
            DeclaredField d;
            if (type == "SFLong" || type == "MFLong") {
                d.type = {ValueKind::Int32, type[0] == 'M'};
            } else if (type == "SFMatrix") {
                d.type = {ValueKind::Matrix4f, false};
            } else if (type == "SFEnum" || type == "SFBitMask") {
                d.type = {ValueKind::String, false};
                d.words = true;
            } else if (auto parsed = parse_type_name(type)) {
                d.type = *parsed;
            } else {
                fail(t, "unknown field type '" + std::string(type) + "' in fields [...]");
            }
            d.name = intern(expect_word("a field name"));
            out.push_back(d);
        }
        return out;
    }

    // A node type VRML 1.0 does not define: its declared fields and its children are read (so that
    // DEFs inside stay usable), and the node is skipped with a warning, unless `isA` names a
    // standard node type.
    uint32_t unknown_node(const Token& type_token, size_t depth) {
        std::string type(lexer_.text(type_token));
        Token open = lexer_.next();
        if (open.kind != TokenKind::LBrace)
            fail(open, "expected '{' after node type '" + type + "', found " + describe(open));
        const size_t field_mark = scratch_fields_.size();
        const size_t child_mark = scratch_children_.size();
        std::vector<DeclaredField> declared;
        std::vector<std::string> is_a;
        for (;;) {
            Token t = lexer_.peek();
            if (t.kind == TokenKind::RBrace) {
                lexer_.next();
                break;
            }
            if (t.kind == TokenKind::End)
                fail(type_token, type + " is not closed: the file ends before its '}'");
            if (t.kind != TokenKind::Word) {
                skip_rest(open);
                break;
            }
            std::string_view w = lexer_.text(t);
            if (w == "fields" && peek_second().kind == TokenKind::LBracket) {
                lexer_.next();
                declared = declarations();
                continue;
            }
            Name name = intern(w);
            const DeclaredField* d = nullptr;
            for (const DeclaredField& f : declared)
                if (f.name == name) d = &f;
            if (d) {
                lexer_.next();
                FieldEntry entry;
                entry.name = name;
                if (d->words) {
                    entry.type = d->type;
                    entry.loc = {file_, lexer_.peek().offset};
                    entry.begin = static_cast<uint32_t>(tree_.strings.size());
                    entry.count = 1;
                    tree_.strings.push_back(read_words());
                } else {
                    value(d->type, nullptr, entry);
                }
                if (w == "isA" && entry.type.kind == ValueKind::String)
                    is_a.assign(tree_.strings.begin() + entry.begin,
                                tree_.strings.begin() + entry.begin + entry.count);
                push_field(entry, field_mark);
                continue;
            }
            if (w == "DEF" || w == "USE" || peek_second().kind == TokenKind::LBrace) {
                uint32_t child = statement(depth + 1);
                if (child != kNone) scratch_children_.push_back(child);
                continue;
            }
            // A field nobody declared: its type is unknown, so the rest of the node cannot be read.
            skip_rest(open);
            break;
        }
        for (const std::string& base : is_a) {
            const NodeTypeDecl* decl = registry_.find(Spec::Vrml1, base);
            if (!decl) continue;
            warn(type_token.offset,
                 "non-standard node type '" + type + "' read as its isA type '" + base + "'",
                 "vrml1-isa:" + type);
            // Keep the fields the standard type has with the same type; drop children of
            // non-groups.
            size_t keep = field_mark;
            for (size_t i = field_mark; i < scratch_fields_.size(); ++i) {
                const FieldDecl* f = decl->find(scratch_fields_[i].name);
                if (f && f->type == scratch_fields_[i].type)
                    scratch_fields_[keep++] = scratch_fields_[i];
            }
            scratch_fields_.resize(keep);
            if (!is_group(base)) scratch_children_.resize(child_mark);
            V1Node n;
            n.decl = decl;
            n.type = decl->name;
            n.loc = {file_, type_token.offset};
            return add(n, field_mark, child_mark, type_token);
        }
        scratch_fields_.resize(field_mark);
        scratch_children_.resize(child_mark);
        warn(type_token.offset, "unknown node type '" + type + "' skipped", "unknown-node:" + type);
        ++scene_.stats.skipped_nodes[type];
        return kNone;
    }

    // Skips to the '}' that closes the group opened by `open` (already read).
    void skip_rest(const Token& open) {
        size_t depth = 1;
        while (depth > 0) {
            Token t = lexer_.next();
            switch (t.kind) {
                case TokenKind::LBrace:
                case TokenKind::LBracket:
                    ++depth;
                    break;
                case TokenKind::RBrace:
                case TokenKind::RBracket:
                    --depth;
                    break;
                case TokenKind::End:
                    fail(open, "this node is not closed before the end of the file");
                case TokenKind::BadString:
                    fail(t, "string is not closed before the end of the file");
                default:
                    break;
            }
        }
    }

    // ---- VRML97 nodes in a VRML 1.0 file ----

    // Some browsers accept VRML97 nodes (NavigationInfo, Background, ...) in VRML 1.0 files. They
    // are read with their VRML97 interface and syntax and placed in the upgraded tree as they are.
    NodeId vrml97_node(const Token& type_token, const NodeTypeDecl& decl, size_t depth) {
        if (depth > limits_.max_nesting_depth)
            fail(type_token, "nodes nested deeper than " +
                                 std::to_string(limits_.max_nesting_depth) + " (limit)");
        std::string type(lexer_.text(type_token));
        warn(type_token.offset,
             "VRML97 node '" + type + "' in a VRML 1.0 file (a browser extension) read as VRML97",
             "vrml1-vrml97-node:" + type);
        expect(TokenKind::LBrace, "'{' after the node type");
        std::vector<FieldEntry> fields;
        for (;;) {
            Token t = lexer_.next();
            if (t.kind == TokenKind::RBrace) break;
            if (t.kind == TokenKind::End)
                fail(type_token, type + " is not closed: the file ends before its '}'");
            if (t.kind != TokenKind::Word)
                fail(t, "expected a field name or '}' in " + type + ", found " + describe(t));
            std::string_view w = lexer_.text(t);
            const FieldDecl* field = registry_.lookup_field(Spec::Vrml97, decl, intern(w));
            if (!field) fail(t, "unknown field '" + std::string(w) + "' in node " + type);
            if (!has_value(field->access))
                fail(t, "'" + std::string(w) + "' is an event of " + type +
                            " and takes no value here");
            if (field->extension)
                warn(t.offset,
                     "non-standard field '" + std::string(w) + "' of " + type +
                         " (a browser extension) read and ignored",
                     "extension-field:" + type + "." + std::string(w));
            FieldEntry entry;
            entry.name = field->name;
            if (field->type.kind == ValueKind::Node) {
                vrml97_nodes(field->type.multi, entry, depth);
            } else {
                ValueContext ctx{tree_, lexer_, &scene_.diagnostics, file_, limits_.max_mf_values};
                read_field_value(ctx, field->type, entry);
            }
            bool replaced = false;
            for (FieldEntry& e : fields)
                if (e.name == entry.name) {
                    e = entry;
                    replaced = true;
                }
            if (!replaced) fields.push_back(entry);
        }
        if (tree_.nodes.size() + out_.nodes.size() >= limits_.max_nodes)
            fail(type_token, "more than " + std::to_string(limits_.max_nodes) + " nodes (limit)");
        Node n;
        n.kind = tree_.kind_of(&decl, decl.name);
        n.loc = {file_, type_token.offset};
        n.first_field = static_cast<uint32_t>(tree_.fields.size());
        const uint32_t field_count = static_cast<uint32_t>(fields.size());
        tree_.fields.insert(tree_.fields.end(), fields.begin(), fields.end());
        tree_.add_node(n, field_count);
        return static_cast<NodeId>(tree_.nodes.size() - 1);
    }

    // SFNode/MFNode value of a VRML97 node: NULL, a node, or [ nodes ].
    void vrml97_nodes(bool multi, FieldEntry& entry, size_t depth) {
        entry.type = {ValueKind::Node, multi};
        Token first = lexer_.peek();
        entry.loc = {file_, first.offset};
        std::vector<NodeId> ids;
        auto one = [&] {
            Token t = lexer_.next();
            if (t.kind != TokenKind::Word) fail(t, "expected a node, found " + describe(t));
            std::string_view w = lexer_.text(t);
            if (w == "NULL") return;
            Name def = kNoName;
            if (w == "USE") {
                Name name = intern(expect_word("a name after USE"));
                auto it = defs97_.find(name);
                if (it == defs97_.end())
                    fail(t, "USE of '" + std::string(name_text(name)) +
                                "', which no VRML97 node DEF before it names");
                ids.push_back(it->second);
                return;
            }
            if (w == "DEF") {
                def = intern(expect_word("a name after DEF"));
                t = lexer_.next();
                if (t.kind != TokenKind::Word)
                    fail(t, "expected a node type, found " + describe(t));
            }
            const NodeTypeDecl* d = registry_.lookup(Spec::Vrml97, intern(lexer_.text(t)));
            if (!d) {
                std::string type(lexer_.text(t));
                Token open = lexer_.next();
                if (open.kind != TokenKind::LBrace)
                    fail(open, "expected '{' after node type '" + type + "'");
                skip_rest(open);
                warn(t.offset, "unknown node type '" + type + "' skipped", "unknown-node:" + type);
                ++scene_.stats.skipped_nodes[type];
                return;
            }
            NodeId id = vrml97_node(t, *d, depth + 1);
            if (def != kNoName) {
                tree_.nodes[id].def_name = def;
                defs97_[def] = id;
            }
            ids.push_back(id);
        };
        if (multi && first.kind == TokenKind::LBracket) {
            lexer_.next();
            while (lexer_.peek().kind != TokenKind::RBracket) {
                if (lexer_.peek().kind == TokenKind::End)
                    fail(first, "'[' is not closed before the end of the file");
                one();
            }
            lexer_.next();
        } else {
            one();
        }
        if (!multi && ids.empty()) ids.push_back(kNullNode);
        entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
        entry.count = static_cast<uint32_t>(ids.size());
        tree_.node_refs.insert(tree_.node_refs.end(), ids.begin(), ids.end());
    }

    LoadedScene& scene_;
    NodeTree& tree_;
    const Registry& registry_;
    const LoadLimits& limits_;
    uint32_t file_;
    Lexer lexer_;
    V1File& out_;
    std::unordered_map<Name, uint32_t> defs_;  // VRML 1.0 DEF names (the latest DEF of a name wins)
    std::unordered_map<Name, NodeId> defs97_;  // DEF names inside VRML97 nodes
    std::vector<FieldEntry> scratch_fields_;   // fields of the nodes being read, innermost last
    std::vector<uint32_t> scratch_children_;   // children of the nodes being read, innermost last
};

}  // namespace

bool read_file(LoadedScene& scene, uint32_t file, const LoadLimits& limits, V1File& out) {
    Reader reader(scene, file, limits, out);
    return reader.run();
}

}  // namespace vrml1

ClassicResult read_vrml1(LoadedScene& scene, uint32_t file, const LoadLimits& limits) {
    ClassicResult result;
    result.protos = std::make_shared<ProtoScope>();
    vrml1::V1File v1;
    if (!vrml1::read_file(scene, file, limits, v1)) {
        result.ok = false;
        return result;
    }
    if (!vrml1::upgrade(scene, v1, limits, result.roots)) {
        result.ok = false;
        result.roots.clear();
    }
    return result;
}

}  // namespace vr
