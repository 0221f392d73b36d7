/* Hostile paths (issue 37, kind 1): a folder name that would reach a shell, and symlinks planted
 * at every file and temporary path the elevation-mapper writes. The mapper is started with an
 * argument vector (fork and exec, no shell); the symlinks are planted by the child after fork,
 * so that the names that would be predictable from the process id are planted too. Nothing
 * outside the output folder may change. */
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <csignal>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "../apps/mapper_run.h"
#include "../common/reliability_helpers.h"
#include "multibin/io/OutputFile.h"

#ifdef ELEVATION_MAPPER_EXE
namespace fs = std::filesystem;
using namespace reliability;

namespace {

/** Every file under `root` (symlinks not followed; `skip` and what is below it left out), with
 * its bytes: what a test compares before and after a run. */
std::map<std::string, std::string> snapshot(const fs::path& root, const fs::path& skip) {
    std::map<std::string, std::string> files;
    for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator();
         ++it) {
        if (it->path() == skip) {
            it.disable_recursion_pending();
            continue;
        }
        if (it->is_symlink())
            files[it->path().string()] = "-> " + fs::read_symlink(it->path()).string();
        else if (it->is_regular_file())
            files[it->path().string()] = readAll(it->path());
        else
            files[it->path().string()] = "(folder)";
    }
    return files;
}

/** Runs the mapper with `args` in `cwd`, output to cwd/stdout.txt and stderr.txt; in the child,
 * before exec (same process id), plant(pid) plants what the test wants. Returns the exit code. */
int runPlanted(const fs::path& cwd, const std::vector<std::string>& args,
               const std::function<void(pid_t)>& plant) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (::chdir(cwd.c_str()) != 0) ::_exit(126);
        plant(::getpid());
        const int out = ::open("stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err = ::open("stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(out, 1);
        ::dup2(err, 2);
        std::vector<char*> argv{const_cast<char*>(ELEVATION_MAPPER_EXE)};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(ELEVATION_MAPPER_EXE, argv.data());
        ::_exit(127);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/** The names the mapper writes with --outputs all, --export-resolution and --ground-truth (a run
 * that writes any other name fails expectNothingOutsideChanges: it was not planted). */
std::vector<std::string> outputNames() {
    return {"elevation_map.bin",
            "elevation_height.tif",
            "elevation_height.tfw",
            "elevation_sigma.tif",
            "elevation_certainty.tif",
            "elevation_source.tif",
            "elevation.3Dscene",
            "elevation_height.png",
            "elevation_sigma.png",
            "elevation_source.png",
            "elevation_height.asc",
            "elevation_sigma.asc",
            "elevation_certainty.asc",
            "elevation_source.asc",
            "elevation_untraversable.asc",
            "elevation_untraversable.png",
            "elevation_step.asc",
            "elevation_slope.asc",
            "elevation_roughness.asc",
            "elevation_foothold.asc",
            "elevation_traversability.gridmap.gz",
            "elevation.ply",
            "elevation_height_supersampled.asc",
            "elevation_sigma_supersampled.asc",
            "report.json",
            "traversability.json",
            "traversability_cells.csv",
            "profile.csv",
            "eval_truth.asc",
            "eval_raw_all.asc",
            "eval_raw_laser.asc",
            "eval_laser_only.asc",
            "eval_multibin.asc",
            "eval_multibin_filled.asc",
            "eval_mrpt_height_grid.asc",
            "eval_untraversable_truth.asc",
            "eval_untraversable_truth.png",
            "eval_untraversable_multibin.asc",
            "eval_untraversable_multibin.png",
            "fig_pi.png",
            "fig_profile.png",
            "layers.png"};
}

/** In `out`, a symlink at each output name and at each temporary name derived from it (hidden,
 * ".partial-PID" before the extension), each to its own file in `victims`; and the scratch
 * folder of the layer panels under the system's temporary folder, to `victims`. */
void plantSymlinks(const fs::path& out, const fs::path& victims, pid_t pid) {
    std::error_code ec;
    fs::create_directories(out, ec);
    for (const std::string& name : outputNames()) {
        const fs::path p(name);
        const std::string partial =
            "." + p.stem().string() + ".partial-" + std::to_string(pid) + p.extension().string();
        fs::create_symlink(victims / name, out / name, ec);
        fs::create_symlink(victims / ("partial-" + name), out / partial, ec);
    }
    fs::create_directory_symlink(
        victims, fs::temp_directory_path() / ("elevation-mapper-layers-" + std::to_string(pid)),
        ec);
}

/** The mock-up's first 20 rawlog entries, not filled, evaluated against its ground truth (every
 * output and figure is written; the whole rawlog took a minute a run under the sanitizers). */
std::vector<std::string> mockupArgs(const fs::path& out) {
    const fs::path src = MULTIBIN_SOURCE_DIR;
    return {"--config",       mapper_run::mockupQuickIni(false),
            "--rawlog",       mapper_run::mockupRawlogPrefix(20),
            "--ground-truth", (src / "rawlogs" / "mockup_gt.asc").string(),
            "--out",          out.string()};
}

/** Runs the mock-up with symlinks planted, `extra` arguments added: exit 0, nothing outside the
 * output folder changed, every output the run writes (all but those of `notWritten`) a regular
 * file, no temporary file left. */
void expectNothingOutsideChanges(const std::string& name, const std::vector<std::string>& extra,
                                 const std::vector<std::string>& notWritten = {}) {
    const fs::path dir = scratchDir(name);
    const fs::path victims = dir / "victims", out = dir / "out";
    fs::create_directories(victims);
    for (const std::string& v : outputNames()) {
        std::ofstream(victims / v) << "victim " << v;
        std::ofstream(victims / ("partial-" + v)) << "victim partial " << v;
    }
    const auto before = snapshot(dir, out);
    std::vector<std::string> args = mockupArgs(out);
    args.insert(args.end(), extra.begin(), extra.end());
    const int rc = runPlanted(dir, args, [&](pid_t pid) { plantSymlinks(out, victims, pid); });
    // The child planted with its own id: the parent cleans the folder under /tmp.
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
        if (e.path().filename().string().rfind("elevation-mapper-layers-", 0) == 0 &&
            e.is_symlink() && fs::read_symlink(e.path()) == victims)
            fs::remove(e.path());
    EXPECT_EQ(rc, 0) << readAll(dir / "stderr.txt");
    auto after = snapshot(dir, out);
    after.erase((dir / "stdout.txt").string());
    after.erase((dir / "stderr.txt").string());
    EXPECT_EQ(after, before) << "a file outside the output folder changed";
    const std::vector<std::string> planted = outputNames();
    for (const auto& e : fs::directory_iterator(out)) {
        const std::string n = e.path().filename().string();
        if (n[0] != '.')
            EXPECT_TRUE(std::find(planted.begin(), planted.end(), n) != planted.end())
                << n << " is written but no symlink was planted there (add it to outputNames)";
        if (n[0] == '.') {
            // Only the planted temporary-name symlinks may remain, untouched.
            EXPECT_TRUE(e.is_symlink()) << n << " left behind";
        } else if (fs::exists(victims / n) &&
                   std::find(notWritten.begin(), notWritten.end(), n) == notWritten.end()) {
            EXPECT_FALSE(e.is_symlink()) << n << " was not written (still the planted symlink)";
        }
    }
}

}  // namespace

