/* Tiled gap filling (fill::fillSparse, multibin/fill/SparseFill.h) against the whole-window
 * raster path (fill::fillGaps): the same heights, sigmas and sources bit for bit, on the shipped
 * mock-up and walk maps, on random scenes and on two data patches far apart; and its work follows
 * the data: two patches 300 m apart cost twice one patch, not the window between them. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "RandomScene.h"
#include "Scenario.h"
#include "SurfaceTexture.h"
#include "multibin/fill/GapFilling.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/grid/CellSurface.h"
#include "multibin/map/MapInternals.h"

using multibin::CellWindow;
using multibin::HeightSource;
using multibin::fill::FillOptions;
using multibin::fill::FillResult;
using multibin::fill::SparseHeights;

namespace {

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/** Both paths on `in`: every cell's height, sigma and source bit for bit, and the per-gap
 * statistics in the same order. Returns the number of filled cells. */
size_t expectSameFill(const SparseHeights& in, const FillOptions& o, const std::string& what) {
    const FillResult dense = multibin::fill::fillGaps(in.toRaster(in.lattice.window), o);
    const multibin::fill::FilledCells sparse = multibin::fill::fillSparse(in, o);
    const FillResult fromSparse = sparse.toResult(in);
    EXPECT_EQ(fromSparse.source.size(), dense.source.size()) << what;
    size_t differ = 0, filled = 0;
    for (size_t k = 0; k < dense.source.size() && k < fromSparse.source.size(); k++) {
        filled += dense.isFilled(k);
        differ += dense.source[k] != fromSparse.source[k] ||
                  !sameBits(dense.height_m[k], fromSparse.height_m[k]) ||
                  !sameBits(dense.sigma_m[k], fromSparse.sigma_m[k]);
    }
    EXPECT_EQ(differ, 0u) << what << ": cells that differ of " << dense.source.size();
    const auto &a = dense.stats, &b = sparse.stats;
    EXPECT_EQ(a.measured, b.measured) << what;
    EXPECT_EQ(a.median, b.median) << what;
    EXPECT_EQ(a.gaussian, b.gaussian) << what;
    EXPECT_EQ(a.harmonic, b.harmonic) << what;
    EXPECT_EQ(a.unfilled, b.unfilled) << what;
    EXPECT_EQ(a.supportAreas, b.supportAreas) << what;
    EXPECT_EQ(a.termsChosen, b.termsChosen) << what;
    EXPECT_EQ(a.movingNeighbourhoods, b.movingNeighbourhoods) << what;
    EXPECT_EQ(a.rimCheckTerms, b.rimCheckTerms) << what;
    EXPECT_EQ(a.shadowGaps, b.shadowGaps) << what;
    EXPECT_EQ(a.shadowCells, b.shadowCells) << what;
    return filled;
}

/** A shipped scenario's map (its ini, its simplemap), with the dual grid if asked. */
void mapScenario(const std::string& scenario, mrpt::maps::CMultiBinElevationMap& map,
                 bool dualGrid = false) {
    const std::string dir = MULTIBIN_SOURCE_DIR;
    mrpt::config::CConfigFile ini(dir + "/ini/" + scenario + ".ini");
    const std::string prefix = "MappingApplication_multiBinElevationMap_00_";
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, prefix + "creationOpts");
    creation.dual_grid = dualGrid;
    map.setCreationOptions(creation);
    map.insertionOptions.loadFromConfigFile(ini, prefix + "insertOpts");
    mrpt::maps::CSimpleMap sm;
    mrpt::io::CFileGZInputStream f(dir + "/rawlogs/" + scenario + ".simplemap");
    mrpt::serialization::archiveFrom(f) >> sm;
    map.insertSimpleMapWithPosePdfs(sm);
}

/** A rough surface [m]: a few bumps and a 12 cm step, so that gaps go to every path. */
float surface(int ix, int iy) {
    const double x = ix * 0.02, y = iy * 0.02;
    return float(0.05 * std::sin(3 * x) * std::cos(2 * y) + (std::fmod(x, 2.0) > 1.2 ? 0.12 : 0));
}

