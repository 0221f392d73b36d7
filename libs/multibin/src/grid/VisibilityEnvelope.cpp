/* Part of the multibin elevation-mapping library. */
/* Stage 3 for a camera frame (VisibilityStages.h): the rays' lower envelope by direction, tested
 * once per cell of the blocks high enough to matter, instead of once per ray and length.
 *
 * A ray of slope s (height gained per metre towards the sensor) from a target at tz, length L,
 * is at height h(r) = sz - s r at horizontal distance r from the sensor; the rule samples it at
 * r in (0, L - step] and tests each cell at h plus the in-cell rise (>= 0). Over a square at
 * distances [near, far] from the sensor, for s >= 0, h >= max(sz - s far, tz + s step); for
 * s < 0, h >= sz. So over any set of rays, every one of them passes over the square no lower
 * than max(sz - S far, B), where S is their largest slope (at least 0) and B the least of
 * their tz + s step (sz for s < 0). The set: the rays whose direction lies within the square's
 * (their samples in the square lie on it) and long enough to have a sample there. A cell whose
 * bound lies no higher than that plus the smallest conflict margin holds no conflicting bin
 * for any of them; a ray none of whose directions' cells is left so is clear. */
#include <algorithm>
#include <cmath>

#include "multibin/grid/VisibilityStages.h"

namespace multibin::visibility {

namespace {
constexpr double kHeightSlack_m = 1e-9;
constexpr unsigned kGroupShift = 6;  // sectors per group: 64
constexpr unsigned kRings = 32;      // length classes of a group's rays, a block wide each

/** The envelope's state for one update: the rays by sector of direction, and per sector the
 * nearest distance of a cell that may conflict with the rays there. */
class EnvelopeTest : RayTestInputs {
public:
    explicit EnvelopeTest(const RayTestInputs& inputs) : RayTestInputs(inputs) {}

    FanOutcome run(std::vector<RayState>& state);

private:
    size_t collectRays(std::vector<RayState>& state, size_t& raysClear);
    void bySector();
    unsigned sectorOf(double key) const {
        return std::min(unsigned(std::max(key, 0.0) * m_keyToSector), m_sectors - 1);
    }
    /** Calls f(first, last) for the sector ranges of keys [lo, hi] (one or two: past key 4). */
    template <class F>
    void forSectors(double lo, double hi, F&& f) const;
    unsigned ringOf(double length_m) const {
        return unsigned(std::min(std::max(length_m, 0.0) * m_invRing, double(kRings - 1)));
    }
    RayEnvelope groupEnvelope(double lo, double hi, bool all, double nearStep_m) const;
    RayEnvelope rayEnvelope(double lo, double hi, bool all, double nearStep_m) const;
    void testCell(int ix, int iy, float bound_m);
    void testBlock(int bx, int by);

