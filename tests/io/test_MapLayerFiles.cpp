/* Part of the multibin elevation-mapping library's tests: the layers read once and kept sparse
 * (knownLayers(), MapLayerFiles.h) against the layers read from the map tile by tile, and the 3D
 * scene coded by runs (RunDeflate.h) as MRPT reads it. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "../common/byte_streams.h"
#include "multibin/io/MapLayerFiles.h"
#include "multibin/io/OutputFile.h"
#include "multibin/io/RunDeflate.h"
#include "route_map.h"

namespace {

using multibin::CellWindow;
using multibin::EsriAsciiGrid;
using multibin::MapLayer;

/** Bit for bit, NaN where the other is NaN. */
void expectSameSamples(const EsriAsciiGrid& a, const EsriAsciiGrid& b, const std::string& what) {
    ASSERT_EQ(a.rows(), b.rows()) << what;
    ASSERT_EQ(a.cols(), b.cols()) << what;
    EXPECT_EQ(a.xllcenter_m, b.xllcenter_m) << what;
    EXPECT_EQ(a.yllcenter_m, b.yllcenter_m) << what;
    size_t differing = 0, known = 0;
    for (Eigen::Index i = 0; i < a.heights_m.size(); i++) {
        const float x = a.heights_m.data()[i], y = b.heights_m.data()[i];
        known += std::isfinite(x);
        differing += !(std::isnan(x) && std::isnan(y)) && std::memcmp(&x, &y, 4) != 0;
    }
    EXPECT_EQ(differing, 0u) << what << " (" << known << " known)";
}

const std::vector<MapLayer> kLayers{MapLayer::Height, MapLayer::Sigma, MapLayer::Source};

}  // namespace

// The sparse layers give what the map gives: every tile's samples and a window across tiles
// bit for bit, the same tiles and known box, and block reductions (running means, so the order
// of the samples counts) equal at factors 1 to 3, on a 30 m route whose heights vary per cell.
TEST(KnownLayers, SamplesBoxAndBlockReductionsAreTheMapsBitForBit) {
    const auto map = route_map::routeMap(30.0);
    const auto known = multibin::knownLayers(*map, kLayers);
    const auto read = multibin::tiledLayers(*map, kLayers);
    ASSERT_EQ(known.size(), 3u);
    ASSERT_GT(read[0].tiles.size(), 3u);
    const CellWindow box = read[0].knownCells();
    ASSERT_GT(box.cellCount(), 10000u);
    EXPECT_EQ(known[0].knownCells(), box);
    for (size_t k = 0; k < kLayers.size(); k++) {
        EXPECT_EQ(known[k].tiles, read[k].tiles);
        EXPECT_EQ(known[k].originX_m, read[k].originX_m);
        for (const CellWindow& t : read[k].tiles)
            expectSameSamples(known[k].samples(t), read[k].samples(t), "a tile");
        const CellWindow across{box.ix0 + 100, box.iy0 + 100, 300, 280};  // 2 x 2 tiles or more
        expectSameSamples(known[k].samples(across), read[k].samples(across), "across tiles");
    }
    for (const int factor : {1, 2, 3}) {
        const std::vector<multibin::BlockReduce> how{
            multibin::BlockReduce::Mean, multibin::BlockReduce::Max, multibin::BlockReduce::Max};
        const auto a = multibin::blockReduced(known, box, factor, how);
        const auto b = multibin::blockReduced(read, box, factor, how);
        for (size_t k = 0; k < a.size(); k++)
            expectSameSamples(a[k], b[k], "block of " + std::to_string(factor));
    }
}

// The 3D scene written as the mapper writes it (serialized, then gzip coded by its runs) loads
// with MRPT's CFileGZInputStream into the same objects: serialized again, the same bytes. The
// view from the sparse layers is the view the map builds from its own read.
TEST(KnownLayers, TheSceneCodedByRunsLoadsIntoTheSameObjects) {
    const auto map = route_map::routeMap(20.0);
    const auto known = multibin::knownLayers(*map, kLayers);
    mrpt::opengl::COpenGLScene scene, fromMap;
    auto view = mrpt::opengl::CSetOfObjects::Create(), own = mrpt::opengl::CSetOfObjects::Create();
    multibin::buildTerrainView(known[0], known[0], map->mapOrigin(),
                               multibin::SceneColouring::Height, *view);
    multibin::buildTerrainView(*map, multibin::SceneColouring::Height, *own);
    ASSERT_GT(view->size(), 3u);
    scene.insert(view);
    fromMap.insert(own);
    const std::vector<uint8_t> bytes = test_bytes::serialized(scene);
    EXPECT_EQ(test_bytes::serialized(fromMap), bytes);

    // Loaded with MRPT's reader, the file gives what MRPT's own file of the scene
    // (COpenGLScene::saveToFile) gives: the same objects, serialized again to the same bytes.
    EXPECT_EQ(test_bytes::inflated(multibin::runDeflateGzip(bytes.data(), bytes.size(), 4),
                                   bytes.size(), 15 + 16),
              bytes);
    const std::filesystem::path dir(MULTIBIN_BINARY_DIR);
    const std::string ours = (dir / "test_map_layer_files_runs.3Dscene").string(),
                      mrpts = (dir / "test_map_layer_files_mrpt.3Dscene").string();
    multibin::writeFileAtomically(ours, multibin::runDeflateGzip(bytes.data(), bytes.size(), 4));
    ASSERT_TRUE(scene.saveToFile(mrpts));
    const auto load = [](const std::string& file) {
        auto s = std::make_shared<mrpt::opengl::COpenGLScene>();
        mrpt::io::CFileGZInputStream in(file);
        auto arch = mrpt::serialization::archiveFrom(in);
        arch >> *s;
        return s;
    };
    const auto back = load(ours), reference = load(mrpts);
    EXPECT_EQ(back->getViewport()->size(), scene.getViewport()->size());
    EXPECT_EQ(test_bytes::serialized(*back), test_bytes::serialized(*reference));
}
