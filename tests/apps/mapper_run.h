/* Running the elevation-mapper program from a test: scratch folders, its output, its exit code. */
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "../core/test_files.h"

namespace mapper_run {

using test_files::readAll;
using test_files::scratchDir;

struct RunResult {
    int exitCode;
    std::string out, err;
};

/** Runs elevation-mapper with `args` (a shell command line fragment) in `dir`; `prefix` goes
 * before the program (e.g. "ulimit -f 16;"). */
inline RunResult runMapper(const std::filesystem::path& dir, const std::string& args,
                           const std::string& prefix = "") {
    const std::string cmd = prefix + " " + ELEVATION_MAPPER_EXE + " " + args + " > " +
                            (dir / "stdout.txt").string() + " 2> " + (dir / "stderr.txt").string() +
                            " < /dev/null";
    const int status = std::system(("/bin/sh -c '" + cmd + "'").c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAll(dir / "stdout.txt"),
            readAll(dir / "stderr.txt")};
}

}  // namespace mapper_run
