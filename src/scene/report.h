// Warnings about one typed node: "Type 'DEF': message" at the node's place, each cause reported
// once per node (and merged across nodes by Diagnostics, which counts the repeats).
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "parser/diagnostics.h"
#include "scene/scene.h"

namespace vr {

std::string node_label(const sg::Origin& origin);  // "IndexedFaceSet" or "IndexedFaceSet 'Mesh1'"

class NodeReport {
  public:
    NodeReport(Diagnostics& diagnostics, const sg::Origin& origin)
        : diagnostics_(diagnostics), origin_(origin) {}
    // The report keeps a reference: a temporary Origin would dangle by the first warning.
    NodeReport(Diagnostics& diagnostics, sg::Origin&& origin) = delete;
    // `cause` is a short key such as "coord-index-range"; the Diagnostics cause is "Type:cause".
    void warn(std::string_view cause, std::string_view message);
    const sg::Origin& origin() const { return origin_; }

  private:
    Diagnostics& diagnostics_;
    const sg::Origin& origin_;
    std::vector<std::string> reported_;
};

}  // namespace vr
