#include "parser/classic.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <unordered_set>

#include "parser/classic_pieces.h"
#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/skip_value.h"
#include "parser/suggest.h"

namespace vr {
namespace {

// Nodes whose interface is partly declared in the file itself (Script and the X3D shader nodes).
bool has_dynamic_interface(std::string_view type) {
    return type == "Script" || type == "ComposedShader" || type == "PackagedShader" ||
           type == "ShaderProgram";
}

// One stream of tokens being read: the file itself, or the body of a PROTO being expanded.
struct Frame {
    Lexer lexer;
    uint32_t file;
    std::unordered_map<Name, NodeId> defs;  // DEF names of this scope (file, or one PROTO instance)
    // PROTO interface defaults may USE what the enclosing scope DEFined, but their own DEFs stay
    // theirs.
    const std::unordered_map<Name, NodeId>* outer_defs = nullptr;
    std::shared_ptr<ProtoScope> protos;
    const std::unordered_map<Name, FieldEntry>* is_values = nullptr;  // inside a PROTO body
    const ProtoDecl* proto = nullptr;
    size_t proto_depth = 0;
    bool whole_file =
        false;  // reads its file from the start: the pages behind it may be given back
};

// Where a reader puts what it reads: a scene, or one piece of a file read on another thread.
struct Target {
    const SourceManager& sources;
    Diagnostics& diagnostics;
    NodeTree& tree;
    ReadStats& stats;
};

class Reader {
  public:
    Reader(Target scene, Spec spec, const LoadLimits& limits, const ExternProtoResolver& resolver)
        : scene_(scene),
          tree_(scene.tree),
          registry_(Registry::builtin()),
          spec_(spec),
          limits_(limits),
          resolver_(resolver) {}

    void set_consumer(PieceConsumer* consumer) { consumer_ = consumer; }

    ClassicResult read_file(uint32_t file) {
        ClassicResult result;
        error_file_ = file;
        const std::string_view text = scene_.sources.file(file).text;
        // A UTF-8 byte-order mark before the header is no token (the header is a comment).
        const SourceOffset bom = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;
        Frame frame{
            Lexer(text, bom, text.size()), file, {}, nullptr, std::make_shared<ProtoScope>()};
        frame.whole_file = true;
        result.protos = frame.protos;
        std::vector<Piece> planned = plan_pieces(text);
        if (consumer_) {
            std::vector<PieceText> texts;
            for (const Piece& p : planned) texts.push_back(piece_text(file, p));
            consumer_->plan(texts);
        }
        PieceScheduler pieces(
            std::move(planned), [this, file](Piece& p) { read_piece(file, p); },
            piece_workers(limits_.read_threads));
        try {
            for (;;) {
                take_pieces(frame, pieces, result.roots);
                if (frame.lexer.peek().kind == TokenKind::End) break;
                NodeId id = statement(frame, 0);
                if (id != kNullNode) result.roots.push_back(id);
            }
        } catch (const SyntaxError& e) {
            scene_.diagnostics.error({error_file_, e.offset}, e.message);
            result.ok = false;
        }
        pieces.stop();
        result.units = units_;
        result.consumed = std::move(consumed_);
        // The last few megabytes release_before kept (it frees in steps) would stay resident
        // through the scene build, the peak of a large scene's memory.
        scene_.sources.release_all(file);
        return result;
    }

  private:
    // ---- tokens ------------------------------------------------------------------------------

    [[noreturn]] void fail(Frame& f, const Token& t, std::string message) {
        error_file_ = f.file;
        throw SyntaxError{t.offset, std::move(message)};
    }

    std::string describe(Frame& f, const Token& t) { return f.lexer.describe(t); }

    Token expect(Frame& f, TokenKind kind, const char* what) {
        Token t = f.lexer.next();
        if (t.kind != kind)
            fail(f, t, std::string("expected ") + what + ", found " + describe(f, t));
        return t;
    }

    std::string_view expect_word(Frame& f, const char* what) {
        Token t = f.lexer.next();
        if (t.kind != TokenKind::Word)
            fail(f, t, std::string("expected ") + what + ", found " + describe(f, t));
        return f.lexer.text(t);
    }

    bool peek_word(Frame& f, std::string_view word) {
        const Token& t = f.lexer.peek();
        return t.kind == TokenKind::Word && f.lexer.text(t) == word;
    }

    void warn(Frame& f, SourceOffset offset, std::string message, const std::string& cause) {
        scene_.diagnostics.warning({f.file, offset}, std::move(message), cause);
    }

    // COMPONENT name:level. The statement only declares what the file uses (the nodes are read
    // whatever it says), but a level no X3D component has (1 to 5 in X3D 3.0-4.0) means the file is
    // not what it claims.
    void component_level(Frame& f, const Token& name, std::string_view text) {
        const size_t colon = text.rfind(':');
        if (colon == std::string_view::npos) return;  // no level: level 1
        const std::string_view digits = text.substr(colon + 1);
        int level = 0;
        const bool number =
            !digits.empty() && digits.size() <= 3 &&
            std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
        if (number) level = std::stoi(std::string(digits));
        if (!number || level < 1 || level > 5)
            warn(f, name.offset,
                 "COMPONENT " + std::string(f.lexer.text(name)) +
                     ": no X3D component has that level (levels run from 1 to 5); the nodes are "
                     "read anyway",
                 "component level");
    }

    // COMPONENT name:level, where the classic grammar lets white space stand on either side of the
    // colon (`Core:1`, `Core :1`, `Core: 1`, `Core : 1`); the lexer makes words of the pieces.
    void component_statement(Frame& f) {
        f.lexer.next();
        const Token name = expect(f, TokenKind::Word, "a component name");
        std::string level(f.lexer.text(name));
        auto next_word_starts = [&](char c) {
            return f.lexer.peek().kind == TokenKind::Word &&
                   f.lexer.text(f.lexer.peek()).front() == c;
        };
        if (level.find(':') == std::string::npos && next_word_starts(':'))
            level += f.lexer.text(f.lexer.next());  // "name :level" or "name : level"
        if (level.back() == ':' && f.lexer.peek().kind == TokenKind::Word) {
            const std::string_view digits = f.lexer.text(f.lexer.peek());
            if (std::isdigit(static_cast<unsigned char>(digits.front())))
                level += f.lexer.text(f.lexer.next());  // "name: level"
        }
        component_level(f, name, level);
    }

