// Many processes rendering (app/render_mpi.cpp, docs/mpi.md): agreeing on an exit code, gathering
// one image to rank 0, and sending whole frames to rank 0, which writes them.
#pragma once
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/frame_render.h"
#include "app/mpi_processes.h"
#include "render/options.h"
#include "render/render.h"

namespace vr {

// The exit code all processes agree on (the largest); rank 0 says so when another process failed
// where it did not, since the failing process's own message may be far up the log.
int agreed(const MpiProcesses& world, int code, const char* step);

// Many processes: rank 0 gets every tile, and every process the totals of the rays, of the
// covered pixels, of the soft-light counts and of the non-finite values, the longest render and
// whether any timed out. Returns the seconds the gather took here.
double combine(const MpiProcesses& world, const RenderOptions& options, RenderStats& stats,
               Pixels& px);

// A temporary file for frame k of this process, with the output's extension, which names the
// image format.
std::string sent_frame_path(const std::string& output, int k);

// Rank 0 writes the frames the others rendered, in frame order, as each sends its own in that
// order; their temporary files go whatever happened. `code`: what all agreed on after rendering.
int write_sent_frames(const RenderCommand& cmd, const MpiProcesses& world,
                      const std::string& output, const std::vector<FrameRecord>& records, int code);

}  // namespace vr
