/* Running the elevation-mapper program from a test: scratch folders, its output, its exit code,
 * and short inputs for the tests whose subject is not the map (paths, outputs, coordinates). */
#pragma once

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "../common/test_files.h"

namespace mapper_run {

using test_files::readAll;
using test_files::scratchDir;

struct RunResult {
    int exitCode;
    std::string out, err;
};

#ifdef ELEVATION_MAPPER_EXE
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
#endif

/** `path` written by `write(tmp)` into a temporary file renamed into place, unless it exists:
 * tests running at the same time (ctest -j) share one copy. */
template <class Write>
std::string sharedTestInput(const std::filesystem::path& path, Write&& write) {
    if (std::filesystem::exists(path)) return path.string();
    std::filesystem::create_directories(path.parent_path());
    const std::filesystem::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
    write(tmp);
    std::filesystem::rename(tmp, path);
    return path.string();
}

/** The first `entries` objects of the mock-up's rawlog (rawlogs/mockup.rawlog, 406 entries:
 * action collections and sensory frames in turn), in the build tree. A test of what the mapper
 * does with its paths and outputs needs a map and the whole pipeline, not the whole scenario:
 * 20 entries already give rasters of 172 x 540 cells and every evaluation figure, at a fifth of
 * the run's time (most of it the evaluation, ten times slower under the sanitizers). */
inline std::string mockupRawlogPrefix(size_t entries) {
    const std::filesystem::path path = std::filesystem::path(MULTIBIN_BINARY_DIR) / "test-inputs" /
                                       ("mockup-first-" + std::to_string(entries) + ".rawlog");
    return sharedTestInput(path, [&](const std::filesystem::path& tmp) {
        mrpt::io::CFileGZInputStream fin(std::string(MULTIBIN_SOURCE_DIR) +
                                         "/rawlogs/mockup.rawlog");
        auto in = mrpt::serialization::archiveFrom(fin);
        mrpt::io::CFileGZOutputStream fout(tmp.string());
        auto out = mrpt::serialization::archiveFrom(fout);
        for (size_t i = 0; i < entries; i++) out << *in.ReadObject();
    });
}

/** ini/mockup.ini with the traversability layer's Monte Carlo draws cut from 128 to 4 (the same
 * code computes the layer, 32 times fewer draws: the layer was most of an evaluated run's time),
 * and without the gap filling when `fill` is false (the fill was most of a short run's time under
 * the sanitizers: Eigen at -O1 with its assertions). For tests of what the mapper does with paths
 * and outputs. */
inline std::string mockupQuickIni(bool fill) {
    const std::filesystem::path path = std::filesystem::path(MULTIBIN_BINARY_DIR) / "test-inputs" /
                                       (fill ? "mockup-4-draws.ini" : "mockup-4-draws-no-fill.ini");
    return sharedTestInput(path, [fill](const std::filesystem::path& tmp) {
        std::string text = readAll(std::string(MULTIBIN_SOURCE_DIR) + "/ini/mockup.ini");
        const std::string on = "fill_enabled = true";
        const size_t at = text.find(on);
        if (at == std::string::npos) throw std::runtime_error("ini/mockup.ini: no '" + on + "'");
        if (!fill) text.replace(at, on.size(), "fill_enabled = false");
        std::ofstream(tmp) << text
                           << "\n[MappingApplication_multiBinElevationMap_00_traversabilityOpts]\n"
                              "monte_carlo_draws = 4\n";
    });
}

}  // namespace mapper_run
