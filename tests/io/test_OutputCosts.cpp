/* Part of the multibin elevation-mapping library's tests: what the cheaper outputs and fill must
 * keep (the map file's checksum is MRPT's CRC-32, the fill's gaps are those of the whole-window
 * path) and the cost they must not exceed (the cells a flood reads beside a wall); the occupied
 * tiles found from the store's slots. */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/crc.h>

#include <cmath>
#include <cstring>
#include <set>
#include <utility>
#include <vector>

#include "../common/byte_streams.h"
#include "multibin/fill/GapFilling.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/io/TiledRaster.h"
#include "multibin/map/MapInternals.h"
#include "route_map.h"

namespace {

using multibin::CellWindow;
using multibin::fill::FillOptions;
using multibin::fill::SparseHeights;

}  // namespace

// The file wraps its payload as uint64 length, payload, uint32 CRC-32, then MRPT's end marker
// byte. The CRC must be the value MRPT's compute_CRC32 gives (files written by older builds must
// load, and files written now must load in older builds): a plain CRC-32 (zlib's or libdeflate's,
// register inverted on entry and exit) would differ on every payload.
TEST(SerializedMapFile, TheChecksumIsMrptsCrc32OfThePayload) {
    const auto map = route_map::routeMap(10.0);
    const std::vector<uint8_t> bytes = test_bytes::serialized(*map);
    ASSERT_GT(bytes.size(), 64u);
    const size_t end = bytes.size() - 1 - 4;  // the payload's end: before the CRC and the marker
    // The length field: 8 bytes that give the distance to `end` (found from the front).
    size_t start = 0;
    for (size_t p = 0; p + 8 <= end && start == 0; p++) {
        uint64_t n = 0;
        std::memcpy(&n, bytes.data() + p, 8);
        if (n > 0 && n == end - (p + 8)) start = p + 8;
    }
    ASSERT_GT(start, 0u) << "no payload length found";
    uint32_t stored = 0;
    std::memcpy(&stored, bytes.data() + end, 4);
    EXPECT_EQ(stored, mrpt::system::compute_CRC32(bytes.data() + start, end - start));
    EXPECT_GT(end - start, 10000u);  // the map's bins, not an empty payload
    // And it reads back: the checksum is checked before anything is parsed.
    mrpt::io::CMemoryStream mem;
    mem.assignMemoryNotOwn(bytes.data(), bytes.size());
    auto arch = mrpt::serialization::archiveFrom(mem);
    mrpt::maps::CMultiBinElevationMap back;
    arch >> back;
    const auto bins = multibin::MapInternals::grid(*map).binCount();
    EXPECT_GT(bins, 0u);
    EXPECT_EQ(multibin::MapInternals::grid(back).binCount(), bins);
}

// A wall of measured cells along the first row of a tile row, across a window of 8 x 8 tiles:
// south of it every tile is without data, so each flood from the wall's south side enters such a
// tile at once and stops as large. Before, the first flood on that side read maxGapCells (2500)
// cells and the next ones the cells up to that blob: 6383 cells in all; now 3590 (the
// north side, inside the wall's tiles, floods as before). The fill is the whole-window path's.
TEST(SparseFillCost, AFloodIntoATileWithoutDataStopsAtOnce) {
    constexpr int kSide = 512, kWallRow = 256;  // 256: the first row of tile row 4
    SparseHeights in;
    in.lattice = multibin::Lattice{0.05, CellWindow{0, 0, kSide, kSide}};
    for (int ix = 0; ix < kSide; ix++) in.setMeasured(ix, kWallRow, 1.0f, 0.01f);
    // A small hole in the wall (3 cells): the one gap, filled from the wall's cells.
    in.setMeasured(100, kWallRow + 1, 1.0f, 0.01f);
    in.setMeasured(102, kWallRow + 1, 1.0f, 0.01f);
    in.setMeasured(100, kWallRow + 2, 1.0f, 0.01f);
    in.setMeasured(101, kWallRow + 2, 1.0f, 0.01f);
    in.setMeasured(102, kWallRow + 2, 1.0f, 0.01f);
    const FillOptions o;
    ASSERT_EQ(o.maxGapCells, 2500);
    const multibin::fill::FilledCells sparse = multibin::fill::fillSparse(in, o);
    const multibin::fill::FillResult whole =
        multibin::fill::fillGaps(in.toRaster(in.lattice.window), o);
    // The same cells filled with the same values.
    size_t filled = 0;
    for (int iy = 0; iy < kSide; iy++)
        for (int ix = 0; ix < kSide; ix++) {
            const size_t k = whole.index(ix, iy);
            const multibin::fill::FilledCell* f = sparse.find(ix, iy);
            ASSERT_EQ(f != nullptr && f->source != multibin::HeightSource::Unknown,
                      whole.isFilled(k))
                << ix << ", " << iy;
            if (!f || !whole.isFilled(k)) continue;
            EXPECT_EQ(f->height_m, whole.height_m[k]);
            EXPECT_EQ(f->sigma_m, whole.sigma_m[k]);
            filled++;
        }
    EXPECT_EQ(filled, 1u);
    // The cost: the wall's south side no longer floods maxGapCells cells.
    EXPECT_LT(sparse.stats.cellsVisited, 2 * size_t(o.maxGapCells)) << sparse.stats.cellsVisited;
}

// occupiedTiles() finds a store tile's corner from its first slot holding a bin when the tiles
// asked for are whole store tiles (64, 256 cells a side), and from every stored bin otherwise
// (100): each against the tiles of every stored bin, on patches west and south of the origin,
// and one cell in a tile's last slot.
TEST(OccupiedTiles, AreTheTilesOfTheStoredBinsAtEveryTileSide) {
    mrpt::maps::CMultiBinElevationMap map;
    map.creationOptions.resolution_m = 0.05;
    map.creationOptions.origin_auto = false;
    map.setCreationOptions(map.creationOptions);
    for (const auto& [x_m, y_m] : std::vector<std::pair<double, double>>{
             {-7.3, -0.2}, {0.02, 0.02}, {3.175, 3.175}, {12.9, -15.1}, {-0.01, 9.6}})
        for (int k = 0; k < 5; k++) map.insertIndividualPoint(x_m + 0.05 * k, y_m, 0.1 * k);
    // A bin in the last slot of the tile of cells [64, 128): cell (127, 127).
    map.insertIndividualPoint(127.5 * 0.05, 127.5 * 0.05, 0.5);
    const multibin::BinStore& store = multibin::MapInternals::grid(map).store();
    for (const int side : {64, 256, 100}) {
        std::set<std::pair<int, int>> expected;  // (iy0, ix0)
        store.forEachStoredBin([&](int ix, int iy, const multibin::Bin&) {
            const CellWindow t = multibin::tileOfCell(ix, iy, side);
            expected.emplace(t.iy0, t.ix0);
        });
        std::vector<std::pair<int, int>> got;
        for (const CellWindow& t : map.occupiedTiles(side)) {
            EXPECT_EQ(t.nx, side);
            EXPECT_EQ(t.ny, side);
            got.emplace_back(t.iy0, t.ix0);
        }
        const std::vector<std::pair<int, int>> want(expected.begin(), expected.end());
        EXPECT_EQ(got, want) << "tiles of " << side << " cells";
        EXPECT_GE(got.size(), 4u);  // the patches lie in several tiles
    }
}