    // UNIT category name conversionFactor. Read by the main reader only: the units belong to the
    // whole file (parser/units.h).
    void unit_statement(Frame& f) {
        not_in_piece(f);
        const Token keyword = f.lexer.next();
        const std::string_view category = expect_word(f, "a unit category (length, angle, ...)");
        expect_word(f, "a unit name");
        const std::string_view factor = expect_word(f, "a conversion factor");
        if (f.proto_depth > 0 || !f.whole_file) return;  // a PROTO body's UNIT: not the file's
        const std::string why = add_unit(units_, category, factor, {f.file, keyword.offset});
        if (!why.empty()) warn(f, keyword.offset, why, "unit:" + why);
        if (units_.angle != 1.0) angle_unit_ = true;  // pieces read from now on stay trees
    }

    // Runs a skipper of parser/skip_value.h on this frame: its syntax errors are this file's.
    void skip(Frame& f, void (*skipper)(Lexer&)) {
        try {
            skipper(f.lexer);
        } catch (const SyntaxError&) {
            error_file_ = f.file;
            throw;
        }
    }

    // A field name that a node does not have, at `t` (already read): a warning that names the
    // node and the field, and its value skipped, so the rest of the node reads as browsers read it.
    // `known`: the fields it has, for a "did you mean".
    void unknown_field(Frame& f, const Token& t, std::string_view type, const char* what,
                       const std::vector<std::string>& known) {
        const std::string name(f.lexer.text(t));
        warn(f, t.offset,
             "unknown field '" + name + "' in " + what + " " + std::string(type) +
                 "; skipped with its value" + did_you_mean(nearest_name(name, known)),
             "unknown-field:" + std::string(type) + "." + name);
        skip(f, skip_unknown_value);
    }

    // ---- statements ---------------------------------------------------------------------------

    // A statement at file or body level; returns the node it makes, or kNullNode.
    NodeId statement(Frame& f, size_t depth) {
        const Token t = f.lexer.peek();
        if (t.kind != TokenKind::Word)
            fail(f, t, "expected a node or statement, found " + describe(f, t));
        std::string_view w = f.lexer.text(t);
        if (w == "PROTO") {
            proto_declaration(f);
            return kNullNode;
        }
        if (w == "EXTERNPROTO") {
            externproto_declaration(f);
            return kNullNode;
        }
        if (w == "ROUTE") {
            route(f);
            return kNullNode;
        }
        {
            // X3D classic statements; accepted in .wrl files too, where they never occur.
            if (w == "PROFILE") {
                f.lexer.next();
                expect_word(f, "a profile name");
                return kNullNode;
            }
            if (w == "UNIT") {
                unit_statement(f);
                return kNullNode;
            }
            if (w == "COMPONENT") {
                component_statement(f);
                return kNullNode;
            }
            if (w == "META") {
                f.lexer.next();
                expect(f, TokenKind::String, "a META name string");
                expect(f, TokenKind::String, "a META value string");
                return kNullNode;
            }
            if (w == "IMPORT" || w == "EXPORT") {
                import_export(f, w == "IMPORT");
                return kNullNode;
            }
        }
        return node_statement(f, depth);
    }

    void route(Frame& f) {
        not_in_piece(f);
        const Token keyword = f.lexer.next();
        const Token from = expect(f, TokenKind::Word, "the source of a ROUTE (node.event)");
        std::string_view to = expect_word(f, "TO");
        if (to != "TO") fail(f, f.lexer.peek(), "expected TO in ROUTE");
        const Token dest = expect(f, TokenKind::Word, "the destination of a ROUTE (node.event)");
        ++scene_.stats.routes;
        Route r;
        r.loc = {f.file, keyword.offset};
        if (!route_end(f, from, r.from, r.from_event, r.from_import) ||
            !route_end(f, dest, r.to, r.to_event, r.to_import))
            return;
        tree_.routes.push_back(r);
    }

    // IMPORT inlineDEF.exportedDEF [AS name] | EXPORT localDEF [AS name] (X3D 4.4.6).
    void import_export(Frame& f, bool import) {
        not_in_piece(f);
        const Token keyword = f.lexer.next();
        const Token what =
            expect(f, TokenKind::Word,
                   import ? "inlineDEF.exportedDEF after IMPORT" : "a DEF name to export");
        std::string_view text = f.lexer.text(what), exported;
        if (import) {
            const size_t dot = text.find('.');
            if (dot == std::string_view::npos || dot == 0 || dot + 1 == text.size())
                fail(f, what,
                     "expected inlineDEF.exportedDEF after IMPORT, found " + describe(f, what));
            exported = text.substr(dot + 1);
            text = text.substr(0, dot);
        }
        std::string_view as = import ? exported : text;
        if (peek_word(f, "AS")) {
            f.lexer.next();
            as = expect_word(f, "a name after AS");
        }
        auto it = f.defs.find(intern(text));
        if (it == f.defs.end()) {  // as a ROUTE naming no DEF: dropped, with a warning
            warn(f, what.offset,
                 std::string(import ? "IMPORT" : "EXPORT") + " names '" + std::string(text) +
                     "', which no DEF before it names; ignored",
                 import ? "import-unknown-def" : "export-unknown-def");
            return;
        }
        if (import) {
            if (it->second != kNullNode && tree_.type_name(it->second) != "Inline")
                fail(f, what,
                     "IMPORT names '" + std::string(text) + "', a " +
                         std::string(tree_.type_name(it->second)) + ", not an Inline");
            imported_[intern(as)] = uint32_t(tree_.imports.size());
            tree_.imports.push_back(
                {it->second, intern(exported), intern(as), PackedLoc(f.file, keyword.offset)});
        } else {
            tree_.exports.push_back({f.file, intern(as), it->second});
        }
    }

    // "NODE.event" of a ROUTE: the node its DEF name has in this scope. A name no DEF before the
    // ROUTE gives is a warning (the ROUTE is dropped), as browsers take it.
    bool route_end(Frame& f, const Token& t, NodeId& node, Name& event, uint32_t& import) {
        const std::string_view text = f.lexer.text(t);
        const size_t dot = text.rfind('.');
        if (dot == std::string_view::npos || dot == 0 || dot + 1 == text.size())
            fail(f, t, "expected NODE.event in ROUTE, found " + describe(f, t));
        auto it = f.defs.find(intern(text.substr(0, dot)));
        // An IMPORTed name (the file's own scope only: a PROTO body cannot see it).
        if (auto imp = imported_.find(intern(text.substr(0, dot)));
            it == f.defs.end() && !f.is_values && imp != imported_.end()) {
            import = imp->second;
            event = intern(text.substr(dot + 1));
            return true;
        }
        if (it != f.defs.end() && it->second == kNullNode) return false;  // skipped, said so
        if (it == f.defs.end()) {
            warn(f, t.offset,
                 "ROUTE names '" + std::string(text.substr(0, dot)) +
                     "', which no DEF before it names here; the ROUTE is ignored",
                 "route-unknown-node");
            return false;
        }
        node = it->second;
        event = intern(text.substr(dot + 1));
        return true;
    }

