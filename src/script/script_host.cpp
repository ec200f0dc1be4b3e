#include "script/script_host.h"

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <iostream>

#include "duktape.h"
#include "parser/load.h"
#include "parser/registry.h"
#include "script/natives.h"
#include "script/prelude.h"

namespace vr {
namespace {

constexpr std::string_view kProtocols[] = {"javascript:", "vrmlscript:", "ecmascript:"};

// The script text after a javascript:/vrmlscript:/ecmascript: prefix, or nothing.
bool inline_script(std::string_view url, std::string& text) {
    const size_t first = url.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) return false;
    url.remove_prefix(first);
    for (std::string_view p : kProtocols) {
        if (url.size() < p.size()) continue;
        std::string head(url.substr(0, p.size()));
        std::transform(head.begin(), head.end(), head.begin(), ::tolower);
        if (head == p) {
            text = std::string(url.substr(p.size()));
            return true;
        }
    }
    return false;
}

// Runs the function and arguments on the stack. No C++ object with a destructor may live in this
// frame: Duktape's fatal handler longjmps back here.
int guarded_pcall(ScriptHeap& heap, int nargs) {
    std::jmp_buf exit;
    heap.fatal_exit = &exit;
    if (setjmp(exit) != 0) {
        heap.fatal_exit = nullptr;
        return -1;
    }
    const int rc = duk_pcall(heap.ctx, nargs);
    heap.fatal_exit = nullptr;
    return rc;
}

// "line N of its script: TypeError: ..." of the error at the stack top.
std::string error_text(duk_context* ctx, const std::string& script_file) {
    std::string where;
    if (duk_is_error(ctx, -1)) {
        duk_get_prop_string(ctx, -1, "fileName");
        const std::string file = duk_safe_to_string(ctx, -1);
        duk_pop(ctx);
        duk_get_prop_string(ctx, -1, "lineNumber");
        const int line = duk_is_number(ctx, -1) ? duk_get_int(ctx, -1) : 0;
        duk_pop(ctx);
        if (file == script_file && line > 0)
            where = "line " + std::to_string(line) + " of its script: ";
        else if (line > 0)
            where = "in the field binding (" + file + " line " + std::to_string(line) + "): ";
    }
    return where + duk_safe_to_string(ctx, -1);
}

}  // namespace

ScriptHost::ScriptHost(NodeTree& tree, Diagnostics& diagnostics, ScriptSettings settings,
                       ScriptWorld& world)
    : tree_(tree), diagnostics_(diagnostics), settings_(std::move(settings)), world_(world) {
    std::vector<NodeId> scripts;
    for (const auto& [id, iface] : tree_.scripts) scripts.push_back(id);
    std::sort(scripts.begin(), scripts.end());  // node order is file order
    for (NodeId id : scripts) {
        std::string text, why;
        if (!script_text(id, text, why)) {
            if (!why.empty()) warn(id, describe(id) + " is not run: " + why, "script-source");
            continue;
        }
        auto rt = std::make_unique<ScriptRuntime>();
        rt->node = id;
        rt->host = this;
        rt->file_name = describe(id);
        rt->heap = std::make_unique<ScriptHeap>(settings_.limits);
        if (!rt->heap->ctx) {
            warn(id, describe(id) + " is not run: no memory for its heap", "script-heap");
            continue;
        }
        if (!start(*rt, text)) continue;
        runtimes_.push_back(std::move(rt));
    }
}

ScriptHost::~ScriptHost() = default;

std::string ScriptHost::describe(NodeId script) const {
    const std::string_view def = tree_.def_name(script);
    return def.empty() ? std::string("Script") : "Script '" + std::string(def) + "'";
}

void ScriptHost::warn(NodeId script, const std::string& message, const std::string& cause) {
    diagnostics_.warning(tree_.nodes[script].loc, message,
                         cause + ":" + std::to_string(script) + ":" + message);
}

