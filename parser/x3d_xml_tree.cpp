// X3D XML elements to nodes: the X3D rules (containerField, DEF/USE, prototypes) on the element
// events that parser/x3d_xml.cpp delivers from libxml2, or that a recorded ProtoBody replays.
#include <algorithm>

#include "parser/suggest.h"
#include "parser/x3d_xml.h"
#include "parser/x3d_xml_reader.h"

namespace vr::x3d_xml_detail {

// ---- elements -----------------------------------------------------------------------------------

namespace {

bool same_ignoring_case(std::string_view a, std::string_view b) {
    auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; };
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(),
                                              [&](char x, char y) { return lower(x) == lower(y); });
}

}  // namespace

// X3D's names are case-sensitive, but X3DOM pages are HTML, where they are not, and writers made
// for X3DOM (ASE's newer x3d writer) put <scene>, <transform> and <material diffusecolor=...> in
// X3D files. A name X3D does not know, that is an X3D element's when case is ignored, is read as
// that element, with a warning; other names stay unknown.
Name XmlReader::tag_in_x3d_case(Name tag, uint32_t offset) {
    const Name structural[] = {n_.x3d,
                               n_.scene,
                               n_.head,
                               n_.unit,
                               n_.proto_interface,
                               n_.proto_body,
                               n_.field,
                               n_.field_value,
                               n_.is,
                               n_.connect,
                               n_.proto_declare,
                               n_.extern_proto_declare,
                               n_.proto_instance,
                               n_.route,
                               n_.import,
                               n_.export_};
    if (registry_.lookup(Spec::X3d, tag) ||
        std::find(std::begin(structural), std::end(structural), tag) != std::end(structural))
        return tag;
    const std::string_view text = name_text(tag);
    Name found = kNoName;
    for (Name s : structural)
        if (same_ignoring_case(name_text(s), text)) found = s;
    for (Spec spec : {Spec::X3d, Spec::Vrml97, Spec::Hint})
        for (const NodeTypeDecl& d : registry_.nodes(spec))
            if (found == kNoName && same_ignoring_case(name_text(d.name), text)) found = d.name;
    if (found == kNoName) return tag;
    warn(main_file_, offset,
         "<" + std::string(text) + "> read as <" + std::string(name_text(found)) +
             ">: X3D's names are case-sensitive; this file spells them as X3DOM pages may",
         "xml-case:" + std::string(text));
    return found;
}

// DEF, USE and containerField in another case (X3DOM: HTML gives "def"), as X3D spells them.
Name XmlReader::attribute_in_x3d_case(Name name, uint32_t offset) {
    for (Name x3d : {n_.def, n_.use, n_.container}) {
        if (name == x3d || !same_ignoring_case(name_text(name), name_text(x3d))) continue;
        const std::string text(name_text(name));
        warn(main_file_, offset,
             "attribute '" + text + "' read as '" + std::string(name_text(x3d)) +
                 "': X3D's names are case-sensitive; this file spells them as X3DOM pages may",
             "xml-case-attribute:" + text);
        return x3d;
    }
    return name;
}

// An attribute named as a field of `decl` when case is ignored (see tag_in_x3d_case).
const FieldDecl* XmlReader::field_in_x3d_case(const XmlElement& e, const NodeTypeDecl& decl,
                                              const XmlAttr& a) {
    const std::string_view text = name_text(a.name);
    for (const FieldDecl& f : decl.fields) {
        if (!same_ignoring_case(name_text(f.name), text)) continue;
        const FieldDecl* field = registry_.lookup_field(Spec::X3d, decl, f.name);
        if (!field) continue;
        warn(e.file, a.name_offset,
             "attribute '" + std::string(text) + "' read as '" +
                 std::string(name_text(field->name)) +
                 "': X3D's names are case-sensitive; this file spells them as X3DOM pages may",
             "xml-case-attribute:" + std::string(text));
        return field;
    }
    return nullptr;
}

// <unit category="length" name="km" conversionFactor="1000"/> (parser/units.h).
void XmlReader::unit(const XmlElement& e) {
    const std::string category = required(e, n_.category, "unit");
    required(e, n_.name, "unit");
    const std::string factor = required(e, n_.conversion_factor, "unit");
    const std::string why = add_unit(units_, trim(category), trim(factor), {e.file, e.offset});
    if (!why.empty()) warn(e.file, e.offset, why, "unit:" + why);
}

