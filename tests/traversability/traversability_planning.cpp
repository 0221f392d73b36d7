/* PlannerSimple2D on a mapped scenario's exported grid against the truth's grid
 * (doc/traversability.md, "Planning on the scoring boards"). Reads an elevation-mapper output
 * folder made with
 * --ground-truth, --eval-area and --outputs gridmap: elevation_traversability.gridmap.gz (the map's
 * grid, P(free) = 1 - P(untraversable), unknown 0.5) and eval_untraversable_truth.asc (the truth's
 * classes on the same lattice over the scored cells). Planning is confined to the scored cells
 * (every other cell an obstacle in both grids); pairs: multibin::planning::oppositeSidePairs.
 *
 * Usage: traversability_planning DIR GT.asc [PAIRS [SEED [P_MAX...]]]
 * One markdown row per P_MAX (the planner treats a cell as an obstacle where P(untraversable) >=
 * P_MAX: occupancyThreshold = 1 - P_MAX), then a row "lattice": the same pairs planned on the
 * truth's heights sampled at the cells' centres (GT.asc, the scenario's fine ground truth),
 * thresholded at the hexapod limits (the lattice's best, no map error). */
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "PlanningCheck.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/traversability/TraversabilityEvaluation.h"

using namespace multibin::planning;

namespace {
/** The truth's classes at the centre of each cell of `g` (nearest sample of the truth raster). */
TruthCells truthOnGrid(const mrpt::maps::COccupancyGridMap2D& g, const multibin::EsriAsciiGrid& t) {
    TruthCells out;
    out.nx = g.getSizeX(), out.ny = g.getSizeY();
    out.cls.assign(size_t(out.nx) * out.ny, -1);
    for (unsigned cy = 0; cy < out.ny; cy++)
        for (unsigned cx = 0; cx < out.nx; cx++) {
            const long c = std::lround((g.idx2x(cx) - t.xllcenter_m) / t.cellsize_m);
            const long r = std::lround((g.idx2y(cy) - t.yllcenter_m) / t.cellsize_m);
            if (c < 0 || r < 0 || c >= t.cols() || r >= t.rows()) continue;
            const float v = t.heights_m(int(r), int(c));
            if (std::isfinite(v)) out.cls[size_t(cy) * out.nx + cx] = v > 0.5f ? 1 : 0;
        }
    return out;
}
/** The truth's height at the centre of each cell of `g` (nearest sample), thresholded at the
 * hexapod limits (the options' defaults, no calibration, no uncertainty), as a grid with the
 * region of `truth`: what a map on this lattice without error would give. */
mrpt::maps::COccupancyGridMap2D latticeBestGrid(const mrpt::maps::COccupancyGridMap2D& g,
                                                const multibin::EsriAsciiGrid& gt,
                                                const TruthCells& truth) {
    multibin::Lattice lattice;
    lattice.cellSize_m = g.getResolution();
    lattice.window.ix0 = int(std::lround(g.idx2x(0) / lattice.cellSize_m - 0.5));
    lattice.window.iy0 = int(std::lround(g.idx2y(0) / lattice.cellSize_m - 0.5));
    lattice.window.nx = int(g.getSizeX()), lattice.window.ny = int(g.getSizeY());
    std::vector<float> h(lattice.cellCount(), NAN);
    for (int r = 0; r < lattice.ny(); r++)
        for (int c = 0; c < lattice.nx(); c++) {
            const long tc =
                std::lround((lattice.cellCenterX_m(c) - gt.xllcenter_m) / gt.cellsize_m);
            const long tr =
                std::lround((lattice.cellCenterY_m(r) - gt.yllcenter_m) / gt.cellsize_m);
            if (tc >= 0 && tr >= 0 && tc < gt.cols() && tr < gt.rows())
                h[lattice.index(c, r)] = gt.heights_m(int(tr), int(tc));
        }
    multibin::traversability::TraversabilityOptions o;
    o = o.uncalibrated();
    o.monte_carlo_draws = 0, o.use_bins = false;
    multibin::traversability::TraversabilityLayers t;
    multibin::traversability::computeLayers(multibin::traversability::cellHeightSamples(lattice, h),
                                            o, t);
    mrpt::maps::COccupancyGridMap2D out = g;
    for (unsigned cy = 0; cy < truth.ny; cy++)
        for (unsigned cx = 0; cx < truth.nx; cx++) {
            const float p = t.untraversable[lattice.index(int(cx), int(cy))];
            const bool free = truth.cls[size_t(cy) * truth.nx + cx] >= 0 && p == 0.f;
            out.setCell(int(cx), int(cy), free ? 1.f : 0.f);
        }
    return out;
}

/** The grid must be the evaluated layer on the truth's lattice: its P(free) against 1 - P of
 * eval_untraversable_multibin.asc at each cell's centre (a shifted lattice would show here).
 * Throws if more than 1 % of the cells known in both differ by more than MRPT's quantization. */
void checkSameLattice(const mrpt::maps::COccupancyGridMap2D& g, const multibin::EsriAsciiGrid& p) {
    size_t both = 0, differ = 0;
    for (unsigned cy = 0; cy < g.getSizeY(); cy++)
        for (unsigned cx = 0; cx < g.getSizeX(); cx++) {
            const long c = std::lround((g.idx2x(cx) - p.xllcenter_m) / p.cellsize_m);
            const long r = std::lround((g.idx2y(cy) - p.yllcenter_m) / p.cellsize_m);
            if (c < 0 || r < 0 || c >= p.cols() || r >= p.rows()) continue;
            const float v = p.heights_m(int(r), int(c));
            if (!std::isfinite(v)) continue;
            both++;
            differ += std::abs(1.f - g.getCell(int(cx), int(cy)) - v) > 0.02f;
        }
    if (both == 0 || differ * 100 > both)
        throw std::runtime_error(
            "the exported grid and eval_untraversable_multibin.asc differ in " +
            std::to_string(differ) + " of " + std::to_string(both) +
            " cells: not the same lattice");
}
}  // namespace

