// DEF names for writing a node tree back out, shared by the classic and the XML writers.
#pragma once
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "parser/node_tree.h"

namespace vr {

// A node keeps its own DEF name, made unique where PROTO expansion repeated one; a node reached
// more than once from the roots (DEF/USE sharing) gets a made-up name if it has none.
class DefNames {
  public:
    explicit DefNames(
        const NodeTree& tree);  // counts how often each node is reached from tree.roots

    // The name the node is written with, "" for none. Names are made unique in the order they are
    // asked for.
    const std::string& name(NodeId id);
    uint32_t references(NodeId id) const;

  private:
    const NodeTree& tree_;
    std::unordered_map<NodeId, uint32_t> references_;
    std::unordered_map<NodeId, std::string> names_;
    std::unordered_set<std::string> used_;
};

}  // namespace vr
