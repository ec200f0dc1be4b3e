// vrmlray render A B ... -o DIR/ and render --list FILE -o DIR/: many scenes in one process (a test
// suite without a start-up per file), each with its own errors, a summary at the end; exit 3 when
// any failed.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/cli.h"
#include "app/commands.h"
#include "app/scene_files.h"

namespace vr {
namespace fs = std::filesystem;
namespace {

struct BatchJob {
    std::string where;  // "LIST:LINE" for a --list line, else the scene argument
    RenderCommand cmd;  // scene and output resolved
    std::string error;  // set: the job fails before rendering (bad line, clashing output)
    std::string named;  // the scene as written, when the output is named after it (no -o NAME)
    fs::path base;      // the folder `named` is relative to: the list's, else the current one
};

// "a/b.wrl.gz" -> "a/b": only scene extensions go, so "1.5_mol.wrl" keeps its first dot.
fs::path strip_scene_extension(fs::path p) {
    auto lower_ext = [&] {
        std::string e = p.extension().string();
        std::transform(e.begin(), e.end(), e.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        return e;
    };
    if (lower_ext() == ".gz") p.replace_extension();
    const std::string ext = lower_ext();
    for (const SceneExtension& e : kSceneExtensions)
        if (ext == e.name) return p.replace_extension();
    return p;
}

// DIR/<where the scene lies, relative to BASE>.FORMAT, however its path was written (relative,
// absolute, through ".." or a link), so that two runs that spell the same files differently
// write the same names; the file name alone for a scene outside BASE, so that no output lands
// outside DIR. With keep_extension (two scenes of one stem, a.wrl and a.x3d), DIR/a.wrl.FORMAT.
fs::path batch_output(const fs::path& dir, const fs::path& base, const std::string& scene,
                      const std::string& format, bool keep_extension = false) {
    std::error_code ec;
    const fs::path from = fs::weakly_canonical(fs::absolute(base.empty() ? "." : base, ec), ec);
    const fs::path where = fs::weakly_canonical(fs::absolute(base / scene, ec), ec);
    fs::path p = where.lexically_relative(from);
    if (p.empty() || *p.begin() == "..") p = where.filename();
    if (!keep_extension) p = strip_scene_extension(p);
    p += "." + format;
    return dir / p;
}

// Scenes of one stem in one batch (pept.wrl and pept.x3d) keep their extensions in the output
// name, whatever their order, so that neither overwrites the other.
void name_apart(std::vector<BatchJob>& jobs, const fs::path& dir, const std::string& format) {
    std::map<std::string, int> uses;
    auto key = [](const BatchJob& j) { return fs::path(j.cmd.output).lexically_normal().string(); };
    for (const BatchJob& job : jobs)
        if (!job.named.empty()) ++uses[key(job)];
    for (BatchJob& job : jobs)
        if (!job.named.empty() && uses[key(job)] > 1)
            job.cmd.output = batch_output(dir, job.base, job.named, format, true).string();
}

// The command line's words less the scenes' destination and the list, which a line replaces.
std::vector<std::string> words_for_lines(const std::vector<std::string>& args) {
    std::vector<std::string> kept;
    for (size_t k = 0; k < args.size(); ++k) {
        const std::string& a = args[k];
        if (a == "-o" || a == "--output" || a == "--list") {
            ++k;
            continue;
        }
        if (a.rfind("--output=", 0) == 0 || a.rfind("--list=", 0) == 0 ||
            (a.rfind("-o", 0) == 0 && a.size() > 2 && a[2] != '-'))
            continue;
        kept.push_back(a);
    }
    return kept;
}

// One job per line of the list: its scene relative to the list's folder, its options after the
// command line's. False when the list cannot be read.
bool list_jobs(const RenderCommand& cmd, const fs::path& dir, std::vector<BatchJob>& jobs) {
    std::ifstream in(cmd.list_path);
    if (!in) {
        std::cerr << cmd.list_path << ": error: cannot read the scene list\n";
        return false;
    }
    const std::vector<std::string> base = words_for_lines(cmd.args);
    const fs::path list_dir = fs::path(cmd.list_path).parent_path();
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::vector<std::string> words = split_line_words(line);
        if (words.empty()) continue;
        BatchJob job;
        job.where = cmd.list_path + ":" + std::to_string(number);
        std::vector<std::string> all = base;
        all.insert(all.end(), words.begin(), words.end());
        // The parser's message, taken to be printed at the line's place ("LIST:LINE: error: ...").
        std::ostringstream message;
        std::streambuf* const cerr_buffer = std::cerr.rdbuf(message.rdbuf());
        const int code = parse_render_words(all, job.cmd);
        std::cerr.rdbuf(cerr_buffer);
        if (code != -1) {
            std::string text = message.str();
            text = text.substr(0, text.find('\n'));
            const std::string prefix = "vrmlray: error: ";
            if (text.rfind(prefix, 0) == 0) text.erase(0, prefix.size());
            job.error = text.empty() ? "bad options" : text;
        } else if (job.cmd.scenes.size() != 1) {
            job.error = "a line names one scene";
        } else {
            const std::string written = job.cmd.scene;
            if (fs::path(written).is_relative()) job.cmd.scene = (list_dir / written).string();
            // The line's own -o names the output inside DIR (a golden image's name).
            if (job.cmd.output.empty()) {
                job.named = written;
                job.base = list_dir;
                job.cmd.output = batch_output(dir, list_dir, written, cmd.format).string();
            } else {
                job.cmd.output = (dir / job.cmd.output).string();
            }
        }
        jobs.push_back(std::move(job));
    }
    return true;
}

std::vector<BatchJob> argument_jobs(const RenderCommand& cmd, const fs::path& dir) {
    std::vector<BatchJob> jobs;
    for (const std::string& scene : cmd.scenes) {
        BatchJob job{scene, cmd, "", scene, "."};
        job.cmd.scene = scene;
        job.cmd.output = batch_output(dir, job.base, scene, cmd.format).string();
        jobs.push_back(std::move(job));
    }
    return jobs;
}

// Runs one job; its exit code (kExitOk or the reason it failed), --strict applied per scene.
int run_job(BatchJob& job) {
    if (!job.error.empty()) {
        std::cerr << job.where << ": error: " << job.error << "; scene not rendered\n";
        return kExitUsage;
    }
    std::error_code ec;
    fs::create_directories(fs::path(job.cmd.output).parent_path(), ec);
    const size_t warnings_before = warnings_reported();
    const int code = run_render(job.cmd);
    if (code == kExitOk && job.cmd.common.strict && warnings_reported() > warnings_before)
        return kExitBadInput;
    return code;
}

}  // namespace

bool is_batch(const RenderCommand& cmd) {
    std::error_code ec;
    return !cmd.list_path.empty() || cmd.scenes.size() > 1 ||
           (!cmd.output.empty() && (cmd.output.back() == '/' || fs::is_directory(cmd.output, ec)));
}

int run_render_batch(const RenderCommand& cmd) {
    const auto t0 = std::chrono::steady_clock::now();
    const fs::path dir = cmd.output.empty() ? fs::path(".") : fs::path(cmd.output);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) {
        std::cerr << "vrmlray: error: cannot create the output folder '" << dir.string() << "'\n";
        return kExitOutput;
    }
    std::vector<BatchJob> jobs;
    if (cmd.list_path.empty())
        jobs = argument_jobs(cmd, dir);
    else if (!list_jobs(cmd, dir, jobs))
        return kExitBadInput;