void XmlReader::start_element(const XmlElement& e) {
    if (recording_) {
        record(e);
        ++record_depth_;
        return;
    }
    const Role parent = stack_.back().role;
    const Name tag = e.tag;
    if (e.foreign && parent != Role::Document && parent != Role::Skip && parent != Role::Leaf) {
        foreign_element(e);
        return push(make_open(Role::Skip, e));
    }
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
            if (tag == n_.x3d) {
                x3d_offset_ = e.offset;
                if (const XmlAttr* v = e.find(n_.version)) version_ = trim(attr_text(e, *v));
                return push(make_open(Role::X3d, e));
            }
            if (tag == n_.scene) return scene_start(e);
            fail(e.file, e.offset,
                 "not an X3D document: the root element is <" + tag_text(e) + ">, expected <X3D>");
        case Role::X3d:
            if (tag == n_.scene) return scene_start(e);
            if (tag == n_.head) return push(make_open(Role::Head, e));
            warn(e.file, e.offset, "element <" + tag_text(e) + "> outside <Scene> ignored",
                 "xml-outside-scene:" + tag_text(e));
            return push(make_open(Role::Skip, e));
        case Role::Head:
            if (tag == n_.unit) unit(e);
            return push(make_open(Role::Skip, e));  // meta, component, unit: nothing inside
        case Role::ProtoDeclare:
            if (tag == n_.proto_interface) return push(make_open(Role::ProtoInterface, e));
            if (tag == n_.proto_body) {
                XmlProtoDecl& decl = *stack_.back().proto;
                if (decl.has_body) fail(e.file, e.offset, "a ProtoDeclare has only one ProtoBody");
                decl.has_body = true;
                decl.file = e.file;
                push(make_open(Role::ProtoBody, e));
                recording_ = &decl;
                record_depth_ = 0;
                return;
            }
            fail(e.file, e.offset,
                 "<" + tag_text(e) +
                     "> inside <ProtoDeclare>: expected <ProtoInterface> or <ProtoBody>");
        case Role::ProtoInterface:
            if (tag == n_.field) return field_start(e, Role::InterfaceField);
            fail(e.file, e.offset,
                 "<" + tag_text(e) + "> inside <ProtoInterface>: expected <field>");
        case Role::ExternProto:
            if (tag == n_.field) return field_start(e, Role::ExternField);
            fail(e.file, e.offset,
                 "<" + tag_text(e) + "> inside <ExternProtoDeclare>: expected <field>");
        case Role::Instance:
            if (tag == n_.field_value) return field_value_start(e);
            if (tag == n_.is) {
                if (!frame().is_values)
                    fail(e.file, e.offset, "<IS> may only be used inside a <ProtoBody>");
                return push(make_open(Role::Is, e));
            }
            warn(e.file, e.offset,
                 "<" + tag_text(e) + "> inside <ProtoInstance> ignored (expected <fieldValue>)",
                 "xml-instance-child:" + tag_text(e));
            return push(make_open(Role::Skip, e));
        case Role::Is:
            if (tag == n_.connect) {
                connect(e);
                return push(make_open(Role::Leaf, e));
            }
            fail(e.file, e.offset, "<" + tag_text(e) + "> inside <IS>: expected <connect>");
        case Role::ExternField:
        case Role::ProtoBody:
            break;
        default:
            return content_element(e);
    }
    fail(e.file, e.offset, "<" + tag_text(e) + "> is not allowed here");
}

