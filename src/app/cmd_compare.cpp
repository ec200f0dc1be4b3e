// vrmlray compare A B: golden-image comparison with pass/fail thresholds (idiff's 1e-6 when none is
// given). Warnings are printed and exit 0, as idiff's are a pass with a remark; failures exit 1.
// Two folders are compared image by image (image/suite.h), with a table, JUnit and HTML report.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

#include "app/cli.h"
#include "app/commands.h"
#include "image/image.h"
#include "qa/compare.h"
#include "qa/suite.h"
#include "qa/suite_report.h"

namespace vr {
namespace {
namespace fs = std::filesystem;

// --update: each failing result (over a threshold, of another size, or with no reference yet)
// becomes the reference. False when a copy failed.
bool update_references(const CompareCommand& cmd, std::vector<SuitePair>& pairs) {
    bool ok = true;
    for (SuitePair& p : pairs) {
        const bool replace = p.status == PairStatus::kFail ||
                             p.status == PairStatus::kSizeMismatch ||
                             p.status == PairStatus::kExtra;
        if (!replace) continue;
        const fs::path target = fs::path(cmd.a) / p.name;
        std::error_code ec;
        fs::create_directories(target.parent_path(), ec);
        fs::copy_file(p.result, target, fs::copy_options::overwrite_existing, ec);
        if (ec) {
            std::cerr << "vrmlray: error: cannot copy '" << p.result.string() << "' to '"
                      << target.string() << "': " << ec.message() << "\n";
            ok = false;
            continue;
        }
        std::cout << (p.status == PairStatus::kExtra ? "added " : "updated ") << target.string()
                  << " <- " << p.result.string() << " (" << pair_status_name(p.status) << ")\n";
        p.status = PairStatus::kPass;  // what the reference folder now holds
    }
    return ok;
}

// --thresholds FILE: a glob and options a line, the options after the command line's. False after
// printing why not (FILE:LINE: error: MESSAGE).
bool read_threshold_rules(const CompareCommand& cmd, SuiteThresholds& thresholds) {
    std::ifstream in(cmd.thresholds_path);
    if (!in) {
        std::cerr << cmd.thresholds_path << ": error: cannot read the thresholds file\n";
        return false;
    }
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::vector<std::string> words = split_line_words(line);
        if (words.empty()) continue;
        std::vector<std::string> all = cmd.args;
        all.insert(all.end(), words.begin() + 1, words.end());
        std::ostringstream message;  // the parser's, printed at the line's place
        std::streambuf* const cerr_buffer = std::cerr.rdbuf(message.rdbuf());
        CompareCommand line_cmd;
        const int code = parse_compare_words(all, line_cmd);
        std::cerr.rdbuf(cerr_buffer);
        if (code != -1) {
            std::string text = message.str().substr(0, message.str().find('\n'));
            const std::string prefix = "vrmlray: error: ";
            if (text.rfind(prefix, 0) == 0) text.erase(0, prefix.size());
            std::cerr << cmd.thresholds_path << ":" << number
                      << ": error: " << (text.empty() ? "bad options" : text) << "\n";
            return false;
        }
        thresholds.rules.push_back({words.front(), thresholds_of(line_cmd)});
    }
    return true;
}

// Reference folder A against result folder B: the table, the JUnit file, the report, --update.
int run_compare_folders(const CompareCommand& cmd) {
    std::string error;
    std::mutex error_mutex;
    std::string report_error;
    PairVisitor visit;
    if (!cmd.report_dir.empty())
        visit = [&](const SuitePair& pair, const Image& ref, const Image& out) {
            std::string e;
            if (write_report_images(cmd.report_dir, pair, ref, out, e)) return;
            std::lock_guard<std::mutex> lock(error_mutex);
            if (report_error.empty()) report_error = e;
        };
    SuiteThresholds thresholds(thresholds_of(cmd));
    if (!cmd.thresholds_path.empty() && !read_threshold_rules(cmd, thresholds)) return kExitUsage;
    std::vector<SuitePair> pairs = compare_folders(cmd.a, cmd.b, thresholds, cmd.threads, visit);
    std::cout << format_suite_table(pairs);
    if (!report_error.empty() ||
        (!cmd.report_dir.empty() &&
         !write_report_html(cmd.report_dir, pairs, "vrmlray compare " + cmd.a + " " + cmd.b,
                            report_error))) {
        std::cerr << "vrmlray: error: --report: " << report_error << "\n";
        return kExitOutput;
    }
    if (!cmd.junit_path.empty()) {
        std::ofstream out(cmd.junit_path, std::ios::binary);
        out << format_junit(pairs, cmd.a + " vs " + cmd.b);
        out.close();
        if (!out) {
            std::cerr << "vrmlray: error: --junit: cannot write '" << cmd.junit_path << "'\n";
            return kExitOutput;
        }
    }
    if (cmd.update && !update_references(cmd, pairs)) return kExitOutput;
    for (const SuitePair& p : pairs)
        if (pair_failed(p.status)) return kExitCompareFailed;
    return kExitOk;
}

}  // namespace

