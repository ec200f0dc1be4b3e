// Gas-volume spheres (docs/rendering.md, Gas mode): spheres of constant extinction sigma, albedo
// rho and emission e, whose extinctions add where they overlap. Along a ray up to the first opaque
// hit t_end:
//
//   L = integral_0^t_end T(0,t) S(t) dt + T(0,t_end) L_end
//   S(t) = sum_j sigma_j (e_j + rho_j (x) sum_l c_l att_l spot_l (a_l + i_l V_l))
//
// The ray is cut where it enters or leaves a sphere; inside each piece the set of spheres, and so
// sigma, sigma*e and sigma*rho, is constant. The emission part and every light term that is
// constant along the piece (the headlight, a directional light's ambient term) are integrated in
// closed form with expm1. The rest (attenuation, spot falloff, visibility through other spheres and
// opaque surfaces) is integrated numerically to the relative tolerance:
//
// * Per light, the spheres that can lie on the path from some point of a piece to the light (those
//   meeting the piece's light fan) are gathered from the BVH once for a run of consecutive pieces
//   about a sphere diameter long (a window). The optical depth to the light at a quadrature node is
//   then the sum of their chords along that path, evaluated from per-sphere coefficients in the
//   window's frame (four spheres at a time where AVX2 is there): no BVH traversal per node.
// * The piece is cut where the path to the light starts or stops crossing one of those spheres (the
//   camera ray meets the cylinder or cone the sphere sweeps away from the light, the sphere lying
//   between the point and the light), where a point light's radius ends and at a spot light's
//   cones. Between cuts the integrand is smooth except for square-root kinks at the cuts themselves
//   (a chord grows like the root of the distance from the silhouette), which the substitution t =
//   t0 + w x^2 (3 - 2x) makes smooth. Each interval first gets the 5-point Gauss-Lobatto rule
//   (three evaluations: the substitution's derivative is 0 at the ends), then, where its error
//   estimate is the largest, Gauss-Kronrod 7/15, then halving (opaque surfaces' shadow edges,
//   near-singular ends), until the estimates over the whole ray add up to 3/4 of the tolerance.
//
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
    double sigma = 1.0;      // extinction per scene unit
    Vec3 sigma_rho{0.0};     // sigma * albedo
    Vec3 sigma_e{0.0};       // sigma * emission
    uint32_t light_set = 0;  // which scene lights reach it (DirectionalLight scoping)
};

struct GasStats {
    uint64_t pieces = 0;           // intervals of constant sphere membership
    uint64_t closed_form = 0;      // light terms integrated exactly
    uint64_t quadrature = 0;       // light terms integrated numerically
    uint64_t visibility_rays = 0;  // shadow evaluations inside the gas
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
    // Collects the scene's gas spheres (Sphere::gas) with their sigma/albedo/emission resolved from
    // the material hints and the options. Empty when there are none.
    void build(const FlatScene& scene, const RenderOptions& options);
    bool empty() const { return spheres_.empty(); }
    size_t size() const { return spheres_.size(); }
    const std::vector<GasSphere>& spheres() const { return spheres_; }

    // sum_j sigma_j * (length of the segment t in [0, ray.t_max) inside sphere j); d need not be
    // unit.
    double optical_depth(const Ray& ray) const;

    struct Result {
        Vec3 radiance{0.0};          // the integral term
        double transmittance = 1.0;  // T(0, t_end)
        double optical_depth =
            0.0;  // -log T, summed piece by piece: alpha = -expm1(-it) keeps thin gas's digits
    };
    // What lights the gas: the scene's lights (unit directions), which of them reach which sphere,
    // and the headlight (never shadowed; null when off).
    struct Lighting {
        const std::vector<Light>* lights = nullptr;
        const std::vector<std::vector<uint32_t>>* light_sets = nullptr;
        const Light* headlight = nullptr;
        SurfaceTransmittance surfaces;  // null: nothing but gas can block light
        // An area light's V_l from a gas point (docs/rendering.md, Soft light with error bounds):
        // the share of its solid angle seen, through surfaces and gas, to --light-tolerance. Null:
        // every light is a point.
        std::function<double(const Light& light, const Vec3& p)> area_visibility;
        // area_visibility's absolute error: the quadrature of an area light's term stops refining
        // at this times the term's unshadowed bound (on top of the relative tolerance).
        double area_tolerance = 0.0;
        bool is_area(const Light& light) const {
            return area_visibility && !light.headlight &&
                   (light.kind == LightKind::Directional ? light.angular_radius > 0.0
                                                         : light.source_radius > 0.0);
        }
    };

    // Integrates along `ray` (unit direction) from 0 to t_end (kInf: no opaque hit) to the relative
    // tolerance `tolerance`. Its brute-force oracle is tests/support/gas_reference.h.
    Result integrate(const Ray& ray, double t_end, const Lighting& lighting, double tolerance,
                     GasStats& stats) const;

  private:
    struct Event {
        double t;
        uint32_t sphere;
        bool enter;
    };
    void collect_events(const Ray& ray, double t_end, std::vector<Event>& events) const;
    // integrate's parts (gas.cpp): the pieces of constant membership with their closed-form terms,
    // then one LightPass per light for the terms that vary along a piece.
    struct Piece;
    struct LightScratch;
    struct LightPass;
    Result march_pieces(const Ray& ray, double t_end, const Lighting& lighting, GasStats& stats,
                        std::vector<Piece>& pieces, std::vector<Vec3>& coef) const;
    // Calls visit(sphere index) for every gas sphere that meets the light fan of the segment [A,
    // B]: the spheres that can lie on the path from a point of the segment to the light (a
    // superset).
    template <class Visit>
    void spheres_in_fan(const Light& light, const Vec3& A, const Vec3& B, Visit&& visit) const;

    std::vector<GasSphere> spheres_;
    Bvh bvh_;
    double window_length_ = 0.0;  // twice the mean radius
};

// phi(x) = (1 - exp(-x)) / x, exact for tiny x (= 1 at 0).
double one_minus_exp_over_x(double x);

}  // namespace vr
