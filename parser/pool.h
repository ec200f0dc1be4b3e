// The node tree's pools: growable arrays of plain values with the part of std::vector's interface
// the readers and the scene builder use. A pool that outgrows a megabyte moves into a mapping of
// its own, which grows by remapping its pages (no copy, and never an old and a new buffer alive at
// once, so a pool costs what it holds) and asks for transparent huge pages (a 100 MB scene's tree
// otherwise takes some 45,000 page faults, which cost as much time as reading the file).
#pragma once
#include <cassert>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace vr {

namespace pool_detail {

// Memory of at least `bytes` (> 0; on return, the size it has) holding the first `keep` bytes of
// `old` (of `old_bytes`; null for none). Small blocks come from malloc, large ones are mappings;
// `mapped` says which `old` is and becomes which the result is. Throws std::bad_alloc.
void* resize(void* old, size_t old_bytes, size_t keep, size_t& bytes, bool& mapped);
void release(void* p, size_t bytes, bool mapped);
// Gives the whole huge pages of a mapping's first `bytes` back to the kernel, those from `from`
// (given back before) on; returns how many bytes from the start are given back now (a multiple of
// the huge page size; 0 for heap blocks).
size_t release_front(void* p, size_t from, size_t bytes, bool mapped);

}  // namespace pool_detail

template <class T>
class Pool {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

  public:
    using value_type = T;
    using size_type = size_t;
    using difference_type = ptrdiff_t;
    using reference = T&;
    using const_reference = const T&;
    using pointer = T*;
    using const_pointer = const T*;
    using iterator = T*;
    using const_iterator = const T*;

    Pool() = default;
    Pool(std::initializer_list<T> values) { insert(end(), values.begin(), values.end()); }
    Pool(const Pool& other) { insert(end(), other.begin(), other.end()); }
    Pool(Pool&& other) noexcept { swap(other); }
    Pool& operator=(const Pool& other) {
        if (this != &other) {
            clear();
            insert(end(), other.begin(), other.end());
        }
        return *this;
    }
    Pool& operator=(Pool&& other) noexcept {
        Pool(std::move(other)).swap(*this);
        return *this;
    }
    ~Pool() {
        if (data_) pool_detail::release(data_, bytes_, mapped_);
    }
    void swap(Pool& other) noexcept {
        std::swap(data_, other.data_);
        std::swap(size_, other.size_);
        std::swap(capacity_, other.capacity_);
        std::swap(bytes_, other.bytes_);
        std::swap(mapped_, other.mapped_);
        std::swap(released_, other.released_);
    }

    size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    size_t capacity() const { return capacity_; }
    T* data() { return data_; }
    const T* data() const { return data_; }
    T* begin() { return data_; }
    T* end() { return data_ + size_; }
    const T* begin() const { return data_; }
    const T* end() const { return data_ + size_; }
    T& operator[](size_t i) {
        assert(i < size_);
        return data_[i];
    }
    const T& operator[](size_t i) const {
        assert(i < size_);
        return data_[i];
    }
    T& front() { return data_[0]; }
    const T& front() const { return data_[0]; }
    T& back() { return data_[size_ - 1]; }
    const T& back() const { return data_[size_ - 1]; }

    void reserve(size_t n) {
        if (n > capacity_) set_capacity(n);
    }
    void clear() {
        size_ = 0;
        released_ = 0;  // pages given back come again, zeroed, when written
    }
    void push_back(const T& value) {
        if (size_ == capacity_) {
            const T copy = value;  // `value` may live in this pool
            grow(size_ + 1);
            data_[size_++] = copy;
            return;
        }
        data_[size_++] = value;
    }
    template <class... Args>
    T& emplace_back(Args&&... args) {
        push_back(T{std::forward<Args>(args)...});
        return back();
    }
    void pop_back() { --size_; }
    void resize(size_t n) { resize(n, T{}); }
    void resize(size_t n, const T& value) {
        if (n > size_) {
            const T copy = value;
            if (n > capacity_) grow(n);
            for (size_t i = size_; i < n; ++i) data_[i] = copy;
        }
        size_ = n;
    }
    // Appends [first, last); only the end is a valid position (all the readers need).
    template <class It>
    T* insert(const T* pos, It first, It last) {
        assert(pos == end());
        const size_t at = static_cast<size_t>(pos - data_);
        const size_t n = static_cast<size_t>(std::distance(first, last));
        if (n == 0) return data_ + at;
        if (size_ + n > capacity_) {
            if constexpr (std::is_pointer_v<It> || std::contiguous_iterator<It>) {
                // The range may lie in this pool, which growing moves: copy from its new place.
                const T* src = std::to_address(first);
                if (src >= data_ && src < data_ + size_) {
                    const size_t offset = static_cast<size_t>(src - data_);
                    grow(size_ + n);
                    std::memmove(data_ + size_, data_ + offset, n * sizeof(T));
                    size_ += n;
                    return data_ + at;
                }
            }
            grow(size_ + n);
        }
        for (T* out = data_ + size_; first != last; ++first, ++out) *out = *first;
        size_ += n;
        return data_ + at;
    }

    // The first `n` values will never be read again: the memory of whole pages under them goes
    // back to the kernel (a large mapped pool only; reading there afterwards gives zeros). For a
    // tree that is freed piece by piece while the scene is built from it.
    void release_front(size_t n) {
        n = n < size_ ? n : size_;
        if (n * sizeof(T) > released_)
            released_ = pool_detail::release_front(data_, released_, n * sizeof(T), mapped_);
    }

  private:
    void grow(size_t min_capacity) {
        size_t n = capacity_ ? capacity_ * 2 : 16;
        set_capacity(n < min_capacity ? min_capacity : n);
    }
    void set_capacity(size_t n) {
        if (n > size_t(-1) / sizeof(T) / 2) throw std::bad_alloc();
        size_t bytes = n * sizeof(T);
        data_ =
            static_cast<T*>(pool_detail::resize(data_, bytes_, size_ * sizeof(T), bytes, mapped_));
        bytes_ = bytes;
        capacity_ = bytes / sizeof(T);
    }

    T* data_ = nullptr;
    size_t size_ = 0;
    size_t capacity_ = 0;
    size_t bytes_ = 0;  // allocated, >= capacity_ * sizeof(T)
    bool mapped_ = false;
    size_t released_ = 0;  // bytes at the start given back by release_front
};

}  // namespace vr
