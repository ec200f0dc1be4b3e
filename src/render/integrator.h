// The opaque-mode integrator (docs/rendering.md): Whitted-style recursion with the VRML97 lighting
// equation at every hit, shadow rays with see-through attenuation, mirror reflection and
// refraction/see-through transparency by the reflectivity/transparency/ior hints.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/ray.h"
#include "render/accel.h"
#include "render/background.h"
#include "render/camera.h"
#include "render/flat_scene.h"
#include "render/gas.h"
#include "render/lines.h"
#include "render/options.h"
#include "render/sampling.h"
#include "render/shading.h"
#include "render/sky_area_light.h"
#include "render/sky_share.h"

namespace vr {

// Non-finite values met while tracing, by where they arose; each is replaced by 0 there (a NaN is a
// bug, counted so that it is never hidden). `light`: one light's term at a hit; `gas`: a gas
// integral along a ray; `shading`: a pixel's colour channel still not finite at output (material,
// texture, mirror...).
struct NonFiniteCounts {
    uint64_t shading = 0, gas = 0, light = 0;
    void add(const NonFiniteCounts& o) {
        shading += o.shading;
        gas += o.gas;
        light += o.light;
    }
    uint64_t total() const { return shading + gas + light; }
};

struct RayCounters {
    uint64_t primary = 0, shadow = 0, secondary = 0;
    NonFiniteCounts nonfinite;
    SoftLightCounts
        soft;  // sky light and area lights (docs/rendering.md, Soft light with error bounds)
    // Not a count: this thread's last shadow-ray blocker, the hint of Accel::transmittance (any
    // value is correct; the thread's next shadow ray tries it first).
    uint32_t shadow_blocker = UINT32_MAX;
    // Not a count: set by the tile loop for one camera ray, whose first surface may take its sky
    // light from the lattice around its image point (render/sky_share.h); empty otherwise.
    SkyShareSample sky_share;
    void add(const RayCounters& o) {
        primary += o.primary;
        shadow += o.shadow;
        secondary += o.secondary;
        nonfinite.add(o.nonfinite);
        soft.add(o.soft);
    }
    uint64_t total() const { return primary + shadow + secondary; }
};

// Exact dielectric Fresnel reflectance for unpolarised light; eta = n_incident / n_transmitted,
// cos_i > 0. Returns 1 on total internal reflection, and sets cos_t otherwise.
double fresnel_dielectric(double cos_i, double eta, double& cos_t);

// Refracted direction of unit `d` through a surface with unit normal `n` facing the incoming ray
// (dot(d, n) < 0); false on total internal reflection.
bool refract_direction(const Vec3& d, const Vec3& n, double eta, Vec3& out);

class Integrator {
  public:
    // `gas`: the scene's gas spheres (may be null or empty: then no gas work is done at all).
    Integrator(const FlatScene& scene, const Accel& accel, const Camera& camera,
               const RenderOptions& options, const GasVolume* gas = nullptr);

    // A camera ray: colour and alpha (1 - the weight with which the background reaches it); with
    // options.alpha the colour leaves that background out (premultiplied by alpha).
    SampleValue trace_camera_ray(const Ray& ray, RayCounters& counters) const;
    // Whether a camera ray that meets no primitive of the Accel sees only the background: no gas
    // and no line marks, which camera rays meet outside the Accel.
    bool camera_misses_see_background() const { return !gas_ && lines_.empty(); }
    // Whether every miss sees the same background, whatever its direction.
    bool uniform_background() const { return background_.uniform(); }
    // trace_camera_ray for a ray known to meet nothing (Accel::frustum_may_hit said so for its
    // tile), without the BVH: the same value, bit for bit.
    SampleValue trace_camera_miss(const Ray& ray, RayCounters& counters) const;

    // Any ray at recursion depth `depth` (camera rays: 0) whose contribution to the pixel is scaled
    // by `weight`.
    SampleValue trace(const Ray& ray, int depth, double weight, RayCounters& counters) const;
    // The same without the gas along the ray: the first surface, or the background.
    // `known_hit`: the closest hit if the caller has already looked for it (null: look here).
    SampleValue trace_surfaces(const Ray& ray, int depth, double weight, RayCounters& counters,
                               const std::optional<Hit>* known_hit = nullptr) const;
    // A ray that meets nothing: the background, reaching the pixel with full weight.
    SampleValue background_sample(const Ray& ray) const {
        SampleValue out;
        out.color = background_.radiance(ray.d);
        out.alpha = 0.0;
        return out;
    }

    // The local VRML97 colour at a hit: emissive + sum over lights of on * att * spot * colour *
    // (ambient + visibility * (diffuse + specular)). `ng`/`ns` face the viewer, `to_viewer` is
    // unit.
    // `share`: the camera ray's claim on the sky light's lattice (null: estimate A here).
    Vec3 shade_local(const SurfaceHit& hit, const SurfaceLook& look, const Vec3& ng, const Vec3& ns,
                     const Vec3& to_viewer, RayCounters& counters,
                     const SkyShareSample* share = nullptr) const;

    // Whether the sky light may be shared between pixels (render/sky_share.h).
    bool shares_sky() const { return soft_ && soft_->shares_sky(); }
    // The sky light's lattice point whose camera ray is `ray`, without its A; then its A.
    SkyShareNode sky_share_node(const Ray& ray, RayCounters& counters) const;
    double sky_share_estimate(const SkyShareNode& node, RayCounters& counters) const;

  private:
    // A camera ray past any line or point mark: trace() with the --alpha rule applied.
    SampleValue trace_behind(const Ray& ray, RayCounters& counters) const;
    // A camera ray's sample with the --alpha rule applied (the background it sees left out).
    SampleValue alpha_rule(SampleValue v, const Ray& ray) const;
    // trace_camera_ray under the look for publication (render/look.h): exposure, tone curve and
    // depth cue applied to the opaque sample, then the --alpha rule with the exposed background.
    SampleValue trace_camera_look(const Ray& ray, RayCounters& counters) const;
    // The light scale, exposure, tone curve and depth cue range from the options.
    void setup_look(const Camera& camera);

    const FlatScene& scene_;
    const Accel& accel_;
    const RenderOptions& options_;
    BackgroundModel background_;
    std::vector<Light>
        lights_;  // scene lights with unit directions; headlights aimed along the view
    std::vector<bool> textured_;      // per Shading: needs texture coordinates
    std::vector<SurfaceLook> looks_;  // material_looks(scene_): clamped once, not at every hit
    bool has_headlight_ = false;
    Light headlight_;
    const GasVolume* gas_ = nullptr;  // non-null only when the scene has gas spheres
    LineOverlay lines_;  // IndexedLineSet, LineSet and PointSet marks, seen by camera rays
    GasVolume::Lighting gas_lighting_;
    // Only with --sky or an area light: without them shading is exactly as before.
    std::unique_ptr<SoftLighting> soft_;
    Vec3 sky_{0.0};
    // The look for publication (render/look.h); `look_` false: camera rays as the VRML model has
    // them, bit for bit.
    bool look_ = false;
    double exposure_ = 1.0;  // 2^EV
    bool tone_hue_ = false, depth_cue_ = false;
    double cue_near_ = 0.0, cue_far_ = 0.0;  // view depths where the depth cue starts and ends
    Vec3 eye_{0.0}, forward_{0.0, 0.0, -1.0};
};

}  // namespace vr
