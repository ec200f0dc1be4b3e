#include "script/natives.h"

#include <cmath>
#include <iostream>

#include "duktape.h"
#include "parser/registry.h"
#include "parser/writer.h"
#include "parser/xml_writer.h"
#include "script/node_merge.h"

namespace vr {
namespace {

void warn_nonfinite(const ScriptRuntime& rt, const std::string& field) {
    rt.host->warn(
        rt.node,
        rt.host->describe(rt.node) + " sent NaN or infinity in " + field + "; 0 is used instead",
        "script-nonfinite");
}

ScriptRuntime& runtime(duk_context* ctx) {
    duk_push_global_stash(ctx);
    duk_get_prop_string(ctx, -1, "runtime");
    auto* rt = static_cast<ScriptRuntime*>(duk_get_pointer(ctx, -1));
    duk_pop_2(ctx);
    return *rt;
}

NodeId node_arg(duk_context* ctx, int index, const NodeTree& tree) {
    const double id = duk_get_number_default(ctx, index, -1);
    if (!(id >= 0) || id >= double(tree.nodes.size())) return kNullNode;
    return NodeId(id);
}

// The field (or event) `name` of `node`'s type: set_x and x_changed name exposedField x.
const FieldDecl* field_of(const NodeTree& tree, NodeId node, std::string_view name) {
    const NodeTypeDecl* decl = tree.decl(node);
    if (!decl) return nullptr;
    const Registry& reg = Registry::builtin();
    if (const FieldDecl* f = reg.lookup_field(decl->spec, *decl, intern(name))) return f;
    if (name.starts_with("set_"))
        return reg.lookup_field(decl->spec, *decl, intern(name.substr(4)));
    if (name.ends_with("_changed"))
        return reg.lookup_field(decl->spec, *decl, intern(name.substr(0, name.size() - 8)));
    return nullptr;
}

duk_ret_t node_type(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    const NodeId node = node_arg(ctx, 0, tree);
    duk_push_string(ctx, node == kNullNode ? "" : std::string(tree.type_name(node)).c_str());
    return 1;
}

duk_ret_t node_field_type(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    const NodeId node = node_arg(ctx, 0, tree);
    const FieldDecl* f =
        node == kNullNode ? nullptr : field_of(tree, node, duk_safe_to_string(ctx, 1));
    duk_push_string(ctx, f ? std::string(type_name(f->type)).c_str() : "");
    return 1;
}

duk_ret_t node_get(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    const NodeId node = node_arg(ctx, 0, tree);
    const FieldDecl* f =
        node == kNullNode ? nullptr : field_of(tree, node, duk_safe_to_string(ctx, 1));
    ScriptValue v;
    if (f) {
        v.type = f->type;
        const FieldView view = tree.get(node, f->name);
        v.numbers.assign(view.numbers.begin(), view.numbers.end());
        v.strings.assign(view.strings.begin(), view.strings.end());
        v.nodes.assign(view.nodes.begin(), view.nodes.end());
    }
    push_flat(ctx, v);
    return 1;
}

duk_ret_t node_set(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    NodeTree& tree = rt.host->tree();
    const NodeId node = node_arg(ctx, 0, tree);
    const std::string name = duk_safe_to_string(ctx, 1);
    const FieldDecl* f = node == kNullNode ? nullptr : field_of(tree, node, name);
    if (!f) return 0;
    size_t nonfinite = 0;
    ScriptValue value = read_flat(ctx, 2, f->type, &nonfinite);
    if (nonfinite > 0) warn_nonfinite(rt, name);
    for (NodeId& id : value.nodes)  // ids the script made up are not nodes
        if (id != kNullNode && id >= tree.nodes.size()) id = kNullNode;
    std::string why;
    if (!rt.host->world().set_field(node, intern(name), value, why))
        rt.host->warn(rt.node,
                      rt.host->describe(rt.node) + ": cannot set " +
                          std::string(tree.type_name(node)) + "." + name + ": " + why,
                      "script-set");
    return 0;
}

duk_ret_t create_nodes(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    NodeTree& tree = rt.host->tree();
    const std::string text = duk_safe_to_string(ctx, 0);
    const bool x3d = duk_to_boolean(ctx, 1);
    const SourceLoc at = tree.nodes[rt.node].loc;
    std::filesystem::path anchor = "createVrmlFromString.wrl";
    const ScriptSettings& s = rt.host->settings();
    if (s.sources && at.valid())
        anchor = std::filesystem::path(s.sources->file(at.file).path).parent_path() / anchor;
    std::string error;
    const std::vector<NodeId> nodes =
        read_nodes_into(tree, text, x3d, anchor, s.allowed_roots, tree.nodes[rt.node].loc, error);
    if (!error.empty())
        rt.host->warn(rt.node,
                      rt.host->describe(rt.node) + ": " +
                          (x3d ? "createX3DFromString" : "createVrmlFromString") +
                          " makes no nodes: " + error,
                      "script-create");
    duk_push_array(ctx);
    for (size_t i = 0; i < nodes.size(); ++i) {
        duk_push_number(ctx, nodes[i]);
        duk_put_prop_index(ctx, -2, duk_uarridx_t(i));
    }
    return 1;
}

duk_ret_t route(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    const NodeTree& tree = rt.host->tree();
    const bool add = duk_to_boolean(ctx, 0);
    const NodeId from = node_arg(ctx, 1, tree), to = node_arg(ctx, 3, tree);
    const std::string from_event = duk_safe_to_string(ctx, 2),
                      to_event = duk_safe_to_string(ctx, 4);
    std::string why = "a node is NULL";
    if (from == kNullNode || to == kNullNode ||
        !rt.host->world().route(add, from, intern(from_event), to, intern(to_event), why))
        rt.host->warn(rt.node,
                      rt.host->describe(rt.node) + ": Browser." +
                          (add ? "addRoute" : "deleteRoute") + " of " + from_event + " to " +
                          to_event + " ignored: " + why,
                      "script-route");
    return 0;
}

duk_ret_t print(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    if (!rt.host->settings().quiet)
        std::cerr << rt.host->describe(rt.node) << ": " << duk_safe_to_string(ctx, 0) << "\n";
    return 0;
}

duk_ret_t warn(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    rt.host->warn(rt.node, rt.host->describe(rt.node) + ": " + duk_safe_to_string(ctx, 0),
                  "script-api");
    return 0;
}

duk_ret_t now(duk_context* ctx) {
    duk_push_number(ctx, runtime(ctx).now);
    return 1;
}

// SplitMix64 (Steele, Lea and Flood 2014): one 64-bit state, full period, 53 random bits a call.
duk_ret_t random_double(duk_context* ctx) {
    uint64_t& state = runtime(ctx).random_state;
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    duk_push_number(ctx, double(z >> 11) * 0x1.0p-53);
    return 1;
}

duk_ret_t version(duk_context* ctx) {
    duk_push_string(ctx, "0.1");
    return 1;
}

duk_ret_t world_url(duk_context* ctx) {
    ScriptRuntime& rt = runtime(ctx);
    const ScriptSettings& s = rt.host->settings();
    const SourceLoc at = rt.host->tree().nodes[rt.node].loc;
    duk_push_string(ctx, s.sources && at.valid() && s.sources->size() > 0
                             ? s.sources->file(0).path.c_str()
                             : "");
    return 1;
}

// Browser.currentScene (X3D 19777-1 7.4, X3DScene): the world as it is now, written by `vrmlray
// convert`'s writers (classic X3D, or XML when the argument is true).
duk_ret_t scene_text(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    const std::string text =
        duk_to_boolean(ctx, 0) ? write_x3d_xml(tree) : write_classic(tree, Encoding::X3dClassic);
    duk_push_lstring(ctx, text.data(), text.size());
    return 1;
}

duk_ret_t root_nodes(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    duk_push_array(ctx);
    for (size_t i = 0; i < tree.roots.size(); ++i) {
        duk_push_number(ctx, tree.roots[i]);
        duk_put_prop_index(ctx, -2, duk_uarridx_t(i));
    }
    return 1;
}

// The node the main file's first DEF of that name gives; -1 when none.
duk_ret_t named_node(duk_context* ctx) {
    const NodeTree& tree = runtime(ctx).host->tree();
    const Name name = intern(duk_safe_to_string(ctx, 0));
    for (NodeId i = 0; i < tree.nodes.size(); ++i)
        if (tree.nodes[i].def_name == name) {
            duk_push_number(ctx, i);
            return 1;
        }
    duk_push_number(ctx, -1);
    return 1;
}

}  // namespace

void install_natives(duk_context* ctx, ScriptRuntime& rt) {
    duk_push_global_stash(ctx);
    duk_push_pointer(ctx, &rt);
    duk_put_prop_string(ctx, -2, "runtime");
    duk_pop(ctx);
    const struct {
        const char* name;
        duk_c_function f;
        duk_idx_t nargs;
    } natives[] = {{"__nodeType", node_type, 1},
                   {"__nodeFieldType", node_field_type, 2},
                   {"__nodeGet", node_get, 2},
                   {"__nodeSet", node_set, 3},
                   {"__createNodes", create_nodes, 2},
                   {"__route", route, 5},
                   {"__print", print, 1},
                   {"__warn", warn, 1},
                   {"__now", now, 0},
                   {"__version", version, 0},
                   {"__worldUrl", world_url, 0},
                   {"__sceneText", scene_text, 1},
                   {"__rootNodes", root_nodes, 0},
                   {"__namedNode", named_node, 1}};
    for (const auto& n : natives) {
        duk_push_c_function(ctx, n.f, n.nargs);
        duk_put_global_string(ctx, n.name);
    }
    // Duktape seeds its own Math.random from the clock: two renders of one file would differ.
    rt.random_state = 0x243F6A8885A308D3ull ^ (uint64_t(rt.node) * 0x9E3779B97F4A7C15ull);
    duk_get_global_string(ctx, "Math");
    duk_push_c_function(ctx, random_double, 0);
    duk_put_prop_string(ctx, -2, "random");
    duk_pop(ctx);
}

void push_flat(duk_context* ctx, const ScriptValue& value) {
    duk_push_array(ctx);
    duk_uarridx_t i = 0;
    if (value.type.kind == ValueKind::String) {
        for (const std::string& s : value.strings) {
            duk_push_lstring(ctx, s.data(), s.size());
            duk_put_prop_index(ctx, -2, i++);
        }
    } else if (value.type.kind == ValueKind::Node) {
        for (NodeId n : value.nodes) {
            duk_push_number(ctx, n == kNullNode ? -1.0 : double(n));
            duk_put_prop_index(ctx, -2, i++);
        }
    } else {
        for (double x : value.numbers) {
            duk_push_number(ctx, x);
            duk_put_prop_index(ctx, -2, i++);
        }
    }
}

ScriptValue read_flat(duk_context* ctx, int index, FieldType type, size_t* nonfinite) {
    ScriptValue v;
    v.type = type;
    index = duk_normalize_index(ctx, index);
    if (!duk_is_array(ctx, index)) return v;
    const duk_size_t n = duk_get_length(ctx, index);
    for (duk_size_t i = 0; i < n; ++i) {
        duk_get_prop_index(ctx, index, duk_uarridx_t(i));
        if (type.kind == ValueKind::String) {
            duk_size_t len = 0;
            const char* s = duk_safe_to_lstring(ctx, -1, &len);
            v.strings.emplace_back(s, len);
        } else if (type.kind == ValueKind::Node) {
            const double id = duk_get_number_default(ctx, -1, -1);
            v.nodes.push_back(id >= 0 && id < double(kNullNode) ? NodeId(id) : kNullNode);
        } else {
            // NaN or infinity never reaches the scene: 0 instead, and the caller warns.
            const double x = duk_get_number_default(ctx, -1, 0.0);
            if (!std::isfinite(x) && nonfinite) ++*nonfinite;
            v.numbers.push_back(std::isfinite(x) ? x : 0.0);
        }
        duk_pop(ctx);
    }
    return v;
}

void read_outputs(duk_context* ctx, const ScriptRuntime& rt, std::vector<ScriptEvent>& out) {
    if (!duk_is_array(ctx, -1)) return;
    const duk_size_t n = duk_get_length(ctx, -1);
    for (duk_size_t i = 0; i < n; ++i) {
        duk_get_prop_index(ctx, -1, duk_uarridx_t(i));
        duk_get_prop_index(ctx, -1, 0);
        const Name name = intern(duk_safe_to_string(ctx, -1));
        duk_pop(ctx);
        if (const ScriptField* f = rt.host->field(rt.node, name)) {
            duk_get_prop_index(ctx, -1, 1);
            size_t nonfinite = 0;
            ScriptEvent e{rt.node, name, read_flat(ctx, -1, f->type, &nonfinite)};
            if (nonfinite > 0) warn_nonfinite(rt, std::string(name_text(name)));
            // Node ids the script made up are not nodes.
            for (NodeId& id : e.value.nodes)
                if (id != kNullNode && id >= rt.host->tree().nodes.size()) id = kNullNode;
            out.push_back(std::move(e));
            duk_pop(ctx);
        }
        duk_pop(ctx);
    }
}

}  // namespace vr
