#include "anim/animator.h"

#include <algorithm>

#include "anim/geo_position.h"
#include "anim/interpolate.h"
#include "anim/time_sensor.h"
#include "parser/registry.h"

namespace vr {
namespace {

uint64_t key_of(NodeId node, Name field) { return (uint64_t(node) << 32) | field; }

bool is_input(Access a) { return a == Access::EventIn || a == Access::ExposedField; }
bool is_output(Access a) { return a == Access::EventOut || a == Access::ExposedField; }

// The interpolators evaluated, by node type, with how they blend.
bool interpolator_blend(std::string_view type, Blend& blend) {
    if (type == "ScalarInterpolator" || type == "PositionInterpolator" ||
        type == "PositionInterpolator2D" || type == "CoordinateInterpolator" ||
        type == "CoordinateInterpolator2D") {
        blend = Blend::Linear;
        return true;
    }
    if (type == "ColorInterpolator")
        blend = Blend::Hsv;
    else if (type == "OrientationInterpolator")
        blend = Blend::Rotation;
    else if (type == "NormalInterpolator")
        blend = Blend::UnitVector;
    else
        return false;
    return true;
}

std::string describe(const NodeTree& tree, NodeId node) {
    std::string text(tree.type_name(node));
    if (!tree.def_name(node).empty()) text += " '" + std::string(tree.def_name(node)) + "'";
    return text;
}

}  // namespace

Animator::Animator(NodeTree& tree, Diagnostics& diagnostics, const ScriptSettings* scripts)
    : tree_(tree), diagnostics_(diagnostics) {
    for (uint32_t i = 0; i < tree_.is_links.size(); ++i) {
        const IsLink& l = tree_.is_links[i];
        is_index_[key_of(l.instance, l.proto_field)].push_back(i);
    }
    const ScriptSettings defaults;
    if (!tree_.scripts.empty() && (scripts ? *scripts : defaults).enabled)
        scripts_ = std::make_unique<ScriptHost>(tree_, diagnostics_, scripts ? *scripts : defaults,
                                                static_cast<ScriptWorld&>(*this));
    for (const Route& r : tree_.routes) resolve(r);
    const Name time_sensor = intern("TimeSensor");
    for (const ResolvedRoute& r : routes_)
        if (tree_.type(r.from.node) == time_sensor &&
            std::find(sensors_.begin(), sensors_.end(), r.from.node) == sensors_.end())
            sensors_.push_back(r.from.node);
    std::sort(sensors_.begin(), sensors_.end());  // node order is file order
    animated_ = !sensors_.empty();
    if (this->scripts() > 0) {
        // initialize() of every Script at load (t = 0), its events through the cascade; what they
        // set is the world's from then on.
        fired_.assign(routes_.size(), 0);
        queue_.clear();
        std::vector<ScriptEvent> sent;
        scripts_->initialize(sent);
        send_script_events(sent);
        run_cascade();
        for (auto& [k, original] : originals_) original = tree_.fields[entries_.at(k)];
    }
    pool_marks_ = {tree_.numbers.size(), tree_.strings.size(), tree_.node_refs.size()};
    for (NodeId s : sensors_)
        for (const char* paused : {"pauseTime", "resumeTime"})
            if (!tree_.get(s, paused).is_default)
                warn_once(s,
                          describe(tree_, s) +
                              ": pauseTime and resumeTime are ignored (the sensor runs as if "
                              "never paused)",
                          "timesensor-pause");
}

Animator::~Animator() = default;

void Animator::warn_once(NodeId node, const std::string& message, const std::string& cause) {
    diagnostics_.warning(tree_.nodes[node].loc, message, cause);
}

// `event` of `node` as a field: its own name, set_x for an input to exposedField x, x_changed for
// an output of it.
bool Animator::field_end(NodeId node, Name event, bool input, RouteEnd& end) const {
    if (is_script(node)) return script_end(node, event, input, end);
    const NodeTypeDecl* decl = tree_.decl(node);
    if (!decl) return false;
    const Registry& reg = Registry::builtin();
    auto accept = [&](const FieldDecl* f, bool exposed_only) {
        if (!f || (exposed_only && f->access != Access::ExposedField)) return false;
        if (input ? !is_input(f->access) : !is_output(f->access)) return false;
        end = {node, f->name, f->type, f->access};
        return true;
    };
    const std::string_view text = name_text(event);
    if (accept(reg.lookup_field(decl->spec, *decl, event), false)) {
        // VRML97's set_x eventIns of plain fields (Extrusion set_spine, IndexedFaceSet
        // set_coordIndex): the event replaces the field's value.
        const FieldDecl* plain = end.access == Access::EventIn && text.starts_with("set_")
                                     ? reg.lookup_field(decl->spec, *decl, intern(text.substr(4)))
                                     : nullptr;
        if (plain && plain->access == Access::Field && plain->type == end.type)
            end = {node, plain->name, plain->type, Access::Field};
        return true;
    }
    if (input && text.starts_with("set_"))
        return accept(reg.lookup_field(decl->spec, *decl, intern(text.substr(4))), true);
    if (!input && text.ends_with("_changed"))
        return accept(reg.lookup_field(decl->spec, *decl, intern(text.substr(0, text.size() - 8))),
                      true);
    return false;
}

// The fields `node`.`event` stands for: through IS links when `node` stands for a PROTO instance
// whose interface has the event (several body fields may share it), else the node's own field.
void Animator::resolve_end(NodeId node, Name event, bool input, std::vector<RouteEnd>& out,
                           int depth) {
    if (depth > 64) return;  // IS chains are as deep as PROTO nesting, which the reader bounds
    const std::string_view text = name_text(event);
    std::vector<Name> names{event};
    if (input && text.starts_with("set_")) names.push_back(intern(text.substr(4)));
    if (!input && text.ends_with("_changed"))
        names.push_back(intern(text.substr(0, text.size() - 8)));
    for (Name n : names) {
        auto it = is_index_.find(key_of(node, n));
        if (it == is_index_.end()) continue;
        for (uint32_t i : it->second) {
            const IsLink& l = tree_.is_links[i];
            if (l.node == node && l.field == n) {  // the instance's own body node: its field
                RouteEnd end;
                if (field_end(node, n, input, end)) out.push_back(end);
            } else {
                resolve_end(l.node, l.field, input, out, depth + 1);
            }
        }
        return;
    }
    RouteEnd end;
    if (field_end(node, event, input, end)) out.push_back(end);
}

void Animator::resolve(const Route& route) {
    std::vector<RouteEnd> from, to;
    resolve_end(route.from, route.from_event, false, from, 0);
    resolve_end(route.to, route.to_event, true, to, 0);
    const bool script_source = tree_.type_name(route.from) == "Script";
    if (!scripts_ && (script_source || tree_.type_name(route.to) == "Script")) {
        if (script_source && tree_.type_name(route.to) != "Script" &&
            warned_scripts_.insert(route.from).second)
            warn_once(route.from,
                      describe(tree_, route.from) +
                          " is not run (--no-scripts): the fields its ROUTEs feed keep their "
                          "file values",
                      "script-not-run:" + std::to_string(route.from));
        return;
    }
    auto unknown = [&](NodeId node, Name event, const char* what) {
        diagnostics_.warning(route.loc,
                             "ROUTE: " + describe(tree_, node) + " has no " + what + " '" +
                                 std::string(name_text(event)) + "'; the ROUTE is ignored",
                             "route-unknown-event");
    };
    if (from.empty()) return unknown(route.from, route.from_event, "output event");
    if (to.empty()) return unknown(route.to, route.to_event, "input event");
    for (const RouteEnd& a : from) {
        for (const RouteEnd& b : to) {
            if (a.type != b.type) {
                diagnostics_.error(route.loc, "ROUTE from " + describe(tree_, route.from) + "." +
                                                  std::string(name_text(route.from_event)) + " (" +
                                                  std::string(type_name(a.type)) + ") to " +
                                                  describe(tree_, route.to) + "." +
                                                  std::string(name_text(route.to_event)) + " (" +
                                                  std::string(type_name(b.type)) +
                                                  "): the types differ");
                continue;
            }
            routes_from_[key_of(a.node, a.field)].push_back(uint32_t(routes_.size()));
            routes_.push_back({a, b, route.loc});
            if (is_script(b.node)) continue;
            if (has_value(b.access)) own_entry(b.node, b.field);
            if (changes_children(b)) own_entry(b.node, intern("children"));
        }
    }
}

// The index in tree.fields of `node`'s own entry for `field`, made (with the default value) when
// the file did not set it. The node's entries move to the end of the pool once: they must stay
// contiguous.
uint32_t Animator::own_entry(NodeId node, Name field) {
    auto found = entries_.find(key_of(node, field));
    if (found != entries_.end()) return found->second;
    const std::span<const FieldEntry> set = tree_.set_fields(node);
    for (size_t i = 0; i < set.size(); ++i)
        if (set[i].name == field) {
            const uint32_t index = tree_.nodes[node].first_field + uint32_t(i);
            entries_[key_of(node, field)] = index;
            originals_.emplace_back(key_of(node, field), tree_.fields[index]);
            return index;
        }
    const FieldView def = tree_.get(node, field);
    FieldEntry entry;
    entry.name = field;
    entry.type = def.type;
    if (def.type.kind == ValueKind::String) {
        entry.begin = uint32_t(tree_.strings.size());
        tree_.strings.insert(tree_.strings.end(), def.strings.begin(), def.strings.end());
        entry.count = uint32_t(def.strings.size());
    } else if (def.type.kind == ValueKind::Node) {
        entry.begin = uint32_t(tree_.node_refs.size());
        tree_.node_refs.insert(tree_.node_refs.end(), def.nodes.begin(), def.nodes.end());
        entry.count = uint32_t(def.nodes.size());
    } else {
        const std::vector<double> copy(def.numbers.begin(), def.numbers.end());  // may alias
        entry.begin = uint32_t(tree_.numbers.size());
        tree_.numbers.insert(tree_.numbers.end(), copy.begin(), copy.end());
        entry.count = uint32_t(copy.size());
    }
    const std::vector<FieldEntry> moved(set.begin(), set.end());
    const uint32_t first = uint32_t(tree_.fields.size());
    tree_.fields.insert(tree_.fields.end(), moved.begin(), moved.end());
    tree_.fields.push_back(entry);
    Node& n = tree_.nodes[node];
    // Entries found before keep their place in the move.
    for (auto& [k, index] : entries_)
        if (NodeId(k >> 32) == node) index = first + (index - n.first_field);
    const uint32_t count = uint32_t(moved.size() + 1);
    n.first_field = first;
    if (count >= Node::kManyFields) {
        n.few_fields = Node::kManyFields;
        tree_.many_fields[node] = count;
    } else {
        n.few_fields = uint8_t(count);
    }
    const uint32_t index = first + uint32_t(moved.size());
    entries_[key_of(node, field)] = index;
    originals_.emplace_back(key_of(node, field), entry);
    return index;
}

void Animator::send(NodeId node, Name field, const FieldType& type, std::vector<double> numbers,
                    std::vector<std::string> strings, std::vector<NodeId> nodes) {
    queue_.push_back({node, field, type, std::move(numbers), std::move(strings), std::move(nodes)});
}

void Animator::deliver(const RouteEnd& to, const FieldType& type,
                       const std::vector<double>& numbers, const std::vector<std::string>& strings,
                       const std::vector<NodeId>& nodes) {
    if (is_script(to.node)) {
        std::vector<ScriptEvent> sent;
        scripts_->deliver(to.node, to.field, ScriptValue{type, numbers, strings, nodes}, now_,
                          sent);
        send_script_events(sent);
        return;
    }
    if (changes_children(to)) return change_children(to, nodes);
    if (has_value(to.access)) {
        FieldEntry& e = tree_.fields[entries_.at(key_of(to.node, to.field))];
        if (type.kind == ValueKind::String) {
            e.begin = uint32_t(tree_.strings.size());
            tree_.strings.insert(tree_.strings.end(), strings.begin(), strings.end());
            e.count = uint32_t(strings.size());
        } else if (type.kind == ValueKind::Node) {
            e.begin = uint32_t(tree_.node_refs.size());
            tree_.node_refs.insert(tree_.node_refs.end(), nodes.begin(), nodes.end());
            e.count = uint32_t(nodes.size());
        } else {
            e.begin = uint32_t(tree_.numbers.size());
            tree_.numbers.insert(tree_.numbers.end(), numbers.begin(), numbers.end());
            e.count = uint32_t(numbers.size());
        }
        if (to.access == Access::ExposedField)
            send(to.node, to.field, type, numbers, strings, nodes);  // x_changed
        return;
    }
    if (to.access != Access::EventIn || name_text(to.field) != "set_fraction" || numbers.empty())
        return;  // other eventIns (set_bind, addChildren, ...) change nothing drawn here
    interpolate_at(to.node, numbers[0]);
}

// What the interpolator `node` sends for set_fraction `fraction`: value_changed (or
// EaseInEaseOut's modifiedFraction_changed) through its ROUTEs.
void Animator::interpolate_at(NodeId node, double fraction) {
    static const Name value_changed = intern("value_changed"), key = intern("key"),
                      key_value = intern("keyValue"), modified = intern("modifiedFraction_changed");
    const std::string_view type = tree_.type_name(node);
    const FieldView keys = tree_.get(node, key);
    if (type == "EaseInEaseOut") {
        const std::optional<double> f =
            ease_in_ease_out(keys.numbers, tree_.get(node, "easeInEaseOut").numbers, fraction);
        if (f) send(node, modified, {ValueKind::Float, false}, {*f}, {}, {});
        return;
    }
    if (type == "GeoPositionInterpolator") {
        std::vector<std::string> problems;
        const std::optional<GeoPositionValue> v = geo_position_at(tree_, node, fraction, problems);
        for (const std::string& p : problems)
            warn_once(node, describe(tree_, node) + ": " + p, "geo-system");
        if (!v) return;
        send(node, intern("geovalue_changed"), {ValueKind::Vec3d, false},
             {v->geovalue.x, v->geovalue.y, v->geovalue.z}, {}, {});
        send(node, value_changed, {ValueKind::Vec3f, false}, {v->value.x, v->value.y, v->value.z},
             {}, {});
        return;
    }
    Blend blend = Blend::Linear;
    const bool spline = type.starts_with("Spline"), squad = type == "SquadOrientationInterpolator";
    if (!spline && !squad && !interpolator_blend(type, blend)) {
        warn_once(node,
                  describe(tree_, node) +
                      " is not evaluated (vrmlray evaluates the VRML97 and X3D interpolators); "
                      "what it drives keeps its file values",
                  "interpolator-not-evaluated:" + std::string(type));
        return;
    }
    const FieldView values = tree_.get(node, key_value);
    RouteEnd out_end;
    if (!field_end(node, value_changed, false, out_end)) return;
    size_t width = size_t(components(values.type.kind));
    if (out_end.type.multi) {  // Coordinate, Normal, Coordinate2D: one set of points per key
        if (keys.numbers.empty() || values.numbers.size() % keys.numbers.size() != 0) {
            warn_once(node,
                      describe(tree_, node) +
                          ": keyValue does not hold the same number of values for each key; "
                          "no event is sent",
                      "interpolator-key-count");
            return;
        }
        width = values.numbers.size() / keys.numbers.size();
    }
    std::vector<double> result;
    if (spline) {
        SplineOptions options;
        options.key_velocity = tree_.get(node, "keyVelocity").numbers;
        options.closed = tree_.get_bool(node, intern("closed"));
        options.normalize_velocity = tree_.get_bool(node, intern("normalizeVelocity"));
        result = interpolate_spline(keys.numbers, values.numbers, width, options, fraction);
    } else if (squad) {
        result = interpolate_squad(keys.numbers, values.numbers, fraction);
    } else {
        result = interpolate(keys.numbers, values.numbers, width, blend, fraction);
    }
    if (result.empty()) return;  // no keys: the spec says it sends nothing
    send(node, value_changed, out_end.type, std::move(result), {}, {});
}

bool Animator::evaluate(double now) {
    // Without a TimeSensor no event is ever sent: nothing to restore or change (and the caller
    // may have released the tree after building it once).
    if (!animated_) return false;
    const bool scripted = scripts() > 0;
    if (scripted && evaluated_ && now == now_) return false;  // that time's events were sent
    now_ = now;
    if (!scripted) {
        for (const auto& [k, original] : originals_) tree_.fields[entries_.at(k)] = original;
        // What earlier calls appended is referenced by no entry now: the pools shrink back, so
        // that a long sequence holds one frame's values, not all of them. (With Scripts the world
        // goes on from the last call, as in a browser, and nodes they made hold values there.)
        tree_.numbers.resize(pool_marks_[0]);
        tree_.strings.resize(pool_marks_[1]);
        tree_.node_refs.resize(pool_marks_[2]);
    }
    // A browser has drawn the load's frame before any later one: a Script that keeps state has
    // seen its events (the first cycleTime, isActive TRUE) by the time of the first render.
    if (scripted && !evaluated_ && now > 0.0) send_sensor_events(0.0, true);
    send_sensor_events(now, scripted);
    // What the fields hold now, against the last call.
    bool changed = false;
    last_numbers_.resize(originals_.size());
    last_nodes_.resize(originals_.size());
    for (size_t i = 0; i < originals_.size(); ++i) {
        const FieldView v = tree_.view(tree_.fields[entries_.at(originals_[i].first)]);
        std::vector<double> now_values(v.numbers.begin(), v.numbers.end());
        std::vector<NodeId> now_nodes(v.nodes.begin(), v.nodes.end());
        if (!evaluated_) {
            const FieldView file = tree_.view(originals_[i].second);
            changed |= !std::equal(now_values.begin(), now_values.end(), file.numbers.begin(),
                                   file.numbers.end()) ||
                       !std::equal(now_nodes.begin(), now_nodes.end(), file.nodes.begin(),
                                   file.nodes.end());
        } else {
            changed |= now_values != last_numbers_[i] || now_nodes != last_nodes_[i];
        }
        last_numbers_[i] = std::move(now_values);
        last_nodes_[i] = std::move(now_nodes);
    }
    evaluated_ = true;
    return changed;
}

// The TimeSensors' events at `now`, through the cascade. Without Scripts the world is rebuilt from
// the file's values at each time, so every event a sensor has sent by now goes out again. With
// Scripts (`as_browser`) the world goes on, and the events go out as a browser sends them (VRML97
// 6.50): cycleTime when a cycle begins, isActive when it changes, fraction_changed, time and
// elapsedTime while active and once more at the stop. A Script counting its events then sees the
// same counts from a frame sequence as from one render.
void Animator::send_sensor_events(double now, bool as_browser) {
    fired_.assign(routes_.size(), 0);
    queue_.clear();
    static const Name fraction = intern("fraction_changed"), active = intern("isActive"),
                      time = intern("time"), cycle_time = intern("cycleTime"),
                      elapsed = intern("elapsedTime");
    const FieldType sf_float{ValueKind::Float, false}, sf_bool{ValueKind::Bool, false},
        sf_time{ValueKind::Time, false};
    sent_.resize(sensors_.size());
    for (size_t i = 0; i < sensors_.size(); ++i) {
        const NodeId s = sensors_[i];
        TimeSensorFields f;
        f.cycle_interval = tree_.get_number(s, intern("cycleInterval"));
        f.enabled = tree_.get_bool(s, intern("enabled"));
        f.loop = tree_.get_bool(s, intern("loop"));
        f.start_time = tree_.get_number(s, intern("startTime"));
        f.stop_time = tree_.get_number(s, intern("stopTime"));
        const TimeSensorState st = time_sensor_at(f, now);
        if (!st.sent) continue;
        const std::optional<TimeSensorState> last = as_browser ? sent_[i] : std::nullopt;
        sent_[i] = st;
        const bool changed_activity = !last || last->active != st.active;
        if (changed_activity) send(s, active, sf_bool, {st.active ? 1.0 : 0.0}, {}, {});
        if (!last || (st.active && last->cycle_time != st.cycle_time))
            send(s, cycle_time, sf_time, {st.cycle_time}, {}, {});
        if (!last || st.active || changed_activity) {
            send(s, fraction, sf_float, {st.fraction}, {}, {});
            send(s, time, sf_time, {st.time}, {}, {});
            send(s, elapsed, sf_time, {st.time - f.start_time}, {}, {});
        }
    }
    run_cascade();
}

// Breadth first: the events of one stage go out in ROUTE order before those they cause.
void Animator::run_cascade() {
    for (size_t head = 0; head < queue_.size(); ++head) {
        auto it = routes_from_.find(key_of(queue_[head].node, queue_[head].field));
        if (it == routes_from_.end()) continue;
        const std::vector<uint32_t> targets = it->second;  // a Script's addRoute may add some
        for (uint32_t r : targets) {
            if (fired_[r]) continue;
            fired_[r] = 1;
            const Pending event = queue_[head];  // deliver may grow the queue
            deliver(routes_[r].to, event.type, event.numbers, event.strings, event.nodes);
        }
    }
}

}  // namespace vr
