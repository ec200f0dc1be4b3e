// The frames of a render (app/frame_plan.cpp): which of them this process renders, how many at
// once, where each is written, and the loop that renders them.
#pragma once
#include <chrono>
#include <string>
#include <vector>

#include "anim/animator.h"
#include "app/commands.h"
#include "app/frame_render.h"
#include "app/mpi_processes.h"
#include "app/pipeline.h"
#include "app/render_stats.h"

namespace vr {

// The frames of a sequence this process renders, and how.
struct FramePlan {
    std::vector<int> frames;  // this process's, in increasing order
    bool by_rank = false;     // whole frames dealt over the processes: frame k to rank k % size
    int at_once = 1;          // frames rendered at the same time here
};

// Whether the command makes one image: no sequence, or one frame of it (--frame K).
bool one_image(const RenderCommand& cmd);

// The threads a render uses: --threads, or all cores.
int thread_count(const RenderOptions& options);

// Frames are independent: under MPI whole frames go round-robin to the processes (no gather
// inside a frame). Within a process, a frame a thread when there are at least as many frames as
// threads: no thread then waits at a frame's end for the last tile, and the BVH builds, the
// encoding and the writing, which run on fewer threads than the tracing, overlap.
FramePlan plan_frames(const RenderCommand& cmd, const MpiProcesses& world);

// The path of frame k: OUT with its printf pattern (%d, %04d, ...) filled in; OUT as it is when it
// has none. `pattern_error` says what is wrong with a pattern ("" when it is fine).
std::string frame_path(const std::string& out, int k, bool& has_pattern,
                       std::string& pattern_error);

// Renders this process's frames, plan.at_once of them at a time, each of them on its share of
// the threads; after an error no further frame is begun. The largest exit code of its frames;
// `builds`: how many scenes were built.
int render_frames(const RenderCommand& cmd, bool own_quiet, const MpiProcesses& world,
                  FramePlan& plan, const std::string& output, LoadedScene& loaded,
                  Animator& animator, const RenderTimings& timings,
                  std::chrono::steady_clock::time_point t0, std::vector<FrameRecord>& records,
                  size_t& builds);

}  // namespace vr