// Defaults (map, tif, scene, png) with the evaluation: the layer panels read a scratch copy of
// the rasters, which lived under a predictable name in /tmp.
TEST(HostilePaths, SymlinksAtEveryOutputAndTemporaryPathChangeNothingOutside) {
    expectNothingOutsideChanges(
        "paths_default", {},
        {"elevation_height.asc", "elevation_sigma.asc", "elevation_certainty.asc",
         "elevation_source.asc", "elevation_untraversable.asc", "elevation_untraversable.png",
         "elevation_step.asc", "elevation_slope.asc", "elevation_roughness.asc",
         "elevation_foothold.asc", "elevation_traversability.gridmap.gz", "elevation.ply",
         "elevation_height_supersampled.asc", "elevation_sigma_supersampled.asc",
         "elevation_sigma.tif", "elevation_certainty.tif", "elevation_source.tif"});
}

// Every output group, the supersampled rasters and the evaluation.
TEST(HostilePaths, SymlinksAtEveryPathOfAllOutputsChangeNothingOutside) {
    expectNothingOutsideChanges("paths_all", {"--outputs", "all", "--export-resolution", "0.2"});
}

// A folder name with quotes and shell syntax reached std::system when the figures were drawn.
TEST(HostilePaths, AnOutputFolderNameIsNeverRunByAShell) {
    const fs::path dir = scratchDir("paths_shell");
    for (const std::string& name :
         {std::string("out'; touch injected-quote; '"), std::string("out$(touch injected-dollar)"),
          std::string("out`touch injected-backtick`")}) {
        SCOPED_TRACE(name);
        const int rc = runPlanted(dir, mockupArgs(dir / name), [](pid_t) {});
        EXPECT_EQ(rc, 0) << readAll(dir / "stderr.txt");
        EXPECT_TRUE(fs::exists(dir / name / "fig_pi.png")) << readAll(dir / "stderr.txt");
    }
    for (const auto& e : fs::recursive_directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().rfind("injected", 0), std::string::npos)
            << e.path() << ": a shell ran the folder's name";
}

// The output folder of another user: files planted there could not be trusted.
TEST(HostilePaths, AnOutputFolderOfAnotherUserIsRefused) {
    if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a folder to another user";
    const fs::path dir = scratchDir("paths_owner");
    const fs::path out = dir / "theirs";
    fs::create_directories(out);
    ASSERT_EQ(::chown(out.c_str(), 65534, 65534), 0);
    const int rc = runPlanted(dir, mockupArgs(out), [](pid_t) {});
    EXPECT_EQ(rc, 1);
    const std::string err = readAll(dir / "stderr.txt");
    EXPECT_NE(err.find("does not belong to the user"), std::string::npos) << err;
    EXPECT_TRUE(fs::is_empty(out));
}

// A run killed while writing left its partial file (600 MB for a fine export): the handlers of
// removePartialFilesOnSignals() remove what is being written, then the signal ends the process.
TEST(HostilePaths, AWriteEndedBySigtermOrSigintLeavesNoPartialFile) {
    for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
        SCOPED_TRACE(sig);
        const fs::path dir = scratchDir("paths_killed_" + std::to_string(sig));
        const pid_t pid = ::fork();
        if (pid == 0) {
            multibin::removePartialFilesOnSignals();
            multibin::writeFileAtomically((dir / "big.asc").string(), [&](const std::string& p) {
                std::ofstream(p) << std::string(1 << 20, 'x');  // half written ...
                ::raise(sig);                                   // ... when the signal comes
                return true;
            });
            ::_exit(0);
        }
        int status = 0;
        ::waitpid(pid, &status, 0);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
        EXPECT_TRUE(fs::is_empty(dir)) << fs::begin(fs::directory_iterator(dir))->path();
    }
}
#endif
