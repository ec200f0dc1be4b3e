// vrmlray: command line. Reads like the pipeline: parse options, run one subcommand, return its
// exit code.
#include "app/cli.h"

int main(int argc, char** argv) {
    vr::CommandLine cmd;
    const int code = vr::parse_command_line(argc, argv, cmd);
    return code >= 0 ? code : vr::run_command_line(cmd);
}