    name_apart(jobs, dir, cmd.format);
    // Two jobs writing one file would leave the later image under the earlier one's name.
    std::map<std::string, std::string> first_writer;
    for (BatchJob& job : jobs) {
        if (!job.error.empty()) continue;
        auto [it, fresh] =
            first_writer.emplace(fs::path(job.cmd.output).lexically_normal().string(), job.where);
        if (!fresh) job.error = "its output " + job.cmd.output + " is also " + it->second + "'s";
    }
    std::vector<std::pair<const BatchJob*, int>> failed;
    nlohmann::ordered_json records = nlohmann::ordered_json::array();
    for (BatchJob& job : jobs) {
        // The batch's --stats file gathers every scene's record; a list line's own file is its own.
        std::string stats;
        const bool gathered = !cmd.stats_path.empty() && job.cmd.stats_path == cmd.stats_path;
        if (gathered) job.cmd.stats_text = &stats;
        const int code = run_job(job);
        if (code != kExitOk) failed.emplace_back(&job, code);
        if (!gathered) continue;
        nlohmann::ordered_json record = {
            {"scene", job.cmd.scene.empty() ? job.where : job.cmd.scene}, {"exit_code", code}};
        if (!stats.empty()) record["stats"] = nlohmann::ordered_json::parse(stats);
        records.push_back(std::move(record));
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!cmd.stats_path.empty()) {
        const nlohmann::ordered_json all = {{"scenes", std::move(records)},
                                            {"rendered", jobs.size() - failed.size()},
                                            {"failed", failed.size()},
                                            {"seconds", seconds}};
        std::ofstream out(cmd.stats_path);
        out << all.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
        if (!out) {
            std::cerr << cmd.stats_path << ": error: cannot write the stats file\n";
            return kExitOutput;
        }
    }
    std::printf("batch: %zu scenes, %zu rendered, %zu failed, %.2f s -> %s\n", jobs.size(),
                jobs.size() - failed.size(), failed.size(), seconds, dir.string().c_str());
    for (const auto& [job, code] : failed)
        std::printf("FAILED %s (exit %d)%s%s\n", job->where.c_str(), code,
                    job->where == job->cmd.scene || job->cmd.scene.empty() ? "" : ": ",
                    job->where == job->cmd.scene ? "" : job->cmd.scene.c_str());
    std::fflush(stdout);
    return failed.empty() ? kExitOk : kExitBadInput;
}

}  // namespace vr
