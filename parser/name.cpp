#include "parser/name.h"

#include <cstring>
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

// Readers intern every node type and field name they read, millions in a big file, and a file uses
// few distinct names: each thread keeps the names it saw last in a small direct-mapped cache, so
// the shared, locked table is asked only on a miss. A key is the length and two overlapping 8-byte
// (or 4-byte, or single-byte) reads that together cover every byte of a name up to 16 bytes long,
// so those compare without memcmp; longer names compare their text too. Texts point into the table
// and never move or die.
struct Key {
    uint64_t head = 0;
    uint64_t tail = 0;
    size_t size = 0;
    bool operator==(const Key&) const = default;
};

inline uint64_t load64(const char* p) {
    uint64_t v;
    std::memcpy(&v, p, 8);
    return v;
}

inline uint32_t load32(const char* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}

inline Key key_of(std::string_view text) {
    const char* p = text.data();
    const size_t n = text.size();
    Key k;
    k.size = n;
    if (n >= 8) {
        k.head = load64(p);
        k.tail = load64(p + n - 8);
    } else if (n >= 4) {
        k.head = load32(p);
        k.tail = load32(p + n - 4);
    } else if (n > 0) {
        k.head = static_cast<unsigned char>(p[0]) |
                 static_cast<unsigned>(static_cast<unsigned char>(p[n / 2])) << 8 |
                 static_cast<unsigned>(static_cast<unsigned char>(p[n - 1])) << 16;
    }
    return k;
}

struct CacheEntry {
    Key key;
    const char* text = nullptr;  // null: empty slot
    Name name = kNoName;
};
constexpr size_t kCacheSize = 1024;  // a power of two
thread_local CacheEntry cache[kCacheSize];

inline size_t cache_slot(const Key& k) {
    uint64_t h = (k.head * 0x9E3779B97F4A7C15ull) ^ (k.tail + k.size) * 0xC2B2AE3D27D4EB4Full;
    return static_cast<size_t>(h >> 54) & (kCacheSize - 1);
}

// A cache miss: the shared table, under its lock.
[[gnu::noinline]] Name intern_slow(std::string_view text, const Key& key, CacheEntry& entry) {
    NameTable& t = table();
    std::lock_guard<std::mutex> lock(t.mutex);
    auto it = t.index.find(text);
    if (it == t.index.end()) {
        t.texts.emplace_back(text);
        Name name = static_cast<Name>(t.texts.size() - 1);
        it = t.index.emplace(std::string_view(t.texts.back()), name).first;
    }
    entry = {key, it->first.data(), it->second};
    return it->second;
}

}  // namespace

Name intern(std::string_view text) {
    const Key key = key_of(text);
    CacheEntry& entry = cache[cache_slot(key)];
    if (entry.text && entry.key == key &&
        (key.size <= 16 || std::memcmp(entry.text, text.data(), key.size) == 0))
        return entry.name;
    return intern_slow(text, key, entry);
}

std::string_view name_text(Name name) {
    NameTable& t = table();
    std::lock_guard<std::mutex> lock(t.mutex);
    return name < t.texts.size() ? std::string_view(t.texts[name]) : std::string_view();
}

}  // namespace vr
