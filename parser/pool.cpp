#include "parser/pool.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>

namespace vr::pool_detail {
namespace {

constexpr size_t kMapFrom = size_t(1) << 20;  // smaller pools live on the heap
constexpr size_t kHuge = size_t(2)
                         << 20;  // transparent huge page size on x86-64 and arm64 (4K pages)

// Anonymous memory of `bytes` (a multiple of kHuge) that starts on a kHuge boundary, so all of it
// can be huge pages.
void* map_aligned(size_t bytes) {
    void* p =
        mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    const uintptr_t raw = reinterpret_cast<uintptr_t>(p);
    const uintptr_t start = (raw + kHuge - 1) & ~uintptr_t(kHuge - 1);
    const size_t head = start - raw;
    if (head) munmap(p, head);
    if (kHuge - head) munmap(reinterpret_cast<void*>(start + bytes), kHuge - head);
    madvise(reinterpret_cast<void*>(start), bytes, MADV_HUGEPAGE);  // advice only: fine if refused
    return reinterpret_cast<void*>(start);
}

}  // namespace

void* resize(void* old, size_t old_bytes, size_t keep, size_t& bytes, bool& mapped) {
    if (!mapped && bytes < kMapFrom) {
        void* p = std::realloc(old, bytes);
        if (!p) throw std::bad_alloc();
        return p;
    }
    if (bytes > SIZE_MAX - kHuge) throw std::bad_alloc();
    bytes = (bytes + kHuge - 1) / kHuge * kHuge;
    if (!mapped) {
        void* fresh = map_aligned(bytes);
        if (keep) std::memcpy(fresh, old, keep);
        std::free(old);
        mapped = true;
        return fresh;
    }
    // Grow in place when the addresses after the mapping are free; else move its pages (not their
    // contents) to the start of a new aligned mapping.
    void* p = mremap(old, old_bytes, bytes, 0);
    if (p != MAP_FAILED) {
        madvise(p, bytes, MADV_HUGEPAGE);
        return p;
    }
    void* fresh = map_aligned(bytes);
    if (mremap(old, old_bytes, old_bytes, MREMAP_MAYMOVE | MREMAP_FIXED, fresh) == MAP_FAILED) {
        std::memcpy(fresh, old, keep);
        munmap(old, old_bytes);
    }
    return fresh;
}

size_t release_front(void* p, size_t from, size_t bytes, bool mapped) {
    if (!mapped) return 0;
    const size_t whole = bytes / kHuge * kHuge;  // mappings start on a kHuge boundary
    if (whole > from) madvise(static_cast<char*>(p) + from, whole - from, MADV_DONTNEED);
    return whole > from ? whole : from;
}

void release(void* p, size_t bytes, bool mapped) {
    if (mapped)
        munmap(p, bytes);
    else
        std::free(p);
}

}  // namespace vr::pool_detail
