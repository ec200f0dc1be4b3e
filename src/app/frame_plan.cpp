// The frames of a render: which this process renders and how many at once (plan_frames), the
// output path of each (frame_path), the scene each frame sees, built again only when it moves
// (FrameScenes), and the loop that renders them (render_frames).
#include "app/frame_plan.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "app/progress.h"
#include "app/render_mpi.h"
#include "app/render_stats.h"
#include "core/math.h"

namespace vr {

// The path of frame k: OUT with its printf pattern (%d, %04d, ...) filled in; OUT as it is when it
// has none. `pattern_error` says what is wrong with a pattern ("" when it is fine).
std::string frame_path(const std::string& out, int k, bool& has_pattern,
                       std::string& pattern_error) {
    has_pattern = false;
    pattern_error.clear();
    std::string result;
    for (size_t i = 0; i < out.size(); ++i) {
        if (out[i] != '%') {
            result += out[i];
            continue;
        }
        if (i + 1 < out.size() && out[i + 1] == '%') {
            result += '%';
            ++i;
            continue;
        }
        size_t j = i + 1;
        bool zero = j < out.size() && out[j] == '0';
        if (zero) ++j;
        int width = 0;
        while (j < out.size() && std::isdigit((unsigned char)out[j]) && width < 100)
            width = width * 10 + (out[j++] - '0');
        if (j >= out.size() || out[j] != 'd' || has_pattern) {
            pattern_error = "-o " + out +
                            ": the frame number pattern must be one %d, %0Nd or %Nd (a literal "
                            "% is written %%)";
            return out;
        }
        char number[128];
        std::snprintf(number, sizeof number, zero ? "%0*d" : "%*d", width, k);
        result += number;
        has_pattern = true;
        i = j;
    }
    return result;
}

// Whether the command makes one image: no sequence, or one frame of it (--frame K).
bool one_image(const RenderCommand& cmd) { return cmd.frames == 1 || cmd.only_frame.has_value(); }

int thread_count(const RenderOptions& options) {
    return options.threads > 0 ? options.threads
                               : std::max(1, int(std::thread::hardware_concurrency()));
}

// Frames are independent: under MPI whole frames go round-robin to the processes (no gather
// inside a frame). Within a process, a frame a thread when there are at least as many frames as
// threads: no thread then waits at a frame's end for the last tile, and the BVH builds, the
// encoding and the writing, which run on fewer threads than the tracing, overlap.
FramePlan plan_frames(const RenderCommand& cmd, const MpiProcesses& world) {
    FramePlan plan;
    if (cmd.only_frame) {  // one image: its tiles are shared out, as for any single frame
        plan.frames = {*cmd.only_frame};
        return plan;
    }
    plan.by_rank = world.parallel() && cmd.frames > 1;
    const int stride = plan.by_rank ? world.size() : 1;
    for (int k = plan.by_rank ? world.rank() : 0; k < cmd.frames; k += stride)
        plan.frames.push_back(k);
    const int n = int(plan.frames.size()), threads = thread_count(cmd.options);
    const int asked = cmd.frames_at_once > 0 ? cmd.frames_at_once : (n >= threads ? threads : 1);
    plan.at_once = std::clamp(asked, 1, std::max(n, 1));
    return plan;
}

namespace {

// The scene of each frame: built once when nothing moves (a static file, a turntable), else
// evaluated at the frame's time and built again when some field changed. The node tree is one, so
// frames rendered at once evaluate and build in turn, under the lock, and trace without it.
class FrameScenes {
  public:
    // `uses`: the calls of at() to come; the last one lets the node tree go.
    FrameScenes(LoadedScene& loaded, Animator& animator, const RenderCommand& cmd, size_t uses)
        : loaded_(loaded), animator_(animator), cmd_(cmd), uses_(uses) {}

    // The scene at `time`; null when its build failed (the diagnostics are printed). `seconds`:
    // what building it took (0: an earlier frame's); `peak_mb`: the peak memory after the first.
    std::shared_ptr<BuiltScene> at(double time, double& seconds, double& peak_mb) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++used_;
        seconds = 0.0;
        peak_mb = first_peak_mb_;
        if (failed_) return nullptr;
        if (last_ && !animator_.animated()) return last_;
        const bool changed =
            evaluate_and_report(animator_, time, loaded_.sources, cmd_.common.quiet);
        if (last_ && !changed) return last_;
        last_.reset();  // gone before the next is built, unless a frame still traces it
        const auto start = std::chrono::steady_clock::now();
        auto built = std::make_shared<BuiltScene>();
        // The tree stays while later frames may change it; otherwise its memory goes.
        const bool keep_tree = animator_.animated() && used_ < uses_;
        if (!build_and_flatten(loaded_, cmd_.options, cmd_.recover_spheres, cmd_.common,
                               built->flat, built->stats, keep_tree)) {
            failed_ = true;
            return nullptr;
        }
        seconds = seconds_since(start);
        ++builds_;
        if (first_peak_mb_ == 0.0) peak_mb = first_peak_mb_ = peak_memory_mb();
        last_ = built;
        return built;
    }

    // The scenes built so far (1 for a static file or a turntable).
    size_t builds() const { return builds_; }

  private:
    LoadedScene& loaded_;
    Animator& animator_;
    const RenderCommand& cmd_;
    const size_t uses_;
    std::mutex mutex_;
    size_t used_ = 0, builds_ = 0;
    bool failed_ = false;
    double first_peak_mb_ = 0.0;
    std::shared_ptr<BuiltScene> last_;
};

// Frames at once cost a tracer (BVH, primitive copies, image) each, and each its own scene when
// the scene moves: one at a time when they would not fit (a frame's own check then says so).
int frames_that_fit(const RenderCommand& cmd, const BuiltScene& first, int at_once, bool animated) {
    RenderOptions one = cmd.options;
    one.threads = 1;
    const double each = double(estimate_render_bytes(first.flat, one)) * (animated ? 2.0 : 1.0);
    const double limit = render_memory_limit(cmd.common);
    return limit > 0.0 && each * at_once > limit ? 1 : at_once;
}

}  // namespace

