// An array kept in chunks (storage blocks; one a fragment's, fragments.h), for the typed scene's
// largest arrays (a PyMOL atom is a group, a translation, a shape and two child references). The
// scene build takes the arrays of the fragments built while a large file is read (fragments.h) as
// chunks of its own, renumbered where they lie, instead of copying them: on the virtual machines we
// run on, the first touch of fresh memory is slow (bench/README.md, "Figures behind the comments"),
// and a copy would touch the scene's memory twice.
//
// Only the last chunk grows; a block taken by resize() lies in one chunk, so spans of it stay
// contiguous (Scene::children_of).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <span>
#include <utility>
#include <vector>

#include "core/huge_pages.h"

namespace vr {

template <class T>
class ChunkedArray {
  public:
    size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }

    const T& operator[](size_t i) const {
        if (i >= last_start_) return chunks_.back()[i - last_start_];  // the common case
        const auto c =
            size_t(std::upper_bound(starts_.begin(), starts_.end(), i) - starts_.begin()) - 1;
        return chunks_[c][i - starts_[c]];
    }
    T& operator[](size_t i) { return const_cast<T&>(std::as_const(*this)[i]); }
    // [first, first + count), which must lie in one chunk.
    std::span<const T> span(size_t first, size_t count) const {
        return count == 0 ? std::span<const T>() : std::span<const T>(&(*this)[first], count);
    }

    void push_back(T value) {
        last().push_back(std::move(value));
        ++size_;
    }
    T& emplace_back() {
        T& made = last().emplace_back();
        ++size_;
        return made;
    }
    T& back() { return chunks_.back().back(); }
    const T& back() const { return chunks_.back().back(); }
    // Grows the last chunk (or shrinks it, never below its start) to make the size `n`.
    void resize(size_t n) {
        if (n == size_) return;
        if (n > size_) last();  // an adopted chunk is not grown: a new one is begun
        chunks_.back().resize(n - last_start_);
        size_ = n;
    }
    // Room for `n` elements in all, in the last chunk, on huge pages.
    void reserve(size_t n) {
        if (n > size_) reserve_huge(last(), n - last_start_);
    }
    // Appends `chunk` as a chunk of its own: no element moves. Later elements go to a new chunk
    // (growing an adopted one would move it).
    void adopt(std::vector<T>&& chunk) {
        if (chunk.empty()) return;
        if (!chunks_.empty() && chunks_.back().empty()) {
            chunks_.pop_back();
            starts_.pop_back();
        }
        starts_.push_back(size_);
        last_start_ = size_;
        size_ += chunk.size();
        chunks_.push_back(std::move(chunk));
        last_adopted_ = true;
    }
    // Frees every chunk that lies wholly below index `bound`, except the last chunk and the one
    // holding index `keep`; returns the bytes freed. A chunk that was emptied stays in place
    // (empty), so the indices of the others do not change. The elements freed must not be read
    // again: for a reader done with the front of the array (flatten_scene_releasing).
    size_t release_below(size_t bound, size_t keep = SIZE_MAX) {
        size_t freed = 0;
        while (released_ + 1 < chunks_.size() &&
               starts_[released_] + chunks_[released_].size() <= bound) {
            std::vector<T>& chunk = chunks_[released_];
            const bool holds_keep =
                keep >= starts_[released_] && keep < starts_[released_] + chunk.size();
            if (!holds_keep) {  // (the kept chunk stays, and the ones after it may go)
                freed += chunk.capacity() * sizeof(T);
                std::vector<T>().swap(chunk);
            }
            ++released_;
        }
        return freed;
    }

    // The bytes the chunks hold (their capacity).
    size_t held_bytes() const {
        size_t bytes = 0;
        for (const std::vector<T>& chunk : chunks_) bytes += chunk.capacity() * sizeof(T);
        return bytes;
    }

    // The elements as one vector (one chunk is given up without a copy).
    std::vector<T> take_all() && {
        std::vector<T> all;
        if (chunks_.size() == 1) all = std::move(chunks_.back());
        for (size_t c = 0; chunks_.size() > 1 && c < chunks_.size(); ++c)
            all.insert(all.end(), chunks_[c].begin(), chunks_[c].end());
        *this = ChunkedArray();
        return all;
    }

    class const_iterator {
      public:
        using iterator_category = std::forward_iterator_tag;
        using value_type = T;
        using difference_type = std::ptrdiff_t;
        using pointer = const T*;
        using reference = const T&;
        const_iterator(const std::vector<std::vector<T>>* chunks, size_t c, size_t i)
            : chunks_(chunks), c_(c), i_(i) {
            skip_empty();
        }
        const T& operator*() const { return (*chunks_)[c_][i_]; }
        const T* operator->() const { return &(*chunks_)[c_][i_]; }
        const_iterator& operator++() {
            ++i_;
            skip_empty();
            return *this;
        }
        bool operator==(const const_iterator& o) const { return c_ == o.c_ && i_ == o.i_; }

      private:
        void skip_empty() {
            while (c_ < chunks_->size() && i_ >= (*chunks_)[c_].size()) ++c_, i_ = 0;
        }
        const std::vector<std::vector<T>>* chunks_;
        size_t c_, i_;
    };
    const_iterator begin() const { return {&chunks_, 0, 0}; }
    const_iterator end() const { return {&chunks_, chunks_.size(), 0}; }

  private:
    std::vector<T>& last() {
        if (chunks_.empty() || last_adopted_) {
            chunks_.emplace_back();
            starts_.push_back(size_);
            last_start_ = size_;
            last_adopted_ = false;
        }
        return chunks_.back();
    }

    std::vector<std::vector<T>> chunks_;
    std::vector<size_t> starts_;  // index of each chunk's first element
    size_t last_start_ = 0;
    size_t size_ = 0;
    bool last_adopted_ = false;
    size_t released_ = 0;  // chunks before this one were freed by release_below
};

}  // namespace vr
