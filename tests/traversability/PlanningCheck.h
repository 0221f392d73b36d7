/* MRPT's PlannerSimple2D on the map's occupancy grid against the same planner on the truth's grid
 * (same lattice, same planner settings): the one home of the comparison, used by the synthetic
 * test (test_TraversabilityPlanning.cpp) and by the scoring boards' check
 * (traversability_planning.cpp, scripts/evaluate-traversability.sh). */
#pragma once

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/nav/planners/PlannerSimple2D.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <random>
#include <utility>
#include <vector>

namespace multibin::planning {

using Pose = mrpt::poses::CPose2D;
using Path = std::deque<mrpt::math::TPoint2D>;

inline double lengthOf(const Path& path) {
    double l = 0;
    for (size_t i = 1; i < path.size(); i++) l += (path[i] - path[i - 1]).norm();
    return l;
}

/** The truth of each cell of an occupancy grid's lattice: 1 untraversable, 0 traversable, -1
 * unknown or outside the scored region (row-major, getSizeX() per row). */
struct TruthCells {
    std::vector<int8_t> cls;
    unsigned nx = 0, ny = 0;
    int8_t at(const mrpt::maps::COccupancyGridMap2D& g, double x_m, double y_m) const {
        const int cx = g.x2idx(x_m), cy = g.y2idx(y_m);
        if (cx < 0 || cy < 0 || unsigned(cx) >= nx || unsigned(cy) >= ny) return -1;
        return cls[size_t(cy) * nx + size_t(cx)];
    }
    /** The truth's own grid on `lattice`'s cells: free where traversable, an obstacle elsewhere
     * (untraversable, unknown, outside). */
    mrpt::maps::COccupancyGridMap2D grid(const mrpt::maps::COccupancyGridMap2D& lattice) const {
        mrpt::maps::COccupancyGridMap2D g = lattice;
        for (unsigned cy = 0; cy < ny; cy++)
            for (unsigned cx = 0; cx < nx; cx++)
                g.setCell(int(cx), int(cy), cls[size_t(cy) * nx + cx] == 0 ? 1.f : 0.f);
        return g;
    }
};

/** `pairs` start/goal pairs of truth-traversable cells on opposite sides of the truth's known
 * cells: half from the westmost `band` share of their x range to the eastmost, half from the
 * southmost to the northmost, drawn uniformly with a fixed seed. */
inline std::vector<std::pair<Pose, Pose>> oppositeSidePairs(
    const mrpt::maps::COccupancyGridMap2D& g, const TruthCells& t, int pairs, unsigned seed,
    double band = 0.1) {
    int x0 = int(t.nx), x1 = -1, y0 = int(t.ny), y1 = -1;
    for (unsigned cy = 0; cy < t.ny; cy++)
        for (unsigned cx = 0; cx < t.nx; cx++)
            if (t.cls[size_t(cy) * t.nx + cx] >= 0)
                x0 = std::min(x0, int(cx)), x1 = std::max(x1, int(cx)), y0 = std::min(y0, int(cy)),
                y1 = std::max(y1, int(cy));
    std::vector<std::pair<Pose, Pose>> out;
    if (x1 < 0) return out;
    const int bx = std::max(1, int(band * (x1 - x0 + 1))),
              by = std::max(1, int(band * (y1 - y0 + 1)));
    std::vector<Pose> west, east, south, north;
    for (unsigned cy = 0; cy < t.ny; cy++)
        for (unsigned cx = 0; cx < t.nx; cx++) {
            if (t.cls[size_t(cy) * t.nx + cx] != 0) continue;
            const Pose p(g.idx2x(cx), g.idx2y(cy), 0);
            const int x = int(cx), y = int(cy);
            if (x < x0 + bx) west.push_back(p);
            if (x > x1 - bx) east.push_back(p);
            if (y < y0 + by) south.push_back(p);
            if (y > y1 - by) north.push_back(p);
        }
    std::mt19937 rng(seed);
    const auto pick = [&](const std::vector<Pose>& v) {
        return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng)];
    };
    for (int k = 0; k < pairs; k++) {
        const bool alongX = k % 2 == 0;
        const auto& a = alongX ? west : south;
        const auto& b = alongX ? east : north;
        if (a.empty() || b.empty()) continue;
        const Pose s = pick(a), e = pick(b);
        out.emplace_back(s, e);
    }
    return out;
}

/** How the map's plans compare with the truth's over a set of pairs. */
struct PlanningScore {
    int pairs = 0;
    int truthFound = 0;                //!< pairs the truth's grid has a path for
    int foundWhereTruth = 0;           //!< of them, pairs the map's grid has a path for too
    int foundWhereNone = 0;            //!< pairs the map has a path for and the truth none
    int unsafePaths = 0;               //!< map paths crossing a cell the truth calls untraversable
    int unsafeCells = 0;               //!< path cells untraversable in truth, over all map paths
    int pathCells = 0;                 //!< path cells over all map paths
    std::vector<double> lengthRatios;  //!< map / truth length, where both have a path
    double maxRatio() const {
        return lengthRatios.empty() ? 0
                                    : *std::max_element(lengthRatios.begin(), lengthRatios.end());
    }
    int ratiosWithin(double r) const {
        return int(std::count_if(lengthRatios.begin(), lengthRatios.end(),
                                 [r](double x) { return x <= r; }));
    }
};

/** Plans every pair on the map's grid and on the truth's grid with the same `planner` (its
 * minStepInReturnedPath should be 0: every cell of the path is checked). */
inline PlanningScore comparePlans(const mrpt::maps::COccupancyGridMap2D& map,
                                  const mrpt::maps::COccupancyGridMap2D& truthGrid,
                                  const TruthCells& truth,
                                  const std::vector<std::pair<Pose, Pose>>& pairs,
                                  const mrpt::nav::PlannerSimple2D& planner) {
    PlanningScore s;
    for (const auto& [start, goal] : pairs) {
        s.pairs++;
        Path truthPath, path;
        bool truthNone = true, none = true;
        planner.computePath(truthGrid, start, goal, truthPath, truthNone);
        planner.computePath(map, start, goal, path, none);
        s.truthFound += !truthNone;
        s.foundWhereTruth += !truthNone && !none;
        s.foundWhereNone += truthNone && !none;
        if (none) continue;
        int bad = 0;
        for (const auto& p : path) bad += truth.at(truthGrid, p.x, p.y) == 1;
        s.unsafePaths += bad > 0, s.unsafeCells += bad, s.pathCells += int(path.size());
        if (!truthNone) s.lengthRatios.push_back(lengthOf(path) / lengthOf(truthPath));
    }
    return s;
}

}  // namespace multibin::planning
