#include "app/limits.h"

#include <charconv>

namespace vr {
namespace {

struct Entry {
    const char* name;
    const char* meaning;
    size_t Limits::*flatten;  // one of the two is set
    size_t LoadLimits::*load;
};

const Entry kEntries[] = {
    {"nesting-depth", "nodes inside nodes, in one file", nullptr, &LoadLimits::max_nesting_depth},
    {"proto-depth", "PROTO instances inside PROTO bodies", nullptr, &LoadLimits::max_proto_depth},
    {"nodes", "nodes in all, PROTO bodies expanded", nullptr, &LoadLimits::max_nodes},
    {"inline-depth", "Inline files inside Inline files", nullptr, &LoadLimits::max_inline_depth},
    {"inline-files", "Inline and EXTERNPROTO files read", nullptr, &LoadLimits::max_inline_files},
    {"file-bytes", "bytes of one file after gzip decompression", nullptr,
     &LoadLimits::max_file_bytes},
    {"mf-values", "numbers or strings in one field", nullptr, &LoadLimits::max_mf_values},
    {"primitives", "spheres, quadrics and meshes after instancing", &Limits::max_primitives,
     nullptr},
    {"triangles", "triangles after instancing", &Limits::max_triangles, nullptr},
    {"group-visits", "grouping nodes visited while instancing", &Limits::max_group_visits, nullptr},
    {"texture-pixels", "pixels of one texture image (a larger one is ignored, with a warning)",
     &Limits::max_texture_pixels, nullptr},
};

}  // namespace

void Limits::apply(FlattenOptions& options) const {
    options.max_primitives = max_primitives;
    options.max_triangles = max_triangles;
    options.max_group_visits = max_group_visits;
    options.max_texture_pixels = max_texture_pixels;
}

std::vector<LimitInfo> limit_table() {
    const Limits defaults;
    std::vector<LimitInfo> table;
    for (const Entry& e : kEntries)
        table.push_back({e.name, e.meaning, e.load ? defaults.load.*e.load : defaults.*e.flatten});
    return table;
}

bool parse_limit(const std::string& text, Limits& limits, std::string& error) {
    const size_t eq = text.find('=');
    const std::string name = text.substr(0, eq);
    const Entry* entry = nullptr;
    for (const Entry& e : kEntries)
        if (name == e.name) entry = &e;
    if (!entry || eq == std::string::npos) {
        error = "--limit wants NAME=VALUE with NAME one of";
        for (const Entry& e : kEntries) error += std::string(" ") + e.name;
        error += " (got '" + text + "')";
        return false;
    }
    const char* first = text.data() + eq + 1;
    const char* last = text.data() + text.size();
    size_t value = 0;
    auto [end, ec] = std::from_chars(first, last, value);
    size_t scale = 1;
    if (ec == std::errc() && end + 1 == last) {
        scale = *end == 'k' ? 1000 : *end == 'M' ? 1000'000 : *end == 'G' ? 1000'000'000 : 0;
        end = scale ? last : end;
    }
    if (ec != std::errc() || end != last || value == 0 || value > SIZE_MAX / scale) {
        error = "--limit " + name +
                " wants a positive whole number, optionally with k, M or G (got '" +
                text.substr(eq + 1) + "')";
        return false;
    }
    // A place in a file holds a 38-bit offset (parser/source.h, PackedLoc): a larger file would be
    // misread, not refused.
    if (entry->load == &LoadLimits::max_file_bytes && value * scale > kMaxSourceBytes) {
        error = "--limit file-bytes is at most " + std::to_string(kMaxSourceBytes) +
                " (256 GiB, the offsets a place in a file holds; got '" + text.substr(eq + 1) +
                "')";
        return false;
    }
    (entry->load ? limits.load.*entry->load : limits.*entry->flatten) = value * scale;
    return true;
}

}  // namespace vr
