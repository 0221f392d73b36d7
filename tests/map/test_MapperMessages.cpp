/* Messages, third round (issue 37, kind 6): never empty, never a library's internals without
 * what was being done, user text (labels, paths) escaped so that it cannot forge a line or
 * reach the terminal as an escape sequence; inputs that are not regular files (a device, a FIFO)
 * a one-line error naming the input, within seconds. The library's wording and escaping alone:
 * io/test_ErrorMessage.cpp. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <stdexcept>
#include <string>

#include "../apps/mapper_run.h"
#include "../common/reliability_helpers.h"

namespace fs = std::filesystem;
using namespace reliability;

#ifdef ELEVATION_MAPPER_EXE
namespace {
struct MapperRun {
    int exitCode;
    std::string err;
};
/** The mapper on `flag input` (the mock-up's first 20 entries for the rest), stopped after 30 s. */
MapperRun runMapper(const fs::path& dir, const std::string& flag, const std::string& input) {
    const fs::path src = MULTIBIN_SOURCE_DIR;
    std::string args = " --config " + (src / "ini" / "mockup.ini").string() + " --rawlog " +
                       mapper_run::mockupRawlogPrefix(20);
    const std::string given = flag + " '" + input + "'";
    if (flag == "--config" || flag == "--rawlog") {
        const size_t at = args.find(flag);
        const size_t end = args.find(' ', args.find(' ', at) + 1);
        args =
            args.substr(0, at) + given + args.substr(end == std::string::npos ? args.size() : end);
    } else {
        args += " " + given;
    }
    const std::string cmd = "timeout 30 " + std::string(ELEVATION_MAPPER_EXE) + args +
                            " --no-plots --out " + (dir / "out").string() + " > /dev/null 2> " +
                            (dir / "stderr.txt").string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAll(dir / "stderr.txt")};
}
void expectOneLineNaming(const MapperRun& r, const std::string& what) {
    EXPECT_EQ(r.exitCode, 1) << r.err;  // 124: timeout's, the mapper blocked
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("error: \n"), std::string::npos) << "an empty message";
}
}  // namespace

// A device file gave "error: " and nothing after it; a FIFO blocked the mapper for ever.
TEST(Messages, InputsThatAreNotRegularFilesAreOneLineErrorsNamingThem) {
    const fs::path dir = scratchDir("messages_devices");
    const fs::path fifo = dir / "fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const auto& [flag, input] : {std::pair{"--rawlog", std::string("/dev/zero")},
                                      {"--rawlog", std::string("/dev/null")},
                                      {"--rawlog", fifo.string()},
                                      {"--config", std::string("/dev/zero")},
                                      {"--config", fifo.string()},
                                      {"--ground-truth", fifo.string()}}) {
        SCOPED_TRACE(std::string(flag) + " " + input);
        expectOneLineNaming(runMapper(dir, flag, input), "'" + input + "' is not a regular file");
    }
}

// A label with a newline and terminal escapes, in an error that quotes it: one line, escaped.
TEST(Messages, ALabelInAnErrorCannotForgeALineOrEscapeTheTerminal) {
    const fs::path dir = scratchDir("messages_labels");
    auto pose = mrpt::obs::CObservationRobotPose::Create();
    pose->sensorLabel = "POSE\x1b[2J\nelevation-mapper: error: forged";
    pose->pose.mean = mrpt::poses::CPose3D(std::nan(""), 0, 0, 0, 0, 0);
    mrpt::obs::CSensoryFrame sf;
    sf.insert(pose);
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << sf;
    const fs::path rawlog = dir / "label.rawlog";
    std::ofstream(rawlog, std::ios::binary)
        .write(static_cast<const char*>(mem.getRawBufferData()), mem.getTotalBytesCount());
    const MapperRun r = runMapper(dir, "--rawlog", rawlog.string());
    expectOneLineNaming(r, "POSE\\x1B[2J\\nelevation-mapper: error: forged");
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
    // A path with the same text: the same.
    const fs::path odd = dir / "odd\x1b[31m\nforged.rawlog";
    std::ofstream(odd) << "not a rawlog";
    const MapperRun p = runMapper(dir, "--rawlog", odd.string());
    EXPECT_EQ(p.exitCode, 1) << p.err;
    EXPECT_EQ(std::count(p.err.begin(), p.err.end(), '\n'), 1) << p.err;
    EXPECT_EQ(p.err.find('\x1b'), std::string::npos) << p.err;
}
#endif

