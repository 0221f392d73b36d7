/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "RandomSceneScore.h"

#include "NaiveStereo.h"
#include "Scenario.h"
#include "SurfaceTexture.h"

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <multibin/grid/BinGrid.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include "multibin/map/MapInternals.h"

namespace terrain_sim {
namespace {

using mrpt::maps::CHeightGridMap2D;
using mrpt::maps::CMultiBinElevationMap;

using CellMask = Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic>;

struct Maps {
    CMultiBinElevationMap map;  // default options
    std::unique_ptr<CHeightGridMap2D> mrptMean;
    std::vector<CellMask> hitInPass;  //!< per pass, the truth raster's cells a point fell in
};

/** Every pass's laser scans into the map and, as points, into MRPT's mean height grid. The noise
 * streams depend on the seed and the pass only, so the runs with and without the object draw
 * alike. */
void mapPasses(const RandomScene& sc, bool withObject, const multibin::EsriAsciiGrid& gt, Maps& m) {
    const Terrain& g = sc.ground;
    const double cell = m.map.dem_get_resolution();
    m.mrptMean = std::make_unique<CHeightGridMap2D>(CHeightGridMap2D::mrSimpleAverage,
                                                    g.x0_m() - 2.0, g.xMax_m() + 2.0,
                                                    g.y0_m() - 2.0, g.yMax_m() + 2.0, cell);
    for (size_t p = 0; p < sc.passes.size(); ++p) {
        const Terrain seen = withObject ? sc.seenIn(p) : g;
        const SurfaceTexture texture(seen, sc.seed, sc.darkPatches);
        const LaserSim laser(sc.laser, seen, texture, sc.seed);
        std::mt19937_64 rng(hash64(sc.seed * 1000003 + p));
        CellMask& hit = m.hitInPass.emplace_back(gt.rows(), gt.cols());
        hit.setConstant(false);
        for (const Frame& f : sc.passes[p].frames) {
            const auto scan = laser.scan(f.truth, syntheticStamp(f.t_s + 100.0 * p), rng);
            m.map.insertObservation(*scan, f.estimate);
            mrpt::maps::CSimplePointsMap points;
            points.insertionOptions.minDistBetweenLaserPoints = 0;
            points.loadFromRangeScan(*scan, f.estimate.mean);
            const mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
            for (size_t k = 0; k < points.size(); k++) {
                float x, y, z;
                points.getPoint(k, x, y, z);
                m.mrptMean->insertIndividualPoint(x, y, z, ip);
                const long col = std::lround((x - gt.xllcenter_m) / gt.cellsize_m);
                const long row = std::lround((y - gt.yllcenter_m) / gt.cellsize_m);
                if (row >= 0 && col >= 0 && row < gt.rows() && col < gt.cols())
                    hit(row, col) = true;
            }
        }
    }
    m.map.dem_update_map();
}

/** Cells of the truth raster, marked per placement: the footprint (any part of the cell on it)
 * grown by one cell. */
struct Regions {
    const multibin::EsriAsciiGrid& gt;
    std::vector<Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic>> grown;

