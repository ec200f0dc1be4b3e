#include "app/fragment_wire.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>

#include "core/huge_pages.h"
#include "scene/fragments.h"

namespace vr {
namespace {

template <class T>
concept HasOrigin = requires(T t) {
    t.origin;
};

// Bytes out: the pieces, then the table of names their numbers stand for (its offset first).
class Writer {
  public:
    // `bytes`: about what the message will hold, reserved at once (on huge pages: the first touch
    // of fresh memory is the cost of a large message, and growing it would touch it again).
    explicit Writer(size_t bytes) {
        reserve_huge(out_, bytes);
        put(uint64_t(0));          // where the table starts, set by finish()
        ids_.emplace(kNoName, 0);  // number 0, always
        order_.push_back(kNoName);
    }

    template <class T>
    void put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        const size_t at = grow(sizeof(T));
        std::memcpy(out_.data() + at, &value, sizeof(T));
    }
    // A number standing for `name` in this message.
    uint32_t name(Name name) {
        if (name == kNoName) return 0;  // most names: an origin's DEF name
        if (name == last_name_) return last_id_;
        const auto [it, added] = ids_.try_emplace(name, uint32_t(order_.size()));
        if (added) order_.push_back(name);
        last_name_ = name;
        return last_id_ = it->second;
    }
    // `count` elements, each copied with its origin's names as this message's numbers.
    template <class Range>
    void elements(const Range& range, size_t count) {
        using T = std::decay_t<decltype(*std::begin(range))>;
        static_assert(std::is_trivially_copyable_v<T>);
        put(uint64_t(count));
        size_t at = grow(count * sizeof(T));
        for (const T& element : range) {
            T e = element;
            if constexpr (HasOrigin<T>) origin(e.origin);
            std::memcpy(out_.data() + at, &e, sizeof(T));
            at += sizeof(T);
        }
    }
    void origin(sg::Origin& o) {
        o.type = name(o.type);
        o.def_name = name(o.def_name);
    }
    std::vector<uint8_t> finish() && {
        const uint64_t table = out_.size();
        std::memcpy(out_.data(), &table, sizeof table);
        put(uint32_t(order_.size()));
        for (Name n : order_) {
            const std::string_view text = name_text(n);
            put(uint32_t(text.size()));
            const size_t at = grow(text.size());
            if (!text.empty()) std::memcpy(out_.data() + at, text.data(), text.size());
        }
        return std::move(out_);
    }

  private:
    size_t grow(size_t bytes) {
        const size_t at = out_.size();
        if (out_.capacity() < at + bytes) out_.reserve(std::max(2 * out_.capacity(), at + bytes));
        out_.resize(at + bytes);
        return at;
    }
    std::vector<uint8_t> out_;
    std::unordered_map<Name, uint32_t> ids_;
    std::vector<Name> order_;
    Name last_name_ = UINT32_MAX;
    uint32_t last_id_ = 0;
};

class Reader {
  public:
    explicit Reader(std::span<const uint8_t> in) : in_(in), end_(in.size()) {
        const auto table = get<uint64_t>();
        const size_t body = at_;
        at_ = table;
        const auto count = get<uint32_t>();
        for (uint32_t k = 0; k < count; ++k) {
            const auto length = get<uint32_t>();
            names_.push_back(intern(
                std::string_view(reinterpret_cast<const char*>(take(length).data()), length)));
        }
        end_ = table;  // the body ends where the table begins
        at_ = body;
    }
    bool more() const { return at_ < end_; }

    template <class T>
    T get() {
        T value;
        std::memcpy(&value, take(sizeof(T)).data(), sizeof(T));
        return value;
    }
    Name name(uint32_t id) const {
        if (id >= names_.size()) throw std::runtime_error("a piece names a name it does not hold");
        return names_[id];
    }
    void origin(sg::Origin& o) const {
        o.type = name(o.type);
        o.def_name = name(o.def_name);
    }
    template <class T>
    std::vector<T> elements() {
        const auto count = get<uint64_t>();
        if (count > (end_ - std::min(at_, end_)) / sizeof(T))
            throw std::runtime_error("a piece ends early");
        std::vector<T> all;
        resize_huge(all, count);
        const std::span<const uint8_t> bytes = take(count * sizeof(T));
        if (count > 0)
            std::memcpy(all.data(), bytes.data(),
                        bytes.size());  // an empty vector's data() may be null
        if constexpr (HasOrigin<T>)
            for (T& e : all) origin(e.origin);
        return all;
    }

