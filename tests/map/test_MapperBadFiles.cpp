/* Bad files: truncated or corrupt rawlogs and simplemaps given to the elevation-mapper program
 * (exit code 1 and a one-line error naming the file). Serialized maps read through CArchive:
 * test_CMultiBinElevationMap_io.cpp. */
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "../common/reliability_helpers.h"

namespace fs = std::filesystem;
using namespace reliability;
using test_files::writeAll;

namespace {
#ifdef ELEVATION_MAPPER_EXE
struct RunResult {
    int exitCode;
    std::string stderrText;
};

/** Runs elevation-mapper with the shipped walk.ini on `input` (--rawlog or --simplemap). */
RunResult runMapper(const std::string& flag, const fs::path& input, const fs::path& dir) {
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = std::string(ELEVATION_MAPPER_EXE) + " --config " +
                            (fs::path(MULTIBIN_SOURCE_DIR) / "rawlogs" / "walk.ini").string() +
                            " " + flag + " " + input.string() + " --out " + (dir / "out").string() +
                            " > " + (dir / "stdout.txt").string() + " 2> " + err.string() +
                            " < /dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAll(err)};
}

/** Exit code 1 and exactly one line on stderr that names the file. */
void expectOneLineErrorNaming(const RunResult& r, const fs::path& file) {
    EXPECT_EQ(r.exitCode, 1) << r.stderrText;
    ASSERT_FALSE(r.stderrText.empty());
    EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
    EXPECT_NE(r.stderrText.find(file.filename().string()), std::string::npos) << r.stderrText;
}

const fs::path kShipped = fs::path(MULTIBIN_SOURCE_DIR) / "rawlogs";
#endif
}  // namespace

#ifdef ELEVATION_MAPPER_EXE
TEST(BadInputFiles, TruncatedRawlogIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("truncated_rawlog");
    const std::string bytes = plainBytes(kShipped / "walk.rawlog");
    // Cut inside an entry a little way in (entries are observations of a few kB).
    const fs::path f = dir / "cut.rawlog";
    writeAll(f, bytes.substr(0, 20000));
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, CorruptRawlogIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("corrupt_rawlog");
    std::string bytes = plainBytes(kShipped / "walk.rawlog");
    bytes.resize(60000);
    // Overwrite 64 bytes in the middle of the stream (inside the second or third entry).
    for (size_t i = 30000; i < 30064; i++) bytes[i] = char(0xA5 ^ (i * 37));
    const fs::path f = dir / "corrupt.rawlog";
    writeAll(f, bytes);
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, RawlogOfAnotherFormatIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("text_rawlog");
    const fs::path f = dir / "notes.rawlog";
    writeAll(f, "this is not a rawlog\n");
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, TruncatedSimplemapIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("truncated_simplemap");
    const std::string bytes = plainBytes(kShipped / "walk.simplemap");
    const fs::path f = dir / "cut.simplemap";
    writeAll(f, bytes.substr(0, bytes.size() / 3));
    expectOneLineErrorNaming(runMapper("--simplemap", f, dir), f);
}

TEST(BadInputFiles, CorruptSimplemapIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("corrupt_simplemap");
    std::string bytes = plainBytes(kShipped / "walk.simplemap");
    for (size_t i = 40; i < 104; i++) bytes[i] = char(0x5A ^ (i * 13));
    const fs::path f = dir / "corrupt.simplemap";
    writeAll(f, bytes);
    expectOneLineErrorNaming(runMapper("--simplemap", f, dir), f);
}

TEST(BadInputFiles, MissingInputAndEmptyFileAreOneLineErrors) {
    const fs::path dir = scratchDir("missing");
    expectOneLineErrorNaming(runMapper("--rawlog", dir / "nowhere.rawlog", dir),
                             dir / "nowhere.rawlog");
    const fs::path empty = dir / "empty.simplemap";
    writeAll(empty, "");
    expectOneLineErrorNaming(runMapper("--simplemap", empty, dir), empty);
}
#endif
