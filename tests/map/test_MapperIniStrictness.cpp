/* ini strictness, third round (issue 37, kind 5): what MRPT's reader merges or accepts silently
 * and the map must not: a key or section given twice in different case, hexadecimal numbers,
 * values beyond any physical meaning, a list naming a label twice, a label cut at '#', the map
 * count given twice, another MRPT map type built at any size by the mapper. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/TMetricMapInitializer.h>

#include <sys/wait.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "../apps/mapper_run.h"
#include "../common/reliability_helpers.h"
#include "multibin/io/ErrorMessage.h"

using namespace reliability;

namespace {

const char* const kCreation = "map_multiBinElevationMap_00_creationOpts";
const char* const kInsertion = "map_multiBinElevationMap_00_insertOpts";

/** The ini of one map with `creation` and `insertion` lines (and `parent` lines in [map]). */
std::string ini(const std::string& creation, const std::string& insertion = "",
                const std::string& parent = "multiBinElevationMap_count = 1\n") {
    return "[map]\n" + parent + "[" + kCreation + "]\n" + creation + "[" + kInsertion + "]\n" +
           insertion;
}

/** Builds the maps of ini file text `text` as observations2map and the mapper do (from a file:
 * MRPT's in-memory ini gives back its text with duplicates already merged). */
void mapsOf(const std::string& text) {
    // A file per test: ctest runs this program's tests side by side.
    const std::filesystem::path file =
        scratchDir("ini_strictness") /
        (std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".ini");
    std::ofstream(file) << text;
    mrpt::config::CConfigFile c(file.string());
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(c, "map");
    mrpt::maps::CMultiMetricMap maps(inits);
}

/** Building the maps of `text` throws; the one-line message holds every word. */
void expectRefused(const std::string& text, const std::vector<std::string>& words) {
    SCOPED_TRACE(text);
    try {
        mapsOf(text);
        ADD_FAILURE() << "accepted";
    } catch (const std::exception& e) {
        const std::string msg = multibin::oneLineMessage(e);
        for (const std::string& w : words)
            EXPECT_NE(msg.find(w), std::string::npos) << "'" << w << "' not in: " << msg;
    }
}

}  // namespace

// MRPT's reader ignores case: the second spelling silently won.
TEST(IniStrictness, AKeyOrSectionGivenTwiceInDifferentCaseIsAnError) {
    expectRefused(ini("resolution_m = 0.02\nRESOLUTION_M = 0.05\n"),
                  {kCreation, "RESOLUTION_M", "more than once"});
    expectRefused(ini("resolution_m = 0.02\n") + "[" + kCreation + "]\n" + "Resolution_M = 0.05\n",
                  {"Resolution_M", "more than once"});
    std::string upper = kCreation;
    for (char& ch : upper) ch = char(std::toupper(static_cast<unsigned char>(ch)));
    expectRefused(ini("bin_height_m = 0.05\n") + "[" + upper + "]\nbin_height_m = 0.1\n",
                  {"bin_height_m", "more than once"});
}

// strtod took hexadecimal and hex-float numbers.
TEST(IniStrictness, HexadecimalAndHexFloatNumbersAreErrors) {
    expectRefused(ini("resolution_m = 0x1p-4\n"), {"resolution_m", "0x1p-4"});
    expectRefused(ini("bin_height_m = 0x10\n"), {"bin_height_m", "0x10"});
    expectRefused(ini("", "default_pose_sigmas = 0x1 0 0 0 0 0\n"), {"default_pose_sigmas"});
    expectRefused(ini("", "laser_agc = LASER:0x2\n"), {"laser_agc", "0x2"});
}

// Finite but meaningless values produced empty or invalid rasters with exit code 0.
TEST(IniStrictness, ValuesBeyondAnyPhysicalMeaningAreErrors) {
    expectRefused(ini("resolution_m = 1e308\n"), {"resolution_m", "from 0.0001 to 1000"});
    expectRefused(ini("", "height_sigma_floor_m = 1e160\n"), {"height_sigma_floor_m", "at most"});
    expectRefused(ini("", "max_range_m = 1e300\n"), {"max_range_m", "at most"});
}

