// The scene builder's state and field readers, shared by build.cpp (grouping, appearance, lights,
// bindable nodes) and build_geometry.cpp (geometry nodes). Private to src/scene.
#pragma once
#include <array>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "parser/load.h"
#include "scene/scene.h"

namespace vr::detail {

// Field and node type names, interned once.
// clang-format off
struct Names {
#define VR_NAME(member, text) Name member = intern(text);
    // fields
    VR_NAME(children, "children") VR_NAME(choice, "choice") VR_NAME(level, "level")
    VR_NAME(which_choice, "whichChoice") VR_NAME(axis_of_rotation, "axisOfRotation")
    VR_NAME(translation, "translation") VR_NAME(rotation, "rotation") VR_NAME(scale, "scale")
    VR_NAME(scale_orientation, "scaleOrientation") VR_NAME(center, "center") VR_NAME(load, "load")
    VR_NAME(shape, "shape") VR_NAME(appearance, "appearance") VR_NAME(geometry, "geometry")
    VR_NAME(metadata, "metadata") VR_NAME(visible, "visible") VR_NAME(material, "material")
    VR_NAME(texture, "texture") VR_NAME(texture_transform, "textureTransform")
    VR_NAME(ambient_intensity, "ambientIntensity") VR_NAME(diffuse_color, "diffuseColor")
    VR_NAME(emissive_color, "emissiveColor") VR_NAME(shininess, "shininess")
    VR_NAME(specular_color, "specularColor") VR_NAME(transparency, "transparency")
    VR_NAME(base_color, "baseColor") VR_NAME(metallic, "metallic") VR_NAME(roughness, "roughness")
    VR_NAME(url, "url") VR_NAME(repeat_s, "repeatS") VR_NAME(repeat_t, "repeatT") VR_NAME(image, "image")
    VR_NAME(color, "color") VR_NAME(intensity, "intensity") VR_NAME(on, "on") VR_NAME(global, "global")
    VR_NAME(direction, "direction") VR_NAME(location, "location") VR_NAME(attenuation, "attenuation")
    VR_NAME(radius, "radius") VR_NAME(beam_width, "beamWidth") VR_NAME(cut_off_angle, "cutOffAngle")
    VR_NAME(position, "position") VR_NAME(orientation, "orientation") VR_NAME(field_of_view, "fieldOfView")
    VR_NAME(description, "description") VR_NAME(sky_color, "skyColor") VR_NAME(sky_angle, "skyAngle")
    VR_NAME(ground_color, "groundColor") VR_NAME(ground_angle, "groundAngle")
    VR_NAME(front_url, "frontUrl") VR_NAME(back_url, "backUrl") VR_NAME(left_url, "leftUrl")
    VR_NAME(right_url, "rightUrl") VR_NAME(top_url, "topUrl") VR_NAME(bottom_url, "bottomUrl")
    VR_NAME(fog_type, "fogType") VR_NAME(visibility_range, "visibilityRange") VR_NAME(headlight, "headlight")
    VR_NAME(size, "size") VR_NAME(height, "height") VR_NAME(side, "side") VR_NAME(top, "top")
    VR_NAME(bottom, "bottom") VR_NAME(bottom_radius, "bottomRadius") VR_NAME(coord, "coord")
    VR_NAME(coord_index, "coordIndex") VR_NAME(normal, "normal") VR_NAME(normal_index, "normalIndex")
    VR_NAME(color_index, "colorIndex") VR_NAME(tex_coord, "texCoord") VR_NAME(tex_coord_index, "texCoordIndex")
    VR_NAME(ccw, "ccw") VR_NAME(solid, "solid") VR_NAME(convex, "convex") VR_NAME(crease_angle, "creaseAngle")
    VR_NAME(color_per_vertex, "colorPerVertex") VR_NAME(normal_per_vertex, "normalPerVertex")
    VR_NAME(x_dimension, "xDimension") VR_NAME(z_dimension, "zDimension") VR_NAME(x_spacing, "xSpacing")
    VR_NAME(z_spacing, "zSpacing") VR_NAME(cross_section, "crossSection") VR_NAME(spine, "spine")
    VR_NAME(begin_cap, "beginCap") VR_NAME(end_cap, "endCap") VR_NAME(index, "index")
    VR_NAME(fan_count, "fanCount") VR_NAME(strip_count, "stripCount") VR_NAME(point, "point")
    VR_NAME(vector, "vector")
    // node types
    VR_NAME(Appearance, "Appearance") VR_NAME(Material, "Material") VR_NAME(TwoSidedMaterial, "TwoSidedMaterial")
    VR_NAME(PhysicalMaterial, "PhysicalMaterial") VR_NAME(UnlitMaterial, "UnlitMaterial")
    VR_NAME(ImageTexture, "ImageTexture") VR_NAME(PixelTexture, "PixelTexture") VR_NAME(MultiTexture, "MultiTexture")
    VR_NAME(TextureTransform, "TextureTransform") VR_NAME(MultiTextureTransform, "MultiTextureTransform")
    VR_NAME(Coordinate, "Coordinate") VR_NAME(CoordinateDouble, "CoordinateDouble") VR_NAME(Normal, "Normal")
    VR_NAME(Color, "Color") VR_NAME(ColorRGBA, "ColorRGBA") VR_NAME(TextureCoordinate, "TextureCoordinate")
    VR_NAME(MultiTextureCoordinate, "MultiTextureCoordinate") VR_NAME(Shape, "Shape")
    VR_NAME(diffuse_texture, "diffuseTexture") VR_NAME(base_texture, "baseTexture")
    VR_NAME(emissive_texture, "emissiveTexture")
#undef VR_NAME
};
// clang-format on
const Names& names();

// 64-bit key -> first index, open addressing in one flat array: the sphere merge looks up every
// Sphere of a 1e6-sphere file, and std::unordered_map's bucket and node loads were two cache
// misses a lookup.
class FirstIndexMap {
  public:
    // The index stored for `key`, storing `index` first if the key is new.
    sg::Index find_or_add(uint64_t key, sg::Index index) {
        if (2 * (size_ + 1) > slots_.size()) grow();
        const size_t mask = slots_.size() - 1;
        for (size_t i = mix(key) & mask;; i = (i + 1) & mask) {
            Slot& s = slots_[i];
            if (s.index == sg::kNone) {
                s = Slot{key, index};
                ++size_;
                return index;
            }
            if (s.key == key) return s.index;
        }
    }

