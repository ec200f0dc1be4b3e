// Materials (deduplicated, hints applied, gas parameters resolved) and textures (pixel textures,
// image files resolved by URL and loaded once per file and way of sampling it).
#include <algorithm>
#include <bit>
#include <cmath>

#include "flatten/flattener.h"
#include "image/texture_file.h"
#include "parser/load.h"
#include "scene/report.h"
#include "scene/transform.h"

namespace vr::flatten_detail {

namespace {

MaterialKey key_of(const Material& m) {
    MaterialKey k{};
    size_t i = 0;
    auto put = [&](double d) { k[i++] = d == 0.0 ? 0.0 : d; };  // -0 and +0 are one material
    auto put3 = [&](const Vec3& v) { put(v.x), put(v.y), put(v.z); };
    put(m.lit);
    put3(m.diffuse);
    put3(m.specular);
    put3(m.emissive);
    put(m.ambient_intensity);
    put(m.shininess);
    put(m.transparency);
    put(m.reflectivity);
    put(m.ior);
    put(m.texture);
    put(m.texture_modulates);
    for (int c = 0; c < 3; ++c) put3(m.texture_transform[c]);
    put(m.sphere_mode);
    put(m.density);
    put3(m.albedo);
    put3(m.emission);
    return k;
}

}  // namespace

uint32_t Flattener::material_of(const sg::Shape& shape, const sg::Geometry& g) {
    const bool plain = shape.hints == sg::kNone && g.hints == sg::kNone;
    const size_t slot =
        shape.appearance == sg::kNone ? scene_.appearances.size() : shape.appearance;
    if (plain && appearance_material_[slot] >= 0) return uint32_t(appearance_material_[slot]);
    const uint32_t index = intern_material(resolve_material(shape, g));
    if (plain) appearance_material_[slot] = int32_t(index);
    return index;
}

uint32_t Flattener::intern_material(const Material& m) {
    const auto [it, inserted] =
        material_index_.try_emplace(key_of(m), uint32_t(out_.materials.size()));
    if (inserted) out_.materials.push_back(m);
    return it->second;
}

uint32_t Flattener::shading_of(uint32_t material, uint32_t light_set, bool cull_back_faces) {
    // Light sets number far below 2^31: the top bit of the light set holds the culling flag.
    const uint32_t lights_and_culling = light_set | (uint32_t(cull_back_faces) << 31);
    if (scope_ != 0) {
        const auto [it, inserted] = scoped_shadings_.try_emplace(
            {material, lights_and_culling, scope_}, uint32_t(out_.shadings.size()));
        if (inserted)
            out_.shadings.push_back(Shading{material, light_set, cull_back_faces, scope_});
        return it->second;
    }
    const uint64_t key = (uint64_t(material) << 32) | lights_and_culling;
    // Atoms of one element follow each other in molecule files: the last answer, before hashing.
    if (key == last_shading_key_) return last_shading_;
    const auto [it, inserted] = shading_index_.try_emplace(key, uint32_t(out_.shadings.size()));
    if (inserted) out_.shadings.push_back(Shading{material, light_set, cull_back_faces});
    last_shading_key_ = key;
    last_shading_ = it->second;
    return it->second;
}

Material Flattener::resolve_material(const sg::Shape& shape, const sg::Geometry& g) {
    Material out;
    sg::Hints hints;
    const sg::Appearance* app =
        shape.appearance == sg::kNone ? nullptr : &scene_.appearances[shape.appearance];
    if (app && app->texture != sg::kNone) out.texture = texture_of(app->texture);
    out.texture_modulates = app && app->texture_modulates;
    if (app && app->has_texture_transform) {
        const sg::TextureTransform& t = app->texture_transform;
        out.texture_transform =
            texture_transform_matrix(t.center, t.rotation, t.scale, t.translation);
    }
    if (!app || app->material == sg::kNone) {
        out.lit = false;
    } else {
        const sg::Material& m = scene_.materials[app->material];
        hints = scene_.hints_of(m.hints);
        NodeReport report(diagnostics_, m.origin);
        auto colour = [&](const Vec3& c, const Vec3& fallback) {
            if (std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z))
                return glm::clamp(c, 0.0, 1.0);
            report.warn("non-finite", "has a NaN or infinite colour; using the default");
            return fallback;
        };
        auto unit = [&](double d, double fallback) {
            if (std::isfinite(d)) return std::clamp(d, 0.0, 1.0);
            report.warn("non-finite", "has a NaN or infinite value; using the default");
            return fallback;
        };
        out.diffuse = colour(m.diffuse_color, Vec3(0.8));
        out.specular = colour(m.specular_color, Vec3(0.0));
        out.emissive = colour(m.emissive_color, Vec3(0.0));
        out.ambient_intensity = unit(m.ambient_intensity, 0.2);
        out.shininess = unit(m.shininess, 0.2);
        out.transparency = unit(m.transparency, 0.0);
        if (m.model == sg::MaterialModel::Physical) {
            out.specular = Vec3(0.0);
            out.reflectivity = unit(m.metallic, 0.0) * (1.0 - unit(m.roughness, 1.0));
        } else if (m.model == sg::MaterialModel::Unlit) {
            out.diffuse = out.specular = Vec3(0.0);
            out.ambient_intensity = 0.0;
            if (out.texture >= 0) out.lit = false;
        }
    }
    hints.override_with(scene_.hints_of(shape.hints));
    hints.override_with(scene_.hints_of(g.hints));
    if (hints.reflectivity >= 0.0) out.reflectivity = hints.reflectivity;
    if (hints.ior >= 0.0) out.ior = hints.ior;
    if (hints.sphere_mode != sg::SphereHint::Unset)
        out.sphere_mode =
            int8_t(hints.sphere_mode == sg::SphereHint::Gas ? SphereMode::Gas : SphereMode::Opaque);
    out.density = hints.density >= 0.0 ? hints.density : options_.density;
    out.albedo = hints.albedo.x >= 0.0 ? hints.albedo
                 : options_.albedo     ? *options_.albedo
                                       : out.diffuse;
    out.emission = hints.emission.x >= 0.0 ? hints.emission
                   : options_.emission     ? *options_.emission
                                           : out.emissive;
    return out;
}

