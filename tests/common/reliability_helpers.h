/* Helpers of the bad-input tests: a map with data in it, its content for "nothing lost"
 * comparisons, and synthetic observations. */
#pragma once

#include <gtest/gtest.h>
#include <mrpt/core/bits_math.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <string>
#include <tuple>
#include <vector>

#include "multibin/grid/BinGrid.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/map/MapInternals.h"
#include "multibin/sensors/StereoDisparity.h"
#include "test_files.h"
#include "test_scenes.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MULTIBIN_TEST_ASAN 1
#endif
#endif

namespace reliability {

/** Whether the memory-bomb tests limit the address space: not under ASan, which reserves
 * terabytes of shadow address space (the Release build tests the limit; ASan still sees every
 * allocation, and the read budget works the same through its allocator). */
#if defined(__SANITIZE_ADDRESS__) || defined(MULTIBIN_TEST_ASAN)
constexpr bool kAddressSpaceLimit = false;
#else
constexpr bool kAddressSpaceLimit = true;
#endif
/** The address-space limit of those tests [bytes]: 1 GB. */
constexpr uint64_t kAddressSpaceLimit_bytes = uint64_t(1) << 30;

/** An empty scratch directory build/test_reliability/NAME for a test's files. */
inline std::filesystem::path scratchDir(const std::string& name) {
    return test_files::scratchDir("test_reliability", name);
}

using test_files::readAll;

/** The shipped file's bytes, gz-decompressed if it is gz (rawlogs and simplemaps may be either). */
inline std::string plainBytes(const std::filesystem::path& p) {
    mrpt::io::CFileGZInputStream in(p.string());
    std::string out;
    char buf[65536];
    for (size_t n; (n = in.Read(buf, sizeof buf)) > 0;) out.append(buf, n);
    return out;
}

using Map = mrpt::maps::CMultiBinElevationMap;

/** The map's bytes as CArchive writes them (options and both grids). */
inline std::vector<uint8_t> serialize(const Map& map) {
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << map;
    const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
    return std::vector<uint8_t>(p, p + mem.getTotalBytesCount());
}

/** Reads serialized `bytes` into `map` through CArchive, as a program loads a map file (throws
 * what MRPT or the map throw). */
inline void deserializeInto(Map& map, const std::vector<uint8_t>& bytes) {
    mrpt::io::CMemoryStream mem;
    mem.assignMemoryNotOwn(bytes.data(), bytes.size());
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch >> map;
}

/** One bin with the cell it belongs to: (grid, ix, iy, index, height, variance, certainty). */
using BinRecord = std::tuple<int, int, int, int, float, float, float, uint32_t>;

/** Everything the map knows, independent of its window (which may legitimately grow): every bin
 * of every non-empty cell of both grids. */
inline std::vector<BinRecord> content(const Map& map) {
    std::vector<BinRecord> out;
    int gi = 0;
    for (const multibin::BinGrid* g :
         {&multibin::MapInternals::grid(map), &multibin::MapInternals::localGrid(map)}) {
        // Tile by tile: a window grown by a far pose is mostly empty.
        g->store().forEachStoredBin([&](int ix, int iy, const multibin::Bin& b) {
            out.emplace_back(gi, ix, iy, b.index, b.height_m, b.variance_m2, b.certainty,
                             b.pointCount);
        });
        gi++;
    }
    std::sort(out.begin(), out.end());
    return out;
}

/** A pitched URG-04LX-like scan of the floor z = 0 from 0.26 m (683 beams over 240 deg). */
inline mrpt::obs::CObservation2DRangeScan::Ptr floorScan(size_t beams = 683) {
    return test_scenes::pitchedScanOverFloor(0.26, mrpt::DEG2RAD(45.0), beams);
}

/** A robot pose PDF with a small diagonal covariance. */
inline mrpt::poses::CPose3DPDFGaussian posePdf(double x_m = 0, double y_m = 0) {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = mrpt::poses::CPose3D(x_m, y_m, 0, 0, 0, 0);
    pdf.cov.setZero();
    for (int i = 0; i < 3; i++) pdf.cov(i, i) = 1e-6;  // 1 mm
    for (int i = 3; i < 6; i++) pdf.cov(i, i) = 1e-6;  // 1 mrad
    return pdf;
}

/** Options of a map fixed to x, y in [-1, 1] m (no growth). */
inline Map::TCreationOptions fixedTwoMetreMap() {
    Map::TCreationOptions c;
    c.grow = false;
    c.min_x = -1, c.max_x = 1, c.min_y = -1, c.max_y = 1;
    return c;
}

/** A map holding other data than mapWithData(): what serialized maps are read into, so that a
 * read that changes it shows. */
inline Map mapWithOtherData() {
    Map map;
    map.insertObservation(*floorScan(200), posePdf(0.5, 0.5));
    return map;
}

/** A map that already holds a floor seen by one good scan. */
inline Map mapWithData(const Map::TCreationOptions& c = Map::TCreationOptions()) {
    Map map(c);
    map.insertObservation(*floorScan(), posePdf());
    return map;
}

/** A rectified 32 x 24 px stereo pair (fx = 300 px, 0.09 m baseline) with a disparity image of
 * w x h px, all 40 px. */
inline mrpt::obs::CObservationStereoImages::Ptr stereoPair(int w, int h) {
    auto obs = mrpt::obs::CObservationStereoImages::Create();
    obs->sensorLabel = "STEREO";
    for (auto* cam : {&obs->leftCamera, &obs->rightCamera}) {
        cam->ncols = 32;
        cam->nrows = 24;
        cam->setIntrinsicParamsFromValues(300, 300, 16, 12);
    }
    obs->rightCameraPose = mrpt::math::TPose3DQuat(0.09, 0, 0, 1, 0, 0, 0);
    // Camera looking down at the floor from 0.5 m (MRPT camera frame: +z forward).
    obs->cameraPose =
        mrpt::poses::CPose3DQuat(mrpt::poses::CPose3D(0, 0, 0.5, -M_PI / 2, 0, -M_PI)).asTPose();
    multibin::sensors::DisparityImage d(w, h);
    for (float& v : d.disparity_px) v = 40.f;  // 0.675 m away
    obs->imageDisparity = multibin::sensors::encodeDisparityImage(d);
    obs->hasImageDisparity = true;
    obs->hasImageRight = false;
    return obs;
}

/** f() throws a std::exception, and the one-line message a program shows
 * (multibin::oneLineMessage, which takes MRPT's "Message:" out of its exception wrapper) holds
 * every word of `words`. */
template <typename F>
void expectErrorMentioning(F&& f, const std::vector<std::string>& words) {
    try {
        f();
        ADD_FAILURE() << "no exception; expected one mentioning '" << words.front() << "'";
    } catch (const std::exception& e) {
        const std::string msg = multibin::oneLineMessage(e);
        for (const auto& w : words)
            EXPECT_NE(msg.find(w), std::string::npos)
                << "'" << w << "' not in: " << msg << "\nwhole: " << e.what();
    }
}

}  // namespace reliability