// Renders this process's frames, plan.at_once of them at a time, each of them on its share of
// the threads; after an error no further frame is begun. The largest exit code of its frames;
// `builds`: how many scenes were built.
int render_frames(const RenderCommand& cmd, bool own_quiet, const MpiProcesses& world,
                  FramePlan& plan, const std::string& output, LoadedScene& loaded,
                  Animator& animator, const RenderTimings& timings,
                  std::chrono::steady_clock::time_point t0, std::vector<FrameRecord>& records,
                  size_t& builds) {
    // Dealt whole frames, a process renders them alone, and says what it did itself.
    const MpiProcesses& frame_world = plan.by_rank ? MpiProcesses::alone() : world;
    if (cmd.orbit_degrees && !one_image(cmd) && world.root() && !own_quiet)
        std::fprintf(
            stderr,
            "%s: note: --orbit: frame k turns by k * %g / %d degrees about the scene's "
            "centre; --frame K renders frame K alone, bit for bit, and prints its camera\n",
            cmd.scene.c_str(), *cmd.orbit_degrees, cmd.frames);
    RenderCommand frame_cmd = cmd;
    if (plan.by_rank) frame_cmd.common.quiet = own_quiet;
    const size_t n = plan.frames.size();
    // Scripts keep state from frame to frame: the frames' events go in time order, one frame
    // after another (docs/animation.md).
    if (animator.scripts() > 0) plan.at_once = 1;
    auto time_of = [&](int k) { return cmd.time + double(k) / cmd.fps; };
    const bool probe = plan.at_once > 1 && cmd.frames_at_once == 0;
    FrameScenes scenes(loaded, animator, cmd, n + (probe ? 1 : 0));
    double first_seconds = 0.0, peak_mb = 0.0;
    if (probe) {
        // Built here to see what frames at once would hold; frame 0 then finds it ready.
        const std::shared_ptr<BuiltScene> first =
            scenes.at(time_of(plan.frames[0]), first_seconds, peak_mb);
        if (!first) return kExitBadInput;
        plan.at_once = frames_that_fit(cmd, *first, plan.at_once, animator.animated());
    }
    records.assign(n, FrameRecord{});
    std::atomic<size_t> next{0};
    std::atomic<int> worst{kExitOk};
    std::mutex bar_mutex;
    ProgressBar bar(plan.at_once > 1 && !frame_cmd.common.quiet);  // over frames, not tiles
    size_t done = 0;
    auto one_frame = [&](size_t i) -> int {
        FrameJob job;
        job.frame = plan.frames[i];
        // Each frame's line of timings covers that frame: the first one's the reading too.
        job.frame_t0 = i == 0 ? t0 : std::chrono::steady_clock::now();
        double built_seconds = 0.0, peak = 0.0;
        const std::shared_ptr<BuiltScene> scene =
            scenes.at(time_of(job.frame), built_seconds, peak);
        const int code = scene ? kExitOk : kExitBadInput;
        if (agreed(frame_world, code, "building the scene") != kExitOk) return kExitBadInput;
        job.scene = scene.get();
        job.options = cmd.options;
        if (plan.at_once > 1)
            job.options.threads = std::max(1, thread_count(cmd.options) / plan.at_once);
        // One frame alone is turned by the whole angle (a still of the turntable at DEG).
        if (cmd.orbit_degrees)
            job.options.orbit_angle =
                cmd.frames == 1
                    ? *cmd.orbit_degrees * (kPi / 180.0)
                    : double(job.frame) * (*cmd.orbit_degrees * (kPi / 180.0)) / cmd.frames;
        bool unused = false;
        std::string error;
        job.output = frame_path(output, job.frame, unused, error);
        // Another process's frame goes to a file of its own, which it then sends to rank 0.
        if (plan.by_rank && !world.root()) job.write_to = sent_frame_path(job.output, job.frame);
        job.spheres_to_free = plan.at_once == 1 && i + 1 == n ? &scene->flat.spheres : nullptr;
        job.progress = plan.at_once == 1;
        job.write_stats = one_image(cmd);
        job.timings = timings;
        job.timings.parse = i == 0 ? timings.parse : 0.0;
        job.timings.scene = i == 0 ? std::max(first_seconds, built_seconds) : built_seconds;
        job.timings.peak_scene_mb = peak;
        const int rendered = render_frame(frame_cmd, frame_world, loaded, job, t0, records[i]);
        records[i].sent = job.write_to;  // removed after sending, or after a failure
        return rendered;
    };
    auto work = [&] {
        while (worst.load() == kExitOk) {
            const size_t i = next.fetch_add(1);
            if (i >= n) return;
            const int code = one_frame(i);
            for (int w = worst.load(); code > w && !worst.compare_exchange_weak(w, code);) {
            }
            std::lock_guard<std::mutex> lock(bar_mutex);
            bar.update(double(++done) / double(n), 0);
        }
    };
    std::vector<std::thread> pool;
    for (int w = 1; w < plan.at_once; ++w) pool.emplace_back(work);
    work();  // MPI's calls stay on this thread (MPI_THREAD_FUNNELED)
    for (std::thread& t : pool) t.join();
    bar.finish();
    builds = scenes.builds();
    return worst.load();
}

}  // namespace vr
