// One frame's render (app/frame_render.cpp): what it is given, what it leaves for a sequence's
// --stats file, and the pixels it traces.
#pragma once
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/mpi_processes.h"
#include "app/pipeline.h"
#include "app/render_stats.h"
#include "flatten/flatten.h"
#include "image/image.h"
#include "render/flat_scene.h"
#include "render/render.h"

namespace vr {

// The pixels of a render: 8-bit (PNG and PPM: the tracing threads encode their tiles straight into
// those bytes, and no float image, 16 bytes a pixel, 33 MB at 1920x1080, is made) or float.
struct Pixels {
    Image image;
    Image8 image8;
    size_t covered = 0;  // pixels where the scene, not only the background, is seen
};

// A scene as a frame renders it: flattened, with what the flattening counted.
struct BuiltScene {
    FlatScene flat;
    FlattenStats stats;
};

// One frame to render.
struct FrameJob {
    int frame = 0;
    std::string output;
    std::string write_to;   // where the image goes when not `output`: a file rank 0 is sent
    RenderOptions options;  // the frame's camera turn and threads
    const BuiltScene* scene = nullptr;
    std::vector<Sphere>* spheres_to_free = nullptr;  // the scene's last frame: its spheres may go
    bool progress = true;                            // a bar of this frame's tiles
    bool write_stats = false;  // now, with the world's shares of this one image's tiles
    std::chrono::steady_clock::time_point frame_t0;
    RenderTimings timings;
};

// What a rendered frame leaves for the --stats file of a sequence, written after the last frame.
struct FrameRecord {
    int frame = -1;  // -1: not rendered
    size_t tiles = 0;
    RenderStats stats;
    RenderTimings timings;
    nlohmann::ordered_json json;  // render_stats_json of the frame (when --stats is given)
    std::string sent;             // the temporary file to send to rank 0, which writes the frame
};

// One frame: camera, this process's tiles, the gather to rank 0, which writes it (and the stats
// when job.write_stats). The exit code all processes of `world` agree on.
int render_frame(const RenderCommand& cmd, const MpiProcesses& world, const LoadedScene& loaded,
                 const FrameJob& job, std::chrono::steady_clock::time_point t0,
                 FrameRecord& record);

}  // namespace vr