// An element where nodes may stand: the Scene, a ProtoBody being replayed, a node, a field's
// default value.
void XmlReader::content_element(const XmlElement& e) {
    const Name tag = e.tag;
    if (tag == n_.proto_declare || tag == n_.extern_proto_declare || tag == n_.proto_instance ||
        tag == n_.route || tag == n_.import || tag == n_.export_)
        not_in_piece(e);
    if (tag == n_.proto_declare) return proto_declare_start(e);
    if (tag == n_.extern_proto_declare) return extern_start(e);
    if (tag == n_.proto_instance) return instance_start(e);
    if (tag == n_.route || tag == n_.import || tag == n_.export_) {
        if (tag == n_.route)
            route(e);
        else
            import_export(e);
        return push(make_open(Role::Leaf, e));
    }
    Open& parent = stack_.back();
    if (tag == n_.is) {
        if (parent.role != Role::Node)
            fail(e.file, e.offset, "<IS> may only stand inside a node or <ProtoInstance>");
        if (!frame().is_values)
            fail(e.file, e.offset, "<IS> may only be used inside a <ProtoBody>");
        return push(make_open(Role::Is, e));
    }
    if (tag == n_.field) {
        if (parent.role == Role::Node && parent.dynamic) return field_start(e, Role::DynamicField);
        fail(e.file, e.offset,
             "<field> may only stand in <ProtoInterface>, <ExternProtoDeclare>, Script and shader "
             "nodes");
    }
    if (tag == n_.field_value && parent.role == Role::Node) {
        // Xj3D's tests set a node's field so; X3D gives <fieldValue> to ProtoInstance only. As an
        // unknown attribute: a warning, and the node is read without it.
        warn(e.file, e.offset,
             "<fieldValue> inside <" + tag_of(parent) +
                 "> ignored: only a <ProtoInstance> takes field values so",
             "xml-node-field-value");
        return push(make_open(Role::Skip, e));
    }
    if (tag == n_.field_value || tag == n_.connect || tag == n_.proto_interface ||
        tag == n_.proto_body || tag == n_.scene || tag == n_.x3d)
        fail(e.file, e.offset,
             "<" + tag_text(e) + "> is not allowed inside <" + tag_of(parent) + ">");
    if (const NodeTypeDecl* decl = registry_.lookup(Spec::X3d, e.tag)) return node_start(e, decl);
    std::string type = tag_text(e);
    std::string hint =
        frame().protos->find(e.tag)
            ? " (to instantiate the prototype, use <ProtoInstance name='" + type + "'>)"
            : did_you_mean(registry_.nearest_node(Spec::X3d, type));
    warn(e.file, e.offset, "unknown node type '" + type + "' skipped" + hint,
         "unknown-node:" + type);
    ++scene_.stats.skipped_nodes[type];
    push(make_open(Role::Skip, e));
}

