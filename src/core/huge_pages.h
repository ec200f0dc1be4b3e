// Large arrays (an HD image, a BVH over 1e5 primitives and more, 1e5 typed nodes) are filled once,
// front to back. On Linux, asking for transparent huge pages before the first touch replaces
// thousands of 4 KiB page faults by a few 2 MiB ones. On virtual machines like the ones we run on,
// zeroing an HD image on 4 KiB pages takes several times as long as on huge pages, and the BVH
// build of 1M spheres spends half its time in faults (bench/README.md, "Figures behind the
// comments"). A hint only: nothing changes if it is refused, and storage below 4 MiB is
// left alone.
#pragma once
#include <cstddef>
#include <vector>

namespace vr {

void advise_huge_pages(void* data, size_t bytes);

// Storage of kMappedBytes or more mapped on its own (page-aligned, so aligned to any cache line)
// and unmapped when freed. glibc serves blocks below its dynamic mmap threshold, which the first
// free of a large block raises up to 32 MiB, from the thread's arena, and keeps them there when
// they are freed: a BVH build's per-task node arrays (a few MiB each, 80 MiB on 10M atoms) stayed
// in the process through the render (bench/README.md, "Issue 45: 10M atoms toward 1 GB").
constexpr size_t kMappedBytes = size_t(1) << 20;
// Throws std::bad_alloc when the system has no room.
void* allocate_mapped(size_t bytes);
void free_mapped(void* data, size_t bytes);

// Reserves `count` elements and advises huge pages for the new, untouched storage.
template <class T, class A>
void reserve_huge(std::vector<T, A>& v, size_t count) {
    v.reserve(count);
    advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

// resize() on storage reserved with reserve_huge.
template <class T, class A>
void resize_huge(std::vector<T, A>& v, size_t count) {
    reserve_huge(v, count);
    v.resize(count);
}

}  // namespace vr
