#include "parser/registry.h"

#include <stdexcept>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/node_tree.h"

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

}  // namespace

Registry::Registry(const std::vector<GrammarText>& texts)
    : defaults_(std::make_unique<NodeTree>()) {
    for (const GrammarText& g : texts) {
        Spec spec = spec_of_file(g.file);
        auto& table = tables_[static_cast<int>(spec)];
        auto& index = index_[static_cast<int>(spec)];
        std::string_view text = g.text;
        size_t line_no = 0;
        NodeTypeDecl* current = nullptr;
        auto bad = [&](const std::string& why) {
            throw std::runtime_error(g.file + ":" + std::to_string(line_no) + ": " + why);
        };
        while (!text.empty()) {
            ++line_no;
            size_t nl = text.find('\n');
            std::string_view raw = text.substr(0, nl);
            text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
            std::string_view line = trim(strip_comment(raw));
            if (line.empty()) continue;
            if (!current) {
                // "Name {" (possibly "Name : Base {")
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
                Name n = intern(name);
                if (index.count(n)) bad("node " + std::string(name) + " defined twice");
                index.emplace(n, static_cast<uint32_t>(table.size()));
                table.push_back({n, spec, role, {}});
                current = &table.back();
                continue;
            }
            if (line == "}") {
                current = nullptr;
                continue;
            }
            std::string_view rest = line;
            std::string_view w1 = next_word(rest);
            std::string_view w2 = next_word(rest);
            FieldDecl decl;
            decl.extension = spec == Spec::Extension;
            if (auto t = parse_type_name(w1)) {  // X3D order: type access name
                auto a = parse_access(w2);
                if (!a) bad("unknown access '" + std::string(w2) + "'");
                decl.type = *t;
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
            if (current->find(decl.name)) bad("field " + std::string(fname) + " listed twice");
            rest = trim(rest);
            if (has_value(decl.access)) {
                // Text views into `rest` stay valid: g.text outlives this loop.
                Lexer lexer(rest);
                ValueContext ctx{*defaults_, lexer};
                FieldEntry entry;
                entry.name = decl.name;
                try {
                    read_field_value(ctx, decl.type, entry);
                } catch (const SyntaxError& e) {
                    bad("default of " + std::string(fname) + ": " + e.message);
                }
                entry.loc = {};
                decl.default_field = static_cast<uint32_t>(defaults_->fields.size());
                defaults_->fields.push_back(entry);
                decl.range = std::string(
                    trim(rest.substr(std::min<size_t>(lexer.next_offset(), rest.size()))));
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
            current->fields.push_back(std::move(decl));
        }
        if (current)
            throw std::runtime_error(g.file + ": node " + std::string(name_text(current->name)) +
                                     " is not closed");
    }
    for (int spec = 0; spec < 5; ++spec) {
        for (const auto& [name, position] : index_[spec]) {
            if (by_name_[spec].size() <= name) by_name_[spec].resize(name + 1, 0);
            by_name_[spec][name] = position + 1;
        }
    }
}

Registry::~Registry() = default;

const Registry& Registry::builtin() {
    static const Registry registry(embedded_grammar());
    return registry;
}

const NodeTypeDecl* Registry::find(Spec spec, Name node) const {
    const auto& index = by_name_[static_cast<int>(spec)];
    const uint32_t position = node < index.size() ? index[node] : 0;
    return position ? &tables_[static_cast<int>(spec)][position - 1] : nullptr;
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
    return tables_[static_cast<int>(spec)];
}

}  // namespace vr