int32_t Flattener::texture_of(sg::Index t) {
    if (texture_index_[t] != kUnloaded) return texture_index_[t];
    const sg::Texture& tex = scene_.textures[t];
    int32_t index = -1;
    if (tex.kind == sg::TextureKind::Pixel) {
        Texture out;
        out.width = tex.width;
        out.height = tex.height;
        out.channels = tex.components;
        out.sampling = tex.sampling;
        out.texels.resize(size_t(tex.width) * tex.height * tex.components);
        for (size_t p = 0; p < tex.pixels.size(); ++p)
            for (int c = 0; c < tex.components; ++c) {
                // Packed high byte first: 0xRRGGBB, 0xIIAA, ...
                const int shift = 8 * (tex.components - 1 - c);
                out.texels[p * tex.components + c] =
                    float((tex.pixels[p] >> shift) & 0xFFu) / 255.0f;
            }
        out_.textures.push_back(std::move(out));
        index = int32_t(out_.textures.size() - 1);
    } else {
        index = load_image(tex.urls, tex.from_file, tex.sampling, tex.origin);
    }
    texture_index_[t] = index;
    return index;
}

int32_t Flattener::load_image(const std::vector<std::string>& urls,
                              const std::filesystem::path& from_file,
                              const TextureSampling& sampling, const sg::Origin& origin) {
    std::vector<std::filesystem::path> roots = options_.allowed_roots;
    if (roots.empty()) roots = scene_.allowed_roots;
    std::filesystem::path from = from_file;
    if (from.empty()) from = options_.scene_file.empty() ? scene_.main_file : options_.scene_file;
    UrlFailures failures;
    for (const std::string& url : urls) {
        const std::filesystem::path path = resolve_or_note(url, from, roots, failures, true);
        if (path.empty()) continue;
        // One image per file and way of sampling it (the border colour bit for bit).
        std::string key = path.string() + "|" + std::to_string(int(sampling.wrap_s)) +
                          std::to_string(int(sampling.wrap_t)) +
                          std::to_string(int(sampling.filter));
        for (int c = 0; c < 4; ++c)
            key += "," + std::to_string(std::bit_cast<uint64_t>(sampling.border_color[c]));
        if (const auto it = image_index_.find(key); it != image_index_.end()) return it->second;
        ImageData image;
        std::string error;
        if (!read_image_file(path, image, error, options_.max_texture_pixels)) {
            failures.add(url + ": " + error);
            continue;
        }
        Texture out;
        out.width = image.width;
        out.height = image.height;
        out.channels = image.channels;
        out.texels = std::move(image.texels);
        out.sampling = sampling;
        out_.textures.push_back(std::move(out));
        const int32_t index = int32_t(out_.textures.size() - 1);
        image_index_[key] = index;
        return index;
    }
    NodeReport(diagnostics_, origin)
        .warn("texture", "no texture image could be loaded (" + failures.reasons + "); untextured");
    return -1;
}

}  // namespace vr::flatten_detail
