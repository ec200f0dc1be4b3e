#include "parser/name.h"

#include <deque>
#include <mutex>
#include <string>
#include <unordered_map>

namespace vr {
namespace {

struct NameTable {
    std::mutex mutex;
    std::deque<std::string> texts{""};  // deque: element addresses never move, so views stay valid
    std::unordered_map<std::string_view, Name> index{{std::string_view(texts.front()), kNoName}};
};

NameTable& table() {
    static NameTable t;
    return t;
}

}  // namespace

Name intern(std::string_view text) {
    NameTable& t = table();
    std::lock_guard<std::mutex> lock(t.mutex);
    auto it = t.index.find(text);
    if (it != t.index.end()) return it->second;
    t.texts.emplace_back(text);
    Name name = static_cast<Name>(t.texts.size() - 1);
    t.index.emplace(std::string_view(t.texts.back()), name);
    return name;
}

std::string_view name_text(Name name) {
    NameTable& t = table();
    std::lock_guard<std::mutex> lock(t.mutex);
    return name < t.texts.size() ? std::string_view(t.texts[name]) : std::string_view();
}

}  // namespace vr
