/* Options misuse (issue 16.2, 16.6, 16.7): options set in code are validated at every insertion
 * entry point, extents and cell sizes are checked against int ranges, time differences do not
 * wrap, recenter(NaN) is refused, and ini errors name the file, section and key also through
 * MRPT's TSetOfMetricMapInitializers. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/maps/TMetricMapInitializer.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>

#include "../common/reliability_helpers.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/map/MapStatistics.h"

namespace fs = std::filesystem;
using namespace reliability;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();

/** Loads the maps of an ini file through MRPT's initializers, as observations2map does. */
void mapsFromIniFile(const fs::path& path) {
    mrpt::config::CConfigFile ini(path.string());
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, "map");
    mrpt::maps::CMultiMetricMap maps(inits);
}

fs::path writeIni(const std::string& name, const std::string& text) {
    const fs::path d = fs::path(MULTIBIN_BINARY_DIR) / "test_reliability" / "options";
    fs::create_directories(d);
    const fs::path p = d / name;
    std::ofstream(p) << text;
    return p;
}

std::string iniWith(const std::string& creation, const std::string& insertion = "",
                    const std::string& count = "1") {
    return "[map]\nmultiBinElevationMap_count = " + count +
           "\n[map_multiBinElevationMap_00_creationOpts]\n" + creation +
           "\n[map_multiBinElevationMap_00_insertOpts]\n" + insertion + "\n";
}

/** Runs f in a child process limited to 1 GB of address space; returns its error message
 * ("" if it returned normally, "crash" if it died). */
std::string inChildUnderOneGigabyte(const std::function<void()>& f) {
    int fds[2];
    if (pipe(fds) != 0) return "pipe";
    const pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        const rlimit lim{rlim_t(kAddressSpaceLimit_bytes), rlim_t(kAddressSpaceLimit_bytes)};
        if (kAddressSpaceLimit) setrlimit(RLIMIT_AS, &lim);
        std::string msg;
        try {
            f();
        } catch (const std::exception& e) {
            msg = e.what();
            if (msg.empty()) msg = "(empty message)";
        }
        if (write(fds[1], msg.data(), msg.size()) < 0) _exit(3);
        _exit(0);
    }
    close(fds[1]);
    std::string out;
    char buf[4096];
    for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, size_t(n));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "crash";
    return out;
}
}  // namespace

// Options set in code used to reach the grid unchecked: NaN or negative certainty increments
// made invalid bins, two default pose sigmas were read past their end.
TEST(OptionsMisuse, InsertionOptionsSetInCodeAreValidatedOnEveryInsertion) {
    const auto check = [](const std::function<void(Map::TInsertionOptions&)>& set,
                          const std::string& key) {
        Map map = mapWithData();
        const auto before = serialize(map);
        set(map.insertionOptions);
        expectErrorMentioning([&] { map.insertObservation(*floorScan(), posePdf()); }, {key});
        expectErrorMentioning([&] { map.insertObservation(*floorScan(), posePdf().mean); }, {key});
        Map::TPointInsertParams pp;
        expectErrorMentioning([&] { map.insertIndividualPoint(0.1, 0.1, 0, pp); }, {key});
        Map::TInsertionOptions ok;
        map.insertionOptions = ok;
        EXPECT_EQ(serialize(map), before) << key;
    };
    check([](auto& o) { o.certainty_increment = float(kNaN); }, "certainty_increment");
    check([](auto& o) { o.certainty_increment = -5; }, "certainty_increment");
    check([](auto& o) { o.certainty_increment = std::numeric_limits<float>::infinity(); },
          "certainty_increment");
    check([](auto& o) { o.max_elevation_uncertainty_m = kNaN; }, "max_elevation_uncertainty");
    check([](auto& o) { o.default_pose_sigmas = {0.1, 0.1}; }, "default_pose_sigmas");
    check([](auto& o) { o.height_sigma_floor_m = std::numeric_limits<double>::infinity(); },
          "height_sigma_floor");
}

