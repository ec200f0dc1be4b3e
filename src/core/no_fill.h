// Vectors whose resize() leaves new elements unset, for large arrays that a parallel loop fills
// right after: the kernel zeroes each fresh page on its first write (slow on the virtual machines
// we run on: bench/README.md, "Figures behind the comments"), and a value-initialising resize()
// would take all those faults on one thread before the loop could share them out.
#pragma once
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace vr {

// An allocator's construct() for vectors that resize() leaves unset: no arguments,
// default-initialised; otherwise as usual.
template <class U, class... Args>
void construct_without_filling(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0)
        ::new (static_cast<void*>(p)) U;
    else
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
}

// std::allocator, except that resize() leaves new elements unset (default-initialised).
template <class T>
struct NoFillAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = NoFillAllocator<U>;
    };
    NoFillAllocator() = default;
    template <class U>
    NoFillAllocator(const NoFillAllocator<U>&) {}
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        construct_without_filling(p, std::forward<Args>(args)...);
    }
};

template <class T>
using NoFillVector = std::vector<T, NoFillAllocator<T>>;

}  // namespace vr