  private:
    struct Slot {
        uint64_t key = 0;
        sg::Index index = sg::kNone;  // kNone: empty
    };
    static uint64_t mix(uint64_t k) {  // splitmix64's finaliser
        k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
        k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
        return k ^ (k >> 31);
    }
    void grow() {
        std::vector<Slot> old = std::move(slots_);
        slots_.assign(old.empty() ? 64 : 2 * old.size(), Slot{});
        size_ = 0;
        for (const Slot& s : old)
            if (s.index != sg::kNone) find_or_add(s.key, s.index);
    }
    std::vector<Slot> slots_;
    size_t size_ = 0;
};

class Builder {
  public:
    static constexpr size_t kMaxDepth =
        2000;  // nesting through USE chains; each level is one stack frame

    Builder(const LoadedScene& loaded, Diagnostics& diagnostics);
    Scene build();

    // ---- field readers: the file's value or the grammar default; `fallback` only when the node
    // type has no such field at all (or the value has the wrong size).
    double number(NodeId node, Name field, double fallback) const;
    int32_t integer(NodeId node, Name field, int32_t fallback) const;
    bool boolean(NodeId node, Name field, bool fallback) const;
    Vec2 vec2(NodeId node, Name field, Vec2 fallback) const;
    Vec3 vec3(NodeId node, Name field, Vec3 fallback) const;
    Vec4 rotation(NodeId node, Name field) const;
    std::vector<double> numbers(NodeId node, Name field) const;
    std::vector<int32_t> integers(NodeId node, Name field) const;
    std::vector<Vec2> vec2s(NodeId node, Name field) const;
    std::vector<Vec3> vec3s(NodeId node, Name field) const;
    std::vector<std::string> strings(NodeId node, Name field) const;
    NodeId node(NodeId node, Name field) const;
    std::span<const NodeId> nodes(NodeId node, Name field) const;