#ifdef ELEVATION_MAPPER_EXE
// MRPT warns once per object it reads: a rawlog or a simplemap of 60 depth scans whose range
// image is smaller than their calibration printed 60 lines "[CObservation3DRangeScan] Warning:
// autofixing incorrect camera resolution ..." (on a terminal, among the progress bar's). The
// reading path collects them: one line, with the count and the first entry.
TEST(Messages, RepeatedMrptWarningsArriveOnceWithTheirCount) {
    const fs::path dir = scratchDir("messages_mrpt_warnings");
    mrpt::maps::CSimpleMap sm;
    {
        mrpt::io::CFileGZOutputStream out((dir / "depth.rawlog").string());
        auto arch = mrpt::serialization::archiveFrom(out);
        for (int i = 0; i < 60; i++) {
            auto scan = mrpt::obs::CObservation3DRangeScan::Create();
            scan->sensorLabel = "DEPTH";
            scan->timestamp = mrpt::Clock::fromDouble(100 + i);
            scan->hasRangeImage = true;
            scan->rangeImage.setConstant(3, 4, 1000);  // 4 x 3 px of 1 m ...
            scan->rangeUnits = 0.001f;
            scan->cameraParams.ncols = 640;  // ... calibrated as 640 x 480 px
            scan->cameraParams.nrows = 480;
            scan->cameraParams.setIntrinsicParamsFromValues(500, 500, 320, 240);
            scan->cameraParamsIntensity = scan->cameraParams;
            scan->sensorPose = mrpt::poses::CPose3D(0, 0, 0.5, 0, mrpt::DEG2RAD(60.0), 0);
            auto pose = mrpt::obs::CObservationRobotPose::Create();
            pose->timestamp = scan->timestamp;
            pose->pose = posePdf(0.01 * i);
            auto sf = mrpt::obs::CSensoryFrame::Create();
            sf->insert(pose);
            sf->insert(scan);
            arch << *sf;
            sm.insert(mrpt::poses::CPose3DPDFGaussian::Create(posePdf(0.01 * i)), sf);
        }
    }
    {
        mrpt::io::CFileGZOutputStream out((dir / "depth.simplemap").string());
        mrpt::serialization::archiveFrom(out) << sm;
    }
    const std::string ini = (fs::path(MULTIBIN_SOURCE_DIR) / "ini" / "mockup.ini").string();
    for (const char* input : {"--rawlog", "--simplemap"}) {
        SCOPED_TRACE(input);
        const std::string file = (dir / (std::string("depth.") + (input + 2))).string();
        const auto r =
            mapper_run::runMapper(dir, "--config " + ini + " " + input + " " + file +
                                           " --outputs map --out " + (dir / "out").string());
        EXPECT_EQ(r.exitCode, 0) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find("MRPT said 60 times (first at "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("autofixing incorrect camera resolution"), std::string::npos) << r.err;
    }
}
#endif

#ifdef ELEVATION_MAPPER_EXE
// A robot beyond the coordinate range the map supports (doc/frames.md) was blamed on the map's
// window ("the map's window (x 1e+08..1e+08 m ...) does not hold the data ... check grow,
// max_size_m"), or mapped without a word where single precision rounds to metres. The error
// names the poses and the range; a run that maps is warned.
TEST(Messages, APoseBeyondTheSupportedRangeIsNamedNotTheMapsWindow) {
    const fs::path dir = scratchDir("messages_pose_range");
    auto rawlogAt = [&](double x_m, double y_m) {
        const fs::path path = dir / ("at_" + std::to_string(x_m) + "_" + std::to_string(y_m));
        mrpt::io::CFileGZOutputStream out(path.string());
        auto arch = mrpt::serialization::archiveFrom(out);
        for (int i = 0; i < 3; i++) {
            auto pose = mrpt::obs::CObservationRobotPose::Create();
            pose->timestamp = mrpt::Clock::fromDouble(100 + i);
            pose->pose = posePdf(x_m + 0.01 * i, y_m);
            auto scan = floorScan(181);
            scan->sensorLabel = "LASER";
            scan->timestamp = pose->timestamp;
            mrpt::obs::CSensoryFrame sf;
            sf.insert(pose);
            sf.insert(scan);
            arch << sf;
        }
        return path.string();
    };
    for (const auto& [x_m, y_m] : {std::pair{1e12, 0.0}, std::pair{0.0, -5e9}}) {
        SCOPED_TRACE(std::to_string(x_m) + ", " + std::to_string(y_m));
        const MapperRun r = runMapper(dir, "--rawlog", rawlogAt(x_m, y_m));
        expectOneLineNaming(r, "beyond the supported range (|x|, |y| <= 1e+07 m");
        EXPECT_EQ(r.err.find("window"), std::string::npos) << r.err;
    }
    const MapperRun far = runMapper(dir, "--rawlog", rawlogAt(5e7, 0));
    EXPECT_EQ(far.exitCode, 0) << far.err;
    EXPECT_NE(far.err.find("warning: the robot poses reach x 5e+07"), std::string::npos) << far.err;
}
#endif

#ifdef ELEVATION_MAPPER_EXE
// Requests that took minutes (issue 37, kind 8): a profile line to a far point was sampled every
// half cell along its whole length; an export resolution near the old cap (1e8 samples) took
// minutes and wrote gigabytes, and failed after the other outputs were written. Both are
// refused within seconds, before any output.
TEST(Messages, SlowRequestsAreRefusedBeforeAnyOutput) {
    const fs::path dir = scratchDir("messages_slow");
    const fs::path src = MULTIBIN_SOURCE_DIR;
    const std::string common = " --config " + (src / "ini" / "mockup.ini").string() + " --rawlog " +
                               mapper_run::mockupRawlogPrefix(20) + " --no-plots --out " +
                               (dir / "out").string();
    for (const auto& [extra, what] :
         {std::pair{std::string(" --ground-truth ") + (src / "rawlogs" / "mockup_gt.asc").string() +
                        " --profile 0,0,1e9,0",
                    std::string("--profile")},
          {std::string(" --export-resolution 0.0004"), std::string("--export-resolution")}}) {
        SCOPED_TRACE(extra);
        fs::remove_all(dir / "out");
        const std::string cmd = "timeout 60 " + std::string(ELEVATION_MAPPER_EXE) + common + extra +
                                " > /dev/null 2> " + (dir / "stderr.txt").string();
        const int status = std::system(cmd.c_str());
        const std::string err = readAll(dir / "stderr.txt");
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status << " " << err;
        EXPECT_NE(err.find(what), std::string::npos) << err;
        EXPECT_FALSE(fs::exists(dir / "out" / "elevation_map.bin")) << "an output was written";
    }
}
#endif
