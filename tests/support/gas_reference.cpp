#include "support/gas_reference.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/lights.h"

namespace vr {
namespace {

struct Event {
    double t;
    uint32_t sphere;
    bool enter;
};

// Where the ray enters and leaves each sphere within [0, t_end], sorted by place, then sphere, as
// the integrator orders them. The chord from the closest-approach vector, as gas.cpp computes it.
std::vector<Event> sphere_events(const std::vector<GasSphere>& spheres, const Ray& ray,
                                 double t_end) {
    std::vector<Event> events;
    const double a = glm::dot(ray.d, ray.d);
    for (uint32_t id = 0; id < spheres.size(); ++id) {
        const GasSphere& g = spheres[id];
        const Vec3 oc = ray.o - g.center;
        const double tca = -glm::dot(oc, ray.d) / a;
        const Vec3 l = oc + tca * ray.d;
        const double disc = std::fma(g.radius, g.radius, -glm::dot(l, l));
        if (!(disc > 0.0)) continue;
        const double thc = std::sqrt(disc / a);
        const double t0 = std::max(tca - thc, 0.0), t1 = std::min(tca + thc, t_end);
        if (!(t1 > t0)) continue;
        events.push_back({t0, id, true});
        events.push_back({t1, id, false});
    }
    std::sort(events.begin(), events.end(), [](const Event& x, const Event& y) {
        if (x.t != y.t) return x.t < y.t;
        if (x.sphere != y.sphere) return x.sphere < y.sphere;
        return x.enter > y.enter;
    });
    return events;
}

// att * spot * (ambient + intensity * V) at p, V by a shadow ray through the surfaces and the gas
// (an area light: the lighting's own V_l).
double light_weight(const GasVolume& gas, const Light& light, const Vec3& p,
                    const GasVolume::Lighting& lighting) {
    const LightIncidence inc = light_incidence(light, p);
    if (!(inc.factor > 0.0)) return 0.0;
    double visibility = 1.0;
    if (lighting.is_area(light)) {
        visibility = lighting.area_visibility(light, p);
    } else if (!light.headlight) {
        Ray shadow;
        shadow.o = p;
        if (light.kind == LightKind::Directional) {
            shadow.d = inc.to_light;
            shadow.t_max = kInf;
        } else {
            shadow.d = light.position - p;  // t = 1 at the light
            shadow.t_max = 1.0;
        }
        if (lighting.surfaces) visibility = lighting.surfaces(shadow);
        if (visibility > 0.0) visibility *= std::exp(-gas.optical_depth(shadow));
    }
    return inc.factor * (light.ambient_intensity + light.intensity * visibility);
}

}  // namespace

GasVolume::Result integrate_gas_reference(const GasVolume& gas, const Ray& ray, double t_end,
                                          const GasVolume::Lighting& lighting, int steps) {
    GasVolume::Result result;
    const std::vector<GasSphere>& spheres = gas.spheres();
    if (spheres.empty()) return result;
    std::vector<uint32_t> active;
    double T = 1.0, tau = 0.0;
    Vec3 L(0.0);
    double prev = 0.0;
    for (const Event& e : sphere_events(spheres, ray, t_end)) {
        if (!active.empty() && e.t > prev) {
            const double a = prev, b = e.t, h = (b - a) / steps;
            double sigma = 0.0;
            Vec3 sigma_e(0.0);
            for (uint32_t id : active) {
                sigma += spheres[id].sigma;
                sigma_e += spheres[id].sigma_e;
            }
            L += T * (b - a) * one_minus_exp_over_x(sigma * (b - a)) * sigma_e;
            for (int k = 0; k < steps; ++k) {
                const double t = a + (k + 0.5) * h;
                const double w = h * std::exp(-sigma * (t - a));
                const Vec3 p = ray.at(t);
                for (uint32_t id : active) {
                    const GasSphere& g = spheres[id];
                    if (lighting.headlight) {
                        const Light& hl = *lighting.headlight;
                        L += T * w * (hl.ambient_intensity + hl.intensity) * g.sigma_rho * hl.color;
                    }
                    if (!lighting.lights) continue;
                    for (uint32_t l : (*lighting.light_sets)[g.light_set]) {
                        const Light& light = (*lighting.lights)[l];
                        L += T * w * light_weight(gas, light, p, lighting) * g.sigma_rho *
                             light.color;
                    }
                }
            }
            T *= std::exp(-sigma * (b - a));
            tau += sigma * (b - a);
        }
        if (e.enter) {
            active.push_back(e.sphere);
        } else {
            auto it = std::find(active.begin(), active.end(), e.sphere);
            if (it != active.end()) active.erase(it);
        }
        prev = std::max(prev, e.t);
    }
    result.radiance = L;
    result.transmittance = T;
    result.optical_depth = tau;
    return result;
}

}  // namespace vr