    // DEF name node | USE name | node
    NodeId node_statement(Frame& f, size_t depth) {
        Token t = f.lexer.next();
        std::string_view w = f.lexer.text(t);
        if (w == "DEF") {
            std::string_view name = expect_word(f, "a name after DEF");
            Name def = intern(name);
            Token type = f.lexer.next();
            if (type.kind != TokenKind::Word)
                fail(f, type, "expected a node type after DEF " + std::string(name));
            NodeId id = node(f, type, depth);
            if (id != kNullNode) {
                if (tree_.nodes[id].def_name == kNoName) tree_.nodes[id].def_name = def;
                ++scene_.stats.def_count;
            }
            f.defs[def] = id;
            return id;
        }
        if (w == "USE") {
            Token nt = f.lexer.next();
            if (nt.kind != TokenKind::Word) fail(f, nt, "expected a name after USE");
            Name name = intern(f.lexer.text(nt));
            auto it = f.defs.find(name);
            if (it == f.defs.end() && f.outer_defs) {
                auto outer = f.outer_defs->find(name);
                if (outer != f.outer_defs->end()) {
                    ++scene_.stats.use_count;
                    return outer->second;
                }
            }
            if (it == f.defs.end() && outer_uses_ && !f.is_values && !f.outer_defs) {
                // A piece's USE of a DEF before it: the main reader resolves it (take_pieces).
                ++scene_.stats.use_count;
                return outer_node(name);
            }
            if (it == f.defs.end()) {  // as browsers do: the node is left out
                warn(f, nt.offset,
                     "USE of '" + std::string(f.lexer.text(nt)) +
                         "', which no DEF before it names" +
                         (f.is_values ? " in this PROTO body" : "") + "; the node is left out",
                     "use-unknown:" + std::string(f.lexer.text(nt)));
                return kNullNode;
            }
            ++scene_.stats.use_count;
            return it->second;
        }
        if (t.kind != TokenKind::Word) fail(f, t, "expected a node, found " + describe(f, t));
        return node(f, t, depth);
    }

    // ---- nodes --------------------------------------------------------------------------------

    static bool is_statement_word(std::string_view w) {
        return w == "ROUTE" || w == "PROTO" || w == "EXTERNPROTO" || w == "IMPORT" ||
               w == "EXPORT" || w == "UNIT" || w == "COMPONENT" || w == "META" || w == "PROFILE";
    }

    // A word that is no node type with no '{' after it, before what can only start the next node
    // or end the list or node it is in (a "*/" closing a C comment on a line of its own, a
    // leftover name): browsers read on, so the word is skipped with a warning. True when it was.
    bool stray_word(Frame& f, const Token& type_token, std::string_view type) {
        const TokenKind next = f.lexer.peek().kind;
        if (next != TokenKind::Word && next != TokenKind::RBracket && next != TokenKind::RBrace &&
            next != TokenKind::End)
            return false;
        warn(f, type_token.offset,
             "'" + std::string(type) +
                 "' is no node type and no '{' follows it; the word is skipped",
             "stray-word");  // once a file, with a count: a comment's words are many
        return true;
    }

    // A node of a type neither built in nor a PROTO: warned (with the nearest known name) and its
    // body skipped.
    void skip_unknown_node(Frame& f, const Token& type_token, std::string_view type) {
        if (f.lexer.peek().kind != TokenKind::LBrace)
            fail(f, f.lexer.peek(),
                 "expected '{' after node type '" + std::string(type) + "', found " +
                     describe(f, f.lexer.peek()));
        warn(f, type_token.offset,
             "unknown node type '" + std::string(type) + "' skipped" +
                 did_you_mean(registry_.nearest_node(spec_, type)),
             "unknown-node:" + std::string(type));
        ++scene_.stats.skipped_nodes[std::string(type)];
        skip(f, skip_group);
    }

    // A type neither built in nor a PROTO: an unknown node, skipped, or a run of stray words (the
    // lines of a C comment), each skipped, the node after them taking their place (a list or the
    // top level reads a statement such as ROUTE itself). A loop, not recursion: a long comment
    // costs no stack.
    NodeId unknown_node(Frame& f, Token word, size_t depth) {
        for (;;) {
            if (!stray_word(f, word, f.lexer.text(word))) {
                skip_unknown_node(f, word, f.lexer.text(word));
                return kNullNode;
            }
            const Token next = f.lexer.peek();
            if (next.kind != TokenKind::Word) return kNullNode;
            const std::string_view w = f.lexer.text(next);
            if (is_statement_word(w)) return kNullNode;
            const char c0 = w.front();
            if (w == "DEF" || w == "USE" || std::isdigit(static_cast<unsigned char>(c0)) ||
                c0 == '+' || c0 == '-' || c0 == '.')
                return node_statement(f, depth);  // a node, or the error a number is here
            word = f.lexer.next();
            if (f.protos->find(intern(w)) || registry_.lookup(spec_, intern(w)))
                return node(f, word, depth);
        }
    }

