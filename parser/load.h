// Reading a scene file of any supported encoding, with its Inlines and EXTERNPROTOs, into one node
// tree.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "parser/node_tree.h"
#include "parser/piece_consumer.h"
#include "parser/registry.h"
#include "parser/source.h"

namespace vr {

enum class Encoding : uint8_t { Vrml97, X3dClassic, X3dXml, Vrml1, Unknown };
std::string_view encoding_name(Encoding encoding);

struct LoadLimits {
    size_t max_nesting_depth = 1000;  // nodes inside nodes (also bounds the reader's recursion)
    size_t max_proto_depth = 64;      // PROTO instances inside PROTO bodies
    // Total nodes, including expanded PROTO bodies. A 4 GiB PyMOL-style export (some 15 million
    // atoms, 5 nodes each) stays below; a file that reaches it without being built in pieces holds
    // a tree of some 4 GB (20 bytes a node, a field entry or two each) when it is refused.
    size_t max_nodes = 100'000'000;
    size_t max_inline_depth = 16;
    size_t max_inline_files = 1000;
    size_t max_file_bytes = size_t(4) << 30;  // after decompression; kMaxSourceBytes at most
    size_t max_mf_values = size_t(1) << 28;   // numbers or strings in one field
    // Threads that read a large file in pieces, the calling one included (--threads); 0: one a
    // core.
    unsigned read_threads = 0;
    // The bytes a large classic-encoding file's pieces are cut to; 0: piece_bytes()
    // (classic_pieces.h). Processes that share the pieces cut them finer (src/app/shared_pieces.h).
    size_t piece_bytes = 0;
    // The bytes before the first piece, which the main reader reads itself; 0: one piece's. Every
    // process that shares the pieces reads that head, so they keep it short.
    size_t head_bytes = 0;
};

struct LoadOptions {
    LoadLimits limits;
    bool resolve_inlines = true;
    // --sandbox: confine every URL (Inline, EXTERNPROTO, textures, Background) to sandbox_dir
    // (empty: the main file's folder) and allowed_roots. Without it, URLs reach any file the user
    // can read, as in a browser.
    bool sandbox = false;
    std::filesystem::path sandbox_dir;
    // Folders besides the sandbox's that URLs may reach (--allow-path); used only with `sandbox`.
    std::vector<std::filesystem::path> allowed_roots;
    // Takes the main file's pieces as they are read (parser/piece_consumer.h); null: every piece
    // joins the node tree. Only for callers that build the scene with it (render).
    std::shared_ptr<PieceConsumer> piece_consumer;
};

struct LoadedScene {
    SourceManager sources;
    Diagnostics diagnostics;
    NodeTree tree;
    ReadStats stats;
    Encoding encoding = Encoding::Unknown;
    // Per source file: the X3D major version its header states (0: VRML or unstated). Rules that
    // changed between versions follow the file a node stands in (an Inline keeps its own).
    std::vector<uint8_t> x3d_major;
    std::filesystem::path main_file;
    // Folders URLs are confined to: the sandbox folder + LoadOptions::allowed_roots; empty: not
    // confined.
    std::vector<std::filesystem::path> allowed_roots;
    // The pieces LoadOptions::piece_consumer took, in file order, and the consumer that holds what
    // it built of them (null when it took none): tree.roots lacks their top-level nodes.
    std::vector<ConsumedPiece> consumed_pieces;
    std::shared_ptr<PieceConsumer> piece_consumer;
    bool ok() const { return !diagnostics.has_errors(); }
};

// Reads `path` (gzip detected by magic bytes). Never throws for bad input: errors land in
// diagnostics.
LoadedScene load_scene(const std::filesystem::path& path, const LoadOptions& options = {});
// Reads scene text held in memory (tests, fuzzers). `path` names it in messages and anchors
// relative URLs.
LoadedScene load_scene_text(std::string text, const std::string& path,
                            const LoadOptions& options = {});

// The X3D major version a file's text states in its header ("#X3D V4.0 utf8", <X3D version='4.0'>);
// 0 for VRML and for none.
int x3d_major_version(std::string_view text);

// Resolves a URL found in `from_file` (relative, absolute or file:) to a local path. An empty
// `allowed_roots` allows any path; otherwise the path, symbolic links and `..` resolved, must lie
// under one of them (the first is the sandbox folder). Returns an empty path and sets `why` when
// the URL is remote (never fetched), missing, or outside the allowed folders.
std::filesystem::path resolve_url(const std::string& url, const std::filesystem::path& from_file,
                                  const std::vector<std::filesystem::path>& allowed_roots,
                                  std::string& why);

// Why each URL of an MFString failed, in the order tried: the one message of a node none of whose
// URLs loads ("Inline not loaded: ...", "EXTERNPROTO X not resolved: ...", "no texture image ...").
struct UrlFailures {
    std::string reasons;  // "; "-separated
    void add(const std::string& why) { reasons += (reasons.empty() ? "" : "; ") + why; }
    // The reasons, or "no URL" when there were none to try.
    std::string message() const { return reasons.empty() ? std::string("no URL") : reasons; }
};
// The first step of each URL's try: resolve_url, and on failure its reason noted in `failures`
// (after "URL: " when `name_url`, for reasons that do not quote it).
std::filesystem::path resolve_or_note(const std::string& url,
                                      const std::filesystem::path& from_file,
                                      const std::vector<std::filesystem::path>& allowed_roots,
                                      UrlFailures& failures, bool name_url = false);

// Reads a whole file, decompressing gzip data (found by its magic bytes). Throws
// std::runtime_error.
std::string read_file_bytes(const std::filesystem::path& path, size_t max_bytes);
// The same, for a reader: a large plain file is mapped instead of copied (see SourceText).
SourceText read_source_text(const std::filesystem::path& path, size_t max_bytes);

}  // namespace vr