// The script of the first url entry that gives one (the X3D XML text content first).
bool ScriptHost::script_text(NodeId id, std::string& text, std::string& why) const {
    const ScriptInterface& iface = tree_.scripts.at(id);
    if (iface.source.find_first_not_of(" \t\r\n") != std::string::npos) {
        if (!inline_script(iface.source, text)) text = iface.source;
        return true;
    }
    UrlFailures failures;
    const SourceLoc loc = tree_.nodes[id].loc;
    for (const std::string& url : tree_.get(id, "url").strings) {
        if (inline_script(url, text)) return true;
        // Another language's inline text (castlescript:) or a Java class: named, never looked up.
        const std::string_view head = std::string_view(url).substr(0, url.find(':'));
        if (head.size() < url.size() && head.ends_with("script")) {
            failures.add(std::string(head) + ": is not ECMAScript");
            continue;
        }
        if (url.ends_with(".class")) {
            failures.add(url + ": Java is not run");
            continue;
        }
        if (!settings_.sources || !loc.valid()) {
            failures.add(url + ": no file to resolve it from");
            continue;
        }
        const std::filesystem::path from = settings_.sources->file(loc.file).path;
        const std::filesystem::path path =
            resolve_or_note(url, from, settings_.allowed_roots, failures, true);
        if (path.empty()) continue;
        try {
            text = read_file_bytes(path, size_t(64) << 20);
            return true;
        } catch (const std::exception& e) {
            failures.add(url + ": " + e.what());
        }
    }
    // A Script with no URL at all (a parser test's) has nothing to run, and nothing to say.
    if (!failures.reasons.empty()) why = "its url gives no script (" + failures.message() + ")";
    return false;
}

// The prelude, the natives, the Script's fields as globals, then its own text run once.
bool ScriptHost::start(ScriptRuntime& rt, const std::string& text) {
    duk_context* ctx = rt.heap->ctx;
    install_natives(ctx, rt);
    duk_push_string(ctx, "prelude");
    if (duk_pcompile_string_filename(ctx, 0, kScriptPrelude) != 0 || duk_pcall(ctx, 0) != 0) {
        warn(rt.node, describe(rt.node) + " is not run: " + error_text(ctx, ""), "script-prelude");
        return false;
    }
    duk_pop(ctx);
    for (const ScriptField& f : tree_.scripts.at(rt.node).fields) {
        if (f.access == Access::EventIn) continue;  // its function has the name
        duk_get_global_string(ctx, "__declare");
        duk_push_string(ctx, std::string(name_text(f.name)).c_str());
        duk_push_string(ctx, std::string(type_name(f.type)).c_str());
        duk_push_boolean(ctx, f.access == Access::EventOut || f.access == Access::ExposedField);
        ScriptValue v;
        v.type = f.type;
        if (f.value.count > 0) {
            const FieldView view = tree_.view(f.value);
            v.numbers.assign(view.numbers.begin(), view.numbers.end());
            v.strings.assign(view.strings.begin(), view.strings.end());
            v.nodes.assign(view.nodes.begin(), view.nodes.end());
        }
        push_flat(ctx, v);
        if (duk_pcall(ctx, 4) != 0) {
            warn(rt.node, describe(rt.node) + " is not run: " + error_text(ctx, ""),
                 "script-field");
            return false;
        }
        duk_pop(ctx);
    }
    duk_push_lstring(ctx, text.data(), text.size());
    duk_push_string(ctx, rt.file_name.c_str());
    if (duk_pcompile(ctx, 0) != 0) {
        warn(rt.node, describe(rt.node) + " is not run: " + error_text(ctx, rt.file_name),
             "script-compile");
        return false;
    }
    std::vector<ScriptEvent> unused;
    return run(rt, 0, "its top-level code", unused);
}