/** A patch of w x h measured cells at (ix0, iy0) with holes drawn from `seed`: single cells, blobs
 * of up to ~800 cells, and one hole larger than maxGapCells; the same patch wherever it lies. */
void addPatch(SparseHeights& in, int ix0, int iy0, int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<char> hole(size_t(w) * size_t(h), 0);
    std::uniform_int_distribution<int> px(0, w - 1), py(0, h - 1);
    for (int k = 0; k < 60; k++) hole[size_t(py(rng)) * size_t(w) + size_t(px(rng))] = 1;
    for (int k = 0; k < 8; k++) {
        const int cx = px(rng), cy = py(rng), r = 2 + int(rng() % 15);
        for (int y = std::max(cy - r, 0); y < std::min(cy + r, h); y++)
            for (int x = std::max(cx - r, 0); x < std::min(cx + r, w); x++)
                if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r) hole[size_t(y) * w + x] = 1;
    }
    for (int y = h / 3; y < h / 3 + 60 && y < h; y++)  // larger than maxGapCells: stays Unknown
        for (int x = w / 4; x < w / 4 + 60 && x < w; x++) hole[size_t(y) * w + x] = 1;
    std::normal_distribution<float> noise(0, 0.004f);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            // The border stays measured: the patch's gaps are its own wherever it lies.
            const bool border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            if (border || !hole[size_t(y) * w + x])
                in.setMeasured(ix0 + x, iy0 + y, surface(x, y) + noise(rng),
                               0.004f + 0.002f * float(rng() % 4));
        }
}

SparseHeights patches(const CellWindow& window, const std::vector<std::array<int, 2>>& at,
                      unsigned seed) {
    SparseHeights in;
    in.lattice = multibin::Lattice{0.02, window};
    for (const auto& p : at) addPatch(in, p[0], p[1], 160, 120, seed);
    return in;
}

}  // namespace

TEST(SparseFill, SameAsTheWholeWindowOnTheShippedMockupAndWalkMaps) {
    for (const std::string scenario : {"mockup", "walk"}) {
        mrpt::maps::CMultiBinElevationMap map;
        mapScenario(scenario, map);
        const SparseHeights in = map.fillInput();
        const size_t filled = expectSameFill(in, map.insertionOptions.fill, scenario);
        EXPECT_GT(filled, 1000u) << scenario;
        // The map's own fill is the tiled one, and lastFill() its raster.
        map.dem_update_map();
        const FillResult dense =
            multibin::fill::fillGaps(in.toRaster(in.lattice.window), map.insertionOptions.fill);
        ASSERT_EQ(multibin::MapInternals::lastFill(map).source, dense.source) << scenario;
    }
}

TEST(SparseFill, FillInputHoldsEveryMeasuredCellOfTheWindowWithOneGridOrTwo) {
    // Every cell of the window queried as the whole-window fill did (the cell surface without
    // the shared pose part): the tiled input holds exactly the measured ones, the same bits.
    for (const bool dual : {false, true}) {
        mrpt::maps::CMultiBinElevationMap map;
        mapScenario("mockup", map, dual);
        const SparseHeights in = map.fillInput();
        const multibin::BinGrid& g = multibin::MapInternals::grid(map);
        const CellWindow& w = g.window();
        ASSERT_EQ(in.lattice.window, w);
        size_t measured = 0, differ = 0;
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
                multibin::CellSurface c;
                const bool known = multibin::surfaceAt(
                    g, dual ? &multibin::MapInternals::localGrid(map) : nullptr, g.cellCenter_m(ix),
                    g.cellCenter_m(iy), map.binUpdateParams(),
                    map.insertionOptions.query.relief_sigma, c);
                measured += known;
                const auto& m = in.cells.get(ix, iy);
                differ += known != in.isMeasured(ix, iy) ||
                          (known && (!sameBits(m.height_m, float(c.height_m)) ||
                                     !sameBits(m.sigma_m, float(std::sqrt(c.variance_m2)))));
            }
        EXPECT_GT(measured, 1000u) << dual;  // the dual grid's global cells are 5 cm
        EXPECT_EQ(differ, 0u) << "dual grid " << dual;
        expectSameFill(in, map.insertionOptions.fill, dual ? "mockup, dual grid" : "mockup");
    }
}

