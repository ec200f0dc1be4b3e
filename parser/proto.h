// PROTO and EXTERNPROTO declarations as the classic reader keeps them. An instance is expanded by
// reading the body's tokens again with the instance's field values bound to the IS names.
#pragma once
#include <memory>
#include <unordered_map>
#include <vector>

#include "parser/field_type.h"
#include "parser/name.h"
#include "parser/node_tree.h"
#include "parser/registry.h"

namespace vr {

struct ProtoField {
    Name name = kNoName;
    FieldType type;
    Access access = Access::Field;
    bool has_default = false;
    FieldEntry default_value;  // values live in the tree's pools
};

struct ProtoScope;

struct ProtoDecl {
    Name name = kNoName;
    std::vector<ProtoField> fields;
    Spec spec = Spec::Vrml97;
    uint32_t file = 0;            // source file of the body
    SourceOffset body_begin = 0;  // byte range of the body, inside its braces
    SourceOffset body_end = 0;
    // Where the PROTO was declared: bodies see the PROTOs before it. Weak, because that scope owns
    // this declaration; whoever reads the body (the file being read, or the EXTERNPROTO file cache)
    // keeps it alive.
    std::weak_ptr<ProtoScope> scope;
    // EXTERNPROTO: the PROTO it resolved to, or null when it could not be resolved.
    bool external = false;
    std::shared_ptr<const ProtoDecl> implementation;
    // An EXTERNPROTO whose URL is a built-in node's URN (urn:web3d:vrml97:node:Shape): that node
    // type.
    const NodeTypeDecl* builtin = nullptr;

    const ProtoField* find(Name field) const {
        for (const ProtoField& f : fields)
            if (f.name == field) return &f;
        return nullptr;
    }
};

struct ProtoScope {
    std::shared_ptr<ProtoScope> parent;
    std::unordered_map<Name, std::shared_ptr<const ProtoDecl>> protos;
    std::vector<Name> order;  // declaration order, for "the first PROTO of a file"

    const ProtoDecl* find(Name name) const {
        const std::shared_ptr<const ProtoDecl>* entry = find_entry(name);
        return entry ? entry->get() : nullptr;
    }
    // For whoever reads an instance: its field values may declare the same name again, which
    // replaces (and so frees) the scope's entry while the instance still uses it.
    std::shared_ptr<const ProtoDecl> find_owned(Name name) const {
        const std::shared_ptr<const ProtoDecl>* entry = find_entry(name);
        return entry ? *entry : nullptr;
    }

  private:
    const std::shared_ptr<const ProtoDecl>* find_entry(Name name) const {
        for (const ProtoScope* s = this; s; s = s->parent.get()) {
            if (s->protos.empty())
                continue;  // most files declare none, and this runs for every node
            auto it = s->protos.find(name);
            if (it != s->protos.end()) return &it->second;
        }
        return nullptr;
    }
};

}  // namespace vr
