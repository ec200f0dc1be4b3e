// The vrmlray command line as a library (the unit tests parse argv with it): every option of every
// subcommand, the mapping of its text to the commands' settings, and the running of the one named.
#pragma once
#include <string>
#include <vector>

#include "app/commands.h"

namespace vr {

enum class Subcommand { None, Render, Info, Convert, Compare, Bench };

struct CommandLine {
    Subcommand command = Subcommand::None;
    RenderCommand render;    // command == Render (its common is `common`)
    BenchCommand bench;      // command == Bench
    CompareCommand compare;  // command == Compare
    std::string in, out;     // info: in; convert: in, out
    ConvertOptions convert;  // command == Convert
    CommonOptions common;
};

// Parses argv into `cmd`. -1 when `cmd` names a command to run; otherwise the exit code to return
// at once: 0 after --help or --version (printed to stdout), kExitUsage after an error (printed to
// stderr as "vrmlray: error: ..." with where to read more).
int parse_command_line(int argc, const char* const* argv, CommandLine& cmd);
// A --list line: `args` are the words after "render" (the scene and its options), parsed into
// `render` as by parse_command_line, except that an option given twice takes its last value (the
// line's own options follow the command line's). Same return values; errors printed likewise.
int parse_render_words(const std::vector<std::string>& args, RenderCommand& render);
// The same for a --thresholds line: `args` are the words after "compare" (A, B and options).
int parse_compare_words(const std::vector<std::string>& args, CompareCommand& compare);
// The words of a --list or --thresholds line: split at blanks, "double" or 'single' quotes keep
// blanks in a word, and a word starting with # begins a comment.
std::vector<std::string> split_line_words(const std::string& line);
// Runs the parsed command and gives its exit code (--strict applied).
int run_command_line(const CommandLine& cmd);

}  // namespace vr
