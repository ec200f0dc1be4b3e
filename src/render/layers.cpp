#include "render/layers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/render.h"

namespace vr {

struct LayerStack::Drawn {
    const FlatScene* scene = nullptr;
    RenderOptions options;
    Camera camera;
    std::unique_ptr<Accel> own_accel;  // null: the active layer's, given
    const Accel* accel = nullptr;
    GasVolume gas;
    std::unique_ptr<Integrator> integrator;
    std::unique_ptr<CameraRays> rays;
    // The Viewport in pixels, y from the top of the image.
    double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

RenderOptions options_for_other_layer(const RenderOptions& options) {
    RenderOptions o = options;
    o.viewpoint.clear();
    o.fit = false;
    o.camera_position.reset();
    o.look_at.reset();
    o.up.reset();
    o.fov.reset();
    o.orbit_angle.reset();
    o.camera = CameraMode::FromViewpoint;
    return o;
}

LayerStack::LayerStack(const FlatScene& scene, const Camera& camera, const Accel& accel,
                       const RenderOptions& options, int threads) {
    const double w = std::max(options.width, 0), h = std::max(options.height, 0);
    for (size_t i = 0; i < scene.layers.size(); ++i) {
        const FlatLayer& layer = scene.layers[i];
        auto d = std::make_unique<Drawn>();
        d->scene = layer.scene ? layer.scene.get() : &scene;
        d->options = layer.scene ? options_for_other_layer(options) : options;
        // Over the layers before it, a layer shows its surfaces only (X3D 35.2.1).
        if (i > 0) d->options.alpha = true;
        d->x0 = layer.clip[0] * w, d->x1 = layer.clip[1] * w;
        d->y0 = (1.0 - layer.clip[3]) * h, d->y1 = (1.0 - layer.clip[2]) * h;
        const int vw = std::max(1, int(std::lround(d->x1 - d->x0)));
        const int vh = std::max(1, int(std::lround(d->y1 - d->y0)));
        // A layer without a Viewpoint of its own (X3D: the default one, at the same place in
        // every layer) is seen through the active layer's camera, framing included.
        if (layer.scene && !layer.scene->viewpoints.empty()) {
            RenderOptions sized = d->options;
            sized.width = vw, sized.height = vh;
            std::string error;
            if (!make_camera(*d->scene, sized, d->camera, error))
                throw std::runtime_error("layer " + std::to_string(i) + ": " + error);
            d->own_accel = std::make_unique<Accel>();
            d->own_accel->build(*d->scene, threads, BvhChoice{BvhBuild::Sah});
            d->accel = d->own_accel.get();
        } else {
            d->camera = camera;
            if (layer.scene) {
                d->own_accel = std::make_unique<Accel>();
                d->own_accel->build(*d->scene, threads, BvhChoice{BvhBuild::Sah});
            }
            d->accel = layer.scene ? d->own_accel.get() : &accel;
        }
        d->gas.build(*d->scene, d->options);
        d->integrator =
            std::make_unique<Integrator>(*d->scene, *d->accel, d->camera, d->options, &d->gas);
        d->rays = std::make_unique<CameraRays>(d->camera, vw, vh);
        drawn_.push_back(std::move(d));
    }
}

LayerStack::~LayerStack() = default;

size_t LayerStack::held_bytes() const {
    size_t bytes = 0;
    for (const auto& d : drawn_)
        if (d->own_accel) bytes += d->own_accel->held_bytes();
    return bytes;
}

void LayerStack::trace_tile(const TileRect& r, SamplerScratch& scratch, RayCounters& counters,
                            std::vector<float>& pixels) const {
    const int x0 = r.x0, y0 = r.y0, x1 = r.x1, y1 = r.y1;
    const size_t row = size_t(x1 - x0);
    std::fill(pixels.begin(), pixels.end(), 0.0f);  // nothing under the first layer
    std::vector<float> mine(pixels.size());
    for (const auto& d : drawn_) {
        // Samples outside the Viewport see nothing of this layer: transparent.
        sample_tile(
            d->camera.sampler, x0, y0, x1, y1, scratch,
            [&](double px, double py) {
                if (px < d->x0 || px >= d->x1 || py < d->y0 || py >= d->y1) return SampleValue{};
                return d->integrator->trace_camera_ray((*d->rays)(px - d->x0, py - d->y0),
                                                       counters);
            },
            [&](int x, int y, const SampleValue& v) {
                float* out = &mine[(size_t(y - y0) * row + size_t(x - x0)) * 4];
                const bool ok = std::isfinite(v.color.x + v.color.y + v.color.z + v.alpha);
                if (!ok) ++counters.nonfinite.shading;
                out[0] = ok ? float(v.color.x) : 0.0f;
                out[1] = ok ? float(v.color.y) : 0.0f;
                out[2] = ok ? float(v.color.z) : 0.0f;
                out[3] = ok ? float(std::clamp(v.alpha, 0.0, 1.0)) : 0.0f;
            });
        // Over: the layer's premultiplied colour, then what is below where it lets it through.
        for (size_t k = 0; k < pixels.size(); k += 4) {
            const float a = mine[k + 3], keep = 1.0f - a;
            for (int c = 0; c < 3; ++c) pixels[k + c] = mine[k + c] + keep * pixels[k + c];
            pixels[k + 3] = a + keep * pixels[k + 3];
        }
    }
}

}  // namespace vr
