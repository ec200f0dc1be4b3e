#include "scene/report.h"

#include <algorithm>

namespace vr {

std::string node_label(const sg::Origin& origin) {
    std::string label(origin.type == kNoName ? std::string_view("node") : origin.type_text());
    if (origin.def_name != kNoName) {
        label += " '";
        label += origin.def_text();
        label += "'";
    }
    return label;
}

void NodeReport::warn(std::string_view cause, std::string_view message) {
    if (std::find(reported_.begin(), reported_.end(), cause) != reported_.end()) return;
    reported_.emplace_back(cause);
    std::string key(origin_.type_text());
    key += ':';
    key += cause;
    diagnostics_.warning(origin_.loc, node_label(origin_) + ": " + std::string(message), key);
}

}  // namespace vr
