// The bounds that keep hostile input from exhausting the machine (docs/input.md and
// docs/rendering.md, Numbers), in one place, each with its default and the name `--limit
// NAME=VALUE` raises or lowers it by.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "flatten/flatten.h"
#include "parser/load.h"

namespace vr {

struct Limits {
    LoadLimits
        load;  // reader: nesting, PROTO depth, nodes, Inline depth and count, file size, MF length
    // flattening: against instancing blow-up
    size_t max_primitives = FlattenOptions().max_primitives;
    size_t max_triangles = FlattenOptions().max_triangles;
    size_t max_group_visits = FlattenOptions().max_group_visits;
    size_t max_texture_pixels =
        FlattenOptions().max_texture_pixels;  // checked from the image's header

    void apply(FlattenOptions& options) const;
};

struct LimitInfo {
    const char* name;  // as written after --limit
    const char* meaning;
    size_t value;  // the default
};

// Every limit with its default, in the order the README and --help list them.
std::vector<LimitInfo> limit_table();

// Parses "NAME=VALUE" (VALUE a positive integer, optionally with a k, M or G suffix for 1e3, 1e6,
// 1e9) into `limits`; false and a message naming the known limits when it is not one of them.
bool parse_limit(const std::string& text, Limits& limits, std::string& error);

}  // namespace vr
