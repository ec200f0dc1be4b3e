// Gas-volume spheres (SPEC section 6): spheres of constant extinction sigma, albedo rho and emission e,
// whose extinctions add where they overlap. Along a ray up to the first opaque hit t_end:
//
//   L = integral_0^t_end T(0,t) S(t) dt + T(0,t_end) L_end
//   S(t) = sum_j sigma_j (e_j + rho_j (x) sum_l c_l att_l spot_l (a_l + i_l V_l))
//
// The ray is cut where it enters or leaves a sphere; inside each piece the set of spheres, and so sigma,
// sigma*e and sigma*rho, is constant. The emission part and every light term that is constant along the
// piece (the headlight, a directional light nothing can shadow there) are integrated in closed form with
// expm1; the rest (attenuation, spot falloff, visibility through other spheres and opaque surfaces) by
// adaptive Gauss-Kronrod (7/15 points) to the relative tolerance, with the piece first cut where the path
// to the light starts or stops crossing a sphere (the camera ray meets the cylinder or cone that sphere
// sweeps away from the light), where a point light's radius ends and where a spot light's cones are.
// A scene without gas spheres builds nothing here and pays one branch per ray.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "core/ray.h"
#include "render/bvh.h"
#include "render/flat_scene.h"
#include "render/options.h"

namespace vr {

struct GasSphere {
    Vec3 center;
    double radius = 1.0;
    double sigma = 1.0;     // extinction per scene unit
    Vec3 sigma_rho{0.0};    // sigma * albedo
    Vec3 sigma_e{0.0};      // sigma * emission
    uint32_t light_set = 0;  // which scene lights reach it (DirectionalLight scoping)
};

struct GasStats {
    uint64_t pieces = 0;          // intervals of constant sphere membership
    uint64_t closed_form = 0;     // light terms integrated exactly
    uint64_t quadrature = 0;      // light terms integrated numerically
    uint64_t visibility_rays = 0; // shadow evaluations inside the gas
    void add(const GasStats& o) {
        pieces += o.pieces;
        closed_form += o.closed_form;
        quadrature += o.quadrature;
        visibility_rays += o.visibility_rays;
    }
};

// How much light passes along a segment because of everything that is not gas (opaque surfaces: 0;
// see-through surfaces: their transparency). Supplied by the opaque tracer.
using SurfaceTransmittance = std::function<double(const Ray& ray)>;

class GasVolume {
public:
    // Collects the scene's gas spheres (Sphere::gas) with their sigma/albedo/emission resolved from the
    // material hints and the options. Empty when there are none.
    void build(const FlatScene& scene, const RenderOptions& options);
    bool empty() const { return spheres_.empty(); }
    size_t size() const { return spheres_.size(); }
    const std::vector<GasSphere>& spheres() const { return spheres_; }

    // sum_j sigma_j * (length of the segment t in [0, ray.t_max) inside sphere j); d need not be unit.
    double optical_depth(const Ray& ray) const;

    struct Result {
        Vec3 radiance{0.0};        // the integral term
        double transmittance = 1.0;  // T(0, t_end)
    };
    // What lights the gas: the scene's lights (unit directions), which of them reach which sphere, and the
    // headlight (never shadowed; null when off).
    struct Lighting {
        const std::vector<Light>* lights = nullptr;
        const std::vector<std::vector<uint32_t>>* light_sets = nullptr;
        const Light* headlight = nullptr;
        SurfaceTransmittance surfaces;  // null: nothing but gas can block light
    };

    // Integrates along `ray` (unit direction) from 0 to t_end (kInf: no opaque hit) to the relative
    // tolerance `tolerance`.
    Result integrate(const Ray& ray, double t_end, const Lighting& lighting, double tolerance,
                     GasStats& stats) const;

    // The same integral by brute force: the midpoint rule with `steps` steps per piece and exact visibility
    // at every step. For tests of the adaptive integrator.
    Result integrate_reference(const Ray& ray, double t_end, const Lighting& lighting, int steps) const;

private:
    struct Event {
        double t;
        uint32_t sphere;
        bool enter;
    };
    void collect_events(const Ray& ray, double t_end, std::vector<Event>& events) const;
    // att * spot * (ambient + intensity * V) at p (with ambient = false: att * spot * intensity * V).
    double light_weight(const Light& light, const Vec3& p, bool ambient, const SurfaceTransmittance& surfaces,
                        GasStats& stats) const;
    // Where along [a, b] of `ray` the light's weight has a kink or a jump that can be found in advance.
    void split_points(const Light& light, const Ray& ray, double a, double b, std::vector<double>& out) const;

    std::vector<GasSphere> spheres_;
    Bvh bvh_;
    Bounds3 bounds_;
};

// phi(x) = (1 - exp(-x)) / x, exact for tiny x (= 1 at 0).
double one_minus_exp_over_x(double x);

}  // namespace vr
