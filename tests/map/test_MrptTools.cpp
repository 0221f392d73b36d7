/* The map inside MRPT's stock programs: observations2map with the library preloaded. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "../common/test_scenes.h"

namespace fs = std::filesystem;

namespace {
/** A simplemap of a pitched laser walking over a floor, each keyframe with its pose PDF. */
void writeFloorSimplemap(const std::string& path) {
    mrpt::maps::CSimpleMap sm;
    for (int k = 0; k < 10; k++) {
        mrpt::poses::CPose3DPDFGaussian pdf;
        pdf.mean = mrpt::poses::CPose3D(0.05 * k, 0, 0, 0, 0, 0);
        pdf.cov.setIdentity();
        pdf.cov *= 1e-6;
        mrpt::obs::CSensoryFrame sf;
        sf.insert(test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0)));
        sm.insert(pdf, sf);
    }
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    arch << sm;
}

std::vector<std::string> filesWithPrefix(const fs::path& dir, const std::string& prefix) {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind(prefix, 0) == 0)
            out.push_back(e.path().filename().string());
    return out;
}
}  // namespace

TEST(MrptTools, Observations2mapBuildsTheMapWithTheLibraryPreloaded) {
    const fs::path dir = fs::path(MULTIBIN_BINARY_DIR) / "test_observations2map";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string sm = (dir / "floor.simplemap").string();
    writeFloorSimplemap(sm);
    const fs::path ini = fs::path(MULTIBIN_SOURCE_DIR) / "ini" / "observations2map.ini";
    ASSERT_TRUE(fs::exists(ini)) << ini;

    auto run = [&](const std::string& prefix, bool preload) {
        const std::string cmd =
            std::string(preload ? "LD_PRELOAD=" MULTIBIN_LIBRARY_FILE " " : "") +
            "observations2map " + ini.string() + " " + sm + " " + (dir / prefix).string() +
            " < /dev/null > " + (dir / (prefix + ".log")).string() + " 2>&1";
        return std::system(cmd.c_str());
    };
    EXPECT_EQ(run("with", true), 0);
    const auto made = filesWithPrefix(dir, "with_mrpt__maps__CMultiBinElevationMap_00");
    EXPECT_FALSE(made.empty()) << "see " << (dir / "with.log");
    EXPECT_TRUE(fs::exists(dir / "with_mrpt__maps__CMultiBinElevationMap_00_height.png"));
    EXPECT_TRUE(fs::exists(dir / "with_mrpt__maps__CMultiBinElevationMap_00.3Dscene"));

    // Without the preload MRPT skips the unknown *_count key without a word: no map at all.
    run("without", false);
    EXPECT_TRUE(filesWithPrefix(dir, "without_mrpt__maps__CMultiBinElevationMap").empty());
}