    unsigned m_sectors = 1;
    double m_keyToSector = 0;
    double m_invRing = 0;  // 1 / the rings' width [1/m]
    RayEnvelope m_all;
    RayEnvelope m_allRings[kRings];
};

/** The rays firstLook leaves to test: their key, length, slope and B in m_s.envRays. Returns
 * the rays firstLook decided. */
size_t EnvelopeTest::collectRays(std::vector<RayState>& state, size_t& raysClear) {
    m_s.envRays.clear();
    const double sz = m_sensor_m.z();
    auto add = [&](size_t i, const BinGrid::UpdatedCell& u, double dx, double dy, double length) {
        const double tz = u.maxHeight_m;
        const double slope = (sz - tz) / length;
        const double low_m = slope >= 0 ? tz + slope * m_step : sz;
        m_s.envRays.push_back(
            {pseudoAngle(-dx, -dy), length, std::max(slope, 0.0), low_m, uint32_t(i)});
    };
    return firstLook(m_grid, m_towards, m_bounds, m_sensor_m, state, raysClear, add);
}

/** The rays sorted by sector (a counting sort; about one ray per sector), and each group of
 * sectors' envelope. */
void EnvelopeTest::bySector() {
    const size_t n = m_s.envRays.size();
    m_sectors = 64;
    while (m_sectors < n && m_sectors < (1u << 18)) m_sectors *= 2;
    m_keyToSector = m_sectors / 4.0;
    std::vector<uint32_t>& start = m_s.start;
    start.assign(m_sectors + 1, 0);
    for (const EnvRay& r : m_s.envRays) start[sectorOf(r.key) + 1]++;
    for (unsigned k = 1; k <= m_sectors; k++) start[k] += start[k - 1];
    m_s.envSorted.resize(n);
    for (const EnvRay& r : m_s.envRays) m_s.envSorted[start[sectorOf(r.key)]++] = r;
    for (unsigned k = m_sectors; k > 0; k--) start[k] = start[k - 1];  // back to the starts
    start[0] = 0;
    // Per group and ring r: the rays at least r ring widths long (a ray's ring and those below).
    m_invRing = 1.0 / (BinGrid::kBlockCells * m_cell);
    const size_t groups = m_sectors >> kGroupShift;
    m_s.envGroups.assign(groups * kRings, RayEnvelope{});
    m_all = RayEnvelope{};
    for (RayEnvelope& e : m_allRings) e = RayEnvelope{};
    for (const EnvRay& r : m_s.envSorted) {
        const unsigned ring = ringOf(r.length);
        m_s.envGroups[(sectorOf(r.key) >> kGroupShift) * kRings + ring].add(r.slope, r.low_m);
        m_allRings[ring].add(r.slope, r.low_m);
        m_all.add(r.slope, r.low_m);
    }
    for (size_t g = 0; g < groups; g++)
        for (unsigned ring = kRings - 1; ring > 0; ring--)
            m_s.envGroups[g * kRings + ring - 1].add(m_s.envGroups[g * kRings + ring]);
    for (unsigned ring = kRings - 1; ring > 0; ring--) m_allRings[ring - 1].add(m_allRings[ring]);
    m_s.hotNear.assign(m_sectors, std::numeric_limits<double>::infinity());
}

template <class F>
void EnvelopeTest::forSectors(double lo, double hi, F&& f) const {
    if (lo < 0) {  // keys [lo + 4, 4) and [0, hi]
        f(sectorOf(lo + 4), m_sectors - 1);
        f(0u, sectorOf(hi));
    } else if (hi >= 4) {  // keys [lo, 4) and [0, hi - 4]
        f(sectorOf(lo), m_sectors - 1);
        f(0u, sectorOf(hi - 4));
    } else {
        f(sectorOf(lo), sectorOf(hi));
    }
}

/** The envelope of the rays within keys [lo, hi] (every ray if `all`) and at least nearStep_m
 * long, by whole groups of sectors and rings of length: a superset, cheap. */
RayEnvelope EnvelopeTest::groupEnvelope(double lo, double hi, bool all, double nearStep_m) const {
    const unsigned ring = ringOf(nearStep_m);  // a ray at least nearStep_m long is in it or above
    if (all) return m_allRings[ring];
    RayEnvelope e;
    forSectors(lo, hi, [&](unsigned first, unsigned last) {
        for (unsigned g = first >> kGroupShift; g <= last >> kGroupShift; g++)
            e.add(m_s.envGroups[g * kRings + ring]);
    });
    return e;
}

/** The same, one by one, of the rays at least nearStep_m long: for a cell's few. */
RayEnvelope EnvelopeTest::rayEnvelope(double lo, double hi, bool all, double nearStep_m) const {
    RayEnvelope e;
    auto add = [&](uint32_t from, uint32_t to) {
        for (uint32_t j = from; j < to; j++) {
            const EnvRay& r = m_s.envSorted[j];
            if (r.length >= nearStep_m) e.add(r.slope, r.low_m);
        }
    };
    if (all)
        add(0, uint32_t(m_s.envSorted.size()));
    else
        forSectors(lo, hi, [&](unsigned first, unsigned last) {
            add(m_s.start[first], m_s.start[last + 1]);
        });
    return e;
}

/** Cell (ix, iy), not updated in this cycle, whose bound lies above its block's envelope: against
 * the rays within its own directions and long enough to reach it; if they may meet a conflicting
 * bin there, their sectors are hot from its nearest distance on. */
void EnvelopeTest::testCell(int ix, int iy, float bound_m) {
    const double sx = m_sensor_m.x(), sy = m_sensor_m.y();
    const double x0 = ix * m_cell - kSlack_m, x1 = (ix + 1) * m_cell + kSlack_m;
    const double y0 = iy * m_cell - kSlack_m, y1 = (iy + 1) * m_cell + kSlack_m;
    const SquareDistances distances = squareDistances(x0, x1, y0, y1, sx, sy);
    const double near_m = distances.near_m, far_m = distances.far_m;
    // No sample of a ray shorter than this lies in the cell (1e-9 m spare).
    const double nearStep_m = near_m + m_step - 1e-9;
    double lo = 0, hi = 0;
    const bool all = !squareKeys(x0, x1, y0, y1, sx, sy, lo, hi);
    // The groups' envelope first (cheap), then the rays one by one.
    if (!m_bounds.mayConflict(
            bound_m, groupEnvelope(lo, hi, all, nearStep_m).lowest_m(m_sensor_m.z(), far_m)))
        return;
    const RayEnvelope e = rayEnvelope(lo, hi, all, nearStep_m);
    if (!m_bounds.mayConflict(bound_m, e.lowest_m(m_sensor_m.z(), far_m))) return;
    auto heat = [&](unsigned first, unsigned last) {
        for (unsigned k = first; k <= last; k++) m_s.hotNear[k] = std::min(m_s.hotNear[k], near_m);
    };
    if (all)
        heat(0, m_sectors - 1);
    else
        forSectors(lo, hi, heat);
}

/** Block (bx, by) of the region against the envelope of the rays within its directions; where
 * it may hold a bin above it, its cells that may. */
void EnvelopeTest::testBlock(int bx, int by) {
    const unsigned blockSlot =
        unsigned(bx - m_region.x0) + unsigned(by - m_region.y0) * m_region.nx;
    const float bound_m = m_region.bound_m[blockSlot];
    const double sz = m_sensor_m.z();
    if (!m_bounds.mayConflict(bound_m, m_all.low_m - kHeightSlack_m)) return;  // below every ray
    const double block_m = BinGrid::kBlockCells * m_cell;
    const double sx = m_sensor_m.x(), sy = m_sensor_m.y();
    const double x0 = bx * block_m - kSlack_m, x1 = (bx + 1) * block_m + kSlack_m;
    const double y0 = by * block_m - kSlack_m, y1 = (by + 1) * block_m + kSlack_m;
    const SquareDistances distances = squareDistances(x0, x1, y0, y1, sx, sy);
    const double near_m = distances.near_m, far_m = distances.far_m;
    double lo = 0, hi = 0;
    const bool all = !squareKeys(x0, x1, y0, y1, sx, sy, lo, hi);
    const double nearStep_m = near_m + m_step - 1e-9;  // no shorter ray has a sample here
    const double blockLow_m = groupEnvelope(lo, hi, all, nearStep_m).lowest_m(sz, far_m);
    if (!m_bounds.mayConflict(bound_m, blockLow_m)) return;
    // Its cells inside the window; a cell no higher than the block's envelope is settled.
    const CellWindow& w = m_grid.window();
    const int ixLo = std::max(bx * BinGrid::kBlockCells, w.ix0);
    const int ixHi = std::min((bx + 1) * BinGrid::kBlockCells, w.ix0 + w.nx);
    const int iyLo = std::max(by * BinGrid::kBlockCells, w.iy0);
    const int iyHi = std::min((by + 1) * BinGrid::kBlockCells, w.iy0 + w.ny);
    const VisibilityIndex& index = m_grid.visibilityIndex();
    for (int iy = iyLo; iy < iyHi; iy++)
        for (int ix = ixLo; ix < ixHi; ix++) {
            const size_t slot = m_grid.store().slot(ix, iy);  // inside the window
            const float cellBound_m = index.cellMaxHeight_m(slot);
            // The rule skips the cells updated in this cycle.
            if (m_bounds.mayConflict(cellBound_m, blockLow_m) && !index.updatedThisCycle(slot))
                testCell(ix, iy, cellBound_m);
        }
}

FanOutcome EnvelopeTest::run(std::vector<RayState>& state) {
    size_t raysClear = 0;
    const size_t decided = collectRays(state, raysClear);
    bySector();
    if (!m_s.envRays.empty()) forEachBlock([&](int bx, int by) { testBlock(bx, by); });
    // A ray with a sample in a cell left hot has its sector among the cell's, and reaches it.
    size_t clear = 0;
    for (const EnvRay& r : m_s.envRays) {
        const bool walk = r.length >= m_s.hotNear[sectorOf(r.key)] + m_step - 1e-9;
        state[r.updatedIndex] = walk ? RayState::Walk : RayState::Clear;
        clear += !walk;
    }
    return FanOutcome::after(state.size(), decided, raysClear, clear);
}
}  // namespace

FanOutcome testEnvelope(const RayTestInputs& inputs, std::vector<RayState>& state) {
    return EnvelopeTest(inputs).run(state);
}

}  // namespace multibin::visibility
