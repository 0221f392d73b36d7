/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "Figures.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "ProgressBar.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/io/OutputFile.h"

extern char** environ;

namespace fs = std::filesystem;

namespace {

const char* const kFigures[] = {"fig_pi.png", "fig_profile.png", "layers.png"};

/** The matplotlib script that draws the figures: beside the sources, or installed. */
std::string plotScript() {
    for (const fs::path& p :
         {fs::path(MULTIBIN_SOURCE_DIR) / "apps/elevation-mapper/plot_report.py",
          fs::path(MULTIBIN_DATA_DIR) / "plot_report.py"})
        if (fs::exists(p)) return p.string();
    return {};
}

/** Runs argv[0] with `argv` (no shell, no PATH search), its standard output discarded; returns
 * its exit status, or a reason it did not run. */
bool runProgram(const std::vector<std::string>& argv, std::string& failure) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        failure = argv[0] + " did not start: " + std::strerror(rc);
        return false;
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            failure = std::string("waiting for ") + argv[0] + ": " + std::strerror(errno);
            return false;
        }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return true;
    failure =
        argv[0] + (WIFEXITED(status) ? " exited with code " + std::to_string(WEXITSTATUS(status))
                                     : " ended by signal " + std::to_string(WTERMSIG(status)));
    return false;
}

}  // namespace

void drawFigures(const OutputFolder& folder, const MapLayers* layersIfNoAsc) {
    const std::string script = plotScript();
    const std::string python = "/usr/bin/python3";
    if (script.empty() || !fs::exists(python)) {
        std::cerr << "elevation-mapper: warning: figures not drawn (needs " << python
                  << " with python3-matplotlib and plot_report.py)\n";
        return;
    }
    for (const char* name : kFigures) folder.checkNotAnInput(name);
    std::string failure;
    bool drawn = false;
    std::string work;
    try {
        work = multibin::createPrivateFolder(folder.dir().string(), ".figures-");
        std::string rasterDir = folder.dir().string();
        if (layersIfNoAsc) {  // the layer panels read the ESRI ASCII rasters: a scratch copy
            layersIfNoAsc->saveAsc(OutputFolder(work, {}));
            rasterDir = work;
        }
        std::cout.flush();
        ProgressBar::runWithProgress("figures", [&] {
            drawn = runProgram({python, script, folder.dir().string(), rasterDir, work}, failure);
        });
        if (drawn)
            for (const char* name : kFigures) folder.moveIn(name, (fs::path(work) / name).string());
    } catch (const std::exception& e) {
        drawn = false;
        failure = multibin::oneLineMessage(e);
    }
    std::error_code ec;
    if (!work.empty()) fs::remove_all(work, ec);
    if (!drawn)
        std::cerr << "elevation-mapper: warning: figures not drawn: " << failure << "\n";
    else
        std::cout << "figures: " << (folder.dir() / kFigures[0]).string() << ", " << kFigures[1]
                  << ", " << kFigures[2] << "\n";
}