    NodeId node(Frame& f, const Token& type_token, size_t depth) {
        {
            // Node type names are identifiers: they never start with a digit, sign or period.
            const char c0 = f.lexer.text(type_token).front();
            if (std::isdigit(static_cast<unsigned char>(c0)) || c0 == '+' || c0 == '-' || c0 == '.')
                fail(f, type_token, "expected a node, found " + describe(f, type_token));
        }
        if (depth > limits_.max_nesting_depth)
            fail(f, type_token,
                 "nodes nested deeper than " + std::to_string(limits_.max_nesting_depth) +
                     " (limit)");
        std::string_view type = f.lexer.text(type_token);
        Name type_name = intern(type);
        if (std::shared_ptr<const ProtoDecl> proto = f.protos->find_owned(type_name))
            return proto_instance(f, type_token, *proto, depth);
        const NodeTypeDecl* decl = registry_.lookup(spec_, type_name);
        if (!decl) return unknown_node(f, type_token, depth);
        const bool dynamic = has_dynamic_interface(type);
        Token open = f.lexer.next();
        if (open.kind != TokenKind::LBrace)
            fail(f, open,
                 "expected '{' after node type '" + std::string(type) + "', found " +
                     describe(f, open));

        const size_t mark = scratch_.size();
        std::vector<ScriptField> dynamic_fields;    // declared in a Script's body
        std::vector<std::pair<Name, Name>> events;  // (field, PROTO field) of `field IS name`
        for (;;) {
            Token t = f.lexer.peek();
            if (t.kind == TokenKind::RBrace) {
                f.lexer.next();
                break;
            }
            if (t.kind != TokenKind::Word)
                fail(f, t,
                     "expected a field name or '}' in " + std::string(type) + ", found " +
                         describe(f, t));
            std::string_view w = f.lexer.text(t);
            if (w == "ROUTE") {
                route(f);
                continue;
            }
            if (w == "PROTO") {
                proto_declaration(f);
                continue;
            }
            if (w == "EXTERNPROTO") {
                externproto_declaration(f);
                continue;
            }
            if (dynamic && parse_access(w) && !peek_is_field(f, decl)) {
                dynamic_fields.push_back(dynamic_field(f, depth, events));
                continue;
            }
            f.lexer.next();
            Name field_name = intern(w);
            const FieldDecl* field = registry_.lookup_field(spec_, *decl, field_name);
            if (!field && dynamic) {
                // A field the Script declared itself, given again: `name IS protoField` or
                // `name value`.
                auto it = std::find_if(dynamic_fields.begin(), dynamic_fields.end(),
                                       [&](const auto& d) { return d.name == field_name; });
                if (it != dynamic_fields.end()) {
                    if (peek_word(f, "IS")) {
                        f.lexer.next();
                        dynamic_is(f, *it, events);
                    } else {
                        field_value(f, it->type, it->value, depth);
                        it->value.name = it->name;
                    }
                    continue;
                }
            }
            if (!field) {
                if (!starts_identifier(w))  // `radius 1 2`: a value too many, no field name
                    fail(f, t,
                         "expected a field name or '}' in " + std::string(type) + ", found " +
                             describe(f, t));
                unknown_field(f, t, type, "node", field_names(*decl));
                continue;
            }
            if (field->extension)
                warn(f, t.offset,
                     "non-standard field '" + std::string(w) + "' of " + std::string(type) +
                         " (a browser extension) read and ignored",
                     "extension-field:" + std::string(type) + "." + std::string(w));
            if (peek_word(f, "IS")) {
                f.lexer.next();
                is_mapping(f, field->name, field->type, field->access, mark, events);
                continue;
            }
            if (!has_value(field->access)) {
                warn(f, t.offset,
                     "'" + std::string(w) + "' is an event of " + std::string(type) +
                         " and takes no value here; the value is skipped",
                     "event-value:" + std::string(type) + "." + std::string(w));
                skip(f, skip_unknown_value);
                continue;
            }
            FieldEntry entry;
            entry.name = field->name;
            field_value(f, field->type, entry, depth);
            push_field(f, mark, entry, t);
        }
        const NodeId id = make_node(f, decl, type_name, type_token, mark);
        for (const auto& [field, proto_field] : events)
            tree_.is_links.push_back({kNullNode, proto_field, id, field});
        if (type == "Script") tree_.scripts[id].fields = std::move(dynamic_fields);
        return id;
    }

    // True when the word at the lexer is an access keyword but also the name of a real field
    // (no such clash exists today; kept so a future field named like a keyword still reads).
    bool peek_is_field(Frame& f, const NodeTypeDecl* decl) {
        return decl->find(f.lexer.text(f.lexer.peek())) != nullptr;
    }

    // Script/shader interface declarations: access type name [value | IS name], kept for a
    // Script (src/script/ runs it).
    ScriptField dynamic_field(Frame& f, size_t depth, std::vector<std::pair<Name, Name>>& events) {
        Token at = f.lexer.next();
        ScriptField field;
        field.access = *parse_access(f.lexer.text(at));
        Token type_token = f.lexer.next();
        auto type = type_token.kind == TokenKind::Word ? parse_type_name(f.lexer.text(type_token))
                                                       : std::nullopt;
        if (!type) fail(f, type_token, "expected a field type, found " + describe(f, type_token));
        field.type = *type;
        field.name = intern(expect_word(f, "a field name"));
        field.value.type = *type;
        field.value.name = field.name;
        field.value.loc = {f.file, at.offset};
        if (peek_word(f, "IS")) {
            f.lexer.next();
            dynamic_is(f, field, events);
        } else if (has_value(field.access)) {
            field_value(f, *type, field.value, depth);
            field.value.name = field.name;
        }
        return field;
    }

    // `IS protoField` of a Script's own field: the instance's value, and its events.
    void dynamic_is(Frame& f, ScriptField& field, std::vector<std::pair<Name, Name>>& events) {
        Token t = f.lexer.peek();
        const Name proto_field = intern(expect_word(f, "a PROTO field name after IS"));
        if (!f.is_values || !f.proto) fail(f, t, "IS may only be used inside a PROTO body");
        const ProtoField* pf = f.proto->find(proto_field);
        if (!pf || pf->type != field.type) {
            warn(f, t.offset,
                 "IS connects Script field '" + std::string(name_text(field.name)) +
                     "' to PROTO field '" + std::string(name_text(proto_field)) +
                     "', which is not a field of that type; the link is dropped",
                 "is-unknown:" + std::string(name_text(proto_field)));
            return;
        }
        if (field.access != Access::Field) events.emplace_back(field.name, proto_field);
        auto it = f.is_values->find(proto_field);
        if (!has_value(field.access) || it == f.is_values->end()) return;
        field.value = it->second;
        field.value.name = field.name;
    }

    void push_field(Frame& f, size_t mark, const FieldEntry& entry, const Token& at) {
        for (size_t i = mark; i < scratch_.size(); ++i) {
            if (scratch_[i].name == entry.name) {
                warn(f, at.offset,
                     "field '" + std::string(name_text(entry.name)) +
                         "' given twice; the last value is used",
                     "duplicate-field");
                scratch_[i] = entry;
                return;
            }
        }
        scratch_.push_back(entry);
    }

    NodeId make_node(Frame& f, const NodeTypeDecl* decl, Name type_name, const Token& at,
                     size_t mark) {
        // Ids from kFirstOuterNode on stand for a piece's outer USEs: the limit stays below them.
        const size_t limit = std::min<size_t>(limits_.max_nodes, kFirstOuterNode);
        if (tree_.nodes.size() + consumed_nodes_ >= limit)
            fail(f, at, "more than " + std::to_string(limit) + " nodes (limit)");
        Node n;
        n.kind = tree_.kind_of(decl, type_name);
        n.loc = {f.file, at.offset};
        n.first_field = static_cast<uint32_t>(tree_.fields.size());
        const uint32_t field_count = static_cast<uint32_t>(scratch_.size() - mark);
        tree_.fields.insert(tree_.fields.end(), scratch_.begin() + static_cast<ptrdiff_t>(mark),
                            scratch_.end());
        scratch_.resize(mark);
        tree_.add_node(n, field_count);
        if (f.whole_file) scene_.sources.release_before(f.file, f.lexer.position());
        return static_cast<NodeId>(tree_.nodes.size() - 1);
    }