int main(int argc, char** argv) try {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s DIR GT.asc [PAIRS [SEED [P_MAX...]]]\n", argv[0]);
        return 2;
    }
    const std::string dir = argv[1];
    const int pairs = argc > 3 ? std::stoi(argv[3]) : 100;
    const unsigned seed = argc > 4 ? unsigned(std::stoul(argv[4])) : 1;
    std::vector<double> pMax;
    for (int k = 5; k < argc; k++) pMax.push_back(std::stod(argv[k]));
    if (pMax.empty()) pMax = {0.5};

    mrpt::maps::COccupancyGridMap2D grid;
    const std::string gridPath = dir + "/elevation_traversability.gridmap.gz";
    mrpt::io::CFileGZInputStream in;
    if (!in.open(gridPath)) throw std::runtime_error(gridPath + ": cannot open");
    mrpt::serialization::archiveFrom(in) >> grid;
    checkSameLattice(grid, multibin::EsriAsciiGrid::load(dir + "/eval_untraversable_multibin.asc"));
    const TruthCells truth =
        truthOnGrid(grid, multibin::EsriAsciiGrid::load(dir + "/eval_untraversable_truth.asc"));
    // Planning only over the scored cells: the map's grid gets the truth's region, not its classes.
    for (unsigned cy = 0; cy < truth.ny; cy++)
        for (unsigned cx = 0; cx < truth.nx; cx++)
            if (truth.cls[size_t(cy) * truth.nx + cx] < 0) grid.setCell(int(cx), int(cy), 0.f);
    const mrpt::maps::COccupancyGridMap2D truthGrid = truth.grid(grid);
    const auto plans = oppositeSidePairs(grid, truth, pairs, seed);

    mrpt::nav::PlannerSimple2D planner;
    planner.robotRadius = 0;  // the layers' disc is the robot's footprint already
    planner.minStepInReturnedPath = 0;
    const auto row = [&](const std::string& name, const mrpt::maps::COccupancyGridMap2D& g) {
        const PlanningScore s = comparePlans(g, truthGrid, truth, plans, planner);
        std::printf("| %s | %d | %d | %d | %d | %d | %d / %d | %d / %zu | %.3f |\n", name.c_str(),
                    s.pairs, s.truthFound, s.foundWhereTruth, s.foundWhereNone, s.unsafePaths,
                    s.unsafeCells, s.pathCells, s.ratiosWithin(1.15), s.lengthRatios.size(),
                    s.maxRatio());
    };
    for (const double p : pMax) {
        planner.occupancyThreshold = float(1 - p);
        char name[16];
        std::snprintf(name, sizeof name, "%.2f", p);
        row(name, grid);
    }
    planner.occupancyThreshold = 0.5f;
    row("lattice", latticeBestGrid(grid, multibin::EsriAsciiGrid::load(argv[2]), truth));
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "traversability_planning: %s\n", e.what());
    return 1;
}
