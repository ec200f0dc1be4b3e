#include "app/fragment_wire.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <type_traits>

#include "core/huge_pages.h"
#include "scene/fragments.h"

namespace vr {
namespace {

template <class T>
concept HasOrigin = requires(T t) {
    t.origin;
};

// The fragment's arrays that travel as their own bytes, in wire order (both sides run the same
// binary). A new array of a plain piece's fragment is one more line here.
template <class S, class F>
void for_each_array(S& s, F&& f) {
    f(s.groups);
    f(s.child_refs);
    f(s.translations);
    f(s.matrices);
    f(s.shapes);
    f(s.appearances);
    f(s.materials);
    f(s.translated_shapes);  // the atoms' records: a place (PackedLoc), no names to renumber
}
constexpr size_t kArrays = 8;
// The parts: the sender's new names, the outer USE names, the arrays, the geometries' records.
constexpr size_t kNamesPart = 0, kOuterPart = 1, kFirstArray = 2, kGeometryPart = 2 + kArrays;
static_assert(kGeometryPart < WireHeader::kMaxParts);

template <class T>
using Element = std::remove_cvref_t<decltype(std::declval<T&>()[0])>;

// A geometry of a plain piece (Sphere, Box, Cylinder or Cone) without its variant, whose other
// kinds own memory.
constexpr size_t kShapeBytes =
    std::max({sizeof(sg::Sphere), sizeof(sg::Box), sizeof(sg::Cylinder), sizeof(sg::Cone)});
struct GeometryRecord {
    sg::Origin origin;
    sg::Index hints = sg::kNone;
    uint8_t cull_back_faces = 0;
    uint8_t kind = 0;        // the variant's index
    uint8_t unused[2] = {};  // no padding: every byte sent is set
    alignas(8) uint8_t shape[kShapeBytes] = {};
};
static_assert(sizeof(GeometryRecord) == sizeof(sg::Origin) + sizeof(sg::Index) + 4 + kShapeBytes);

template <class Shape>
bool put_shape(const sg::GeometryShape& from, GeometryRecord& r) {
    const Shape* s = std::get_if<Shape>(&from);
    if (s == nullptr) return false;
    static_assert(std::is_trivially_copyable_v<Shape>);
    r.kind = uint8_t(from.index());
    std::memcpy(r.shape, s, sizeof(Shape));
    return true;
}

template <class Shape>
bool get_shape(const GeometryRecord& r, sg::GeometryShape& to) {
    if (r.kind != sg::GeometryShape(Shape{}).index()) return false;
    Shape s;
    std::memcpy(&s, r.shape, sizeof(Shape));
    to = s;
    return true;
}

template <class T>
std::span<const uint8_t> bytes_of(std::span<const T> s) {
    return std::as_bytes(s).empty()
               ? std::span<const uint8_t>()
               : std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(s.data()),
                                          s.size_bytes());
}

// A sender's array as one span of bytes: its storage, or a copy when it lies in several chunks.
template <class T>
std::span<const uint8_t> whole_bytes(const std::vector<T>& v, std::vector<std::vector<uint8_t>>&) {
    return bytes_of(std::span<const T>(v));
}
template <class T>
std::span<const uint8_t> whole_bytes(const ChunkedArray<T>& a,
                                     std::vector<std::vector<uint8_t>>& copies) {
    const size_t n = a.size();
    if (n == 0) return {};
    // A fragment as built keeps each array in one chunk: its last element is where the first's
    // storage puts it.
    const auto first = reinterpret_cast<uintptr_t>(&a[0]);
    if (reinterpret_cast<uintptr_t>(&a[n - 1]) - first == (n - 1) * sizeof(T))
        return bytes_of(a.span(0, n));
    std::vector<uint8_t>& copy = copies.emplace_back(n * sizeof(T));
    size_t at = 0;
    for (const T& e : a) {
        std::memcpy(copy.data() + at, &e, sizeof(T));
        at += sizeof(T);
    }
    return copy;
}

// A receiver's array of `count` elements, fresh (on huge pages, in one chunk), as the bytes to
// receive into.
template <class T>
std::span<uint8_t> make_bytes(std::vector<T>& v, size_t count) {
    resize_huge(v, count);
    return {reinterpret_cast<uint8_t*>(v.data()), count * sizeof(T)};
}
template <class T>
std::span<uint8_t> make_bytes(ChunkedArray<T>& a, size_t count) {
    if (count == 0) return {};
    a.reserve(count);
    a.resize(count);
    return {reinterpret_cast<uint8_t*>(&a[0]), count * sizeof(T)};
}
template <class T>
std::span<T> elements(std::vector<T>& v) {
    return v;
}
template <class T>
std::span<T> elements(ChunkedArray<T>& a) {  // one chunk: a received array
    return a.empty() ? std::span<T>() : std::span<T>(&a[0], a.size());
}

void remap(sg::Origin& o, const NameMap& names) {
    o.type = names(o.type);
    o.def_name = names(o.def_name);
}

}  // namespace