    // A field value of any type, including node values.
    void field_value(Frame& f, FieldType type, FieldEntry& entry, size_t depth) {
        if (type.kind != ValueKind::Node) {
            ValueContext ctx{tree_, f.lexer, &scene_.diagnostics, f.file, limits_.max_mf_values};
            try {
                read_field_value(ctx, type, entry);
            } catch (const SyntaxError&) {
                error_file_ = f.file;
                throw;
            }
            return;
        }
        entry.type = type;
        Token first = f.lexer.peek();
        entry.loc = {f.file, first.offset};
        // Node values collect on a stack shared by all levels (no allocation per field): nested
        // fields push above this mark and are gone again before control returns here.
        const size_t mark = node_scratch_.size();
        struct Ids {
            std::vector<NodeId>& v;
            size_t mark;
            void push_back(NodeId id) { v.push_back(id); }
            size_t size() const { return v.size() - mark; }
        } ids{node_scratch_, mark};
        if (!type.multi) {
            if (peek_word(f, "NULL")) {
                f.lexer.next();
                ids.push_back(kNullNode);
            } else {
                if (first.kind != TokenKind::Word)
                    fail(f, first, "expected a node or NULL, found " + describe(f, first));
                ids.push_back(node_statement(f, depth + 1));
            }
        } else if (first.kind == TokenKind::LBracket) {
            f.lexer.next();
            for (;;) {
                Token t = f.lexer.peek();
                if (t.kind == TokenKind::RBracket) {
                    f.lexer.next();
                    break;
                }
                if (t.kind == TokenKind::End)
                    fail(f, first, "'[' is not closed before the end of the file");
                if (t.kind != TokenKind::Word)
                    fail(f, t, "expected a node or ']', found " + describe(f, t));
                if (f.lexer.text(t) ==
                    "NULL") {  // not valid in MFNode, but written by some exporters
                    f.lexer.next();
                    continue;
                }
                if (f.lexer.text(t) == "ROUTE") {  // some exporters put ROUTEs among children
                    route(f);
                    continue;
                }
                if (f.lexer.text(t) == "PROTO") {
                    proto_declaration(f);
                    continue;
                }
                NodeId id = node_statement(f, depth + 1);
                if (id != kNullNode) ids.push_back(id);
                if (ids.size() > limits_.max_mf_values)
                    fail(f, first, "too many nodes in one field (limit)");
            }
        } else {
            if (first.kind != TokenKind::Word)
                fail(f, first, "expected a node or '[', found " + describe(f, first));
            if (!peek_word(f, "NULL")) {
                NodeId id = node_statement(f, depth + 1);
                if (id != kNullNode) ids.push_back(id);
            } else {
                f.lexer.next();
            }
        }
        entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
        tree_.node_refs.insert(tree_.node_refs.end(),
                               node_scratch_.begin() + static_cast<ptrdiff_t>(mark),
                               node_scratch_.end());
        entry.count = static_cast<uint32_t>(node_scratch_.size() - mark);
        node_scratch_.resize(mark);
    }

    // `field IS protoField` inside a PROTO body: the node's field takes the instance's value.
    void is_mapping(Frame& f, Name field, FieldType type, Access access, size_t mark,
                    std::vector<std::pair<Name, Name>>& events) {
        Token t = f.lexer.next();
        if (t.kind != TokenKind::Word) fail(f, t, "expected a PROTO field name after IS");
        if (!f.is_values) fail(f, t, "IS may only be used inside a PROTO body");
        Name proto_field = intern(f.lexer.text(t));
        const ProtoField* pf = f.proto->find(proto_field);
        if (!pf) {
            warn(f, t.offset,
                 "IS names '" + std::string(f.lexer.text(t)) + "', which is not a field of PROTO " +
                     std::string(name_text(f.proto->name)) + "; the link is dropped",
                 "is-unknown:" + std::string(f.lexer.text(t)));
            return;
        }
        if (pf->type != type) {
            warn(f, t.offset,
                 "IS connects a " + std::string(type_name(type)) + " field to PROTO field '" +
                     std::string(name_text(pf->name)) + "' of type " +
                     std::string(type_name(pf->type)) + "; the link is dropped",
                 "is-type:" + std::string(name_text(pf->name)));
            return;
        }
        if (access != Access::Field) events.emplace_back(field, proto_field);
        if (!has_value(access)) return;  // events carry no value at time 0
        auto it = f.is_values->find(proto_field);
        if (it == f.is_values->end()) return;  // PROTO event: the node keeps its default
        FieldEntry entry = it->second;
        entry.name = field;
        push_field(f, mark, entry, t);
    }

    // ---- PROTO --------------------------------------------------------------------------------

    std::vector<ProtoField> interface_declarations(Frame& f, bool external, size_t depth) {
        expect(f, TokenKind::LBracket, "'[' to open the PROTO interface");
        std::vector<ProtoField> fields;
        // Default values are DEF scopes of their own; they may USE the enclosing scope's names.
        std::unordered_map<Name, NodeId> saved;
        saved.swap(f.defs);
        const auto* saved_outer = f.outer_defs;
        f.outer_defs = &saved;
        for (;;) {
            Token t = f.lexer.next();
            if (t.kind == TokenKind::RBracket) break;
            if (t.kind != TokenKind::Word)
                fail(f, t, "expected a field declaration or ']', found " + describe(f, t));
            auto access = parse_access(f.lexer.text(t));
            if (!access)
                fail(f, t,
                     "expected eventIn, eventOut, field or exposedField, found " + describe(f, t));
            Token type_token = f.lexer.next();
            auto type = type_token.kind == TokenKind::Word
                            ? parse_type_name(f.lexer.text(type_token))
                            : std::nullopt;
            if (!type)
                fail(f, type_token, "expected a field type, found " + describe(f, type_token));
            ProtoField pf;
            pf.name = intern(expect_word(f, "a field name"));
            pf.type = *type;
            pf.access = *access;
            if (has_value(*access) && !external) {
                f.defs.clear();  // each default value is a DEF scope of its own
                pf.has_default = true;
                pf.default_value.name = pf.name;
                field_value(f, pf.type, pf.default_value, depth);
            }
            fields.push_back(pf);
        }
        saved.swap(f.defs);
        f.outer_defs = saved_outer;
        return fields;
    }

