// Where the tests find the outside corpus of real files (../shared/corpus/: exports nobody here
// wrote). One setting, read at run time so that a user points the tests at a corpus without
// rebuilding:
//   VRMLRAY_CORPUS=DIR    that folder (it must exist: a named corpus that is missing is a failure)
//   VRMLRAY_CORPUS=none   no corpus: its tests are skipped
//   unset                 ../shared/corpus beside the source tree, when it exists; else skipped
// VRMLRAY_REQUIRE_CORPUS=1 (set by CI, where the folder is laid beside the clone) turns a skip into
// a failure, so that the tests the project's claims rest on cannot quietly stop running.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "parser/load.h"

namespace vr::test {

struct CorpusLookup {
    std::filesystem::path folder;  // the corpus (sub)folder, when found
    std::string why_not;           // empty when found
    bool must_fail = false;        // a missing corpus that was asked for is a failure, not a skip
};

inline CorpusLookup lookup_corpus(const std::string& subfolder = "") {
    namespace fs = std::filesystem;
    const char* setting = std::getenv("VRMLRAY_CORPUS");
    const char* required = std::getenv("VRMLRAY_REQUIRE_CORPUS");
    CorpusLookup out;
    out.must_fail = required && std::string(required) == "1";
    fs::path root;
    if (setting && std::string(setting) == "none") {
        out.why_not = "corpus skipped: VRMLRAY_CORPUS=none";
        return out;
    }
    if (setting && *setting) {
        root = setting;
        if (!fs::is_directory(root)) {
            out.why_not = "VRMLRAY_CORPUS=" + root.string() + " is not a folder";
            out.must_fail = true;
            return out;
        }
    } else {
        root = VRMLRAY_CORPUS_DIR;
        if (!fs::is_directory(root)) {
            out.why_not = "corpus not found at " + root.lexically_normal().string() +
                          "; set VRMLRAY_CORPUS=DIR to run this test";
            return out;
        }
    }
    out.folder = subfolder.empty() ? root : root / subfolder;
    if (!fs::is_directory(out.folder)) {
        // The corpus is there but lacks a folder the test reads: an incomplete corpus, not an
        // absent one.
        out.why_not = "the corpus at " + root.string() + " has no folder " + subfolder;
        out.must_fail = true;
        out.folder.clear();
        return out;
    }
    return out;
}

// The classic-encoding files under `folder` (.wrl, .wrz, .x3dv and gzip), sorted: what the tests of
// reading in pieces cut up.
inline std::vector<std::filesystem::path> classic_files(const std::filesystem::path& folder) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (ext == ".wrl" || ext == ".wrz" || ext == ".x3dv" || ext == ".gz" || ext == ".x3dvz")
            files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

// The X3D XML files under `folder`, sorted: every file whose text (gzip undone) begins with '<'
// after a byte order mark and white space, whatever its name says.
inline std::vector<std::filesystem::path> xml_files(const std::filesystem::path& folder) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
        if (!entry.is_regular_file()) continue;
        std::string text;
        try {
            text = read_file_bytes(entry.path(), size_t(64) << 20);
        } catch (const std::exception&) {
            continue;
        }
        size_t p = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
        p = text.find_first_not_of(" \t\r\n", p);
        if (p != std::string::npos && text[p] == '<') files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

// A piece size (VRMLRAY_PIECE_BYTES) that cuts `file` into about 200 pieces, never below 64 bytes:
// small files are cut at most lines.
inline size_t small_piece_bytes(const std::filesystem::path& file) {
    return std::max<size_t>(64, std::filesystem::file_size(file) / 200);
}

}  // namespace vr::test

// Declares `std::filesystem::path VAR` as the corpus folder SUBFOLDER, or ends the test: skipped
// with one line saying where it looked and how to give it, or failed when the corpus was required
// or asked for.
#define VR_CORPUS_FOLDER(VAR, SUBFOLDER)                                                \
    const ::vr::test::CorpusLookup VAR##_lookup = ::vr::test::lookup_corpus(SUBFOLDER); \
    if (!VAR##_lookup.why_not.empty()) {                                                \
        if (VAR##_lookup.must_fail) FAIL() << VAR##_lookup.why_not;                     \
        GTEST_SKIP() << VAR##_lookup.why_not;                                           \
    }                                                                                   \
    const std::filesystem::path VAR = VAR##_lookup.folder
