// Folder comparison: pairing by relative path, a work queue over the pairs, the summary table.
#include "qa/suite.h"

#include <fnmatch.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <thread>

#include "core/parallel.h"

namespace vr {
namespace fs = std::filesystem;

const char* pair_status_name(PairStatus status) {
    switch (status) {
        case PairStatus::kMissing:
            return "missing";
        case PairStatus::kExtra:
            return "extra";
        case PairStatus::kSizeMismatch:
            return "size";
        case PairStatus::kUnreadable:
            return "error";
        case PairStatus::kFail:
            return "fail";
        case PairStatus::kWarn:
            return "warn";
        case PairStatus::kPass:
            return "pass";
    }
    return "error";
}

namespace {

bool is_image_name(const fs::path& p) {
    static const char* const kExtensions[] = {"png", "exr", "tif", "tiff", "jpg", "jpeg",
                                              "ppm", "pfm", "hdr", "bmp",  "tga"};
    std::string ext = p.extension().string();
    if (ext.empty()) return false;
    ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return std::find(std::begin(kExtensions), std::end(kExtensions), ext) != std::end(kExtensions);
}

// Reads and compares one pair whose files both exist.
void compare_pair(SuitePair& pair, const CompareThresholds& thresholds, Image& ref, Image& out) {
    std::string error;
    if (!read_image(pair.reference.string(), ref, error) ||
        !read_image(pair.result.string(), out, error)) {
        pair.status = PairStatus::kUnreadable;
        pair.message = error;
        return;
    }
    if (ref.width != out.width || ref.height != out.height) {
        pair.status = PairStatus::kSizeMismatch;
        pair.message = "reference " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                       ", result " + std::to_string(out.width) + "x" + std::to_string(out.height);
        return;
    }
    // The result is A, the reference B, as in `vrmlray compare RESULT REFERENCE`.
    if (!compare_images(out, ref, thresholds, pair.metrics, error)) {
        pair.status = PairStatus::kUnreadable;
        pair.message = error;
        return;
    }
    pair.compared = true;
    pair.failures = failed_thresholds(pair.metrics, thresholds);
    pair.warnings = warned_thresholds(pair.metrics, thresholds);
    pair.status = !pair.failures.empty()   ? PairStatus::kFail
                  : !pair.warnings.empty() ? PairStatus::kWarn
                                           : PairStatus::kPass;
}

// Worst first; NaN RMSE (never produced: non-finite differences count as infinite) sorts last.
bool worse(const SuitePair& a, const SuitePair& b) {
    if (a.status != b.status) return a.status < b.status;
    if (a.compared && b.compared && a.metrics.rmse != b.metrics.rmse)
        return a.metrics.rmse > b.metrics.rmse;
    return a.name < b.name;
}

// A missing reference whose file name an extra result has in another folder (a.png against
// scenes/a.png): most likely one batch was given the scenes by other paths, so say where it is.
void hint_moved_images(std::vector<SuitePair>& pairs) {
    std::map<std::string, std::vector<const SuitePair*>> extra_by_file;
    for (const SuitePair& p : pairs)
        if (p.status == PairStatus::kExtra)
            extra_by_file[fs::path(p.name).filename().string()].push_back(&p);
    for (SuitePair& p : pairs) {
        if (p.status != PairStatus::kMissing) continue;
        const auto found = extra_by_file.find(fs::path(p.name).filename().string());
        if (found == extra_by_file.end() || found->second.size() != 1) continue;
        p.message += "; the result " + found->second.front()->name +
                     " has its file name (were the scenes given by other paths? a batch names "
                     "its images after where each scene lies under the current folder)";
    }
}

}  // namespace

const CompareThresholds& SuiteThresholds::for_pair(const std::string& name) const {
    for (const ThresholdRule& rule : rules)
        if (fnmatch(rule.pattern.c_str(), name.c_str(), 0) == 0) return rule.thresholds;
    return fallback;
}

std::vector<std::string> list_suite_images(const fs::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    // An unreadable subfolder is skipped: its references then show as missing, not as a crash.
    const auto options = fs::directory_options::skip_permission_denied;
    for (fs::recursive_directory_iterator it(dir, options, ec), end; !ec && it != end;
         it.increment(ec)) {
        if (it->is_directory(ec) && fs::exists(it->path() / kReportMarker, ec)) {
            it.disable_recursion_pending();
            continue;
        }
        if (!it->is_regular_file(ec) || !is_image_name(it->path())) continue;
        names.push_back(it->path().lexically_relative(dir).generic_string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

std::vector<SuitePair> compare_folders(const fs::path& reference_dir, const fs::path& result_dir,
                                       const SuiteThresholds& thresholds, int threads,
                                       const PairVisitor& visit) {
    std::map<std::string, SuitePair> by_name;
    for (const std::string& name : list_suite_images(reference_dir)) {
        by_name[name].name = name;
        by_name[name].reference = reference_dir / name;
    }
    for (const std::string& name : list_suite_images(result_dir)) {
        by_name[name].name = name;
        by_name[name].result = result_dir / name;
    }
    std::vector<SuitePair> pairs;
    pairs.reserve(by_name.size());
    for (auto& [name, pair] : by_name) pairs.push_back(std::move(pair));

    // A queue, not fixed chunks: one large image must not leave the other core idle.
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    std::atomic<size_t> next{0};
    parallel_ranges(size_t(threads), threads, [&](size_t, size_t, int) {
        for (size_t k; (k = next.fetch_add(1)) < pairs.size();) {
            SuitePair& pair = pairs[k];
            const auto t0 = std::chrono::steady_clock::now();
            Image ref, out;
            std::string ignored;  // the visitor shows what can be read of a lone image
            if (pair.result.empty()) {
                pair.status = PairStatus::kMissing;
                pair.message = "no result image for the reference " + pair.reference.string();
                if (visit) read_image(pair.reference.string(), ref, ignored);
            } else if (pair.reference.empty()) {
                pair.status = PairStatus::kExtra;
                pair.message = "no reference image for the result " + pair.result.string();
                if (visit) read_image(pair.result.string(), out, ignored);
            } else {
                compare_pair(pair, thresholds.for_pair(pair.name), ref, out);
            }
            pair.seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (visit) visit(pair, ref, out);
        }
    });
    hint_moved_images(pairs);
    std::sort(pairs.begin(), pairs.end(), worse);
    return pairs;
}

std::string format_suite_table(const std::vector<SuitePair>& pairs) {
    std::string text;
    char line[160];
    std::snprintf(line, sizeof line, "%-7s %10s %8s %10s %8s %7s  %s\n", "status", "rmse", "psnr",
                  "max_abs", "ssim", "fail%", "image");
    text += line;
    size_t counts[int(PairStatus::kPass) + 1] = {};
    for (const SuitePair& p : pairs) {
        ++counts[int(p.status)];
        if (p.compared)
            std::snprintf(line, sizeof line, "%-7s %10.4g %8.2f %10.4g %8.5f %7.3f  ",
                          pair_status_name(p.status), p.metrics.rmse, p.metrics.psnr,
                          p.metrics.max_abs, p.metrics.ssim, p.metrics.fail_percent);
        else
            std::snprintf(line, sizeof line, "%-7s %10s %8s %10s %8s %7s  ",
                          pair_status_name(p.status), "-", "-", "-", "-", "-");
        text += line + p.name;
        std::string why = p.message;
        for (const std::string& f : p.failures) why += (why.empty() ? "" : "; ") + f;
        for (const std::string& w : p.warnings)
            why += (why.empty() ? "" : "; ") + ("warning: " + w);
        text += why.empty() ? "\n" : "  (" + why + ")\n";
    }
    size_t failed = 0;
    for (int s = 0; s < int(PairStatus::kWarn); ++s) failed += counts[s];
    std::snprintf(line, sizeof line,
                  "%zu images: %zu passed, %zu warned, %zu failed (%zu over a threshold, %zu "
                  "missing, %zu extra, %zu of another size, %zu unreadable)\n",
                  pairs.size(), counts[int(PairStatus::kPass)], counts[int(PairStatus::kWarn)],
                  failed, counts[int(PairStatus::kFail)], counts[int(PairStatus::kMissing)],
                  counts[int(PairStatus::kExtra)], counts[int(PairStatus::kSizeMismatch)],
                  counts[int(PairStatus::kUnreadable)]);
    text += line;
    return text;
}

}  // namespace vr
