// What a ray sees when it hits nothing (Background: sky and ground gradients, panorama cube), and
// the Fog that mixes hit colours toward the fog colour with distance.
#pragma once
#include <optional>

#include "core/math.h"
#include "render/flat_scene.h"
#include "render/sky_map.h"

namespace vr {

class BackgroundModel {
  public:
    // `override` (--background) replaces the scene's Background with a constant colour; else a
    // `sky_map` (--sky FILE) is the background of a scene that binds no Background node.
    BackgroundModel(const FlatScene& scene, const std::optional<Vec3>& override_color,
                    const SkyMap* sky_map = nullptr);

    // Radiance arriving from world direction `dir` (any length). VRML97 Background / X3D 24.4.1:
    //   sky: skyColor[0] at the zenith, skyColor[i+1] at skyAngle[i] from the zenith, linear in the
    //        angle in between, the last colour beyond the last angle down to the nadir;
    //   ground: groundColor[0] at the nadir, groundColor[i+1] at groundAngle[i] from the nadir,
    //   drawn
    //        over the sky up to the last groundAngle and transparent beyond it. A single
    //        groundColor without angles fills the lower hemisphere (our reading; the specification
    //        is silent);
    //   panorama: six images on a cube in front of sky and ground, blended by their alpha.
    Vec3 radiance(const Vec3& dir) const;
    // radiance() is one colour for every direction (--background, or one sky colour only).
    bool uniform() const { return constant_.has_value(); }

  private:
    Vec3 gradient(const Vec3& local) const;
    const FlatScene& scene_;
    std::optional<Vec3> constant_;     // --background, or a Background of one sky colour only
    const SkyMap* sky_map_ = nullptr;  // instead of the default black: --sky FILE, no Background
    Mat3 background_from_world_{1.0};
};

// Fog visibility factor f at distance d (VRML97 Fog): colour = f * surface + (1 - f) * fogColor.
//   LINEAR:      f = (visibilityRange - d) / visibilityRange, clamped to [0, 1]
//   EXPONENTIAL: f = exp(-d / (visibilityRange - d)) for d < visibilityRange, else 0
// A visibilityRange of 0 disables fog (f = 1). The background is not fogged (VRML97 Background).
double fog_factor(const Fog& fog, double distance);
// The same factor where a FogCoordinate gives the point's fog depth d (X3D 24.4.3): f = 1 - d, d
// clamped to its range [0, 1], whatever the Fog's type and visibilityRange (which still switches
// fog on), as view3dscene reads the specification. NaN reads as no fog.
double fog_coordinate_factor(double depth);

}  // namespace vr