// A list naming a label twice kept one of its meanings.
TEST(IniStrictness, AListNamingALabelTwiceIsAnError) {
    expectRefused(ini("", "sensor_labels = LASER,STEREO,LASER\n"), {"sensor_labels", "LASER"});
    expectRefused(ini("", "sensor_models = CAM:depth,CAM:lidar\n"), {"sensor_models", "CAM"});
    expectRefused(ini("", "laser_agc = LASER:1,LASER:2\n"), {"laser_agc", "LASER"});
}

// A '#' inside a label cut it: "cam#2" became "cam". A comment starts after a blank.
TEST(IniStrictness, ALabelHoldingAHashIsKeptWhole) {
    mrpt::config::CConfigFileMemory c(
        ini("", "sensor_models = cam#2:depth, LASER:laser   # a comment\n"));
    Map::TInsertionOptions o;
    o.loadFromConfigFile(c, kInsertion);
    EXPECT_EQ(o.sensors.modelByLabel.count("cam#2"), 1u);
    EXPECT_EQ(o.sensors.modelByLabel.count("cam"), 0u);
    EXPECT_EQ(o.sensors.modelByLabel.size(), 2u);
    mrpt::config::CConfigFileMemory labels(ini("", "sensor_labels = A#1, B;2 ; a comment\n"));
    o.loadFromConfigFile(labels, kInsertion);
    EXPECT_EQ(o.sensor_labels, (std::vector<std::string>{"A#1", "B;2"}));
}

// The map count twice (in any case) silently took the last.
TEST(IniStrictness, TheMapCountGivenTwiceIsAnError) {
    expectRefused(ini("", "", "multiBinElevationMap_count = 1\nmultiBinElevationMap_count = 2\n"),
                  {"multiBinElevationMap_count", "more than once"});
    expectRefused(ini("", "", "multiBinElevationMap_count = 1\nMULTIBINELEVATIONMAP_COUNT = 1\n"),
                  {"MULTIBINELEVATIONMAP_COUNT", "more than once"});
}

#ifdef ELEVATION_MAPPER_EXE
// Another MRPT map type in the mapper's ini was built at any size (an occupancy grid of 3.5 GB),
// though the mapper never writes it: it is not built, and a note says so.
TEST(IniStrictness, TheMapperBuildsNoOtherMapType) {
    const auto dir = scratchDir("ini_other_maps");
    const std::filesystem::path src = MULTIBIN_SOURCE_DIR;
    std::string text = readAll(src / "rawlogs" / "mockup.ini");
    for (const auto& [count, section, body] :
         {std::tuple{"occupancyGrid_count=1", "occupancyGrid_00_creationOpts",
                     "min_x=-40000\nmax_x=40000\nmin_y=-40000\nmax_y=40000\nresolution=0.05\n"},
          std::tuple{"heightMap_count=1", "heightMap_00_creationOpts",
                     "min_x=-20000\nmax_x=20000\nmin_y=-20000\nmax_y=20000\nresolution=0.01\n"}}) {
        SCOPED_TRACE(count);
        std::string withOther = text;
        withOther.insert(withOther.find("multiBinElevationMap_count"), std::string(count) + "\n");
        withOther += std::string("\n[MappingApplication_") + section + "]\n" + body;
        std::ofstream(dir / "maps.ini") << withOther;
        const std::string cmd = std::string(kAddressSpaceLimit ? "ulimit -v 2000000; " : "") +
                                ELEVATION_MAPPER_EXE + " --config " + (dir / "maps.ini").string() +
                                " --rawlog " + mapper_run::mockupRawlogPrefix(20) +
                                " --outputs map --no-plots --out " + (dir / "out").string() +
                                " > " + (dir / "log.txt").string() + " 2>&1";
        const int status = std::system(("/bin/sh -c '" + cmd + "'").c_str());
        const std::string log = readAll(dir / "log.txt");
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;
        EXPECT_NE(log.find("1 other map(s) of [MappingApplication] not built"), std::string::npos)
            << log;
    }
}
#endif
