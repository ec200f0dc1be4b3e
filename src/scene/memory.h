// Large arenas (1e5 typed nodes and more) are filled once, front to back. On Linux, asking for
// transparent huge pages before the first touch replaces thousands of 4 KiB page faults by a few 2
// MiB ones; page faults cost most of build_scene's time on virtual machines. A hint only: nothing
// changes if it is refused.
#pragma once
#include <cstddef>
#include <vector>

namespace vr {

void advise_huge_pages(void* data, size_t bytes);

// Reserves `count` elements and advises huge pages for the new, untouched storage.
template <class T>
void reserve_huge(std::vector<T>& v, size_t count) {
    v.reserve(count);
    advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace vr