    Regions(const multibin::EsriAsciiGrid& truth, const std::vector<SceneObject>& objects)
        : gt(truth) {
        const double c = gt.cellsize_m;
        for (const SceneObject& o : objects) {
            Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> on(gt.rows(), gt.cols());
            on.setConstant(false);
            for (int r = 0; r < gt.rows(); ++r)
                for (int k = 0; k < gt.cols(); ++k) {
                    const double x = gt.xllcenter_m + k * c, y = gt.yllcenter_m + r * c;
                    if (std::hypot(x - o.x_m, y - o.y_m) > o.boundingRadius_m() + c) continue;
                    for (int a = 0; a < 4 && !on(r, k); ++a)  // 4 x 4 points per cell
                        for (int b = 0; b < 4 && !on(r, k); ++b)
                            on(r, k) = o.covers(x + c * (a - 1.5) / 4, y + c * (b - 1.5) / 4);
                }
            auto grownOn = on;
            for (int r = 0; r < gt.rows(); ++r)
                for (int k = 0; k < gt.cols(); ++k)
                    for (int dr = -1; dr <= 1; ++dr)
                        for (int dk = -1; dk <= 1; ++dk) {
                            const int rr = r + dr, kk = k + dk;
                            if (rr >= 0 && kk >= 0 && rr < gt.rows() && kk < gt.cols() &&
                                on(rr, kk))
                                grownOn(r, k) = true;
                        }
            grown.push_back(grownOn);
        }
    }
    bool inAny(int r, int k) const {
        for (const auto& g : grown)
            if (g(r, k)) return true;
        return false;
    }
    bool inAnyAt(double x, double y) const {
        const int k = int(std::lround((x - gt.xllcenter_m) / gt.cellsize_m));
        const int r = int(std::lround((y - gt.yllcenter_m) / gt.cellsize_m));
        return r < 0 || k < 0 || r >= gt.rows() || k >= gt.cols() || inAny(r, k);
    }
};

struct Rms {
    double sum = 0;
    size_t n = 0;
    void add(double e) {
        sum += e * e;
        ++n;
    }
    double value() const { return n ? std::sqrt(sum / n) : RandomSceneScores::kNaN; }
};

/** What cell (x, y) of the map holds, against the truth there (RandomSceneScores::CellKind). */
RandomSceneScores::CellKind cellKind(const CMultiBinElevationMap& map, double x, double y,
                                     double truth_m) {
    constexpr double kAtGround_m = 0.03;
    const multibin::BinGrid& grid = multibin::MapInternals::grid(map);
    const auto origin = map.mapOrigin();
    const int ix = grid.cellIndex(x - origin.x), iy = grid.cellIndex(y - origin.y);
    if (!grid.window().contains(ix, iy)) return RandomSceneScores::NoBin;
    int bins = 0;
    bool ground = false;
    grid.forEachBin(ix, iy, [&](const multibin::Bin& b) {
        bins++;
        ground = ground || std::abs(b.height_m - truth_m) < kAtGround_m;
    });
    const multibin::Bin* win = grid.winningBin(ix, iy);
    if (bins == 0) return RandomSceneScores::NoBin;
    if (!ground) return RandomSceneScores::OnlyStale;
    return win && std::abs(win->height_m - truth_m) >= kAtGround_m
               ? RandomSceneScores::StaleWinsBesideGround
               : RandomSceneScores::GroundWins;
}

void scoreObject(const RandomScene& sc, const Regions& reg, Maps& m, Maps& without,
                 RandomSceneScores& s) {
    const int last = sc.passes.back().placement;
    Rms dem, mrptMean, noObject, seenAfter;
    double worst = 0;
    for (int r = 0; r < reg.gt.rows(); ++r)
        for (int k = 0; k < reg.gt.cols(); ++k) {
            bool vacated = false;
            for (int v : sc.vacatedPlacements()) vacated = vacated || reg.grown[v](r, k);
            if (!vacated || (last >= 0 && reg.grown[last](r, k))) continue;
            // Seen again: a pass after the last one in which the object stood on the cell (any
            // placement's footprint + 1 cell) put a point in it. A point of a pass in which the
            // object stood there again (moved within reach of its old place) is the object's.
            size_t after = 0;
            for (size_t p = 0; p < sc.passes.size(); ++p)
                if (sc.passes[p].placement >= 0 && reg.grown[sc.passes[p].placement](r, k))
                    after = p + 1;
            bool seenAgain = false;
            for (size_t p = after; p < m.hitInPass.size(); ++p)
                seenAgain = seenAgain || m.hitInPass[p](r, k);
            const double x = reg.gt.xllcenter_m + k * reg.gt.cellsize_m;
            const double y = reg.gt.yllcenter_m + r * reg.gt.cellsize_m;
            const double truth = reg.gt.heights_m(r, k);
            double z;
            if (!std::isfinite(truth)) continue;
            if (!m.map.dem_get_z(x, y, z)) {
                s.objectUnknown++;
                continue;
            }
            dem.add(z - truth);
            if (seenAgain) seenAfter.add(z - truth);
            double z0;
            if (without.map.dem_get_z(x, y, z0)) noObject.add(z0 - truth);
            worst = std::max(worst, std::abs(z - truth));
            const auto kind = cellKind(m.map, x, y, truth);
            s.objectSquaredError_m2[kind][seenAgain] += (z - truth) * (z - truth);
            s.objectCellsOfKind[kind][seenAgain]++;
            const auto* c = m.mrptMean->cellByPos(x, y);
            if (c && c->w > 0) mrptMean.add(c->h - truth);
        }
    s.objectCells = dem.n;
    s.objectRmse_m = dem.value();
    s.objectMrptRmse_m = mrptMean.value();
    s.objectNoObjectRmse_m = noObject.value();
    s.objectSeenAgainRmse_m = seenAfter.value();
    s.objectSeenAgainCells = seenAfter.n;
    s.objectWorstError_m = dem.n ? worst : RandomSceneScores::kNaN;
}

void scoreStaticAndFilled(const Regions& reg, Maps& with, Maps& without, RandomSceneScores& s) {
    Rms withObj, noObj, filled, mrptMean;
    for (int r = 0; r < reg.gt.rows(); ++r)
        for (int k = 0; k < reg.gt.cols(); ++k) {
            const double truth = reg.gt.heights_m(r, k);
            if (!std::isfinite(truth) || reg.inAny(r, k)) continue;
            const double x = reg.gt.xllcenter_m + k * reg.gt.cellsize_m;
            const double y = reg.gt.yllcenter_m + r * reg.gt.cellsize_m;
            double z1, s1, z0, s0;
            const auto src1 = with.map.cellElevation(x, y, z1, s1, true);
            const auto src0 = without.map.cellElevation(x, y, z0, s0, false);
            const auto* c = with.mrptMean->cellByPos(x, y);
            const bool mrptGap = !c || c->w == 0;
            if (src1 == multibin::HeightSource::Measured &&
                src0 == multibin::HeightSource::Measured) {
                withObj.add(z1 - truth);
                noObj.add(z0 - truth);
                if (!mrptGap) mrptMean.add(c->h - truth);
            }
            if (mrptGap && src1 != multibin::HeightSource::Measured &&
                src1 != multibin::HeightSource::Unknown)
                filled.add(z1 - truth);
        }
    s.staticCells = withObj.n;
    s.staticRmse_m = withObj.value();
    s.staticRmseNoObject_m = noObj.value();
    s.staticMrptRmse_m = mrptMean.value();
    s.filledCells = filled.n;
    s.filledRmse_m = filled.value();
}

void scoreQueries(const RandomScene& sc, const Regions& reg, Maps& m, RandomSceneScores& s) {
    const Terrain& g = sc.ground;
    std::mt19937_64 rng(hash64(sc.seed ^ 0x51554552u));
    std::uniform_real_distribution<double> ux(0.0, g.tilesX() * g.tileSide_m());
    std::uniform_real_distribution<double> uy(-0.5 * g.tilesY() * g.tileSide_m(),
                                              0.5 * g.tilesY() * g.tileSide_m());
    Rms map, mrptMean, floor;
    for (int i = 0; i < 4000; ++i) {
        const double x = ux(rng), y = uy(rng);
        if (reg.inAnyAt(x, y)) continue;
        double h, sigma;
        const auto* c = m.mrptMean->cellByPos(x, y);
        if (!m.map.heightAt(x, y, h, sigma) || !c || c->w == 0) continue;
        const double truth = g.height(x, y);
        const int k = int(std::lround((x - reg.gt.xllcenter_m) / reg.gt.cellsize_m));
        const int r = int(std::lround((y - reg.gt.yllcenter_m) / reg.gt.cellsize_m));
        const double cellMean = reg.gt.heights_m(r, k);  // inside: inAnyAt() checked the range
        if (!std::isfinite(cellMean)) continue;
        map.add(h - truth);
        mrptMean.add(c->h - truth);
        floor.add(cellMean - truth);
    }
    s.queryPoints = map.n;
    s.queryRmse_m = map.value();
    s.queryMrptRmse_m = mrptMean.value();
    s.queryFloorRmse_m = floor.value();
}

/** Adds cell (x, y) of truth `truth` to `a`: what the map and the naive grid hold there. */
/** The map's measured height at (x, y), or (the control) a second naive grid's mean. */
struct StereoMapSide {
    const CMultiBinElevationMap& map;
    const CHeightGridMap2D* naiveAsMap;
    bool height(double x, double y, double& h, double& sigma) const {
        if (!naiveAsMap) return map.getHeight(x, y, h, sigma);
        const auto* c = naiveAsMap->cellByPos(x, y);
        h = c ? c->h : 0;
        sigma = RandomSceneScores::kNaN;
        return c && c->w > 0;
    }
};

void scoreStereoCell(const StereoMapSide& map, const CHeightGridMap2D& naive, double x, double y,
                     double truth, bool besideStep, StereoSceneScores::Area& a,
                     std::vector<std::array<double, 6>>* cells) {
    a.truthCells++;
    double h, sigma;
    const bool hasMap = map.height(x, y, h, sigma);
    const auto* c = naive.cellByPos(x, y);
    const bool hasNaive = c && c->w > 0;
    a.mapCells += hasMap;
    a.naiveCells += hasNaive;
    if (cells && (hasMap || hasNaive))
        cells->push_back({x, y, truth, hasMap ? h : RandomSceneScores::kNaN,
                          hasMap ? sigma : RandomSceneScores::kNaN,
                          hasNaive ? double(c->h) : RandomSceneScores::kNaN});
    const double kFar_m = StereoSceneScores::Area::kFar_m;
    a.mapGood += hasMap && std::abs(h - truth) <= kFar_m;
    a.naiveGood += hasNaive && std::abs(c->h - truth) <= kFar_m;
    if (hasNaive && !hasMap) {
        a.naiveOnlyCells++;
        a.naiveOnlySumSq_m2 += (c->h - truth) * (c->h - truth);
    }
    if (!hasMap || !hasNaive) return;
    a.commonCells++;
    const double e = h - truth, en = c->h - truth;
    a.mapSumSq_m2 += e * e;
    a.naiveSumSq_m2 += en * en;
    if (besideStep) {
        a.stepCells++;
        a.mapStepSumSq_m2 += e * e;
        a.naiveStepSumSq_m2 += en * en;
    }
    if (std::abs(e) > kFar_m) {
        a.mapFarCells++;
        a.mapFarSumSq_m2 += e * e;
        a.naiveOnMapFarSumSq_m2 += en * en;
    }
}

/** Whether two cells within 2 of cell (r, k) (5 x 5) have truths more than `step_m` apart: a
 * step of the truth, or its 2 cells beyond, where a drop's occluded side lies. */
bool besideStep(const multibin::EsriAsciiGrid& gt, int r, int k, double step_m) {
    float lo = gt.heights_m(r, k), hi = lo;
    for (int dr = -2; dr <= 2; ++dr)
        for (int dk = -2; dk <= 2; ++dk) {
            const int rr = r + dr, kk = k + dk;
            if (rr < 0 || kk < 0 || rr >= gt.rows() || kk >= gt.cols()) continue;
            lo = std::min(lo, gt.heights_m(rr, kk));
            hi = std::max(hi, gt.heights_m(rr, kk));
        }
    return hi - lo > step_m;
}

}  // namespace

double StereoSceneScores::Area::ratioOffSteps() const {
    const double n = double(commonCells - stepCells);
    return std::sqrt((mapSumSq_m2 - mapStepSumSq_m2) / n) /
           std::sqrt((naiveSumSq_m2 - naiveStepSumSq_m2) / n);
}

double StereoSceneScores::Area::mapRmse_m() const {
    return commonCells ? std::sqrt(mapSumSq_m2 / commonCells) : RandomSceneScores::kNaN;
}
double StereoSceneScores::Area::naiveRmse_m() const {
    return commonCells ? std::sqrt(naiveSumSq_m2 / commonCells) : RandomSceneScores::kNaN;
}

StereoSceneScores scoreRandomSceneStereo(
    const RandomScene& sc, const std::function<void(CMultiBinElevationMap&)>& configure,
    bool keepCells, bool naiveAsMap) {
    CMultiBinElevationMap map;
    {  // the rig's calibration sigmas, as terrain-sim writes them for its scenarios
        ScenarioConfig rig;
        rig.stereo = sc.stereo;
        const mrpt::config::CConfigFileMemory ini(mapperIni(rig));
        map.insertionOptions.loadFromConfigFile(
            ini, "MappingApplication_multiBinElevationMap_00_insertOpts");
    }
    if (configure) configure(map);
    const Terrain& g = sc.ground;
    const double cell = map.dem_get_resolution();
    auto meanGrid = [&] {
        return CHeightGridMap2D(CHeightGridMap2D::mrSimpleAverage, g.x0_m() - 2.0, g.xMax_m() + 2.0,
                                g.y0_m() - 2.0, g.yMax_m() + 2.0, cell);
    };
    CHeightGridMap2D naive = meanGrid(), naiveCopy = meanGrid();  // the copy: the control's map
    StereoSceneScores s;
    for (size_t p = 0; p < sc.passes.size(); ++p) {
        const Terrain seen = sc.seenIn(p);
        const SurfaceTexture texture(seen, sc.seed, sc.darkPatches);
        const StereoSim camera(sc.stereo, seen, texture);
        std::mt19937_64 rng(hash64((sc.seed * 1000003 + p) ^ 0x53544552u));
        for (const Frame& f : sc.passes[p].frames) {
            if (!f.stereo) continue;
            const auto obs =
                camera.observation(camera.render(f.truth, rng), syntheticStamp(f.t_s + 100.0 * p));
            if (naiveAsMap)
                insertNaiveStereo(naiveCopy, *obs, f.estimate.mean);
            else
                map.insertObservation(*obs, f.estimate);
            insertNaiveStereo(naive, *obs, f.estimate.mean);
            s.stereoFrames++;
        }
    }
    const multibin::EsriAsciiGrid gt = g.groundTruth(cell);
    const Regions reg(gt, sc.placements);
    const StereoMapSide side{map, naiveAsMap ? &naiveCopy : nullptr};
    const double xTiles_m = g.tilesX() * g.tileSide_m(),
                 yTiles_m = 0.5 * g.tilesY() * g.tileSide_m();
    for (int r = 0; r < gt.rows(); ++r)
        for (int k = 0; k < gt.cols(); ++k) {
            const double truth = gt.heights_m(r, k);
            if (!std::isfinite(truth) || reg.inAny(r, k)) continue;
            const double x = gt.xllcenter_m + k * cell, y = gt.yllcenter_m + r * cell;
            const bool step = besideStep(gt, r, k, StereoSceneScores::Area::kStep_m);
            scoreStereoCell(side, naive, x, y, truth, step, s.raster, nullptr);
            if (x >= 0 && x <= xTiles_m && std::abs(y) <= yTiles_m)
                scoreStereoCell(side, naive, x, y, truth, step, s.boards,
                                keepCells ? &s.cells : nullptr);
        }
    return s;
}

RandomSceneScores scoreRandomScene(const RandomScene& sc,
                                   const std::function<void(CMultiBinElevationMap&)>& configure) {
    Maps with, without;
    if (configure) {
        configure(with.map);
        configure(without.map);
    }
    const multibin::EsriAsciiGrid gt = sc.ground.groundTruth(with.map.dem_get_resolution());
    mapPasses(sc, true, gt, with);
    mapPasses(sc, false, gt, without);
    const Regions reg(gt, sc.placements);
    RandomSceneScores s;
    scoreObject(sc, reg, with, without, s);
    scoreStaticAndFilled(reg, with, without, s);
    scoreQueries(sc, reg, with, s);
    return s;
}

}  // namespace terrain_sim