    void proto_declaration(Frame& f) {
        not_in_piece(f);
        f.lexer.next();  // PROTO
        Token name_token = f.lexer.next();
        if (name_token.kind != TokenKind::Word) fail(f, name_token, "expected a PROTO name");
        auto decl = std::make_shared<ProtoDecl>();
        decl->name = intern(f.lexer.text(name_token));
        decl->spec = spec_;
        decl->fields = interface_declarations(f, false, 0);
        Token open = expect(f, TokenKind::LBrace, "'{' to open the PROTO body");
        decl->file = f.file;
        decl->body_begin = open.offset + 1;
        // Find the matching '}' without building anything: the body is read per instance.
        size_t depth = 1;
        Token t;
        while (depth > 0) {
            t = f.lexer.next();
            if (t.kind == TokenKind::LBrace || t.kind == TokenKind::LBracket) ++depth;
            if (t.kind == TokenKind::RBrace || t.kind == TokenKind::RBracket) --depth;
            if (t.kind == TokenKind::End)
                fail(f, open, "PROTO body is not closed before the end of the file");
            if (t.kind == TokenKind::BadString)
                fail(f, t, "string is not closed before the end of the file");
        }
        decl->body_end = t.offset;
        decl->scope = f.protos;
        if (!f.protos->protos.count(decl->name)) f.protos->order.push_back(decl->name);
        f.protos->protos[decl->name] = decl;
        ++scene_.stats.proto_declarations;
    }

    void externproto_declaration(Frame& f) {
        not_in_piece(f);
        Token kw = f.lexer.next();  // EXTERNPROTO
        Token name_token = f.lexer.next();
        if (name_token.kind != TokenKind::Word) fail(f, name_token, "expected an EXTERNPROTO name");
        auto decl = std::make_shared<ProtoDecl>();
        decl->name = intern(f.lexer.text(name_token));
        decl->spec = spec_;
        decl->external = true;
        decl->fields = interface_declarations(f, true, 0);
        FieldEntry urls;
        ValueContext ctx{tree_, f.lexer, &scene_.diagnostics, f.file, limits_.max_mf_values};
        try {
            read_field_value(ctx, FieldType{ValueKind::String, true}, urls);
        } catch (const SyntaxError&) {
            error_file_ = f.file;
            throw;
        }
        std::vector<std::string> url_list(tree_.strings.begin() + urls.begin,
                                          tree_.strings.begin() + urls.begin + urls.count);
        decl->scope = f.protos;
        if (resolver_)
            decl->implementation = resolver_(url_list, f.file, {f.file, kw.offset}, decl->name);
        if (!f.protos->protos.count(decl->name)) f.protos->order.push_back(decl->name);
        f.protos->protos[decl->name] = decl;
        ++scene_.stats.externproto_declarations;
    }

    NodeId proto_instance(Frame& f, const Token& type_token, const ProtoDecl& proto, size_t depth) {
        expect(f, TokenKind::LBrace, "'{' after PROTO instance type");
        std::unordered_map<Name, FieldEntry> values;
        std::vector<std::pair<Name, Name>> events;  // (field, enclosing PROTO's field) of IS
        instance_values(f, proto, depth, values, events);
        ++scene_.stats.proto_instances;

        const ProtoDecl* impl = &proto;
        if (proto.external) {
            impl = proto.implementation.get();
            if (!impl) {
                warn(f, type_token.offset,
                     "instance of EXTERNPROTO " + std::string(name_text(proto.name)) +
                         " skipped: it was not resolved",
                     "unresolved-externproto:" + std::string(name_text(proto.name)));
                ++scene_.stats.skipped_nodes[std::string(name_text(proto.name))];
                return kNullNode;
            }
        }
        if (impl->builtin) return builtin_instance(f, type_token, *impl->builtin, values);
        std::unordered_map<Name, FieldEntry> bound =
            bind_fields(f, type_token, proto, *impl, values);
        return instance_body(f, type_token, *impl, bound, events, depth);
    }

    // The fields an instance gives, up to its '}': values by name, and the (field, enclosing
    // PROTO's field) pairs of its IS events.
    void instance_values(Frame& f, const ProtoDecl& proto, size_t depth,
                         std::unordered_map<Name, FieldEntry>& values,
                         std::vector<std::pair<Name, Name>>& events) {
        for (;;) {
            Token t = f.lexer.next();
            if (t.kind == TokenKind::RBrace) break;
            if (t.kind != TokenKind::Word)
                fail(f, t,
                     "expected a field name or '}' in " + std::string(name_text(proto.name)) +
                         ", found " + describe(f, t));
            Name field_name = intern(f.lexer.text(t));
            const ProtoField* pf = proto.find(field_name);
            if (!pf) {
                if (!starts_identifier(f.lexer.text(t)))
                    fail(f, t,
                         "expected a field name or '}' in " + std::string(name_text(proto.name)) +
                             ", found " + describe(f, t));
                std::vector<std::string> known;
                for (const ProtoField& p : proto.fields) known.emplace_back(name_text(p.name));
                unknown_field(f, t, name_text(proto.name), "PROTO instance", known);
                continue;
            }
            if (peek_word(f, "IS")) {
                is_link(f, *pf, field_name, values, events);
                continue;
            }
            if (!has_value(pf->access)) {
                warn(f, t.offset,
                     "'" + std::string(f.lexer.text(t)) +
                         "' is an event and takes no value; the value is skipped",
                     "event-value:" + std::string(name_text(proto.name)) + "." +
                         std::string(f.lexer.text(t)));
                skip(f, skip_unknown_value);
                continue;
            }
            FieldEntry entry;
            entry.name = field_name;
            field_value(f, pf->type, entry, depth);
            values[field_name] = entry;
        }
    }

    // `field IS outer` in a PROTO body: the enclosing instance's value of `outer`, if it has one,
    // and for an event field the link; dropped with a warning when `outer` is unknown or of another
    // type.
    void is_link(Frame& f, const ProtoField& field, Name field_name,
                 std::unordered_map<Name, FieldEntry>& values,
                 std::vector<std::pair<Name, Name>>& events) {
        f.lexer.next();
        Token is_name = f.lexer.next();
        if (!f.is_values) fail(f, is_name, "IS may only be used inside a PROTO body");
        Name outer = intern(f.lexer.text(is_name));
        const ProtoField* opf = f.proto->find(outer);
        if (!opf) {
            warn(f, is_name.offset,
                 "IS names a field that PROTO " + std::string(name_text(f.proto->name)) +
                     " does not have; the link is dropped",
                 "is-unknown:" + std::string(f.lexer.text(is_name)));
            return;
        }
        if (opf->type != field.type) {
            warn(f, is_name.offset,
                 "IS connects a " + std::string(type_name(field.type)) + " field to PROTO field '" +
                     std::string(name_text(opf->name)) + "' of type " +
                     std::string(type_name(opf->type)) + "; the link is dropped",
                 "is-type:" + std::string(name_text(opf->name)));
            return;
        }
        if (field.access != Access::Field) events.emplace_back(field_name, outer);
        auto it = f.is_values->find(outer);
        if (it != f.is_values->end()) values[field_name] = it->second;
    }

