#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "render/lights.h"
#include "render/look.h"

namespace vr {
namespace {

bool finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

double fresnel_dielectric(double cos_i, double eta, double& cos_t) {
    cos_i = std::clamp(cos_i, 0.0, 1.0);
    const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        cos_t = 0.0;
        return 1.0;
    }
    cos_t = std::sqrt(1.0 - sin2_t);
    // Reflection amplitudes for s and p polarisation (Fresnel equations divided by n_transmitted).
    const double rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const double rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

bool refract_direction(const Vec3& d, const Vec3& n, double eta, Vec3& out) {
    const double cos_i = -glm::dot(d, n);
    const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return false;
    const double cos_t = std::sqrt(1.0 - sin2_t);
    out = glm::normalize(eta * d + (eta * cos_i - cos_t) * n);
    return true;
}

Integrator::Integrator(const FlatScene& scene, const Accel& accel, const Camera& camera,
                       const RenderOptions& options, const GasVolume* gas)
    : scene_(scene),
      accel_(accel),
      options_(options),
      background_(scene, options.background, options.sky_map.get()),
      looks_(material_looks(scene)),
      gas_(gas && !gas->empty() ? gas : nullptr),
      lines_(scene, camera, options.width, options.height, options.line_width, options.point_size) {
    const Vec3 view = camera.forward();
    lights_ = scene.lights;
    for (Light& l : lights_) {
        if (l.headlight) l.direction = view;
        double len = glm::length(l.direction);
        l.direction = len > 0.0 && std::isfinite(len) ? l.direction / len : Vec3(0.0, 0.0, -1.0);
    }
    textured_.resize(scene.shadings.size(), false);
    for (size_t i = 0; i < scene.shadings.size(); ++i) {
        uint32_t m = scene.shadings[i].material;
        textured_[i] = m < scene.materials.size() && scene.materials[m].texture >= 0;
    }
    // NavigationInfo headlight: directional along the view, intensity 1, ambient 0, white.
    has_headlight_ = options.headlight.value_or(scene.headlight);
    headlight_.kind = LightKind::Directional;
    headlight_.color = Vec3(1.0);
    headlight_.intensity = 1.0;
    headlight_.ambient_intensity = 0.0;
    headlight_.direction = view;
    headlight_.headlight = true;
    bool area_lights = false;
    for (const Light& l : lights_)
        area_lights = area_lights || (l.kind == LightKind::Directional ? l.angular_radius > 0.0
                                                                       : l.source_radius > 0.0);
    if (options.sky || options.sky_map || area_lights) {
        soft_ = std::make_unique<SoftLighting>(scene, accel, gas_, options);
        sky_ = options.sky.value_or(Vec3(0.0));
    }
    setup_look(camera);
    if (gas_) {
        gas_lighting_.lights = &lights_;
        gas_lighting_.light_sets = &scene_.light_sets;
        gas_lighting_.headlight = has_headlight_ ? &headlight_ : nullptr;
        gas_lighting_.surfaces = [this](const Ray& r) { return accel_.transmittance(r); };
        gas_lighting_.area_tolerance = options.light_tolerance;
        if (area_lights)
            gas_lighting_.area_visibility = [this](const Light& light, const Vec3& p) {
                SoftLightCounts unused;  // the gas counts these as its visibility evaluations
                return soft_->light_visibility(light, p, Vec3(0.0), Vec3(0.0), unused);
            };
    }
}

void Integrator::setup_look(const Camera& camera) {
    double scale = options_.light_scale;
    if (options_.light_scale_auto) {
        double sky_max = 0.0;
        if (options_.sky) sky_max = std::max({options_.sky->x, options_.sky->y, options_.sky->z});
        if (options_.sky_map) {
            const Vec3& h = options_.sky_map->highest();
            sky_max = std::max({h.x, h.y, h.z});
        }
        double ambient_max = 0.0;
        for (const SurfaceLook& l : looks_)
            if (l.lit) ambient_max = std::max(ambient_max, l.ambient_intensity);
        scale = auto_light_scale(lights_, has_headlight_, sky_max, ambient_max);
    }
    if (scale != 1.0 && std::isfinite(scale) && scale >= 0.0) {
        for (Light& l : lights_) l.color *= scale;
        headlight_.color *= scale;
    }
    exposure_ = std::exp2(options_.exposure);
    tone_hue_ = options_.tone_hue;
    depth_cue_ = options_.depth_cue;
    look_ = options_.exposure != 0.0 || tone_hue_ || depth_cue_;
    if (!depth_cue_) return;
    eye_ = camera.position;
    forward_ = camera.forward();
    if (!options_.depth_cue_near || !options_.depth_cue_far) {
        const DepthRange range = scene_depth_range(scene_, eye_, forward_);
        cue_near_ = range.near + kDepthCueStart * (range.far - range.near);
        cue_far_ = range.far;
    }
    cue_near_ = options_.depth_cue_near.value_or(cue_near_);
    cue_far_ = options_.depth_cue_far.value_or(cue_far_);
}

Vec3 Integrator::shade_local(const SurfaceHit& hit, const SurfaceLook& look, const Vec3& ng,
                             const Vec3& ns, const Vec3& to_viewer, RayCounters& counters,
                             const SkyShareSample* share) const {
    if (!look.lit) return look.diffuse;
    Vec3 color = look.emissive;
    const double exponent = look.shininess * 128.0;
    if (soft_ && soft_->sky()) {
        if (soft_->sky_map()) {
            color += soft_->sky_radiance(hit.p, hit.p_error, ng, ns, counters.soft) * look.diffuse;
        } else {
            double a = 0.0;
            if (share && sky_share_interpolate(*share->tile, share->x, share->y, share->surface,
                                               hit.p, ns, soft_->tolerance(), a))
                ++counters.soft.shared_points;
            else
                a = soft_->sky_visibility(hit.p, hit.p_error, ng, ns, counters.soft);
            color += a * sky_ * look.diffuse;
        }
    }

    auto add_light = [&](const Light& light) {
        const LightIncidence inc = light_incidence(light, hit.p);
        if (std::isnan(inc.factor)) ++counters.nonfinite.light;
        if (!(inc.factor > 0.0)) return;
        const Vec3 light_rgb = light.color * inc.factor;
        // The ambient term is never shadowed (docs/rendering.md).
        Vec3 term = light.ambient_intensity * look.ambient_intensity * look.diffuse;
        const Vec3& l = inc.to_light;
        const double n_dot_l = glm::dot(ns, l);
        // Lights behind the surface add only their ambient term, and then no specular either (the
        // OpenGL convention VRML browsers follow; the VRML97 formula leaves N.H unguarded).
        if (n_dot_l > 0.0 && light.intensity > 0.0) {
            double visibility = 1.0;
            const bool area = light.kind == LightKind::Directional ? light.angular_radius > 0.0
                                                                   : light.source_radius > 0.0;
            if (area && soft_ && !light.headlight) {
                visibility = soft_->light_visibility(light, hit.p, hit.p_error, ng, counters.soft);
            } else if (!light.headlight) {
                Ray shadow = light.kind == LightKind::Directional
                                 ? spawn_ray(hit.p, hit.p_error, ng, l)
                                 : spawn_ray_to(hit.p, hit.p_error, ng, light.position);
                ++counters.shadow;
                visibility = accel_.transmittance(shadow, &counters.shadow_blocker);
                // Gas spheres on the way dim the light by their transmittance (docs/rendering.md).
                if (gas_ && visibility > 0.0) visibility *= std::exp(-gas_->optical_depth(shadow));
                if (std::isnan(visibility))
                    ++counters.nonfinite.light;  // dropped below, not hidden
            }
            if (visibility > 0.0) {
                Vec3 h = l + to_viewer;
                double h_len = glm::length(h);
                double n_dot_h = h_len > 0.0 ? std::max(glm::dot(ns, h / h_len), 0.0) : 0.0;
                Vec3 lit = look.diffuse * n_dot_l + look.specular * std::pow(n_dot_h, exponent);
                term += (visibility * light.intensity) * lit;
            }
        }
        const Vec3 add = light_rgb * term;
        if (!finite(add)) {
            ++counters.nonfinite.light;
            return;
        }
        color += add;
    };

    if (hit.shading < scene_.shadings.size()) {
        uint32_t set = scene_.shadings[hit.shading].light_set;
        if (set < scene_.light_sets.size()) {
            for (uint32_t li : scene_.light_sets[set])
                if (li < lights_.size()) add_light(lights_[li]);
        }
    }
    if (has_headlight_) add_light(headlight_);
    return color;
}

SkyShareNode Integrator::sky_share_node(const Ray& ray, RayCounters& counters) const {
    SkyShareNode node;
    Hit hit;
    ++counters.soft.rays;  // the lattice point's camera ray: the sky light's work
    if (!accel_.intersect(ray, hit)) return node;
    const uint32_t shading = accel_.shading_of(hit);
    const SurfaceHit s = accel_.surface(ray, hit, false);
    if (!look_up_surface(scene_, looks_, s).lit) return node;
    // Normals face the camera, as trace_surfaces turns them.
    const bool front = glm::dot(s.ng, ray.d) < 0.0;
    node.valid = true;
    node.surface = sky_share_surface(hit.prim, hit.part, shading);
    node.p = s.p;
    node.p_error = s.p_error;
    node.ng = front ? s.ng : -s.ng;
    node.ns = front ? s.ns : -s.ns;
    return node;
}

double Integrator::sky_share_estimate(const SkyShareNode& node, RayCounters& counters) const {
    return soft_->shared_sky_visibility(node.p, node.p_error, node.ng, node.ns, counters.soft);
}

SampleValue Integrator::alpha_rule(SampleValue v, const Ray& ray) const {
    // With --alpha the colour leaves out the background that reaches the pixel (docs/manual.md,
    // render), so that colour + (1 - alpha) * background, the image composited over its background,
    // is the opaque image again. A clean miss gives exactly 0.
    if (options_.alpha && v.alpha < 1.0) v.color -= (1.0 - v.alpha) * background_.radiance(ray.d);
    return v;
}

SampleValue Integrator::trace_behind(const Ray& ray, RayCounters& counters) const {
    return alpha_rule(trace(ray, 0, 1.0, counters), ray);
}

SampleValue Integrator::trace_camera_look(const Ray& ray, RayCounters& counters) const {
    Hit first;
    const bool met = accel_.intersect(ray, first);
    const double t_surface = met ? first.t : kInf;
    SampleValue v;
    if (gas_) {
        v = trace(ray, 0, 1.0, counters);
    } else if (met) {
        const std::optional<Hit> known(first);
        v = trace_surfaces(ray, 0, 1.0, counters, &known);
    } else {
        v = background_sample(ray);
    }
    const Vec3 background = exposure_ * background_.radiance(ray.d);
    v.color *= exposure_;
    if (tone_hue_ && v.alpha > 0.0) v.color = tone_hue(v.color);
    if (depth_cue_ && met) {
        const double z = glm::dot(ray.o + first.t * ray.d - eye_, forward_);
        const double f = depth_cue_fraction(z, cue_near_, cue_far_);
        // An exporter's depth cue colour (<chimera:DepthCue color>); with --alpha the surface
        // fades out, towards no colour at all.
        const Vec3 fade_to = options_.depth_cue_color && !options_.alpha
                                 ? exposure_ * *options_.depth_cue_color
                                 : background;
        v.color = (1.0 - f) * v.color + f * fade_to;
        // With --alpha the surface fades out (the rule below then leaves f * background out);
        // without, alpha stays the coverage that a render's "nothing seen" check counts.
        if (options_.alpha) v.alpha *= 1.0 - f;
    }
    SampleValue mark;
    double opacity = 1.0;
    if (!lines_.empty() && lines_.nearest(ray, t_surface, mark.color, opacity)) {
        mark.color *= exposure_;
        v.color = opacity * mark.color + (1.0 - opacity) * v.color;
        v.alpha = opacity + (1.0 - opacity) * v.alpha;
    }
    if (options_.alpha && v.alpha < 1.0) v.color -= (1.0 - v.alpha) * background;
    return v;
}

SampleValue Integrator::trace_camera_ray(const Ray& ray, RayCounters& counters) const {
    ++counters.primary;
    if (look_) return trace_camera_look(ray, counters);
    if (!lines_.empty()) {
        // Lines and points are seen by camera rays only, in front of the first surface.
        Hit hit;
        const double t_surface = accel_.intersect(ray, hit) ? hit.t : kInf;
        SampleValue mark;
        double opacity = 1.0;
        if (lines_.nearest(ray, t_surface, mark.color, opacity)) {
            mark.alpha = 1.0;
            if (opacity >= 1.0) return mark;
            // A translucent mark over what the ray sees behind it (surfaces and background; a
            // farther mark is not seen through a nearer one), as Material.transparency blends.
            const SampleValue behind = trace_behind(ray, counters);
            mark.color = opacity * mark.color + (1.0 - opacity) * behind.color;
            mark.alpha = opacity + (1.0 - opacity) * behind.alpha;
            return mark;
        }
    }
    return trace_behind(ray, counters);
}

SampleValue Integrator::trace_camera_miss(const Ray& ray, RayCounters& counters) const {
    ++counters.primary;
    if (look_) {
        // Only the exposure reaches a clean miss (no surface to tone or depth-cue).
        SampleValue v = background_sample(ray);
        v.color *= exposure_;
        if (options_.alpha) v.color -= exposure_ * background_.radiance(ray.d);
        return v;
    }
    return alpha_rule(background_sample(ray), ray);
}

SampleValue Integrator::trace(const Ray& ray, int depth, double weight,
                              RayCounters& counters) const {
    if (!gas_) {
        // Misses (most camera rays of a small scene) return here, without entering the large frame
        // of trace_surfaces: on a one-sphere scene at 1920x1080 that is a tenth of the render.
        std::optional<Hit> hit(std::in_place);
        if (!accel_.intersect(ray, *hit)) return background_sample(ray);
        return trace_surfaces(ray, depth, weight, counters, &hit);
    }
    // Gas along the ray up to the first surface (docs/rendering.md, Gas mode): L = gas + T * L_end.
    std::optional<Hit> surface;
    if (Hit hit; accel_.intersect(ray, hit)) surface = hit;
    const double len = glm::length(ray.d);
    Ray unit = ray;
    unit.d = ray.d / len;
    unit.t_max = kInf;
    GasStats stats;
    const GasVolume::Result g = gas_->integrate(unit, surface ? surface->t * len : kInf,
                                                gas_lighting_, options_.tolerance, stats);
    counters.shadow += stats.visibility_rays;
    double transmittance = g.transmittance;
    double optical_depth = g.optical_depth;  // may be +inf (dense gas): alpha 1, not a fault
    Vec3 radiance = g.radiance;
    if (!std::isfinite(transmittance) || std::isnan(optical_depth) || !finite(radiance)) {
        ++counters.nonfinite.gas;
        if (!std::isfinite(transmittance) || std::isnan(optical_depth)) {
            transmittance = 1.0;  // as if the gas were not there
            optical_depth = 0.0;
        }
        if (!finite(radiance)) radiance = Vec3(0.0);
    }
    SampleValue out;
    out.alpha = 1.0;  // gas that lets nothing through hides whatever is behind it
    if (transmittance > 0.0) {
        out = trace_surfaces(ray, depth, weight * transmittance, counters, &surface);
        out.color *= transmittance;
    }
    out.color += radiance;
    // 1 - T * (1 - alpha behind) as a sum of non-negative terms; the gas's own share from its
    // optical depth, not as 1 - T.
    out.alpha = -std::expm1(-optical_depth) + transmittance * out.alpha;
    return out;
}

SampleValue Integrator::trace_surfaces(const Ray& ray, int depth, double weight,
                                       RayCounters& counters,
                                       const std::optional<Hit>* known_hit) const {
    SampleValue out;
    Hit hit;
    const bool found = known_hit ? known_hit->has_value() : accel_.intersect(ray, hit);
    if (known_hit && found) hit = **known_hit;
    if (!found) return background_sample(ray);
    const uint32_t shading = accel_.shading_of(hit);
    const SurfaceHit s = accel_.surface(ray, hit, shading < textured_.size() && textured_[shading]);
    const SurfaceLook look = look_up_surface(scene_, looks_, s);

    const double len = glm::length(ray.d);
    const Vec3 d = ray.d / len;
    // Normals face the incoming ray: VRML `solid TRUE` allows culling back faces, but a ray tracer
    // sees both sides (through transparent or reflecting surfaces too), so we shade both.
    const bool front = glm::dot(s.ng, d) < 0.0;
    const Vec3 ng = front ? s.ng : -s.ng;
    const Vec3 ns = front ? s.ns : -s.ns;
    const Vec3 to_viewer = -d;

    const double kt = look.transparency, kr = look.reflectivity;
    const double local_weight = std::max(0.0, 1.0 - kr - kt);
    // The camera ray's claim on the sky light's lattice holds for its first surface only: taken
    // off before any other ray is traced.
    SkyShareSample share = std::exchange(counters.sky_share, SkyShareSample{});
    if (share.tile) share.surface = sky_share_surface(hit.prim, hit.part, shading);
    Vec3 color(0.0);
    if (local_weight > 0.0)
        color += local_weight *
                 shade_local(s, look, ng, ns, to_viewer, counters, share.tile ? &share : nullptr);

    double alpha =
        1.0;  // an opaque hit, unless the transmitted ray below brings background through
    if (depth + 1 < options_.max_depth && (kr > 0.0 || kt > 0.0)) {
        double w_reflect = kr, w_transmit = kt;
        Vec3 t_dir = d;
        // An interpolated normal can face away from the viewer near silhouettes; mirror and refract
        // about the true surface then.
        const Vec3 n = glm::dot(ns, to_viewer) > 0.0 ? ns : ng;
        if (kt > 0.0 && look.ior != 1.0) {
            // Refraction: the outside medium is taken as vacuum; `front` says whether we enter.
            const double eta = front ? 1.0 / look.ior : look.ior;
            double cos_t;
            const double cos_i = std::clamp(glm::dot(to_viewer, n), 0.0, 1.0);
            const double f = fresnel_dielectric(cos_i, eta, cos_t);
            w_reflect += kt * f;
            w_transmit = kt * (1.0 - f);
            if (w_transmit > 0.0 && !refract_direction(d, n, eta, t_dir)) {
                w_reflect += w_transmit;
                w_transmit = 0.0;
            }
            // A shading normal may bend the refracted ray back over the surface: use the true one.
            if (w_transmit > 0.0 && glm::dot(t_dir, ng) >= 0.0 &&
                !refract_direction(d, ng, eta, t_dir)) {
                w_reflect += w_transmit;
                w_transmit = 0.0;
            }
        }
        if (w_reflect > 0.0 && weight * w_reflect >= options_.min_weight) {
            Vec3 r_dir = d - 2.0 * glm::dot(d, n) * n;
            if (glm::dot(r_dir, ng) <= 0.0) r_dir = d - 2.0 * glm::dot(d, ng) * ng;
            ++counters.secondary;
            SampleValue r = trace(spawn_ray(s.p, s.p_error, ng, r_dir), depth + 1,
                                  weight * w_reflect, counters);
            color += w_reflect * r.color;
        }
        if (w_transmit > 0.0 && weight * w_transmit >= options_.min_weight) {
            ++counters.secondary;
            SampleValue t = trace(spawn_ray(s.p, s.p_error, ng, t_dir), depth + 1,
                                  weight * w_transmit, counters);
            color += w_transmit * t.color;
            alpha = (1.0 - w_transmit) + w_transmit * t.alpha;
        }
    }

    // A LocalFog above the shape replaces the scene's Fog for it (X3D 24.4.3).
    const uint32_t scope = scene_.local_fogs.empty() ? 0 : scene_.shadings[shading].scope;
    const int32_t local_fog = scope == 0 ? -1 : scene_.scopes[scope].local_fog;
    const Fog& fog = local_fog < 0 ? scene_.fog : scene_.local_fogs[size_t(local_fog)];
    if (fog.kind != FogKind::None) {
        const double f =
            s.has_fog_depth ? fog_coordinate_factor(s.fog_depth) : fog_factor(fog, s.t * len);
        color = f * color + (1.0 - f) * fog.color;
        alpha = (1.0 - f) + f * alpha;
    }
    out.color = color;
    out.alpha = alpha;
    return out;
}

}  // namespace vr