CompareThresholds thresholds_of(const CompareCommand& cmd) {
    CompareThresholds thresholds;
    thresholds.max_rmse = cmd.max_rmse;
    thresholds.min_psnr = cmd.min_psnr;
    thresholds.min_ssim = cmd.min_ssim;
    thresholds.max_abs = cmd.max_abs;
    thresholds.max_fail_percent = cmd.max_fail_percent;
    thresholds.fail = cmd.fail;
    thresholds.failpercent = cmd.failpercent;
    thresholds.hardfail = cmd.hardfail;
    thresholds.warn = cmd.warn;
    thresholds.warnpercent = cmd.warnpercent;
    thresholds.hardwarn = cmd.hardwarn;
    thresholds.pixel_threshold = cmd.pixel_threshold;
    return thresholds;
}

int run_compare(const CompareCommand& cmd) {
    std::error_code ec;
    const bool a_dir = fs::is_directory(cmd.a, ec), b_dir = fs::is_directory(cmd.b, ec);
    if (a_dir && b_dir) return run_compare_folders(cmd);
    if (a_dir || b_dir) {
        std::cerr << "vrmlray: error: '" << (a_dir ? cmd.a : cmd.b)
                  << "' is a folder and the other is not: compare two images or two folders\n";
        return kExitUsage;
    }
    for (auto [set, name] :
         {std::pair{!cmd.junit_path.empty(), "--junit"},
          std::pair{!cmd.report_dir.empty(), "--report"}, std::pair{cmd.update, "--update"},
          std::pair{!cmd.thresholds_path.empty(), "--thresholds"}})
        if (set) {
            std::cerr << "vrmlray: error: " << name << " compares folders: give two folders\n";
            return kExitUsage;
        }
    Image a, b;
    std::string error;
    if (!read_image(cmd.a, a, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    if (!read_image(cmd.b, b, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    const CompareThresholds thresholds = thresholds_of(cmd);
    CompareMetrics metrics;
    if (!compare_images(a, b, thresholds, metrics, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    const std::vector<std::string> failures = failed_thresholds(metrics, thresholds);
    const std::vector<std::string> warnings = warned_thresholds(metrics, thresholds);
    if (cmd.json) {
        std::cout << format_metrics_json(metrics, failures, warnings);
    } else {
        std::cout << format_metrics_text(metrics);
        for (const std::string& w : warnings) std::cout << "WARNING: " << w << "\n";
        for (const std::string& f : failures) std::cout << "FAIL: " << f << "\n";
    }
    if (!cmd.diff_path.empty()) {
        Image diff = difference_heatmap(a, b);
        if (!write_image(cmd.diff_path, diff, false, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return kExitOutput;
        }
    }
    return failures.empty() ? kExitOk : kExitCompareFailed;
}

}  // namespace vr