    // Every field of the implementation gets a value: the instance's, else the PROTO default.
    std::unordered_map<Name, FieldEntry> bind_fields(
        Frame& f, const Token& type_token, const ProtoDecl& proto, const ProtoDecl& impl,
        const std::unordered_map<Name, FieldEntry>& values) {
        std::unordered_map<Name, FieldEntry> bound;
        for (const ProtoField& pf : impl.fields) {
            auto it = values.find(pf.name);
            if (it != values.end() && it->second.type != pf.type) {
                warn(f, type_token.offset,
                     "field '" + std::string(name_text(pf.name)) + "' of EXTERNPROTO " +
                         std::string(name_text(proto.name)) +
                         " has another type in its implementation; its default is used",
                     "externproto-type:" + std::string(name_text(pf.name)));
                it = values.end();
            }
            if (it != values.end()) {
                bound[pf.name] = it->second;
            } else if (pf.has_default) {
                bound[pf.name] = pf.default_value;
            }
        }
        return bound;
    }

    // The implementation's body read with `bound` as its IS values: its first node stands for the
    // instance (kNullNode when it has none), and takes the IS events of the body and `events`.
    NodeId instance_body(Frame& f, const Token& type_token, const ProtoDecl& impl,
                         std::unordered_map<Name, FieldEntry>& bound,
                         const std::vector<std::pair<Name, Name>>& events, size_t depth) {
        if (f.proto_depth + 1 > limits_.max_proto_depth)
            fail(f, type_token,
                 "PROTO instances nested deeper than " + std::to_string(limits_.max_proto_depth) +
                     " (limit; a PROTO that instantiates itself?)");
        const std::string_view text = scene_.sources.file(impl.file).text;
        Frame body{Lexer(text, impl.body_begin, impl.body_end),
                   impl.file,
                   {},
                   nullptr,
                   std::make_shared<ProtoScope>(),
                   &bound,
                   &impl,
                   f.proto_depth + 1};
        body.protos->parent = impl.scope.lock();
        NodeId first = kNullNode;
        bool have_first = false;
        const size_t links_mark = tree_.is_links.size();
        while (body.lexer.peek().kind != TokenKind::End) {
            NodeId id = statement(body, depth + 1);
            if (!have_first && id != kNullNode) {
                first = id;
                have_first = true;
            }
        }
        // This body's IS events belong to this instance, which the first body node stands for;
        // nested instances set theirs before.
        auto& links = tree_.is_links;
        for (size_t i = links_mark; i < links.size(); ++i)
            if (links[i].instance == kNullNode) links[i].instance = first;
        if (first == kNullNode)
            links.erase(
                std::remove_if(links.begin() + static_cast<ptrdiff_t>(links_mark), links.end(),
                               [](const IsLink& l) { return l.instance == kNullNode; }),
                links.end());
        // `field IS outer` on this instance: the enclosing instance's events reach this one.
        if (first != kNullNode)
            for (const auto& [field, outer] : events)
                links.push_back({kNullNode, outer, first, field});
        return first;
    }

    // An EXTERNPROTO that names a built-in node: the instance is that node with the fields it was
    // given.
    NodeId builtin_instance(Frame& f, const Token& at, const NodeTypeDecl& decl,
                            const std::unordered_map<Name, FieldEntry>& values) {
        const size_t mark = scratch_.size();
        for (const auto& [name, entry] : values) {
            const FieldDecl* field = decl.find(name);
            if (!field || field->type != entry.type || !has_value(field->access)) {
                warn(f, at.offset,
                     "field '" + std::string(name_text(name)) + "' does not match built-in node " +
                         std::string(name_text(decl.name)) + "; ignored",
                     "builtin-proto-field:" + std::string(name_text(name)));
                continue;
            }
            scratch_.push_back(entry);
        }
        return make_node(f, &decl, decl.name, at, mark);
    }

    // ---- pieces (classic_pieces.h) -----------------------------------------------------------

    std::vector<Piece> plan_pieces(std::string_view text) const {
        std::vector<Piece> pieces;
        const std::vector<SourceOffset> starts =
            piece_starts(text, 0, limits_.piece_bytes > 0 ? limits_.piece_bytes : piece_bytes(),
                         limits_.head_bytes);
        for (size_t k = 0; k < starts.size(); ++k) {
            pieces.emplace_back();
            pieces.back().index = static_cast<uint32_t>(k);
            pieces.back().begin = starts[k];
            pieces.back().end = k + 1 < starts.size() ? starts[k + 1] : SourceOffset(text.size());
        }
        return pieces;
    }

    // At the file's top level, between statements: appends every piece that starts here, the one
    // after it if that starts where it ends, and so on; drops the pieces the main reader has
    // passed.
    void take_pieces(Frame& f, PieceScheduler& pieces, std::vector<NodeId>& roots) {
        while (next_piece_ < pieces.size()) {
            const SourceOffset begin = pieces.begin(next_piece_);
            // With a token peeked, where the last statement ended is not known: read on.
            if (f.lexer.has_peek() && f.lexer.peek().offset < begin) return;
            if (f.lexer.has_peek() || f.lexer.position() > begin || !f.protos->protos.empty()) {
                drop_piece(pieces);  // began inside a statement, or after a PROTO
                continue;
            }
            if (f.lexer.peek().offset < begin) return;  // the next statement starts before it
            Piece& piece = pieces.get(next_piece_++);
            const size_t nodes = piece.consumed ? piece.nodes : piece.tree.nodes.size();
            // A UNIT angle converts the file's nodes after reading: a consumed piece would miss it.
            const bool units_apply = piece.consumed && units_.angle != 1.0;
            if (!piece.usable || units_apply ||
                tree_.nodes.size() + consumed_nodes_ + nodes > limits_.max_nodes) {
                if (piece.consumed) consumer_->discard(piece.index);
                return;  // read here: the same messages, the same limit error
            }
            std::vector<NodeId> outer;
            if (!resolve_outer(f, piece.outer_uses, outer)) {
                if (piece.consumed) consumer_->discard(piece.index);
                return;  // read here: the same error message
            }
            const SourceOffset end = piece.end;
            join_piece(piece, std::move(outer),
                       {tree_, roots, f.defs, consumed_, consumed_nodes_, scene_.stats,
                        scene_.diagnostics});
            f.lexer = Lexer(f.lexer.source(), end, f.lexer.source_end());
            // The pages of a mapped file the workers read stay resident until given back, and the
            // main reader, jumping from piece to piece, makes no node that would give them back.
            if (f.whole_file) scene_.sources.release_before(f.file, end);
        }
    }