TEST(OptionsMisuse, CreationOptionsSetInCodeAreValidatedOnInsertion) {
    Map map = mapWithData();
    const auto before = serialize(map);
    map.creationOptions.bin_height_m = kNaN;
    expectErrorMentioning([&] { map.insertObservation(*floorScan(), posePdf()); }, {"bin_height"});
    map.creationOptions.bin_height_m = Map::TCreationOptions().bin_height_m;
    EXPECT_EQ(serialize(map), before);
}

// grow = false with min_x = 1e9 overflowed int cell indices into a 0-cell window at -4.29e7 m;
// extents, sizes and cell sizes must give cell indices well inside int.
TEST(OptionsMisuse, ExtentsBeyondTheIntRangeOfCellIndicesAreErrors) {
    Map::TCreationOptions c = fixedTwoMetreMap();
    c.min_x = 1e9, c.max_x = 1e9 + 10;
    expectErrorMentioning([&] { Map m(c); }, {"min_x", "cell index"});
    c = fixedTwoMetreMap();
    c.min_y = -1e12;
    expectErrorMentioning([&] { Map m(c); }, {"min_y"});
    c = fixedTwoMetreMap();
    c.min_x = kNaN;
    expectErrorMentioning([&] { Map m(c); }, {"min_x"});
    c = Map::TCreationOptions();
    c.resolution_m = 1e-12;  // cell indices beyond int within metres
    expectErrorMentioning([&] { Map m(c); }, {"resolution"});
}

// A dual grid told to centre on NaN dropped every bin.
TEST(OptionsMisuse, RecenterOnANonFinitePositionIsRefused) {
    Map::TCreationOptions c;
    c.dual_grid = true;
    Map map(c);
    map.insertObservation(*floorScan(), posePdf());
    const auto before = serialize(map);
    expectErrorMentioning([&] { map.recenter(kNaN, 0); }, {"recenter", "finite"});
    expectErrorMentioning([&] { map.recenter(0, std::numeric_limits<double>::infinity()); },
                          {"recenter"});
    EXPECT_EQ(serialize(map), before);
}

// A robot pose 2^64 ticks older than the scan: the tick difference wrapped to 1.6 us and the
// pose was used as fresh.
TEST(OptionsMisuse, ARobotPoseFromTheFarPastIsNotFresh) {
    Map map;
    mrpt::obs::CObservationRobotPose rp;
    rp.pose = posePdf(0.5, 0);
    rp.timestamp = mrpt::Clock::time_point(
        mrpt::Clock::duration(std::numeric_limits<mrpt::Clock::rep>::min() + 10));
    map.insertObservation(rp);
    auto scan = floorScan();
    scan->timestamp = mrpt::Clock::time_point(
        mrpt::Clock::duration(std::numeric_limits<mrpt::Clock::rep>::max() - 5));
    map.insertObservation(*scan);
    EXPECT_EQ(map.statistics().poseFallbacks, 1u) << "a pose 2^64 ticks old was taken as fresh";
}

// multiBinElevationMap_count = -1 or 100000 took 9-23 GB inside MRPT's initializers.
TEST(OptionsMisuse, AMapCountOutOfRangeIsAnErrorUnderAOneGigabyteLimit) {
    for (const std::string count : {"-1", "100000", "65"}) {
        const fs::path p = writeIni("count.ini", iniWith("", "", count));
        const std::string msg = inChildUnderOneGigabyte([&] { mapsFromIniFile(p); });
        EXPECT_NE(msg.find("multiBinElevationMap_count"), std::string::npos)
            << count << ": " << msg;
    }
    EXPECT_EQ(
        inChildUnderOneGigabyte([] {
            mapsFromIniFile(writeIni(
                "two.ini", iniWith("", "", "2") + "[map_multiBinElevationMap_01_creationOpts]\n"));
        }),
        "");
}

// MRPT's exception wrapper dropped the section ("error: , key 'bin_heigth': unknown key") and
// nothing named the file.
TEST(OptionsMisuse, IniErrorsThroughMrptsInitializersNameFileSectionAndKey) {
    const fs::path p = writeIni("typo.ini", iniWith("bin_heigth = 0.05"));
    expectErrorMentioning([&] { mapsFromIniFile(p); },
                          {"typo.ini", "map_multiBinElevationMap_00_creationOpts", "bin_heigth"});
    const fs::path q = writeIni("value.ini", iniWith("", "certainty_increment = -1"));
    expectErrorMentioning(
        [&] { mapsFromIniFile(q); },
        {"value.ini", "map_multiBinElevationMap_00_insertOpts", "certainty_increment"});
}

