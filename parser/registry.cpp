#include "parser/registry.h"

#include <stdexcept>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/node_tree.h"
#include "parser/suggest.h"

namespace vr {

const FieldDecl* NodeTypeDecl::find(Name field) const {
    for (const FieldDecl& f : fields)
        if (f.name == field) return &f;
    return nullptr;
}

const FieldDecl* NodeTypeDecl::find(std::string_view field) const { return find(intern(field)); }

namespace {

Spec spec_of_file(const std::string& file) {
    if (file.rfind("vrml97", 0) == 0) return Spec::Vrml97;
    if (file.rfind("vrml1", 0) == 0) return Spec::Vrml1;
    if (file.rfind("x3d", 0) == 0) return Spec::X3d;
    if (file.rfind("extensions", 0) == 0) return Spec::Extension;
    return Spec::Hint;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

// Removes a '#' comment that is not inside a string.
std::string_view strip_comment(std::string_view line) {
    bool in_string = false;
    for (size_t i = 0; i < line.size(); ++i) {
        char c = line[i];
        if (c == '\\' && in_string) {
            ++i;
        } else if (c == '"') {
            in_string = !in_string;
        } else if (c == '#' && !in_string) {
            return line.substr(0, i);
        }
    }
    return line;
}

std::string_view next_word(std::string_view& rest) {
    rest = trim(rest);
    size_t end = rest.find_first_of(" \t");
    std::string_view w = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end);
    return w;
}

// One line of a table at a time: its number, and its text without comment and outer blanks.
struct Lines {
    std::string_view text;
    size_t number;
    bool next(std::string_view& line, std::string_view& raw) {
        while (!text.empty()) {
            ++number;
            const size_t nl = text.find('\n');
            raw = text.substr(0, nl);
            text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
            line = trim(strip_comment(raw));
            if (!line.empty()) return true;
        }
        return false;
    }
};

}  // namespace

Registry::Registry(const std::vector<GrammarText>& texts) : Registry(texts, Lazy{}) {
    for (int s = 0; s < kSpecs; ++s) nodes(static_cast<Spec>(s));
}

// Only the node headers ("Name {" or "Name : Role {") are read here, and where each node's
// field lines lie; parse_node reads those lines when the node is first asked for.
Registry::Registry(const std::vector<GrammarText>& texts, Lazy) : texts_(texts) {
    for (const GrammarText& g : texts_) {
        const Spec spec = spec_of_file(g.file);
        Table& t = tables_[static_cast<int>(spec)];
        Lines lines{g.text, 0};
        std::string_view line, raw;
        bool open = false;
        auto bad = [&](const std::string& why) {
            throw std::runtime_error(g.file + ":" + std::to_string(lines.number) + ": " + why);
        };
        while (lines.next(line, raw)) {
            if (open) {
                if (line == "}") {
                    t.bodies.back().text =
                        std::string_view(t.bodies.back().text.data(),
                                         size_t(raw.data() - t.bodies.back().text.data()));
                    open = false;
                }
                continue;
            }
            if (line.back() != '{') bad("expected 'NodeName {'");
            std::string_view rest = line.substr(0, line.size() - 1);
            std::string_view name = next_word(rest);
            if (name.empty()) bad("node without a name");
            Name role = kNoName;  // "Name : Role {": what vrmlray does with the node
            if (std::string_view colon = next_word(rest); colon == ":") {
                const std::string_view r = next_word(rest);
                if (r.empty()) bad("node " + std::string(name) + ": ':' without a role");
                role = intern(r);
            } else if (!colon.empty()) {
                bad("expected 'NodeName {' or 'NodeName : Role {'");
            }
            const Name n = intern(name);
            if (t.by_name.size() <= n) t.by_name.resize(n + 1, 0);
            if (t.by_name[n] != 0) bad("node " + std::string(name) + " defined twice");
            t.decls.push_back({n, spec, role, {}});
            t.by_name[n] = static_cast<uint32_t>(t.decls.size());  // 1 + position
            t.bodies.push_back({lines.text, &g, lines.number});
            open = true;
        }
        if (open)
            throw std::runtime_error(g.file + ": node " +
                                     std::string(name_text(t.decls.back().name)) +
                                     " is not closed");
    }
    for (int s = 0; s < kSpecs; ++s) {
        Table& t = tables_[s];
        t.parsed = std::make_unique<std::atomic<bool>[]>(t.decls.size());
        t.defaults.resize(t.decls.size());
    }
}

void Registry::parse_node(Spec spec, uint32_t position) const {
    std::lock_guard<std::mutex> lock(parse_mutex_);
    Table& t = tables_[static_cast<int>(spec)];
    if (t.parsed[position].load(std::memory_order_relaxed)) return;
    NodeTypeDecl& node = t.decls[position];
    const NodeBody& body = t.bodies[position];
    // Defaults of their own: the trees of nodes parsed earlier are being read by other threads.
    // The node changes only once all its lines are read: after a throw it is as before.
    auto defaults = std::make_unique<NodeTree>();
    NodeTypeDecl parsed{node.name, node.spec, node.role, {}};
    Lines lines{body.text, body.first_line};
    std::string_view line, raw;
    auto bad = [&](const std::string& why) {
        throw std::runtime_error(body.grammar->file + ":" + std::to_string(lines.number) + ": " +
                                 why);
    };
    while (lines.next(line, raw)) {
        std::string_view rest = line;
        std::string_view w1 = next_word(rest);
        std::string_view w2 = next_word(rest);
        FieldDecl decl;
        decl.extension = spec == Spec::Extension;
        if (auto type = parse_type_name(w1)) {  // X3D order: type access name
            auto a = parse_access(w2);
            if (!a) bad("unknown access '" + std::string(w2) + "'");
            decl.type = *type;
            decl.access = *a;
        } else {  // VRML97 order: access type name
            auto a = parse_access(w1);
            auto t2 = parse_type_name(w2);
            if (!a || !t2) bad("expected 'access type name' or 'type access name'");
            decl.type = *t2;
            decl.access = *a;
        }
        std::string_view fname = next_word(rest);
        if (fname.empty()) bad("field without a name");
        decl.name = intern(fname);
        if (parsed.find(decl.name)) bad("field " + std::string(fname) + " listed twice");
        rest = trim(rest);
        if (has_value(decl.access)) {
            // Text views into `rest` stay valid: texts_ lives as long as the registry.
            Lexer lexer(rest);
            ValueContext ctx{*defaults, lexer};
            FieldEntry entry;
            entry.name = decl.name;
            try {
                read_field_value(ctx, decl.type, entry);
            } catch (const SyntaxError& e) {
                bad("default of " + std::string(fname) + ": " + e.message);
            }
            entry.loc = {};
            decl.default_field = static_cast<uint32_t>(defaults->fields.size());
            decl.default_tree = defaults.get();
            defaults->fields.push_back(entry);
            decl.range =
                std::string(trim(rest.substr(std::min<size_t>(lexer.next_offset(), rest.size()))));
        } else {
            decl.range = std::string(rest);
        }
        if (is_numeric(decl.type.kind) && decl.type.kind != ValueKind::Bool &&
            decl.type.kind != ValueKind::Image) {
            std::string error;
            auto range = parse_numeric_range(decl.range, error);
            if (!range) bad("field " + std::string(fname) + ": " + error);
            decl.numeric_range = std::move(*range);
        }
        parsed.fields.push_back(std::move(decl));
    }
    node.fields = std::move(parsed.fields);
    t.defaults[position] = std::move(defaults);
    t.parsed[position].store(true, std::memory_order_release);
}

Registry::~Registry() = default;

const Registry& Registry::builtin() {
    static const Registry registry(embedded_grammar(), Lazy{});
    return registry;
}

const NodeTypeDecl* Registry::find(Spec spec, Name node) const {
    const Table& t = tables_[static_cast<int>(spec)];
    const uint32_t position = node < t.by_name.size() ? t.by_name[node] : 0;
    if (position == 0) return nullptr;
    if (!t.parsed[position - 1].load(std::memory_order_acquire)) parse_node(spec, position - 1);
    return &t.decls[position - 1];
}

const NodeTypeDecl* Registry::find(Spec spec, std::string_view node) const {
    return find(spec, intern(node));
}

const NodeTypeDecl* Registry::lookup(Spec encoding, Name node) const {
    if (const NodeTypeDecl* d = find(encoding, node)) return d;
    if (encoding == Spec::Vrml97) {
        if (const NodeTypeDecl* d = find(Spec::X3d, node)) return d;
    } else if (encoding == Spec::X3d) {
        if (const NodeTypeDecl* d = find(Spec::Vrml97, node)) return d;
    }
    return find(Spec::Hint, node);
}

std::vector<std::string> field_names(const NodeTypeDecl& decl) {
    std::vector<std::string> names;
    for (const FieldDecl& f : decl.fields) names.emplace_back(name_text(f.name));
    return names;
}

std::string Registry::nearest_node(Spec encoding, std::string_view node) const {
    std::vector<std::string> names;
    for (Spec spec : {encoding, encoding == Spec::Vrml97 ? Spec::X3d : Spec::Vrml97, Spec::Hint})
        for (const NodeTypeDecl& d : tables_[int(spec)].decls)
            names.emplace_back(name_text(d.name));
    return nearest_name(node, names);
}

const FieldDecl* Registry::lookup_field(Spec encoding, const NodeTypeDecl& decl, Name field) const {
    if (const FieldDecl* f = decl.find(field)) return f;
    const FieldDecl* other = nullptr;
    if (decl.spec == Spec::Vrml97) {
        if (const NodeTypeDecl* x = find(Spec::X3d, decl.name)) other = x->find(field);
    } else if (decl.spec == Spec::X3d) {
        if (const NodeTypeDecl* v = find(Spec::Vrml97, decl.name)) other = v->find(field);
    }
    if (other) return other;
    if (const NodeTypeDecl* e = find(Spec::Extension, decl.name)) return e->find(field);
    return nullptr;
}

const std::vector<NodeTypeDecl>& Registry::nodes(Spec spec) const {
    const Table& t = tables_[static_cast<int>(spec)];
    for (uint32_t i = 0; i < t.decls.size(); ++i)
        if (!t.parsed[i].load(std::memory_order_acquire)) parse_node(spec, i);
    return t.decls;
}

}  // namespace vr