// Calls what start() or call() put on the stack, under the time budget; the outputs it returns
// (call()'s) go to `out`. False, with a warning, when it threw, ran out of time or memory.
bool ScriptHost::run(ScriptRuntime& rt, int nargs, const std::string& what,
                     std::vector<ScriptEvent>& out) {
    ScriptHeap& heap = *rt.heap;
    heap.timed_out = heap.interrupted = false;
    heap.deadline = std::chrono::steady_clock::now() +
                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(heap.limits.seconds_per_call));
    const int rc = guarded_pcall(heap, nargs);
    heap.deadline = std::chrono::steady_clock::time_point::max();
    if (rc == -1) {
        rt.dead = true;
        warn(rt.node,
             describe(rt.node) + ": " + what + " ended the script engine (" + heap.fatal_message +
                 ", heap limit " + std::to_string(heap.limits.heap_bytes >> 20) +
                 " MiB); the Script is not run again",
             "script-fatal");
        return false;
    }
    duk_context* ctx = heap.ctx;
    if (rc != 0) {
        std::string message = error_text(ctx, rt.file_name);
        if (heap.timed_out) {
            rt.dead = true;
            char seconds[32];
            std::snprintf(seconds, sizeof seconds, "%g", heap.limits.seconds_per_call);
            message = "ran longer than " + std::string(seconds) + " s (" + message +
                      "); its outputs are dropped and the Script is not run again";
        } else {
            message += "; that call's outputs are dropped";
        }
        warn(rt.node, describe(rt.node) + ": " + what + " " + message, "script-error");
        duk_pop(ctx);
        return false;
    }
    read_outputs(ctx, rt, out);
    duk_pop(ctx);
    return true;
}

bool ScriptHost::runs(NodeId script) const {
    for (const auto& rt : runtimes_)
        if (rt->node == script) return !rt->dead;
    return false;
}

const ScriptField* ScriptHost::field(NodeId script, Name name) const {
    auto it = tree_.scripts.find(script);
    return it == tree_.scripts.end() ? nullptr : it->second.find(name);
}

bool ScriptHost::call(ScriptRuntime& rt, const std::string& function, Name field,
                      const ScriptValue* value, double now, std::vector<ScriptEvent>& out) {
    if (rt.dead) return false;
    duk_context* ctx = rt.heap->ctx;
    rt.now = now;
    duk_get_global_string(ctx, "__call");
    duk_push_string(ctx, function.c_str());
    duk_push_string(ctx, field == kNoName ? "" : std::string(name_text(field)).c_str());
    duk_push_string(ctx, value ? std::string(type_name(value->type)).c_str() : "");
    if (value)
        push_flat(ctx, *value);
    else
        duk_push_array(ctx);
    duk_push_number(ctx, now);
    return run(rt, 5,
               function == "initialize" || function == "eventsProcessed"
                   ? function + "()"
                   : "event function " + function + "()",
               out);
}

void ScriptHost::initialize(std::vector<ScriptEvent>& out) {
    for (auto& rt : runtimes_) call(*rt, "initialize", kNoName, nullptr, 0.0, out);
}

void ScriptHost::deliver(NodeId script, Name event, const ScriptValue& value, double now,
                         std::vector<ScriptEvent>& out) {
    for (auto& rt : runtimes_) {
        if (rt->node != script || rt->dead) continue;
        const ScriptField* f = field(script, event);
        if (!f) return;
        const std::string name(name_text(event));
        std::string function = name;
        if (f->access == Access::ExposedField) {  // set_x(), else x() for an inputOutput field
            duk_get_global_string(rt->heap->ctx, "__hasFunction");
            duk_push_string(rt->heap->ctx, ("set_" + name).c_str());
            if (duk_pcall(rt->heap->ctx, 1) == 0 && duk_get_boolean(rt->heap->ctx, -1))
                function = "set_" + name;
            duk_pop(rt->heap->ctx);
        }
        if (call(*rt, function, f->access == Access::ExposedField ? event : kNoName, &value, now,
                 out))
            call(*rt, "eventsProcessed", kNoName, nullptr, now, out);
        return;
    }
}

}  // namespace vr