TEST(OptionsMisuse, ADuplicatedKeyIsAnError) {
    const fs::path p = writeIni("dup.ini", iniWith("resolution = 0.02\nresolution = 0.05"));
    expectErrorMentioning([&] { mapsFromIniFile(p); }, {"dup.ini", "resolution", "more than once"});
}

TEST(OptionsMisuse, AMisspeltSectionOfTheMapsPrefixIsAnError) {
    const fs::path p =
        writeIni("section.ini",
                 iniWith("", "") + "[map_multiBinElevationMap_00_insertOps]\nrange_sigma = 1\n");
    expectErrorMentioning([&] { mapsFromIniFile(p); },
                          {"section.ini", "map_multiBinElevationMap_00_insertOps"});
}

// The map's simplemap helpers skipped null keyframe parts silently (a map from part of the data).
TEST(OptionsMisuse, NullEntriesOfASimplemapAreErrorsBeforeAnythingIsInserted) {
    auto sf = mrpt::obs::CSensoryFrame::Create();
    sf->insert(floorScan());
    const auto pose = mrpt::poses::CPose3DPDFGaussian::Create(posePdf());
    for (int bad = 0; bad < 3; bad++) {
        mrpt::maps::CSimpleMap sm;
        sm.insert(pose, sf);
        auto badSf = mrpt::obs::CSensoryFrame::Create();
        if (bad == 2) badSf->insert(mrpt::obs::CObservation::Ptr());
        sm.insert(bad == 0 ? mrpt::poses::CPose3DPDF::Ptr() : pose,
                  bad == 1 ? mrpt::obs::CSensoryFrame::Ptr() : badSf);
        Map map;
        const auto before = serialize(map);
        expectErrorMentioning([&] { map.insertSimpleMapWithPosePdfs(sm); }, {"keyframe 1"});
        EXPECT_EQ(serialize(map), before);
    }
}

// Keys carry their unit (local_size_m beside local_resolution before): the suffixed names are
// read and written; the old names stay as aliases, so shipped and users' ini files keep working.
TEST(OptionsMisuse, OldKeyNamesAreAliasesOfTheUnitSuffixedOnesAndBothIsAnError) {
    const auto load = [](const std::string& creation, const std::string& insertion) {
        mrpt::config::CConfigFileMemory ini("[c]\n" + creation + "\n[i]\n" + insertion + "\n");
        Map::TCreationOptions c;
        Map::TInsertionOptions o;
        c.loadFromConfigFile(ini, "c");
        o.loadFromConfigFile(ini, "i");
        return std::pair{c, o};
    };
    const auto [cOld, iOld] = load("resolution = 0.03\nlocal_resolution = 0.02\nmin_x = -2",
                                   "range_sigma = 0.02\nrobot_pose_max_dt = 0.2");
    const auto [cNew, iNew] = load("resolution_m = 0.03\nlocal_resolution_m = 0.02\nmin_x_m = -2",
                                   "range_sigma_m = 0.02\nrobot_pose_max_dt_s = 0.2");
    EXPECT_EQ(cOld.resolution_m, 0.03);
    EXPECT_EQ(cNew.resolution_m, 0.03);
    EXPECT_EQ(cOld.local_resolution_m, cNew.local_resolution_m);
    EXPECT_EQ(cOld.min_x, cNew.min_x);
    EXPECT_EQ(iOld.range_sigma_m, iNew.range_sigma_m);
    EXPECT_EQ(iOld.robot_pose_max_dt_s, iNew.robot_pose_max_dt_s);
    expectErrorMentioning([&] { load("resolution = 0.03\nresolution_m = 0.03", ""); },
                          {"resolution_m", "old name 'resolution'"});
    // Saved options use the suffixed names.
    mrpt::config::CConfigFileMemory out;
    cNew.saveToConfigFile(out, "c");
    EXPECT_TRUE(out.keyExists("c", "resolution_m"));
    EXPECT_FALSE(out.keyExists("c", "resolution"));
}
