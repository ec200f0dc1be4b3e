// The look for publication (docs/rendering.md, "Leaving the VRML lighting model"): adjustments
// that leave the VRML97 lighting model on purpose, each off by default. A camera sample's colour
// goes through them in this order: exposure (x 2^EV), the tone curve (surfaces only), depth cue
// (a blend toward the background); the direct lights are scaled before shading.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "render/flat_scene.h"

namespace vr {

// --tone: what happens to a colour with a channel above 1.
enum class ToneCurve : uint8_t {
    Clip,  // each channel clipped at output (the VRML default): a bright colour turns white
    Hue,   // the colour scaled by tone_shoulder(max channel) / max channel: channel ratios kept
};

// The hue-keeping tone curve's knee: below it a colour is unchanged; above it the largest
// channel m is compressed smoothly (slope 1 at the knee, so the curve has no visible corner)
// toward 1, which it reaches at kToneWhite; beyond that the colour is scaled to max channel 1.
constexpr double kToneKnee = 0.7;
constexpr double kToneWhite = 2.5;

// The shoulder: m for m <= kToneKnee; k + (1 - k) h(x) above it, x = (m - k) / (1 - k) and
// h(x) = x (1 + x / xw^2) / (1 + x) (Reinhard's curve with a white point xw, slope 1 at 0,
// h(xw) = 1); 1 from kToneWhite on. Monotone, continuous with its first derivative at the knee.
double tone_shoulder(double m);
// The colour under the hue-keeping curve: c * tone_shoulder(max) / max (negative channels, which
// the tracer never makes, are left as they are).
Vec3 tone_hue(const Vec3& c);

// The scale --light-scale auto gives the direct lights so that the brightest lit colour of a
// white diffuse surface stays within 1 beside the sky light: min(1, (1 - S) / D), where S is the
// sky light's largest channel (0 without one) and D the largest value the direct lights' diffuse
// and ambient terms can add up to at one point: the maximum over unit normals n of
// sum_i w_i max(0, n . l_i) for directional lights (w_i = intensity x largest colour channel;
// the maximum is |sum over some subset of w_i l_i|, found by trying every subset of up to 16
// lights), plus w_i for each point or spot light (any direction), plus each light's ambient term
// at the scene's largest Material ambientIntensity. 1 when D is 0. Tachyon's -auto_skylight F
// scales by 1 - F instead, blind to how many lights the file has.
double auto_light_scale(const std::vector<Light>& lights, bool headlight, double sky_max,
                        double material_ambient_max);

// Where along the view the scene lies: the smallest and largest distance along `forward` from
// `eye` of any point of its primitives (sphere surfaces, mesh vertices, quadric box corners, line
// and point marks). near > far for an empty scene.
struct DepthRange {
    double near = kInf, far = -kInf;
};
DepthRange scene_depth_range(const FlatScene& scene, const Vec3& eye, const Vec3& forward);

// --depth-cue without values starts this share of the way from the nearest to the farthest point
// of the scene and ends at the farthest: ChimeraX's default (depth_cue_start 0.5, end 1; PyMOL's
// fog_start is 0.45), so that the front half of a molecule keeps its colours.
constexpr double kDepthCueStart = 0.5;

// How far a point at view depth z has gone toward the background: 0 at or before `near`, 1 at
// or beyond `far`, linear between (ChimeraX's and PyMOL's depth cue). A range that is empty or
// inverted gives 0 everywhere.
double depth_cue_fraction(double z, double near, double far);

}  // namespace vr