void XmlReader::node_start(const XmlElement& e, const NodeTypeDecl* decl) {
    if (const XmlAttr* use = e.find(n_.use)) return use_start(e, *use, false);
    Open o = make_open(Role::Node, e);
    o.decl = decl;
    o.dynamic = dynamic_type(e.tag);
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
        const FieldDecl* field = registry_.lookup_field(Spec::X3d, *decl, x3d_field(e.tag, a.name));
        // HTML-style attributes, unless the node has a field of that name (FontStyle.style).
        if (!field && (a.name == n_.cls || a.name == n_.id || a.name == n_.style)) continue;
        if (!field) field = field_in_x3d_case(e, *decl, a);
        const std::string_view type = name_text(e.tag);  // for messages
        if (!field) {  // as browsers do: a warning, and the rest of the node is read
            warn(e.file, a.name_offset,
                 "unknown attribute '" + std::string(name_text(a.name)) + "' of node " +
                     std::string(type) + "; ignored" +
                     did_you_mean(nearest_name(name_text(a.name), field_names(*decl))),
                 "unknown-field:" + std::string(type) + "." + std::string(name_text(a.name)));
            continue;
        }
        if (field->extension)
            warn(e.file, a.name_offset,
                 "non-standard field '" + std::string(name_text(a.name)) + "' of " +
                     std::string(type) + " (a browser extension) read and ignored",
                 "extension-field:" + std::string(type) + "." + std::string(name_text(a.name)));
        if (!has_value(field->access)) {
            warn(e.file, a.name_offset,
                 "'" + std::string(name_text(a.name)) + "' is an event of " + std::string(type) +
                     " and takes no value; ignored",
                 "event-value:" + std::string(type) + "." + std::string(name_text(a.name)));
            continue;
        }
        FieldEntry entry;
        entry.name = field->name;
        if (read_value_or_warn(e, a, field->type, entry, What{"attribute", a.name, e.tag}))
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
    } else if (piece_content_ && frames_.size() == 1) {
        o.use = outer_node(key, e);  // a DEF before the piece: the main reader resolves it
    } else {                         // as browsers do: the element is left out
        warn(e.file, use.begin,
             "USE of '" + name + "', which no DEF before it names" +
                 (f.is_values ? " in this ProtoBody" : "") + "; the node is left out",
             "use-unknown:" + name);
        push(make_open(Role::Skip, e));
        return;
    }
    ++scene_.stats.use_count;
    for (const XmlAttr& a : e.attrs) {
        if (a.name == n_.container) {
            o.container = intern(trim(attr_text(e, a)));
            o.container_offset = a.begin;
        } else if (a.name != n_.use && a.name != n_.cls && a.name != n_.id && a.name != n_.style &&
                   !(instance && a.name == n_.name)) {
            warn(e.file, a.name_offset,
                 "attribute '" + std::string(name_text(a.name)) + "' of a USE element ignored",
                 "xml-use-attribute");
        }
    }
    if (!instance && o.use != kNullNode && !is_outer_node(o.use) && tree_.type(o.use) != e.tag)
        warn(e.file, e.offset,
             "USE '" + name + "' names a " + std::string(tree_.type_name(o.use)) + ", not a " +
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
    if (piece_content_ && stack_.size() <= piece_depth_)
        fail(main_file_, current_offset(), "a piece ends the <Scene> it began in");
    Open o = std::move(stack_.back());
    stack_.pop_back();
    switch (o.role) {
        case Role::Node:
            return node_end(o);
        case Role::Use:
            return attach(o.use, o);
        case Role::Instance: {
            ++scene_.stats.proto_instances;
            NodeId id = expand(*o.instance, o.file, o.offset);
            if (o.def != kNoName) {
                if (id != kNullNode && tree_.nodes[id].def_name == kNoName)
                    tree_.nodes[id].def_name = o.def;
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
        case Role::DynamicField:
            return field_end(o);
        case Role::ProtoDeclare: {
            auto& scope = *frame().protos;
            if (!o.proto->has_body)
                warn(o.file, o.offset,
                     "ProtoDeclare '" + std::string(name_text(o.proto->name)) +
                         "' has no ProtoBody; its instances are empty",
                     "xml-no-protobody");
            if (!scope.protos.count(o.proto->name)) scope.order.push_back(o.proto->name);
            scope.protos[o.proto->name] = o.proto;
            ++scene_.stats.proto_declarations;
            return;
        }
        case Role::ExternProto: {
            auto& scope = *frame().protos;
            if (resolver_)
                o.proto->implementation =
                    resolver_(o.urls, o.file, {o.file, o.offset}, o.proto->name);
            if (!scope.protos.count(o.proto->name)) scope.order.push_back(o.proto->name);
            scope.protos[o.proto->name] = o.proto;
            ++scene_.stats.externproto_declarations;
            return;
        }
        default:
            return;
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
        // An outer node's place is known where the piece joins (PackedLoc(): none yet).
        const NodeId first = children_[i].id;
        entry.loc = is_outer_node(first) ? PackedLoc() : tree_.nodes[first].loc;
        entry.begin = static_cast<uint32_t>(tree_.node_refs.size());
        for (size_t k = i; k < children_.size(); ++k)
            if (children_[k].field == field) tree_.node_refs.push_back(children_[k].id);
        entry.count = static_cast<uint32_t>(tree_.node_refs.size() - entry.begin);
        if (!decl->type.multi && entry.count > 1) {
            if (!entry.loc.valid()) not_in_piece(o.file, o.offset);
            warn(entry.loc.get().file, static_cast<uint32_t>(entry.loc.get().offset),
                 "field '" + std::string(name_text(field)) + "' of " + tag_of(o) +
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
    for (const auto& [field, proto_field] : o.events)
        tree_.is_links.push_back({kNullNode, proto_field, id, field});
    if (o.tag == n_.script)
        tree_.scripts[id] = ScriptInterface{std::move(o.script_fields), std::move(o.script_text)};
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
        case Role::Scene:
            roots_.push_back(id);
            return;
        case Role::ReplayRoot:
        case Role::InterfaceField:
        case Role::FieldValue:
        case Role::DynamicField:
            children_.push_back({kNoName, id});
            return;
        case Role::Node:
            break;
        default:
            return;
    }
    auto parent_type = [&] { return std::string(name_text(parent.tag)); };
    // A piece's outer node is of the type of its USE element (the main reader checks that).
    const Name id_type = is_outer_node(id) ? child.tag : tree_.type(id);
    auto type = [&] { return std::string(name_text(id_type)); };
    if (child.container != kNoName) {
        const Name wanted = x3d_field(parent.tag, child.container);
        const FieldDecl* field = registry_.lookup_field(Spec::X3d, *parent.decl, wanted);
        // As an unknown field: a warning, and the child is left out.
        if (!field || field->type.kind != ValueKind::Node) {
            warn(child.file, child.container_offset,
                 "containerField '" + std::string(name_text(child.container)) + "' of " + type() +
                     " is not a node field of its parent " + parent_type() +
                     "; the node is left out",
                 "unknown-field:" + parent_type() + "." + std::string(name_text(child.container)));
            return;
        }
        if (!has_value(field->access)) {
            warn(child.file, child.container_offset,
                 "containerField '" + std::string(name_text(wanted)) + "' is an event of " +
                     parent_type() + " and takes no nodes; the node is left out",
                 "event-value:" + parent_type() + "." + std::string(name_text(wanted)));
            return;
        }
        children_.push_back({field->name, id});
        return;
    }
    const Name wanted_name = default_container(id_type);
    const FieldDecl* field = registry_.lookup_field(Spec::X3d, *parent.decl, wanted_name);
    if (!field || field->type.kind != ValueKind::Node || !has_value(field->access)) {
        const std::string wanted(name_text(wanted_name));
        warn(child.file, child.offset,
             type() + " ignored: its parent " + parent_type() + " has no field '" + wanted +
                 "' (the default containerField of " + type() +
                 "); give a containerField attribute",
             "xml-container:" + parent_type() + "." + wanted);
        return;
    }
    children_.push_back({field->name, id});
}

Name XmlReader::default_container(Name type) {
    auto it = container_cache_.find(type);
    if (it != container_cache_.end()) return it->second;
    Name field = intern(x3d_default_container_field(name_text(type)));
    container_cache_.emplace(type, field);
    return field;
}

void XmlReader::instance_start(const XmlElement& e) {
    if (const XmlAttr* use = e.find(n_.use)) return use_start(e, *use, true);
    std::string name = required(e, n_.name, "ProtoInstance");
    Open o = make_open(Role::Instance, e);
    std::shared_ptr<const ProtoDecl> proto = frame().protos->find_owned(intern(name));
    if (!proto) {
        warn(e.file, e.offset,
             "ProtoInstance of '" + name +
                 "', which no ProtoDeclare or ExternProtoDeclare before it declares; skipped",
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
    if (!pf || !has_value(pf->access)) {  // as an unknown attribute: warned, skipped
        const std::string proto(name_text(inst.proto->name));
        warn(e.file, pf ? e.offset : e.find(n_.name)->begin,
             pf ? "field '" + name + "' of " + proto + " is an event and takes no value; ignored"
                : "ProtoInstance of " + proto + " has no field '" + name + "'; ignored",
             (pf ? "event-value:" : "unknown-field:") + proto + "." + name);
        return push(make_open(Role::Skip, e));
    }
    if (const XmlAttr* value = e.find(n_.value)) {
        FieldEntry entry;
        entry.name = pf->name;
        if (read_value_or_warn(e, *value, pf->type, entry, What{"fieldValue", name}))
            inst.values[pf->name] = entry;
        return push(make_open(Role::Skip, e));
    }
    if (pf->type.kind != ValueKind::Node)
        return push(make_open(Role::Skip, e));  // no value: the default stays
    Open o = make_open(Role::FieldValue, e);
    o.field = *pf;
    push(std::move(o));
}

// <ROUTE fromNode fromField toNode toField>, its nodes resolved in this scope's DEF names.
void XmlReader::route(const XmlElement& e) {
    ++scene_.stats.routes;
    Route r;
    r.loc = {e.file, e.offset};
    const std::string from(trim(required(e, n_.from_node, "ROUTE")));
    const std::string to(trim(required(e, n_.to_node, "ROUTE")));
    r.from_event = intern(trim(required(e, n_.from_field, "ROUTE")));
    r.to_event = intern(trim(required(e, n_.to_field, "ROUTE")));
    for (const std::string* name : {&from, &to}) {
        auto it = frame().defs.find(intern(*name));
        // An IMPORTed name (the file's own scope only: a ProtoBody cannot see it).
        if (auto imp = imported_.find(intern(*name));
            it == frame().defs.end() && !frame().is_values && imp != imported_.end()) {
            (name == &from ? r.from_import : r.to_import) = imp->second;
            continue;
        }
        if (it != frame().defs.end() && it->second == kNullNode) return;  // skipped, said so
        if (it == frame().defs.end()) {
            warn(e.file, e.offset,
                 "ROUTE names '" + *name +
                     "', which no DEF before it names here; the ROUTE is "
                     "ignored",
                 "route-unknown-node");
            return;
        }
        (name == &from ? r.from : r.to) = it->second;
    }
    tree_.routes.push_back(r);
}

// <IMPORT inlineDEF importedDEF AS> and <EXPORT localDEF AS> (X3D 4.4.6).
void XmlReader::import_export(const XmlElement& e) {
    const bool import = e.tag == n_.import;
    const Name def_attr = import ? n_.inline_def : n_.local_def;
    const std::string def(trim(required(e, def_attr, import ? "IMPORT" : "EXPORT")));
    const std::string exported = import ? imported_def(e) : def;
    const XmlAttr* as_attr = e.find(n_.as);
    std::string as = as_attr ? std::string(trim(attr_text(e, *as_attr))) : "";
    if (as.empty()) as = exported;
    auto it = frame().defs.find(intern(def));
    const uint32_t at = e.find(def_attr)->begin;
    if (it == frame().defs.end()) {  // as a ROUTE naming no DEF: dropped, with a warning
        warn(e.file, at,
             std::string(import ? "IMPORT" : "EXPORT") + " names '" + def +
                 "', which no DEF before it names; ignored",
             import ? "import-unknown-def" : "export-unknown-def");
        return;
    }
    if (!import) {
        tree_.exports.push_back({e.file, intern(as), it->second});
        return;
    }
    if (it->second != kNullNode && tree_.type_name(it->second) != "Inline")
        fail(e.file, at,
             "IMPORT names '" + def + "', a " + std::string(tree_.type_name(it->second)) +
                 ", not an Inline");
    imported_[intern(as)] = uint32_t(tree_.imports.size());
    tree_.imports.push_back(
        {it->second, intern(exported), intern(as), PackedLoc(e.file, e.offset)});
}

// IMPORT's importedDEF attribute, or exportedDEF, its name in X3D 3.0's XML encoding (warned).
std::string XmlReader::imported_def(const XmlElement& e) {
    if (e.find(n_.imported_def) || !e.find(n_.exported_def))
        return std::string(trim(required(e, n_.imported_def, "IMPORT")));
    const XmlAttr& a = *e.find(n_.exported_def);
    warn(e.file, a.name_offset,
         "IMPORT attribute 'exportedDEF' is the older spelling of 'importedDEF'; read as it",
         "xml-import-exported-def");
    return std::string(trim(attr_text(e, a)));
}

// <connect nodeField protoField>: the enclosing node (or PROTO instance) field takes the instance's
// value.
void XmlReader::connect(const XmlElement& e) {
    Open& owner = stack_[stack_.size() - 2];
    Frame& f = frame();
    const std::string node_field = required(e, n_.node_field, "connect");
    const std::string proto_field = required(e, n_.proto_field, "connect");
    const ProtoField* outer = f.proto->find(intern(proto_field));
    if (!outer) {
        warn(e.file, e.find(n_.proto_field)->begin,
             "connect names '" + proto_field + "', which is not a field of " +
                 std::string(name_text(f.proto->name)) + "; the link is dropped",
             "is-unknown:" + proto_field);
        return;
    }
    auto bound = f.is_values->find(outer->name);
    if (owner.role == Role::Instance) {
        Instance& inst = *owner.instance;
        const ProtoField* inner = inst.proto->find(intern(node_field));
        if (!inner) {
            warn(e.file, e.find(n_.node_field)->begin,
                 "connect names '" + node_field + "', which is not a field of " +
                     std::string(name_text(inst.proto->name)) + "; the link is dropped",
                 "is-unknown:" + node_field);
            return;
        }
        if (inner->type != outer->type) {
            warn(e.file, e.offset,
                 "connect joins " + std::string(name_text(inst.proto->name)) + "." + node_field +
                     " (" + std::string(type_name(inner->type)) + ") to " + proto_field +
                     " of type " + std::string(type_name(outer->type)) + "; the link is dropped",
                 "is-type:" + proto_field);
            return;
        }
        if (inner->access != Access::Field) inst.events.emplace_back(inner->name, outer->name);
        if (bound != f.is_values->end()) {
            inst.values[inner->name] = bound->second;
            inst.values[inner->name].name = inner->name;
        }
        return;
    }
    const std::string_view type = name_text(owner.tag);
    const FieldDecl* field =
        registry_.lookup_field(Spec::X3d, *owner.decl, intern(x3d_field_name(type, node_field)));
    if (!field) {
        if (owner.dynamic) return script_connect(owner, node_field, *outer, bound);
        warn(e.file, e.find(n_.node_field)->begin,
             "connect names '" + node_field + "', which is not a field of " + std::string(type) +
                 "; the link is dropped",
             "is-unknown:" + node_field);
        return;
    }
    if (field->type != outer->type) {
        warn(e.file, e.offset,
             "connect joins " + std::string(type) + "." + node_field + " (" +
                 std::string(type_name(field->type)) + ") to " + proto_field + " of type " +
                 std::string(type_name(outer->type)) + "; the link is dropped",
             "is-type:" + proto_field);
        return;
    }
    // Events go through IS links (as the classic reader keeps them), for ROUTEs into and out of
    // the instance.
    if (field->access != Access::Field) owner.events.emplace_back(field->name, outer->name);
    if (!has_value(field->access) || bound == f.is_values->end())
        return;  // events carry no value at time 0
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
        read_value(e, *value, *type, o.field.default_value, What{"field", name});
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

// <connect> of a field a Script (or shader) declared itself: the instance's value, and its events.
void XmlReader::script_connect(Open& owner, const std::string& node_field, const ProtoField& outer,
                               std::unordered_map<Name, FieldEntry>::const_iterator bound) {
    for (ScriptField& field : owner.script_fields) {
        if (name_text(field.name) != node_field || field.type != outer.type) continue;
        if (field.access != Access::Field) owner.events.emplace_back(field.name, outer.name);
        if (has_value(field.access) && bound != frame().is_values->end()) {
            field.value = bound->second;
            field.value.name = field.name;
        }
        return;
    }
}

void XmlReader::field_end(Open& o) {
    if (o.role == Role::DynamicField) {
        ScriptField field{o.field.name, o.field.type, o.field.access, o.field.default_value};
        field.value.name = field.name;
        field.value.type = field.type;
        if (field.type.kind == ValueKind::Node && has_value(field.access))
            node_entry(field.type, o.child_mark, field.value, o.file, o.offset,
                       "field '" + std::string(name_text(field.name)) + "'");
        children_.resize(o.child_mark);
        Open& owner = stack_.back();
        if (owner.role == Role::Node) owner.script_fields.push_back(std::move(field));
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
        fail(o.file, o.offset,
             "field '" + std::string(name_text(o.field.name)) + "' declared twice in " +
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
        read_value(e, *url, FieldType{ValueKind::String, true}, urls,
                   What{"attribute", "url", "ExternProtoDeclare"});
        o.urls.assign(tree_.strings.begin() + urls.begin,
                      tree_.strings.begin() + urls.begin + urls.count);
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

// Text in a ProtoBody, for the Scripts in it (a Script's text is its ECMAScript): one event for
// each run of text between elements, replayed into the Script it stands in.
void XmlReader::record_text(const char* text, size_t length) {
    XmlProtoDecl& decl = *recording_;
    static const Name text_event = intern("#text");
    if (!decl.events.empty() && decl.events.back().tag == text_event) {
        decl.strings[decl.events.back().first_attr].append(text, length);
        return;
    }
    decl.strings.emplace_back(text, length);
    decl.events.push_back({text_event, 0, uint32_t(decl.strings.size() - 1), 0, false});
}

NodeId XmlReader::expand(const Instance& inst, uint32_t file, uint32_t offset) {
    const ProtoDecl& proto = *inst.proto;
    const std::string name(name_text(proto.name));
    const ProtoDecl* impl = &proto;
    if (proto.external) {
        impl = proto.implementation.get();
        if (!impl) {
            warn(file, offset,
                 "instance of ExternProtoDeclare " + name + " skipped: it was not resolved",
                 "unresolved-externproto:" + name);
            ++scene_.stats.skipped_nodes[name];
            return kNullNode;
        }
    }
    if (impl->builtin) return builtin_instance(*impl->builtin, inst.values, file, offset);
    if (!is_xml_text(scene_.sources.file(impl->file).text)) {
        warn(file, offset,
             "instance of " + name +
                 " skipped: its implementation is a classic-encoding PROTO, which an X3D XML file "
                 "cannot instantiate",
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
                fail(file, offset,
                     "field '" + std::string(name_text(pf.name)) + "' of " + name +
                         " has another type in its implementation");
            bound[pf.name] = it->second;
        } else if (pf.has_default) {
            bound[pf.name] = pf.default_value;
        }
    }
    if (frame().proto_depth + 1 > limits_.max_proto_depth)
        fail(file, offset,
             "ProtoInstances nested deeper than " + std::to_string(limits_.max_proto_depth) +
                 " (limit; a prototype that instantiates itself?)");
    auto scope = std::make_unique<Frame>();
    scope->file = body.file;
    scope->protos = std::make_shared<ProtoScope>();
    scope->protos->parent = impl->scope.lock();
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
    const size_t links_mark = tree_.is_links.size();
    push(std::move(root));
    static const Name text_event = intern("#text");
    for (const RecordedEvent& ev : body.events) {
        if (ev.tag == text_event) {
            if (stack_.back().role == Role::Node && stack_.back().tag == n_.script)
                stack_.back().script_text += body.strings[ev.first_attr];
            continue;
        }
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
        fail(file, offset,
             "the ProtoBody of " + name + " is not balanced");  // cannot happen for recorded XML
    // The first node of the body is the instance; the others are built but not part of the scene.
    NodeId first = children_.size() > stack_.back().child_mark
                       ? children_[stack_.back().child_mark].id
                       : kNullNode;
    children_.resize(stack_.back().child_mark);
    stack_.pop_back();
    frames_.pop_back();
    // This body's IS events belong to this instance, which its first node stands for (nested
    // instances set theirs before); the instance's own connects reach the enclosing instance.
    auto& links = tree_.is_links;
    for (size_t i = links_mark; i < links.size(); ++i)
        if (links[i].instance == kNullNode) links[i].instance = first;
    if (first == kNullNode) {
        links.erase(std::remove_if(links.begin() + static_cast<ptrdiff_t>(links_mark), links.end(),
                                   [](const IsLink& l) { return l.instance == kNullNode; }),
                    links.end());
        return first;
    }
    for (const auto& [field, outer] : inst.events)
        links.push_back({kNullNode, outer, first, field});
    return first;
}

NodeId XmlReader::builtin_instance(const NodeTypeDecl& decl,
                                   const std::unordered_map<Name, FieldEntry>& values,
                                   uint32_t file, uint32_t offset) {
    const size_t mark = scratch_.size();
    for (const auto& [name, entry] : values) {
        const FieldDecl* field = decl.find(name);
        if (!field || field->type != entry.type || !has_value(field->access)) {
            warn(file, offset,
                 "field '" + std::string(name_text(name)) + "' does not match built-in node " +
                     std::string(name_text(decl.name)) + "; ignored",
                 "builtin-proto-field:" + std::string(name_text(name)));
            continue;
        }
        scratch_.push_back(entry);
    }
    return make_node(&decl, decl.name, file, offset, mark);
}

}  // namespace vr::x3d_xml_detail