  private:
    std::span<const uint8_t> take(size_t bytes) {
        if (bytes > end_ - std::min(at_, end_)) throw std::runtime_error("a piece ends early");
        const std::span<const uint8_t> s = in_.subspan(at_, bytes);
        at_ += bytes;
        return s;
    }
    std::span<const uint8_t> in_;
    size_t at_ = 0, end_ = 0;  // end_: of what may be read now
    std::vector<Name> names_;
};

// The geometry kinds a plain piece makes: the variant's index and its value's bytes.
template <class Shape>
void put_shape(Writer& w, const sg::Geometry& g) {
    w.put(uint8_t(g.shape.index()));
    w.put(std::get<Shape>(g.shape));
}

void put_geometries(Writer& w, const std::vector<sg::Geometry>& all) {
    w.put(uint64_t(all.size()));
    for (const sg::Geometry& g : all) {
        sg::Origin o = g.origin;
        w.origin(o);
        w.put(o);
        w.put(g.hints);
        w.put(uint8_t(g.cull_back_faces));
        if (std::holds_alternative<sg::Sphere>(g.shape)) put_shape<sg::Sphere>(w, g);
        if (std::holds_alternative<sg::Box>(g.shape)) put_shape<sg::Box>(w, g);
        if (std::holds_alternative<sg::Cylinder>(g.shape)) put_shape<sg::Cylinder>(w, g);
        if (std::holds_alternative<sg::Cone>(g.shape)) put_shape<sg::Cone>(w, g);
    }
}

std::vector<sg::Geometry> get_geometries(Reader& r) {
    const auto count = r.get<uint64_t>();
    std::vector<sg::Geometry> all;
    for (uint64_t k = 0; k < count; ++k) {
        sg::Geometry& g = all.emplace_back();
        g.origin = r.get<sg::Origin>();
        r.origin(g.origin);
        g.hints = r.get<sg::Index>();
        g.cull_back_faces = r.get<uint8_t>() != 0;
        const auto index = r.get<uint8_t>();
        if (index == sg::GeometryShape(sg::Sphere{}).index())
            g.shape = r.get<sg::Sphere>();
        else if (index == sg::GeometryShape(sg::Box{}).index())
            g.shape = r.get<sg::Box>();
        else if (index == sg::GeometryShape(sg::Cylinder{}).index())
            g.shape = r.get<sg::Cylinder>();
        else if (index == sg::GeometryShape(sg::Cone{}).index())
            g.shape = r.get<sg::Cone>();
        else
            throw std::runtime_error("a piece holds a geometry no plain piece makes");
    }
    return all;
}

// The atoms' records (sg::TranslatedShape), after the rest of a fragment: they hold no names.
void put_translated_shapes(Writer& w, const Scene& s) {
    w.elements(s.translated_shapes, s.translated_shapes.size());
}
void get_translated_shapes(Reader& r, Scene& s) {
    s.translated_shapes.adopt(r.elements<sg::TranslatedShape>());
}

void put_fragment(Writer& w, const Scene& s, const TextConsumed& counts) {
    w.put(counts.roots);
    w.put(counts.nodes);
    w.put(counts.uses);
    w.put(uint32_t(counts.outer_uses.size()));
    for (Name n : counts.outer_uses) w.put(w.name(n));
    w.elements(s.groups, s.groups.size());
    w.elements(s.child_refs, s.child_refs.size());
    w.elements(s.translations, s.translations.size());
    w.elements(s.matrices, s.matrices.size());
    w.elements(s.shapes, s.shapes.size());
    put_geometries(w, s.geometries);
    w.elements(s.appearances, s.appearances.size());
    w.elements(s.materials, s.materials.size());
    put_translated_shapes(w, s);
}

void get_fragment(Reader& r, WirePiece& p) {
    TextConsumed& c = p.counts;
    c.roots = r.get<uint32_t>();
    c.nodes = r.get<uint32_t>();
    c.uses = r.get<uint32_t>();
    const auto outer = r.get<uint32_t>();
    for (uint32_t k = 0; k < outer; ++k) c.outer_uses.push_back(r.name(r.get<uint32_t>()));
    Scene& s = p.fragment.emplace();
    // One chunk each, as read_plain_piece's fragment has them (ChunkedArray::adopt).
    s.groups.adopt(r.elements<sg::Group>());
    s.child_refs.adopt(r.elements<sg::ChildRef>());
    s.translations.adopt(r.elements<Vec3>());
    s.matrices = r.elements<Mat4>();
    s.shapes.adopt(r.elements<sg::Shape>());
    s.geometries = get_geometries(r);
    s.appearances = r.elements<sg::Appearance>();
    s.materials = r.elements<sg::Material>();
    get_translated_shapes(r, s);
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

// The bytes put_fragment writes, but for the names' table.
size_t fragment_bytes(const Scene& s, const TextConsumed& counts) {
    return 64 + 4 * counts.outer_uses.size() + s.groups.size() * sizeof(sg::Group) +
           s.child_refs.size() * sizeof(sg::ChildRef) + s.translations.size() * sizeof(Vec3) +
           s.matrices.size() * sizeof(Mat4) + s.shapes.size() * sizeof(sg::Shape) +
           s.geometries.size() * (sizeof(sg::Origin) + 8 + sizeof(sg::Cylinder)) +
           s.appearances.size() * sizeof(sg::Appearance) +
           s.materials.size() * sizeof(sg::Material) +
           s.translated_shapes.size() * sizeof(sg::TranslatedShape);
}

std::vector<uint8_t> pack_pieces(std::span<const WirePiece> pieces) {
    size_t bytes = 1024;
    for (const WirePiece& p : pieces)
        bytes += 8 + (p.fragment ? fragment_bytes(*p.fragment, p.counts) : 0);
    Writer w(bytes);
    for (const WirePiece& p : pieces) {
        const bool plain = p.fragment && fits_wire(*p.fragment);
        w.put(p.piece);
        w.put(uint8_t(plain));
        if (plain) put_fragment(w, *p.fragment, p.counts);
    }
    return std::move(w).finish();
}

std::vector<WirePiece> unpack_pieces(std::span<const uint8_t> message) {
    std::vector<WirePiece> pieces;
    if (message.empty()) return pieces;
    Reader r(message);
    while (r.more()) {
        WirePiece& p = pieces.emplace_back();
        p.piece = r.get<uint32_t>();
        if (r.get<uint8_t>() != 0) get_fragment(r, p);
    }
    return pieces;
}

}  // namespace vr
