/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/VisibilityConstraint.h"
#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <vector>

#include "multibin/grid/VisibilityStages.h"
#include "multibin/io/OptionKeys.h"
#include "multibin/util/Counters.h"

namespace multibin {

VisibilityStats& VisibilityStats::operator+=(const VisibilityStats& o) {
    return util::addMembers(*this, o, &VisibilityStats::raysCast, &VisibilityStats::cellsVisited,
                            &VisibilityStats::binsRemoved, &VisibilityStats::binsWeakened);
}

namespace {
/** The most cells a line of sight is followed for the clearance [cells]. */
constexpr int kClearanceReach_cells = 16;
/** The fewest points of one update a cell needs to end a line of sight for the clearance. */
constexpr uint32_t kClearanceMinPoints = 2;

/** The visibility keys of `o` (a VisibilityParams or a const one), for the options protocol
 * (multibin/io/OptionKeys.h). */
template <class Params, class Visit>
void visitKeys(Params& o, Visit&& visit) {
    visit("visibility_constraint", o.enabled);
    visit({"visibility_margin_m", "visibility_margin"}, o.margin_m, atLeast(0, "m"));
    visit("visibility_certainty_decrement", o.certaintyDecrement, positive());
    visit("visibility_certainty_share", o.certaintyShare, between(0, 1));
}
}  // namespace

void VisibilityParams::read(StrictConfigSection& s) { visitKeys(*this, OptionReader{s}); }

void VisibilityParams::write(mrpt::config::CConfigFileBase& c, const std::string& section) const {
    visitKeys(*this, OptionWriter{c, section});
}

void VisibilityParams::validate() const {
    visitKeys(*this, OptionChecker("CMultiBinElevationMap insertion option"));
}

namespace visibility {
FanOutcome testRays(RayFan fan, const BinGrid& grid, const Region& region,
                    const TowardsSensor& towards, const Eigen::Vector3d& sensor_m,
                    const BoundTest& bounds, VisibilityScratch& scratch,
                    std::vector<RayState>& state) {
    state.clear();
    if (!rayTestsApply(grid, region, sensor_m)) return FanOutcome{};
    const RayTestInputs inputs(grid, region, towards, sensor_m, bounds, scratch);
    return fan == RayFan::Test ? testFan(inputs, state) : testEnvelope(inputs, state);
}
}  // namespace visibility

namespace {
/** This thread's scratch arrays. Out of line so that the caller holds a plain reference: named
 * directly, a thread_local of this shared library is looked up again (__tls_get_addr) at almost
 * every use (13 % of the constraint's instructions once). */
__attribute__((noinline)) visibility::VisibilityScratch& threadScratch() {
    thread_local visibility::VisibilityScratch scratch;
    return scratch;
}
}  // namespace

void noteClearances(BinGrid& grid, const Eigen::Vector3d& sensor_m, double maxRise_m) {
    const double cell_m = grid.cellSize_m();
    // A shallow line (a lidar's far rays) also stops after kClearanceReach_cells: its cost.
    const double maxReach_m = kClearanceReach_cells * cell_m;
    for (BinGrid::UpdatedCell u : grid.updatedCells()) {
        // A lone point may be a range outlier beyond the surface, whose line runs under the
        // ground before it: only cells two points or more of this update agree on end a line.
        if (u.points < kClearanceMinPoints) continue;
        // The line ends at the highest bin the cell ever held, not at this update's point: a
        // point below the surface (a range outlier, a mixed pixel) would draw a line under the
        // ground before it, and one such line sets the clearance for good.
        u.maxHeight_m = std::max(u.maxHeight_m, grid.cellMaxHeight_m(u.ix, u.iy));
        SightLine ray;
        // A line rising towards the sensor stops at maxRise_m; one that does not (a sensor below
        // its point) bounds nothing near the point and is not followed.
        if (!ray.set(grid, u, sensor_m) || !(ray.slope > 0)) continue;
        const double stop_m = ray.tz_m + std::min(maxRise_m, ray.slope * maxReach_m);
        // One sample a cell (the rule takes two): a cell a diagonal line only grazes may be
        // missed, at half the cost. The cell's clearance is the line's height at the sample.
        for (double d = cell_m; d < ray.walk_m; d += cell_m) {
            const double z_m = ray.tz_m + ray.slope * d;
            if (z_m > stop_m) break;
            grid.noteClearance(ray.cellOf(grid, ray.tx_m + ray.ux * d),
                               ray.cellOf(grid, ray.ty_m + ray.uy * d), z_m);
        }
    }
}

VisibilityStats applyVisibilityConstraint(BinGrid& grid, const Eigen::Vector3d& sensor_m,
                                          const VisibilityParams& vis,
                                          const BinUpdateParams& binParams, RayFan fan) {
    using namespace visibility;
    VisibilityStats stats;
    if (!vis.enabled) return stats;
    const ConflictTest conflicts(vis, binParams);
    const BoundTest bounds{conflicts.minMargin_m()};
    const double step = 0.5 * grid.cellSize_m();
    VisibilityScratch& scratch = threadScratch();
    // Rays stop once they clear every bin they could still meet by the margin: the highest
    // stored anywhere, or the highest in the region of this update.
    double stopHeight_m = grid.maxHeight_m() + vis.margin_m;  // hoisted: edits write memory
    const Region region = buildRegion(grid, sensor_m, scratch.regionBound);
    if (!region.empty())
        stopHeight_m =
            std::min(stopHeight_m, BoundTest::tolerant_m(region.maxBound_m) + vis.margin_m);
    if (!regionMayConflict(region, bounds)) {  // a floor seen from above: most laser scans
        stats.raysCast = countRays(grid, sensor_m);
        return stats;
    }
    const TowardsSensor towards =
        buildTowardsSensor(grid, region, sensor_m, bounds, scratch.towardsSensor);
    std::vector<RayState>& state = scratch.rayState;
    const FanOutcome decided =
        testRays(fan, grid, region, towards, sensor_m, bounds, scratch, state);
    if (decided.noWalk) stats.raysCast += decided.clearRays;
    scratch.sampleAt.assign({0.0, step});

    const std::vector<BinGrid::UpdatedCell>& updated = grid.updatedCells();
    for (size_t i = 0; i < updated.size(); i++) {
        const BinGrid::UpdatedCell& u = updated[i];
        const float decrement = vis.certaintyDecrement * float(u.points);
        LazyTargetCertainty target(grid, u, binParams);
        // Bins of the updated cell above all that was measured in it now.
        if (bounds.mayConflict(grid.cellMaxHeight_m(u.ix, u.iy), u.maxHeight_m)) {
            target();  // before the cell's own edit
            weakenBinsAboveMeasurements(grid, u, u.maxHeight_m, conflicts, decrement, stats);
        }
        // The line of sight from the updated cell back to the sensor.
        if (decided.noWalk) continue;  // counted above
        if (!state.empty() && state[i] != RayState::Walk) {
            stats.raysCast += state[i] == RayState::Clear;
            continue;
        }
        SightLine ray;
        if (!ray.setEnds(grid, u, sensor_m)) continue;
        stats.raysCast++;
        // The whole ray at once: if no block between its cell's and the sensor's can conflict,
        // its walk would edit nothing (most floor rays of a lidar revolution in a room).
        if (restOfRayClear(towards, bounds, BinGrid::blockOf(u.ix), BinGrid::blockOf(u.iy),
                           u.maxHeight_m, sensor_m.z()))
            continue;
        const double reach_m = sweepColumns(grid, region, towards, u, sensor_m, ray.length_m,
                                            bounds, stopHeight_m, scratch.stretches);
        if (!(reach_m >= step)) continue;  // the first sample lies beyond it
        ray.setWalk(grid, sensor_m);
        walkStretches(grid, region, ray, u.ix, u.iy, scratch.stretches, reach_m, stopHeight_m,
                      bounds, conflicts, target, decrement, scratch.sampleAt, stats);
    }
    return stats;
}

}  // namespace multibin