TEST(SparseFill, SameAsTheWholeWindowOnRandomScenes) {
    terrain_sim::RandomSceneOptions pool;
    for (const std::string b : {"AC", "CC", "CD"}) {
        pool.boardNames.push_back(b);
        pool.boards.push_back(multibin::EsriAsciiGrid::load(
            std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/terrain/littledog/" + b + ".asc"));
    }
    for (uint64_t seed : {5u, 11u, 23u}) {
        pool.seed = seed;
        const terrain_sim::RandomScene sc = terrain_sim::makeRandomScene(pool);
        mrpt::maps::CMultiBinElevationMap map;
        for (size_t p = 0; p < sc.passes.size(); ++p) {
            const terrain_sim::Terrain seen = sc.seenIn(p);
            const terrain_sim::SurfaceTexture texture(seen, sc.seed, sc.darkPatches);
            const terrain_sim::LaserSim laser(sc.laser, seen, texture, sc.seed);
            std::mt19937_64 rng(seed * 1000003 + p);
            for (const terrain_sim::Frame& f : sc.passes[p].frames)
                map.insertObservation(
                    *laser.scan(f.truth, terrain_sim::syntheticStamp(f.t_s + 100.0 * p), rng),
                    f.estimate);
        }
        const size_t filled = expectSameFill(map.fillInput(), map.insertionOptions.fill,
                                             "random scene " + std::to_string(seed));
        EXPECT_GT(filled, 100u) << seed;
    }
}

TEST(SparseFill, SameAsTheWholeWindowOnSyntheticPatchesAndAtTheWindowsEdge) {
    // Patches touching the window's edges: the per-gap rasters are clipped as the whole one is.
    const CellWindow w{-40, 10, 400, 300};
    for (unsigned seed : {1u, 2u, 3u}) {
        const SparseHeights in = patches(w, {{-40, 10}, {200, 180}, {80, 60}}, seed);
        EXPECT_GT(expectSameFill(in, FillOptions{}, "patches " + std::to_string(seed)), 1000u);
    }
    FillOptions repeatedMedian;  // the fallback path
    repeatedMedian.gaussianEnabled = false;
    expectSameFill(patches(w, {{0, 40}}, 4), repeatedMedian, "repeated median");
    FillOptions off;
    off.enabled = false;
    EXPECT_EQ(expectSameFill(patches(w, {{0, 40}}, 4), off, "filling off"), 0u);
}

TEST(SparseFill, TwoPatchesFarApartCostTwoPatchesNotTheWindowBetween) {
    // 300 m apart at 2 cm: a window of 15 160 x 120 cells, 1.8 M, nearly all empty.
    const int apart_cells = 15000;
    const SparseHeights one = patches(CellWindow{0, 0, 160, 120}, {{0, 0}}, 7);
    const SparseHeights two =
        patches(CellWindow{0, 0, apart_cells + 160, 120}, {{0, 0}, {apart_cells, 0}}, 7);
    const FillOptions o;
    const size_t filledOne = expectSameFill(one, o, "one patch");
    const size_t filledTwo = expectSameFill(two, o, "two patches");
    EXPECT_GT(filledOne, 1000u);
    EXPECT_EQ(filledTwo, 2 * filledOne) << "the far patch is filled as the near one";
    const auto a = multibin::fill::fillSparse(one, o), b = multibin::fill::fillSparse(two, o);
    // The gap search and the per-gap rasters: twice one patch plus the floods of the empty
    // region from each patch's side (a few of up to maxGapCells + 1 cells each), far below the
    // 1.8 M cells between.
    EXPECT_LE(b.stats.cellsVisited, 2 * a.stats.cellsVisited + 6 * size_t(o.maxGapCells))
        << a.stats.cellsVisited;
    EXPECT_LT(b.stats.cellsVisited, two.lattice.cellCount() / 20);
    // Memory follows the filled cells: tiles of the result near the two patches only.
    EXPECT_LE(b.cells.tileCount(), 2 * a.cells.tileCount() + 2);
}
