// X3D layers drawn over each other (docs/rendering.md "Layers"): each layer of FlatScene::layers
// is traced with its own camera, BVH and lights, inside its Viewport, and laid over the layers
// before it by its alpha. The first layer keeps its background; a later one is traced with the
// background left out (as --alpha does), so it is transparent where it shows nothing.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "render/accel.h"
#include "render/camera.h"
#include "render/gas.h"
#include "render/integrator.h"
#include "render/sampling.h"

namespace vr {

struct TileRect;

class LayerStack {
  public:
    // `scene` holds the list (its `layers` not empty); its own entry is traced with `camera` and
    // `accel`. Every other layer with a Viewpoint gets the camera make_camera chooses for it from
    // them, without the command line's camera options (they belong to the active layer); one
    // without is seen through `camera` (FlatScene::bounds frames them together).
    LayerStack(const FlatScene& scene, const Camera& camera, const Accel& accel,
               const RenderOptions& options, int threads);
    ~LayerStack();
    // Traces tile r of every layer and lays them over each other into `pixels` (RGBA rows).
    void trace_tile(const TileRect& r, SamplerScratch& scratch, RayCounters& counters,
                    std::vector<float>& pixels) const;
    size_t held_bytes() const;

  private:
    struct Drawn;
    std::vector<std::unique_ptr<Drawn>> drawn_;
};

// The camera options that only the active layer takes removed (the others frame themselves).
RenderOptions options_for_other_layer(const RenderOptions& options);

}  // namespace vr
