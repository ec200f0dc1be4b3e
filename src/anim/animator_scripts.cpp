// The Animator's side of Scripts (docs/scripts.md): their events into the cascade, and what a
// Script may do to other nodes (directOutput, Browser.addRoute), as ScriptWorld.
#include <algorithm>

#include "anim/animator.h"
#include "parser/registry.h"

namespace vr {
namespace {

uint64_t key_of(NodeId node, Name field) { return (uint64_t(node) << 32) | field; }

}  // namespace

// `event` of a Script's own interface: its name, or set_x / x_changed of an inputOutput x.
bool Animator::script_end(NodeId node, Name event, bool input, RouteEnd& end) const {
    auto accept = [&](const ScriptField* f, bool exposed_only) {
        if (!f || (exposed_only && f->access != Access::ExposedField)) return false;
        const bool ok = input ? f->access == Access::EventIn || f->access == Access::ExposedField
                              : f->access == Access::EventOut || f->access == Access::ExposedField;
        if (ok) end = {node, f->name, f->type, f->access};
        return ok;
    };
    if (accept(scripts_->field(node, event), false)) return true;
    const std::string_view text = name_text(event);
    if (input && text.starts_with("set_"))
        return accept(scripts_->field(node, intern(text.substr(4))), true);
    if (!input && text.ends_with("_changed"))
        return accept(scripts_->field(node, intern(text.substr(0, text.size() - 8))), true);
    return false;
}

bool Animator::changes_children(const RouteEnd& end) {
    static const Name add = intern("addChildren"), remove = intern("removeChildren");
    return end.access == Access::EventIn && (end.field == add || end.field == remove);
}

// addChildren / removeChildren of a grouping node: its children gain the nodes it lacks, or lose
// those it has; children_changed goes out.
void Animator::change_children(const RouteEnd& to, const std::vector<NodeId>& nodes) {
    static const Name children = intern("children"), add = intern("addChildren");
    const uint32_t index = own_entry(to.node, children);
    const FieldView now = tree_.view(tree_.fields[index]);
    std::vector<NodeId> result(now.nodes.begin(), now.nodes.end());
    for (NodeId n : nodes) {
        if (n == kNullNode) continue;
        auto found = std::find(result.begin(), result.end(), n);
        if (to.field == add && found == result.end()) result.push_back(n);
        if (to.field != add && found != result.end()) result.erase(found);
    }
    FieldEntry& e = tree_.fields[index];
    e.begin = uint32_t(tree_.node_refs.size());
    tree_.node_refs.insert(tree_.node_refs.end(), result.begin(), result.end());
    e.count = uint32_t(result.size());
    send(to.node, children, e.type, {}, {}, result);
}

void Animator::send_script_events(std::vector<ScriptEvent>& events) {
    for (ScriptEvent& e : events)
        send(e.script, e.field, e.value.type, std::move(e.value.numbers),
             std::move(e.value.strings), std::move(e.value.nodes));
    events.clear();
}

bool Animator::set_field(NodeId node, Name field, const ScriptValue& value, std::string& why) {
    if (tree_.scripts.count(node)) {
        why = "a Script's fields change through events only";
        return false;
    }
    RouteEnd end;
    if (!field_end(node, field, true, end)) {
        // A plain field (IndexedFaceSet coordIndex): directOutput may set it too.
        const NodeTypeDecl* decl = tree_.decl(node);
        const FieldDecl* f =
            decl ? Registry::builtin().lookup_field(decl->spec, *decl, field) : nullptr;
        if (!f || !has_value(f->access)) {
            why = "no such field or eventIn";
            return false;
        }
        end = {node, f->name, f->type, f->access};
    }
    if (end.type != value.type) {
        why = "the value is not a " + std::string(type_name(end.type));
        return false;
    }
    if (has_value(end.access)) own_entry(end.node, end.field);
    if (changes_children(end)) own_entry(end.node, intern("children"));
    deliver(end, value.type, value.numbers, value.strings, value.nodes);
    return true;
}

bool Animator::route(bool add, NodeId from, Name from_event, NodeId to, Name to_event,
                     std::string& why) {
    std::vector<RouteEnd> a, b;
    resolve_end(from, from_event, false, a, 0);
    resolve_end(to, to_event, true, b, 0);
    if (a.empty() || b.empty()) {
        why = a.empty() ? "no such output event" : "no such input event";
        return false;
    }
    for (const RouteEnd& x : a)
        for (const RouteEnd& y : b)
            if (x.type != y.type) {
                why = "the types differ";
                return false;
            }
    if (add) {
        Route r;
        r.from = from;
        r.from_event = from_event;
        r.to = to;
        r.to_event = to_event;
        r.loc = tree_.nodes[from].loc;
        resolve(r);
        fired_.resize(routes_.size(), 0);
        // A TimeSensor routed only now sends its events from the next time on.
        if (tree_.type_name(from) == "TimeSensor" &&
            std::find(sensors_.begin(), sensors_.end(), from) == sensors_.end()) {
            sensors_.insert(std::upper_bound(sensors_.begin(), sensors_.end(), from), from);
            animated_ = true;
        }
        return true;
    }
    for (const RouteEnd& x : a) {
        auto it = routes_from_.find(key_of(x.node, x.field));
        if (it == routes_from_.end()) continue;
        std::erase_if(it->second, [&](uint32_t r) {
            return std::any_of(b.begin(), b.end(), [&](const RouteEnd& y) {
                return routes_[r].to.node == y.node && routes_[r].to.field == y.field;
            });
        });
    }
    return true;
}

}  // namespace vr