    // The nodes a piece's outer USEs name, as the file's DEFs stand where the piece begins; false
    // if one names no DEF (a single-thread read reports it there).
    static bool resolve_outer(const Frame& f, const std::vector<Name>& names,
                              std::vector<NodeId>& nodes) {
        for (Name name : names) {
            const auto it = f.defs.find(name);
            if (it == f.defs.end()) return false;
            nodes.push_back(it->second);
        }
        return true;
    }

    // A piece's reference to the node an earlier DEF names (piece_consumer.h).
    NodeId outer_node(Name name) {
        const auto [it, added] = outer_index_.try_emplace(
            name, kFirstOuterNode + static_cast<NodeId>(outer_uses_->size()));
        if (added) {
            if (outer_uses_->size() >= kNullNode - kFirstOuterNode - 1) throw std::bad_alloc();
            outer_uses_->push_back(name);
        }
        return it->second;
    }

    // A piece the main reader has passed: what a consumer built of it goes too.
    void drop_piece(PieceScheduler& pieces) {
        const size_t k = next_piece_++;
        pieces.drop(k);
        if (consumer_) consumer_->discard(k);
    }

    // Reads one piece on its own, as the file's top level; any failure only makes it unusable.
    void read_piece(uint32_t file, Piece& piece) {
        // The tree of the last piece this thread read and a consumer took, emptied: its memory
        // serves the next piece.
        static thread_local NodeTree spare;
        if (consume_text(file, piece)) return;  // no tree: the spare waits for the next piece
        if (spare.nodes.capacity() > 0) {
            piece.tree = std::move(spare);
            spare = NodeTree{};
        }
        Reader reader(Target{scene_.sources, piece.diagnostics, piece.tree, piece.stats}, spec_,
                      limits_, resolver_);
        reader.in_piece_ = true;
        reader.outer_uses_ = &piece.outer_uses;
        Frame frame{Lexer(scene_.sources.file(file).text, piece.begin, piece.end),
                    file,
                    {},
                    nullptr,
                    std::make_shared<ProtoScope>()};
        try {
            while (frame.lexer.peek().kind != TokenKind::End) {
                NodeId id = reader.statement(frame, 0);
                if (id != kNullNode) piece.roots.push_back(id);
            }
        } catch (const SyntaxError&) {
            return;
        }
        piece.defs = std::move(frame.defs);
        piece.usable = piece.diagnostics.error_count() == 0;
        const NodeTree& t = piece.tree;
        // What the main reader must see (DEF names) or what lives outside the nodes stays a tree.
        if (!consumer_ || angle_unit_ || !piece.usable || !piece.defs.empty() ||
            !t.routes.empty() || !t.is_links.empty() || !t.exports.empty() || !t.imports.empty() ||
            !t.inline_roots.empty() || !t.many_fields.empty())
            return;
        if (!consumer_->consume(piece.index, t, piece.roots)) return;
        piece.consumed = true;
        piece.nodes = static_cast<uint32_t>(t.nodes.size());
        piece.root_count = static_cast<uint32_t>(piece.roots.size());
        piece.tree.clear_keeping_memory();
        spare = std::move(piece.tree);
        piece.tree = NodeTree{};
    }

    // A piece's text and the limits a consumer reads it with.
    PieceText piece_text(uint32_t file, const Piece& piece) const {
        return PieceText{scene_.sources.file(file).text,
                         file,
                         piece.begin,
                         piece.end,
                         spec_,
                         std::min<size_t>(limits_.max_nodes, kFirstOuterNode),
                         limits_.max_nesting_depth,
                         limits_.max_mf_values};
    }

    // A piece the consumer read from its text with no node tree (piece_consumer.h): usable as a
    // tree read without a message would be.
    bool consume_text(uint32_t file, Piece& piece) {
        if (!consumer_ || angle_unit_) return false;
        std::optional<TextConsumed> took =
            consumer_->consume_text(piece.index, piece_text(file, piece));
        if (!took) return false;
        piece.usable = piece.consumed = true;
        piece.nodes = took->nodes;
        piece.root_count = took->roots;
        piece.stats.use_count = took->uses;
        piece.outer_uses = std::move(took->outer_uses);
        return true;
    }

    // A piece read on its own cannot see the PROTOs and DEFs of the file before it, nor may it
    // resolve EXTERNPROTOs on its thread: the main reader reads such a piece itself.
    void not_in_piece(Frame& f) {
        if (in_piece_) fail(f, f.lexer.peek(), "needs the rest of the file");
    }

    Target scene_;
    bool in_piece_ = false;
    PieceConsumer* consumer_ = nullptr;  // the main file's, if any (never a piece reader's own)
    std::vector<Name>* outer_uses_ = nullptr;       // a piece reader's: names USEd from before it
    std::unordered_map<Name, NodeId> outer_index_;  // and the outer node each stands as
    std::vector<ConsumedPiece> consumed_;           // pieces it took, in file order
    size_t consumed_nodes_ = 0;                     // their nodes, counted against the node limit
    // The main reader has read a UNIT angle: the workers stop consuming (a header's UNIT is read
    // long before a worker ends its first piece; a later one makes take_pieces discard instead).
    std::atomic<bool> angle_unit_{false};
    FileUnits units_;        // the file's UNIT statements so far
    size_t next_piece_ = 0;  // the first piece not yet taken or dropped
    NodeTree& tree_;
    const Registry& registry_;
    Spec spec_;
    const LoadLimits& limits_;
    const ExternProtoResolver& resolver_;
    std::vector<FieldEntry> scratch_;   // fields of the nodes being read, innermost last
    std::vector<NodeId> node_scratch_;  // node values of the fields being read, innermost last
    uint32_t error_file_ = 0;
    std::unordered_map<Name, uint32_t> imported_;  // IMPORT AS names -> tree.imports
};

}  // namespace

ClassicResult read_classic(LoadedScene& scene, uint32_t file, Spec spec, const LoadLimits& limits,
                           const ExternProtoResolver& resolve_externproto,
                           PieceConsumer* consumer) {
    Reader reader(Target{scene.sources, scene.diagnostics, scene.tree, scene.stats}, spec, limits,
                  resolve_externproto);
    reader.set_consumer(consumer);
    return reader.read_file(file);
}

}  // namespace vr
