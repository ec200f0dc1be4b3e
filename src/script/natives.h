// The host functions a Script's prelude calls (node fields, createVrmlFromString, routes, print),
// and the conversions between the cascade's values and the prelude's flat arrays.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "script/heap.h"
#include "script/script_host.h"

namespace vr {

struct ScriptRuntime {
    NodeId node = kNullNode;
    ScriptHost* host = nullptr;
    std::string file_name;  // what Duktape names the script in errors: "Script 'NAME'"
    std::unique_ptr<ScriptHeap> heap;
    bool dead = false;  // ran out of time or memory: not run again
    double now = 0.0;   // the time of the event being handled
    // Math.random's state: a fixed seed (set from the node by the host), so that a Script that
    // draws random numbers renders the same image every run, as a golden-image test needs.
    uint64_t random_state = 0;
};

// Defines __nodeType, __nodeFieldType, __nodeGet, __nodeSet, __createNodes, __route, __print,
// __warn, __now, __version and __worldUrl in the heap's global object, and replaces Math.random
// with a generator seeded from the Script's node id (docs/scripts.md).
void install_natives(duk_context* ctx, ScriptRuntime& rt);
// Pushes `value` as the prelude's flat array (numbers, strings, or node ids with -1 for NULL).
void push_flat(duk_context* ctx, const ScriptValue& value);
// The array at `index` as a value of `type`; NaN and infinities become 0, counted in `nonfinite`.
ScriptValue read_flat(duk_context* ctx, int index, FieldType type, size_t* nonfinite = nullptr);
// __call()'s result at the stack top, [[name, flat], ...], as events of the Script's eventOuts.
void read_outputs(duk_context* ctx, const ScriptRuntime& rt, std::vector<ScriptEvent>& out);

}  // namespace vr