bool fits_wire(const Scene& s) {
    if (!s.textures.empty() || !s.lights.empty() || !s.viewpoints.empty() ||
        !s.backgrounds.empty() || !s.fogs.empty() || !s.navigation_infos.empty() ||
        !s.hints.empty() || !s.billboard_axes.empty() || !s.clip_planes.empty() ||
        !s.layouts.empty() || !s.layers.empty() || !s.layer_order.empty() || s.active_layer != 0 ||
        !s.main_file.empty() || !s.allowed_roots.empty())
        return false;
    return only_plain_primitives(s);
}

std::vector<uint8_t> NameTexts::next(uint32_t& first, uint32_t& count) {
    first = sent_;
    std::vector<uint8_t> bytes;
    for (;; ++sent_) {
        const std::string_view text = name_text(sent_);
        if (text.empty() && sent_ != kNoName) break;  // no such name yet: only kNoName is empty
        const auto length = uint32_t(text.size());
        const size_t at = bytes.size();
        bytes.resize(at + sizeof length + text.size());
        std::memcpy(bytes.data() + at, &length, sizeof length);
        if (!text.empty()) std::memcpy(bytes.data() + at + sizeof length, text.data(), text.size());
    }
    count = sent_ - first;
    return bytes;
}

void NameMap::add(std::span<const uint8_t> texts, uint32_t first, uint32_t count) {
    if (first != names_.size()) throw std::runtime_error("a piece's names do not follow the last");
    size_t at = 0;
    for (uint32_t k = 0; k < count; ++k) {
        uint32_t length = 0;
        if (texts.size() - at < sizeof length) throw std::runtime_error("a piece ends early");
        std::memcpy(&length, texts.data() + at, sizeof length);
        at += sizeof length;
        if (texts.size() - at < length) throw std::runtime_error("a piece ends early");
        const Name mine =
            intern(std::string_view(reinterpret_cast<const char*>(texts.data() + at), length));
        at += length;
        identity_ = identity_ && mine == names_.size();
        names_.push_back(mine);
    }
}

Name NameMap::operator()(uint32_t sender_name) const {
    if (sender_name >= names_.size())
        throw std::runtime_error("a piece names a name it does not hold");
    return names_[sender_name];
}

