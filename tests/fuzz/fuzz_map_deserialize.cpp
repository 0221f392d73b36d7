/* libFuzzer target: bytes -> CArchive >> CMultiBinElevationMap.
 * Properties: no crash, no sanitizer report; a stream that throws leaves the map as it was (or,
 * if only the end-of-object marker after a complete map was wrong, holds that map); a map that
 * loads has only valid bins and serializes and loads again to the same bytes. */
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/serialization/CArchive.h>

#include "fuzz_common.h"
#include "multibin/io/EsriAsciiGrid.h"

namespace {
/** A small map with data, the state every input is read over. */
const mrpt::maps::CMultiBinElevationMap& referenceMap() {
    static const mrpt::maps::CMultiBinElevationMap map = [] {
        mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
        c.grow = false;
        c.min_x = -0.5, c.max_x = 1.5, c.min_y = -0.5, c.max_y = 0.5;
        mrpt::maps::CMultiBinElevationMap m(c);
        multibin::PointsWithCov pts;
        for (int i = 0; i < 20; i++) {
            multibin::PointWithCov p;
            p.point_m = Eigen::Vector3f(0.05f * float(i), 0.02f * float(i % 5), 0.01f * float(i));
            p.cov_m2 = multibin::SymmetricCov3::fromMatrix(Eigen::Matrix3d::Identity() * 1e-4);
            pts.push_back(p);
        }
        m.insertPoints(pts);
        return m;
    }();
    return map;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    mrpt::maps::CMultiBinElevationMap map = referenceMap();
    static const std::vector<uint8_t> before = fuzz::serialize(referenceMap());
    mrpt::io::CMemoryStream mem;
    mem.assignMemoryNotOwn(data, size);
    auto arch = mrpt::serialization::archiveFrom(mem);
    try {
        arch >> map;
    } catch (const std::exception& e) {
        fuzz::debugRejected(e);
        // Unchanged, unless serializeFrom() read a whole map and only MRPT's end-of-object marker
        // after it was wrong (a version-0 stream has no trailer to check first): then the map
        // must hold that complete, valid map -- checked below like any loaded map.
        if (fuzz::serialize(map) == before) return 0;
    }
    fuzz::checkInvariants(map);
    double h, s;
    map.getHeight(0.1, 0.0, h, s);
    (void)map.toRaster(mrpt::maps::CMultiBinElevationMap::RasterLayer::Sigma);
    // What loaded must serialize and load again to the same bytes.
    const std::vector<uint8_t> once = fuzz::serialize(map);
    mrpt::maps::CMultiBinElevationMap again;
    mrpt::io::CMemoryStream mem2;
    mem2.assignMemoryNotOwn(once.data(), once.size());
    auto arch2 = mrpt::serialization::archiveFrom(mem2);
    arch2 >> again;
    if (fuzz::serialize(again) != once) fuzz::fail("serialize(load(serialize(x))) differs");
    return 0;
}