    sg::Origin origin(NodeId node) const;
    sg::Index hints(
        NodeId node);  // the node's `metadata` hints, stored in Scene::hints if there are any
    Name type(NodeId node) const { return tree_.type(node); }
    // A warning about `node` ("Type 'DEF': message"); `cause` is merged across nodes.
    void warn(NodeId node, std::string_view cause, const std::string& message);
    std::filesystem::path file_of(NodeId node) const;

    // ---- build_geometry.cpp
    sg::Index geometry(NodeId node);

  private:
    void reserve();
    static bool is_geometry_type(Name type);  // build_geometry.cpp
    std::optional<sg::ChildRef> child(NodeId node);
    std::optional<sg::ChildRef> make_child(NodeId node);
    void add_children(sg::Index group, std::span<const NodeId> children);
    sg::Index make_group(NodeId node);
    std::optional<sg::ChildRef> make_shape(NodeId node);
    sg::Index appearance(NodeId node);
    sg::Index material(NodeId node);
    sg::Index texture(NodeId node);
    sg::Index make_light(NodeId node);
    sg::Index make_viewpoint(NodeId node);
    sg::Index make_background(NodeId node);
    sg::Index make_fog(NodeId node);
    sg::Index make_navigation_info(NodeId node);
    void read_texture_transform(NodeId node, sg::Appearance& appearance);

    // build_geometry.cpp
    sg::Geometry make_geometry(NodeId node);
    void read_vertex_data(NodeId node, sg::VertexData& data, bool want_coords,
                          const sg::Origin& origin);

  public:
    const LoadedScene& loaded_;
    const NodeTree& tree_;
    Diagnostics& diagnostics_;
    Scene scene_;

  private:
    // What the builder remembers of a node the file refers to more than once (DEF/USE). A node
    // referred to once is reached at most once (its one parent is built at most once), so only
    // shared nodes are memoised; a dense memo cost 13 bytes a tree node. A cycle always passes
    // through a shared node (its entry is referred to from outside and from inside), so the
    // cycle check needs no state for the others either.
    struct Memo {
        sg::Index typed = sg::kNone;  // its appearance, material, texture or geometry index
        sg::ChildRef child;           // as a child: index kNone for nothing to render
        uint8_t state = 0;            // as a child: 0 new, 1 being built, 2 built
    };
    Memo* shared(NodeId id) {
        return (referred_twice_[id / 64] >> (id % 64)) & 1 ? &memo_[id] : nullptr;
    }
    void count_references();
    std::vector<uint64_t> referred_once_, referred_twice_;  // bit sets over the tree's nodes
    std::unordered_map<NodeId, Memo> memo_;

    // Content-equal nodes with no identity the renderer can see share one typed node: PyMOL writes
    // an identical Material and Appearance per atom, and a Sphere per atom with a few radii. The
    // first node's origin is kept (only non-finite values are reported against a Material, and
    // those are never merged).
    using MaterialKey = std::array<uint64_t, 15>;  // the model and every value's bits
    struct KeyHash {
        size_t operator()(const MaterialKey& key) const;
    };
    std::unordered_map<MaterialKey, sg::Index, KeyHash> same_material_;
    FirstIndexMap same_appearance_;  // (material, texture)
    FirstIndexMap same_sphere_;      // radius bits
    size_t depth_ = 0;
};

}  // namespace vr::detail