OutgoingPiece::OutgoingPiece(uint32_t piece, const Scene* fragment, const TextConsumed& counts,
                             NameTexts& names) {
    header_.piece = piece;
    if (fragment == nullptr || !fits_wire(*fragment)) return;  // not plain: the header alone
    const Scene& s = *fragment;
    header_.plain = 1;
    header_.roots = counts.roots;
    header_.nodes = counts.nodes;
    header_.uses = counts.uses;
    // After the piece was built: its names are interned by now.
    names_ = names.next(header_.first_name, header_.new_names);
    outer_.assign(counts.outer_uses.begin(), counts.outer_uses.end());
    std::vector<std::span<const uint8_t>> parts(kGeometryPart + 1);
    parts[kNamesPart] = names_;
    parts[kOuterPart] = bytes_of(std::span<const uint32_t>(outer_));
    header_.counts[kNamesPart] = names_.size();
    header_.counts[kOuterPart] = outer_.size();
    size_t part = kFirstArray;
    for_each_array(s, [&](const auto& array) {
        using T = Element<decltype(array)>;
        static_assert(std::is_trivially_copyable_v<T>);
        header_.counts[part] = array.size();
        parts[part++] = whole_bytes(array, copies_);
    });
    geometries_.resize(s.geometries.size() * sizeof(GeometryRecord));
    for (size_t i = 0; i < s.geometries.size(); ++i) {
        const sg::Geometry& g = s.geometries[i];
        GeometryRecord r;
        r.origin = g.origin;
        r.hints = g.hints;
        r.cull_back_faces = uint8_t(g.cull_back_faces);
        put_shape<sg::Sphere>(g.shape, r) || put_shape<sg::Box>(g.shape, r) ||
            put_shape<sg::Cylinder>(g.shape, r) || put_shape<sg::Cone>(g.shape, r);
        std::memcpy(geometries_.data() + i * sizeof r, &r, sizeof r);
    }
    header_.counts[kGeometryPart] = s.geometries.size();
    parts[kGeometryPart] = geometries_;
    for (const std::span<const uint8_t> p : parts)
        if (!p.empty()) parts_.push_back(p);
}

size_t OutgoingPiece::bytes() const {
    size_t bytes = sizeof header_;
    for (const std::span<const uint8_t> p : parts_) bytes += p.size();
    return bytes;
}

IncomingPiece::IncomingPiece(const WireHeader& header) : header_(header) {
    if (!plain()) return;
    std::vector<std::span<uint8_t>> parts(kGeometryPart + 1);
    names_.resize(header_.counts[kNamesPart]);
    parts[kNamesPart] = names_;
    outer_.resize(header_.counts[kOuterPart]);
    parts[kOuterPart] = {reinterpret_cast<uint8_t*>(outer_.data()),
                         outer_.size() * sizeof(uint32_t)};
    size_t part = kFirstArray;
    for_each_array(fragment_, [&](auto& array) {
        parts[part] = make_bytes(array, header_.counts[part]);
        ++part;
    });
    geometries_.resize(header_.counts[kGeometryPart] * sizeof(GeometryRecord));
    parts[kGeometryPart] = geometries_;
    for (const std::span<uint8_t> p : parts)
        if (!p.empty()) parts_.push_back(p);
}

std::optional<Scene> IncomingPiece::finish(NameMap& names, TextConsumed& counts) && {
    if (!plain()) return std::nullopt;
    names.add(names_, header_.first_name, header_.new_names);
    counts.roots = header_.roots;
    counts.nodes = header_.nodes;
    counts.uses = header_.uses;
    counts.outer_uses.clear();
    for (const uint32_t n : outer_) counts.outer_uses.push_back(names(n));
    // Origins keep their numbers when the sender's are this process's (one pass over the
    // fragment saved, most of a received piece's time after the copy).
    if (!names.identity())
        for_each_array(fragment_, [&](auto& array) {
            if constexpr (HasOrigin<Element<decltype(array)>>)
                for (auto& e : elements(array)) remap(e.origin, names);
        });
    const size_t count = header_.counts[kGeometryPart];
    std::vector<sg::Geometry>& geometries = fragment_.geometries;
    reserve_huge(geometries, count);
    for (size_t i = 0; i < count; ++i) {
        GeometryRecord r;
        std::memcpy(&r, geometries_.data() + i * sizeof r, sizeof r);
        sg::Geometry& g = geometries.emplace_back();
        g.origin = r.origin;
        if (!names.identity()) remap(g.origin, names);
        g.hints = r.hints;
        g.cull_back_faces = r.cull_back_faces != 0;
        if (!get_shape<sg::Sphere>(r, g.shape) && !get_shape<sg::Box>(r, g.shape) &&
            !get_shape<sg::Cylinder>(r, g.shape) && !get_shape<sg::Cone>(r, g.shape))
            throw std::runtime_error("a piece holds a geometry no plain piece makes");
    }
    geometries_ = std::vector<uint8_t>();
    return std::move(fragment_);
}

}  // namespace vr
