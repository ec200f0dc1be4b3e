// Runs the ECMAScript of Script nodes (VRML97 Annex C, ISO/IEC 19777-1; docs/scripts.md) for the
// event cascade of src/anim/: each Script gets a Duktape heap of its own, with its fields as
// globals, initialize() at load, and a function call per event that reaches it. What it sends
// comes back as ScriptEvents for the cascade to route; what it does to other nodes (directOutput,
// createVrmlFromString, addRoute) goes through the ScriptWorld the caller gives.
//
//     ScriptHost host(tree, diagnostics, settings, world);   // compiles every Script
//     host.initialize(events);                                // initialize() in file order
//     host.deliver(script, event, value, now, events);        // an event reaching a Script
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "parser/node_tree.h"
#include "parser/source.h"
#include "script/heap.h"

namespace vr {

// A field's value as the cascade carries it: the numbers, strings or nodes of its type.
struct ScriptValue {
    FieldType type;
    std::vector<double> numbers;
    std::vector<std::string> strings;
    std::vector<NodeId> nodes;
};

// An eventOut a Script sent.
struct ScriptEvent {
    NodeId script = kNullNode;
    Name field = kNoName;
    ScriptValue value;
};

struct ScriptSettings {
    bool enabled = true;  // --no-scripts: false
    bool quiet = false;   // --quiet: print() and println() say nothing
    ScriptLimits limits;
    const SourceManager* sources = nullptr;  // to find a Script's file (for .js URLs)
    // Folders .js URLs are confined to (--sandbox; empty: not confined), as for other URLs.
    std::vector<std::filesystem::path> allowed_roots;
};

// What a Script may do to the world beyond its own eventOuts; src/anim/ implements it.
class ScriptWorld {
  public:
    virtual ~ScriptWorld() = default;
    // directOutput: `node`.`field` (or an eventIn of it) takes `value`; false and `why` when not.
    virtual bool set_field(NodeId node, Name field, const ScriptValue& value, std::string& why) = 0;
    virtual bool route(bool add, NodeId from, Name from_event, NodeId to, Name to_event,
                       std::string& why) = 0;
    virtual double now() const = 0;
};

struct ScriptRuntime;  // one Script's heap and its interface

class ScriptHost {
  public:
    // Compiles every Script of `tree` (in file order): a Script whose URL gives no script, or
    // whose script does not compile, is warned about and left out.
    ScriptHost(NodeTree& tree, Diagnostics& diagnostics, ScriptSettings settings,
               ScriptWorld& world);
    ~ScriptHost();

    // Scripts that compiled.
    size_t size() const { return runtimes_.size(); }
    bool runs(NodeId script) const;
    // The declared interface of a Script, or null.
    const ScriptField* field(NodeId script, Name name) const;

    // initialize() of every Script, in file order, at time 0.
    void initialize(std::vector<ScriptEvent>& out);
    // The event `event` (an eventIn or inputOutput field of `script`) with `value` at `now`:
    // the function of that name, then eventsProcessed(). Outputs are appended to `out`.
    void deliver(NodeId script, Name event, const ScriptValue& value, double now,
                 std::vector<ScriptEvent>& out);

    NodeTree& tree() { return tree_; }
    // Warns once per Script and cause, at the Script.
    void warn(NodeId script, const std::string& message, const std::string& cause);
    std::string describe(NodeId script) const;
    const ScriptSettings& settings() const { return settings_; }
    ScriptWorld& world() { return world_; }

  private:
    bool script_text(NodeId id, std::string& text, std::string& why) const;
    bool start(ScriptRuntime& rt, const std::string& text);
    bool run(ScriptRuntime& rt, int nargs, const std::string& what, std::vector<ScriptEvent>& out);
    bool call(ScriptRuntime& rt, const std::string& function, Name field, const ScriptValue* value,
              double now, std::vector<ScriptEvent>& out);

    NodeTree& tree_;
    Diagnostics& diagnostics_;
    ScriptSettings settings_;
    ScriptWorld& world_;
    std::vector<std::unique_ptr<ScriptRuntime>> runtimes_;  // in file order
};

}  // namespace vr
