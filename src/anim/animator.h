// The world at time T (docs/animation.md): TimeSensors send their events, interpolators map them,
// and ROUTEs carry them into fields of the node tree, which the scene build then reads as it reads
// any file value. The tracer never sees time.
//
//     Animator animator(loaded.tree, loaded.diagnostics);  // checks every ROUTE
//     animator.evaluate(t);                                // fields hold their values at t
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "anim/time_sensor.h"
#include "parser/diagnostics.h"
#include "parser/node_tree.h"
#include "script/script_host.h"

namespace vr {

// One end of a ROUTE matched to a field: an exposedField (its value lives in the tree), or an
// event of the node (eventIn, eventOut).
struct RouteEnd {
    NodeId node = kNullNode;
    Name field = kNoName;  // the field's own name: "translation" for set_translation
    FieldType type;
    Access access = Access::Field;
};

struct ResolvedRoute {
    RouteEnd from, to;
    PackedLoc loc;
};

class Animator : private ScriptWorld {
  public:
    // Matches every ROUTE of `tree` to fields (set_x and x_changed name the exposedField x; a
    // PROTO instance's events reach its body through IS) and checks it: mismatched types are
    // errors, unknown events warnings. `tree` must outlive this. Scripts (docs/scripts.md) run
    // with `scripts` (null: the defaults, .js files not found); their initialize() runs here, at
    // time 0, and what it sends becomes part of the world. A file without Scripts starts no
    // script engine.
    Animator(NodeTree& tree, Diagnostics& diagnostics, const ScriptSettings* scripts = nullptr);
    ~Animator() override;

    // True when some TimeSensor reaches a field through ROUTEs: the scene changes with time.
    bool animated() const { return animated_; }
    const std::vector<ResolvedRoute>& routes() const { return routes_; }
    // Where the checks, and the Scripts' errors of every evaluate(), are collected.
    const Diagnostics& diagnostics() const { return diagnostics_; }

    // Gives every field ROUTEs reach its file value back, then runs the event cascade of time `now`
    // (seconds on the world's clock; the tree must still be there when animated() is true): each
    // TimeSensor's last events, then every event through the
    // ROUTEs from it in ROUTE order, each ROUTE at most once (which also ends loops). Returns
    // true when some field now holds another value than after the previous call (the first call:
    // than in the file).
    //
    // With Scripts the world is not reset between calls (a Script keeps its state, and what it
    // set stays, as in a browser): calls must come in time order, and a call at the time of
    // the last one changes nothing.
    bool evaluate(double now);
    // Scripts that run (0 without Scripts, or with them turned off).
    size_t scripts() const { return scripts_ ? scripts_->size() : 0; }

  private:
    // ScriptWorld: what a Script may do to other nodes.
    bool set_field(NodeId node, Name field, const ScriptValue& value, std::string& why) override;
    bool route(bool add, NodeId from, Name from_event, NodeId to, Name to_event,
               std::string& why) override;
    double now() const override { return now_; }
    void start_scripts(const ScriptSettings& settings);
    void run_cascade();
    void send_script_events(std::vector<ScriptEvent>& events);
    bool is_script(NodeId node) const { return scripts_ && tree_.scripts.count(node) > 0; }
    void change_children(const RouteEnd& to, const std::vector<NodeId>& nodes);
    bool script_end(NodeId node, Name event, bool input, RouteEnd& end) const;
    static bool changes_children(const RouteEnd& end);

    void resolve(const Route& route);
    void resolve_end(NodeId node, Name event, bool input, std::vector<RouteEnd>& out, int depth);
    bool field_end(NodeId node, Name event, bool input, RouteEnd& end) const;
    uint32_t own_entry(NodeId node, Name field);
    void send(NodeId node, Name field, const FieldType& type, std::vector<double> numbers,
              std::vector<std::string> strings, std::vector<NodeId> nodes);
    void deliver(const RouteEnd& to, const FieldType& type, const std::vector<double>& numbers,
                 const std::vector<std::string>& strings, const std::vector<NodeId>& nodes);
    void interpolate_at(NodeId node, double fraction);
    void warn_once(NodeId node, const std::string& message, const std::string& cause);
    void send_sensor_events(double now, bool as_browser);

    NodeTree& tree_;
    Diagnostics& diagnostics_;
    std::vector<ResolvedRoute> routes_;
    std::unordered_map<uint64_t, std::vector<uint32_t>> routes_from_;  // (node, field) -> routes
    std::unordered_map<uint64_t, std::vector<uint32_t>> is_index_;     // (instance, field) -> links
    std::vector<NodeId> sensors_;                                      // TimeSensors, in file order
    std::vector<std::optional<TimeSensorState>> sent_;  // per sensor, its last events (Scripts)
    // Entries (into tree.fields) that ROUTEs write, with the value each had in the file.
    std::unordered_map<uint64_t, uint32_t> entries_;
    std::vector<std::pair<uint64_t, FieldEntry>> originals_;  // (node, field) -> file value
    std::vector<std::vector<double>> last_numbers_;  // per originals_ entry, after the last call
    struct Pending {
        NodeId node;
        Name field;
        FieldType type;
        std::vector<double> numbers;
        std::vector<std::string> strings;
        std::vector<NodeId> nodes;
    };
    std::vector<Pending> queue_;
    std::vector<char> fired_;
    std::array<size_t, 3> pool_marks_{};  // numbers, strings, node_refs sizes before any event
    std::unordered_set<NodeId> warned_scripts_;
    bool animated_ = false;
    bool evaluated_ = false;
    std::unique_ptr<ScriptHost> scripts_;          // null: no Script in the file, or --no-scripts
    double now_ = 0.0;                             // the time of the cascade running
    std::vector<std::vector<NodeId>> last_nodes_;  // per originals_ entry, node values
};

}  // namespace vr
