/* Part of the multibin elevation-mapping library. */
#include "multibin/traversability/TerrainFeatures.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace multibin::traversability {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
}  // namespace

// ---------------------------------------------------------------------------------------------
// DiscAccumulator: the feature definitions
// ---------------------------------------------------------------------------------------------
void DiscAccumulator::add(double dx_m, double dy_m, double h_m) {
    if (m_n == 0) m_h0 = h_m;
    const double h = h_m - m_h0;  // relative heights: the sums stay well conditioned
    m_n++;
    m_sx += dx_m, m_sy += dy_m;
    m_sxx += dx_m * dx_m, m_sxy += dx_m * dy_m, m_syy += dy_m * dy_m;
    m_sh += h, m_sxh += dx_m * h, m_syh += dy_m * h, m_shh += h * h;
    m_max = std::max(m_max, h_m), m_min = std::min(m_min, h_m);
}

void DiscAccumulator::add(double dx_m, double dy_m, double h_m, double reliefVariance_m2) {
    add(dx_m, dy_m, h_m);
    if (!(reliefVariance_m2 > 0)) return;
    m_relief += reliefVariance_m2;
    const double halfWidth = reliefHalfWidth_m(reliefVariance_m2);
    addStepOnly(h_m - halfWidth);
    addStepOnly(h_m + halfWidth);
}

void DiscAccumulator::addStepOnly(double h_m) {
    m_max = std::max(m_max, h_m), m_min = std::min(m_min, h_m);
}

bool DiscAccumulator::plane(DiscPlane& out) const {
    if (m_n < 3) return false;
    const double n = double(m_n), mx = m_sx / n, my = m_sy / n, mh = m_sh / n;
    const double cxx = m_sxx - n * mx * mx, cxy = m_sxy - n * mx * my, cyy = m_syy - n * my * my;
    const double cxh = m_sxh - n * mx * mh, cyh = m_syh - n * my * mh, chh = m_shh - n * mh * mh;
    const double det = cxx * cyy - cxy * cxy;
    if (!(det > 1e-12 * (cxx + cyy) * (cxx + cyy))) return false;  // collinear points
    const double b = (cyy * cxh - cxy * cyh) / det, c = (cxx * cyh - cxy * cxh) / det;
    out = {mx, my, m_h0 + mh, b, c, cxx, cxy, cyy, std::max(0.0, chh - b * cxh - c * cyh)};
    return true;
}

bool DiscAccumulator::features(DiscFeatures& out) const {
    DiscPlane p;
    if (!plane(p)) return false;
    out.step_m = m_max - m_min;
    out.slope_deg = std::atan(std::hypot(p.gx, p.gy)) * kRadToDeg;
    out.roughness_m = std::sqrt((p.rss_m2 + m_relief) / double(m_n));
    return true;
}

// ---------------------------------------------------------------------------------------------
// Layers
// ---------------------------------------------------------------------------------------------
SurfaceSamples::SurfaceSamples(const Lattice& l, int k) : lattice(l), perCell(k) {
    const size_t samples = l.cellCount() * size_t(k) * size_t(k);
    height_m.assign(samples, kNaN);
    sigma_m.assign(samples, kNaN);
    for (auto* v : {&binLow_m, &binLowSigma_m, &binHigh_m, &binHighSigma_m})
        v->assign(l.cellCount(), kNaN);
    relief_m2.assign(l.cellCount(), 0.f);
}

void SurfaceSamples::setCell(int col, int row, float h_m, float s_m) {
    for (int r = 0; r < perCell; r++)
        for (int c = 0; c < perCell; c++) {
            const size_t i = sampleIndex(col * perCell + c, row * perCell + r);
            height_m[i] = h_m;
            sigma_m[i] = s_m;
        }
}

void SurfaceSamples::copyFrom(const SurfaceSamples& o) {
    const CellWindow& w = lattice.window;
    const CellWindow& v = o.lattice.window;
    const int k = perCell;
    for (int iy = std::max(w.iy0, v.iy0); iy < std::min(w.iy0 + w.ny, v.iy0 + v.ny); iy++)
        for (int ix = std::max(w.ix0, v.ix0); ix < std::min(w.ix0 + w.nx, v.ix0 + v.nx); ix++) {
            const int col = ix - w.ix0, row = iy - w.iy0, oc = ix - v.ix0, orow = iy - v.iy0;
            const size_t to = lattice.index(col, row), from = o.lattice.index(oc, orow);
            for (auto [dst, src] : {std::pair{&binLow_m, &o.binLow_m},
                                    {&binLowSigma_m, &o.binLowSigma_m},
                                    {&binHigh_m, &o.binHigh_m},
                                    {&binHighSigma_m, &o.binHighSigma_m},
                                    {&relief_m2, &o.relief_m2}})
                (*dst)[to] = (*src)[from];
            for (int r = 0; r < k; r++)
                for (int c = 0; c < k; c++) {
                    const size_t i = sampleIndex(col * k + c, row * k + r);
                    const size_t j = o.sampleIndex(oc * k + c, orow * k + r);
                    height_m[i] = o.height_m[j];
                    sigma_m[i] = o.sigma_m[j];
                }
        }
}

TraversabilityLayers::TraversabilityLayers(const Lattice& l) : lattice(l) {
    for (auto* v : {&step_m, &stepSigma_m, &slope_deg, &slopeSigma_deg, &roughness_m,
                    &roughnessSigma_m, &untraversable, &foothold})
        v->assign(l.cellCount(), kNaN);
}

void TraversabilityLayers::copyFrom(const TraversabilityLayers& o) {
    const CellWindow& w = lattice.window;
    const CellWindow& v = o.lattice.window;
    for (int iy = std::max(w.iy0, v.iy0); iy < std::min(w.iy0 + w.ny, v.iy0 + v.ny); iy++)
        for (int ix = std::max(w.ix0, v.ix0); ix < std::min(w.ix0 + w.nx, v.ix0 + v.nx); ix++) {
            const size_t to = lattice.index(ix - w.ix0, iy - w.iy0);
            const size_t from = o.lattice.index(ix - v.ix0, iy - v.iy0);
            for (auto [dst, src] : {std::pair{&step_m, &o.step_m},
                                    {&stepSigma_m, &o.stepSigma_m},
                                    {&slope_deg, &o.slope_deg},
                                    {&slopeSigma_deg, &o.slopeSigma_deg},
                                    {&roughness_m, &o.roughness_m},
                                    {&roughnessSigma_m, &o.roughnessSigma_m},
                                    {&untraversable, &o.untraversable},
                                    {&foothold, &o.foothold}})
                (*dst)[to] = (*src)[from];
        }
}

namespace {

/** Which discs a point of the stencil lies in. */
enum : uint8_t { kDisc = 1, kFoot = 2, kClear = 4 };

/** One sample position around a cell: its offset in samples and metres from the cell's centre,
 * its cell (group) and its discs. The same for every cell of the lattice. */
struct StencilPoint {
    int dsc, dsr;      //!< sample offset from the cell's first sample
    float dx_m, dy_m;  //!< from the cell's centre
    int group;         //!< the cell it lies in, numbered over the stencil's cells
    uint8_t discs;
};
/** A cell around the centre cell whose bins count (some of it inside a disc). */
struct StencilCell {
    int dc, dr;
    int group;
    uint8_t discs;
};

struct Stencil {
    std::vector<StencilPoint> points;
    std::vector<StencilCell> cells;
    int groups = 0;
    size_t discPoints = 0;  //!< points inside the features' disc
};

uint8_t discsAt(double d2_m2, const TraversabilityOptions& o) {
    const double clear_m = o.foothold.radius_m + o.foothold.clearance_m;
    return uint8_t((d2_m2 <= o.radius_m * o.radius_m ? kDisc : 0) |
                   (d2_m2 <= o.foothold.radius_m * o.foothold.radius_m ? kFoot : 0) |
                   (d2_m2 <= clear_m * clear_m ? kClear : 0));
}

Stencil makeStencil(double cell_m, int k, const TraversabilityOptions& o) {
    Stencil s;
    const int rc = int(std::ceil(o.reach_m() / cell_m)) + 1;  // cells each way
    const int side = 2 * rc + 1;
    s.groups = side * side;
    const double step_m = cell_m / k;
    for (int dsr = -rc * k; dsr < (rc + 1) * k; dsr++)
        for (int dsc = -rc * k; dsc < (rc + 1) * k; dsc++) {
            const double dx = (dsc + 0.5 - 0.5 * k) * step_m, dy = (dsr + 0.5 - 0.5 * k) * step_m;
            const uint8_t discs = discsAt(dx * dx + dy * dy, o);
            if (!discs) continue;
            const int dc = dsc >= 0 ? dsc / k : -((-dsc + k - 1) / k);
            const int dr = dsr >= 0 ? dsr / k : -((-dsr + k - 1) / k);
            s.points.push_back(
                {dsc, dsr, float(dx), float(dy), (dr + rc) * side + (dc + rc), discs});
            if (discs & kDisc) s.discPoints++;
        }
    for (int dr = -rc; dr <= rc; dr++)
        for (int dc = -rc; dc <= rc; dc++) {
            // A cell whose any part lies in a disc: its other surface may lie anywhere in it.
            const double dx = std::max(0.0, (std::abs(dc) - 0.5) * cell_m);
            const double dy = std::max(0.0, (std::abs(dr) - 0.5) * cell_m);
            const uint8_t discs = discsAt(dx * dx + dy * dy, o);
            if (discs) s.cells.push_back({dc, dr, (dr + rc) * side + (dc + rc), discs});
        }
    return s;
}

/** Standard normal draws, fixed (a small xorshift generator and Box-Muller): the same map gives
 * the same layers on every machine. draws x groups x 3 (surface, low bin, high bin). */
std::vector<float> fixedNormalDraws(size_t count) {
    std::vector<float> z(count);
    uint64_t state = 0x9E3779B97F4A7C15ull;
    const auto uniform = [&] {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        return (double(state >> 11) + 0.5) * (1.0 / 9007199254740992.0);
    };
    for (size_t i = 0; i < count; i += 2) {
        const double r = std::sqrt(-2.0 * std::log(uniform())), a = 6.283185307179586 * uniform();
        z[i] = float(r * std::cos(a));
        if (i + 1 < count) z[i + 1] = float(r * std::sin(a));
    }
    return z;
}

/** A known surface point or bin around one cell. */
struct Known {
    float dx_m, dy_m, h_m, sigma_m;
    float relief_m2;  //!< the relief below the samples of its cell [m^2]
    int draw;         //!< column of the draws table: group * 3 + (0 surface, 1 low bin, 2 high bin)
    uint8_t discs;
    bool stepOnly;
};

/** The running ranges of one realisation of the surface around a cell. */
struct Realisation {
    DiscAccumulator disc;
    float footLo = 1e30f, footHi = -1e30f, clearLo = 1e30f, clearHi = -1e30f;

    void add(const Known& p, float h) {
        if (p.discs & kDisc)
            p.stepOnly ? disc.addStepOnly(h) : disc.add(p.dx_m, p.dy_m, h, p.relief_m2);
        if (p.discs & kFoot) footLo = std::min(footLo, h), footHi = std::max(footHi, h);
        if (p.discs & kClear) clearLo = std::min(clearLo, h), clearHi = std::max(clearHi, h);
    }
    bool untraversable(const DiscFeatures& f, const TraversabilityOptions& o) const {
        return f.step_m > o.max_step_m || f.slope_deg > o.max_slope_deg ||
               f.roughness_m > o.max_roughness_m;
    }
    bool goodFoothold(const TraversabilityOptions& o) const {
        return footHi - footLo <= o.foothold.flatness_m && clearHi - clearLo <= o.max_step_m;
    }
};

/** Gathers the known samples and bins around cell (col, row); false if the cell is unknown. */
bool gatherCell(const SurfaceSamples& s, const Stencil& st, const TraversabilityOptions& o, int col,
                int row, std::vector<Known>& known) {
    known.clear();
    const int k = s.perCell;
    size_t discKnown = 0;
    bool centreKnown = false;
    for (const StencilPoint& p : st.points) {
        const int sc = col * k + p.dsc, sr = row * k + p.dsr;
        if (sc < 0 || sr < 0 || sc >= s.sx() || sr >= s.sy()) continue;
        const size_t i = s.sampleIndex(sc, sr);
        if (!std::isfinite(s.height_m[i])) continue;
        const float relief = s.relief_m2[s.lattice.index(sc / k, sr / k)];
        known.push_back(
            {p.dx_m, p.dy_m, s.height_m[i], s.sigma_m[i], relief, p.group * 3, p.discs, false});
        if (p.discs & kDisc) discKnown++;
        centreKnown = centreKnown || (p.dsc >= 0 && p.dsc < k && p.dsr >= 0 && p.dsr < k);
    }
    if (!centreKnown || double(discKnown) < o.min_known_fraction * double(st.discPoints))
        return false;
    if (!o.use_bins) return true;
    for (const StencilCell& c : st.cells) {
        if (!s.lattice.inside(col + c.dc, row + c.dr)) continue;
        const size_t i = s.lattice.index(col + c.dc, row + c.dr);
        const float dx = float(c.dc * s.lattice.cellSize_m),
                    dy = float(c.dr * s.lattice.cellSize_m);
        if (std::isfinite(s.binLow_m[i]))
            known.push_back(
                {dx, dy, s.binLow_m[i], s.binLowSigma_m[i], 0.f, c.group * 3 + 1, c.discs, true});
        if (std::isfinite(s.binHigh_m[i]))
            known.push_back(
                {dx, dy, s.binHigh_m[i], s.binHighSigma_m[i], 0.f, c.group * 3 + 2, c.discs, true});
    }
    return true;
}

/** Mean and standard deviation of a running sum. */
struct Moments {
    double s = 0, ss = 0;
    void add(double v) { s += v, ss += v * v; }
    float sigma(int n) const {
        return n > 1 ? float(std::sqrt(std::max(0.0, (ss - s * s / n) / (n - 1)))) : 0.f;
    }
};

/** The truth's features as the calibration predicts them from the map's (without model error). */
DiscFeatures calibrated(const DiscFeatures& f, const TraversabilityOptions& o) {
    return {o.step.apply(f.step_m) + o.step_roughness_gain * f.roughness_m +
                o.step_slope_gain * f.slope_deg,
            o.slope.apply(f.slope_deg), o.roughness.apply(f.roughness_m)};
}

void computeCell(const std::vector<Known>& known, const std::vector<float>& z, int groups,
                 const TraversabilityOptions& o, TraversabilityLayers& out, size_t k) {
    Realisation mean;
    for (const Known& p : known) mean.add(p, p.h_m);
    DiscFeatures f;
    if (!mean.disc.features(f)) return;  // stays unknown: no plane
    const DiscFeatures fc = calibrated(f, o);
    out.step_m[k] = float(fc.step_m);
    out.slope_deg[k] = float(fc.slope_deg);
    out.roughness_m[k] = float(fc.roughness_m);
    const int draws = o.monte_carlo_draws;
    if (draws == 0) {
        out.untraversable[k] = mean.untraversable(fc, o) ? 1.f : 0.f;
        out.foothold[k] = mean.goodFoothold(o) ? 1.f : 0.f;
        out.stepSigma_m[k] = out.slopeSigma_deg[k] = out.roughnessSigma_m[k] = 0.f;
        return;
    }
    // The draws give each feature's spread about the mean surface's feature, not their own mean:
    // the estimated heights already carry one draw of the noise, and a range or an RMS of
    // noisier heights is larger, so the draws' own mean would count the noise twice.
    std::vector<DiscFeatures> drawn;
    drawn.reserve(size_t(draws));
    int good = 0;
    Moments step, slope, rough;
    const size_t stride = size_t(groups) * 3;
    for (int n = 0; n < draws; n++) {
        const float* zn = z.data() + size_t(n) * stride;
        Realisation r;
        for (const Known& p : known) r.add(p, p.h_m + p.sigma_m * zn[p.draw]);
        DiscFeatures fn;
        if (!r.disc.features(fn)) continue;
        drawn.push_back(fn);
        good += r.goodFoothold(o);
        step.add(fn.step_m), slope.add(fn.slope_deg), rough.add(fn.roughness_m);
    }
    const int valid = int(drawn.size());
    if (valid == 0) return;
    const DiscFeatures shift{f.step_m - step.s / valid, f.slope_deg - slope.s / valid,
                             f.roughness_m - rough.s / valid};
    // Each draw calibrated, with its own draw of what the lattice cannot resolve.
    const float* model = z.data() + size_t(draws) * stride;
    int bad = 0;
    for (size_t n = 0; n < drawn.size(); n++) {
        const float* zm = model + 3 * n;
        DiscFeatures c =
            calibrated({drawn[n].step_m + shift.step_m, drawn[n].slope_deg + shift.slope_deg,
                        drawn[n].roughness_m + shift.roughness_m},
                       o);
        c.step_m += o.step.model_sigma * zm[0];
        c.slope_deg += o.slope.model_sigma * zm[1];
        c.roughness_m += o.roughness.model_sigma * zm[2];
        bad += mean.untraversable(c, o);
    }
    out.untraversable[k] = float(bad) / float(valid);
    out.foothold[k] = float(good) / float(valid);
    const auto total = [&](const Moments& m, const TraversabilityOptions::FeatureCalibration& c) {
        return float(std::hypot(c.gain * m.sigma(valid), c.model_sigma));
    };
    out.stepSigma_m[k] = total(step, o.step);
    out.slopeSigma_deg[k] = total(slope, o.slope);
    out.roughnessSigma_m[k] = total(rough, o.roughness);
}

/** P(x <= limit) for x ~ N(mean, sigma^2); a step where sigma is 0. */
double below(double mean_, double sigma, double limit) {
    if (!(sigma > 0)) return mean_ <= limit ? 1.0 : 0.0;
    return 0.5 * std::erfc((mean_ - limit) / (sigma * std::sqrt(2.0)));
}

/** A range (highest minus lowest) over points of several independent error sources, linearised.
 * An end is the highest (lowest) point of one source, but which one is uncertain where several
 * are near: the end moves with source g by p_g s_g k, p_g its share of the pairwise chances
 * P(g's point beyond the top one's) (1/2 for the top one, so m tied sources share 1/m each), s_g
 * its sigma, and k such that the end's variance is (sum p s^2) sqrt(sum p^2): within 3 % of the
 * variance of the largest of m equal Gaussians for m = 1..5, and a single source's sigma when one
 * dominates. */
class SourcedRange {
public:
    void reset(size_t sources) {
        m_hi.assign(sources, -1e30f), m_lo.assign(sources, 1e30f);
        m_hiSigma.assign(sources, 0.f), m_loSigma.assign(sources, 0.f);
        m_top = m_bottom = -1;
    }
    void add(float h, float sigma, int g) {
        const size_t i = size_t(g);
        if (h > m_hi[i]) m_hi[i] = h, m_hiSigma[i] = sigma;
        if (h < m_lo[i]) m_lo[i] = h, m_loSigma[i] = sigma;
        if (m_top < 0 || h > m_hi[size_t(m_top)]) m_top = g;
        if (m_bottom < 0 || h < m_lo[size_t(m_bottom)]) m_bottom = g;
    }
    bool empty() const { return m_top < 0; }
    double range() const { return double(m_hi[size_t(m_top)]) - double(m_lo[size_t(m_bottom)]); }
    /** d range / d z_g added to d[g] (d sized as the sources). */
    void derivatives(std::vector<double>& d, std::vector<double>& share) const {
        end(m_hi, m_hiSigma, m_top, 1, d, share);
        end(m_lo, m_loSigma, m_bottom, -1, d, share);
    }

private:
    /** The highest end (sign 1) or the lowest (sign -1). */
    static void end(const std::vector<float>& h, const std::vector<float>& s, int top, int sign,
                    std::vector<double>& d, std::vector<double>& share) {
        share.assign(h.size(), 0.0);
        const size_t t = size_t(top);
        double sum = 0;
        for (size_t g = 0; g < h.size(); g++) {
            if (std::abs(h[g]) >= 1e29f) continue;                    // no point of this source
            const double gap = sign * (double(h[t]) - double(h[g]));  // >= 0
            const double spread = std::hypot(double(s[g]), double(s[t]));
            if (g == t || (spread == 0 && gap == 0))
                share[g] = 0.5;
            else if (spread > 0 && gap < 5 * spread)
                share[g] = 0.5 * std::erfc(gap / (spread * std::sqrt(2.0)));
            sum += share[g];
        }
        double a = 0, b = 0, c = 0;  // sum p s^2, sum p^2, sum p^2 s^2
        for (size_t g = 0; g < h.size(); g++) {
            const double p = share[g] /= sum, s2 = double(s[g]) * s[g];
            a += p * s2, b += p * p, c += p * p * s2;
        }
        const double k = c > 0 ? std::sqrt(a * std::sqrt(b) / c) : 0;
        for (size_t g = 0; g < h.size(); g++) d[g] += sign * share[g] * s[g] * k;
    }
    std::vector<float> m_hi, m_lo, m_hiSigma, m_loSigma;
    int m_top = -1, m_bottom = -1;
};

/** What computeCellLinear reuses from cell to cell. */
struct LinearScratch {
    std::vector<double> perSource, stepD, footD, clearD, share;
    SourcedRange step, foot, clear;
};

/** sqrt(sum of squares) of `d`. */
double norm(const std::vector<double>& d) {
    double s = 0;
    for (const double v : d) s += v * v;
    return std::sqrt(s);
}

/** One cell's layers with the samples' errors propagated linearly (options.linear_uncertainty):
 * each feature as a function of the error sources (one standard normal per stencil cell and kind,
 * Known::draw) linearised at the map's surface. The plane's gradient is linear in the heights; the
 * roughness r moves by sum e_i dh_i / (n r) (e the residuals); a range as SourcedRange. The
 * calibrated features are then Gaussian (the model error added), and P(untraversable) = 1 - the
 * product of the three P(feature <= limit): their correlation is left out. */
void computeCellLinear(const std::vector<Known>& known, int groups, const TraversabilityOptions& o,
                       TraversabilityLayers& out, size_t k, LinearScratch& w) {
    const size_t sources = size_t(groups) * 3;
    Realisation mean;
    SourcedRange &step = w.step, &foot = w.foot, &clear = w.clear;
    step.reset(sources), foot.reset(sources), clear.reset(sources);
    for (const Known& p : known) {
        mean.add(p, p.h_m);
        const float half = float(reliefHalfWidth_m(p.relief_m2));  // as DiscAccumulator::add
        if (p.discs & kDisc)
            step.add(p.h_m - half, p.sigma_m, p.draw), step.add(p.h_m + half, p.sigma_m, p.draw);
        if (p.discs & kFoot) foot.add(p.h_m, p.sigma_m, p.draw);
        if (p.discs & kClear) clear.add(p.h_m, p.sigma_m, p.draw);
    }
    DiscFeatures f;
    DiscPlane pl;
    if (!mean.disc.features(f) || !mean.disc.plane(pl)) return;  // stays unknown: no plane
    const DiscFeatures fc = calibrated(f, o);
    out.step_m[k] = float(fc.step_m);
    out.slope_deg[k] = float(fc.slope_deg);
    out.roughness_m[k] = float(fc.roughness_m);
    // Per source: the sums the gradient (x, y) and the roughness (residual) move by.
    std::vector<double>& perSource = w.perSource;
    perSource.assign(sources * 3, 0.0);
    for (const Known& p : known) {
        if (!(p.discs & kDisc) || p.stepOnly) continue;
        const double x = p.dx_m - pl.mx_m, y = p.dy_m - pl.my_m;
        const double e = p.h_m - pl.mh_m - pl.gx * x - pl.gy * y;
        double* v = &perSource[size_t(p.draw) * 3];
        v[0] += x * p.sigma_m, v[1] += y * p.sigma_m, v[2] += e * p.sigma_m;
    }
    const double det = pl.cxx * pl.cyy - pl.cxy * pl.cxy, n = double(mean.disc.count());
    const double g = std::hypot(pl.gx, pl.gy), r = f.roughness_m;
    const double ux = g > 1e-12 ? pl.gx / g : 1.0, uy = g > 1e-12 ? pl.gy / g : 0.0;
    const double slopePerGradient_deg = kRadToDeg / (1 + g * g);  // d atan(g) / dg
    double mapVar[3] = {0, 0, 0}, calVar[3] = {0, 0, 0};          // step, slope, roughness
    w.stepD.assign(sources, 0.0);
    step.derivatives(w.stepD, w.share);
    for (size_t src = 0; src < sources; src++) {
        const double* v = &perSource[src * 3];
        const double dgx = (pl.cyy * v[0] - pl.cxy * v[1]) / det;
        const double dgy = (pl.cxx * v[1] - pl.cxy * v[0]) / det;
        double d[3] = {0, slopePerGradient_deg * (ux * dgx + uy * dgy),
                       r > 1e-9 ? v[2] / (n * r) : 0};
        d[0] = w.stepD[src];
        const double c[3] = {
            o.step.gain * d[0] + o.step_roughness_gain * d[2] + o.step_slope_gain * d[1],
            o.slope.gain * d[1], o.roughness.gain * d[2]};
        for (int j = 0; j < 3; j++) mapVar[j] += d[j] * d[j], calVar[j] += c[j] * c[j];
    }
    const TraversabilityOptions::FeatureCalibration* cal[3] = {&o.step, &o.slope, &o.roughness};
    const double value[3] = {fc.step_m, fc.slope_deg, fc.roughness_m};
    const double limit[3] = {o.max_step_m, o.max_slope_deg, o.max_roughness_m};
    float* sigmaOut[3] = {&out.stepSigma_m[k], &out.slopeSigma_deg[k], &out.roughnessSigma_m[k]};
    double traversable = 1;
    for (int j = 0; j < 3; j++) {
        const double ms = cal[j]->model_sigma;
        *sigmaOut[j] = float(std::hypot(cal[j]->gain * std::sqrt(mapVar[j]), ms));
        traversable *= below(value[j], std::sqrt(calVar[j] + ms * ms), limit[j]);
    }
    out.untraversable[k] = float(1 - traversable);
    if (foot.empty() || clear.empty()) {
        out.foothold[k] = 0.f;
        return;
    }
    w.footD.assign(sources, 0.0), w.clearD.assign(sources, 0.0);
    foot.derivatives(w.footD, w.share), clear.derivatives(w.clearD, w.share);
    out.foothold[k] = float(below(foot.range(), norm(w.footD), o.foothold.flatness_m) *
                            below(clear.range(), norm(w.clearD), o.max_step_m));
}

}  // namespace

void computeLayers(const SurfaceSamples& s, const TraversabilityOptions& o,
                   TraversabilityLayers& out, const std::vector<uint8_t>& cellMask) {
    if (!(out.lattice == s.lattice)) out = TraversabilityLayers(s.lattice);
    const Stencil st = makeStencil(s.lattice.cellSize_m, s.perCell, o);
    // Per draw: the surface's errors (3 per stencil cell), then the features' model errors (3).
    // With 0 draws the layers are thresholded, linear_uncertainty or not.
    const bool linear = o.linear_uncertainty && o.monte_carlo_draws > 0;
    const std::vector<float> z = fixedNormalDraws(
        linear ? 0 : size_t(std::max(0, o.monte_carlo_draws)) * (size_t(st.groups) * 3 + 3));
    std::vector<Known> known;
    LinearScratch scratch;
    for (int row = 0; row < s.lattice.ny(); row++)
        for (int col = 0; col < s.lattice.nx(); col++) {
            const size_t k = s.lattice.index(col, row);
            if (!cellMask.empty() && !cellMask[k]) continue;
            for (auto* v :
                 {&out.step_m, &out.stepSigma_m, &out.slope_deg, &out.slopeSigma_deg,
                  &out.roughness_m, &out.roughnessSigma_m, &out.untraversable, &out.foothold})
                (*v)[k] = kNaN;
            if (!gatherCell(s, st, o, col, row, known)) continue;
            if (linear)
                computeCellLinear(known, st.groups, o, out, k, scratch);
            else
                computeCell(known, z, st.groups, o, out, k);
        }
}

std::vector<uint8_t> dilateMask(const std::vector<uint8_t>& mask, int nx, int ny, int cells) {
    // Two passes of a running count: along rows, then along columns.
    std::vector<uint8_t> rows(mask.size(), 0), out(mask.size(), 0);
    for (int r = 0; r < ny; r++) {
        int count = 0;
        for (int c = -cells; c < nx + cells; c++) {
            if (c + cells < nx) count += mask[size_t(r) * nx + size_t(c + cells)] != 0;
            if (c - cells - 1 >= 0) count -= mask[size_t(r) * nx + size_t(c - cells - 1)] != 0;
            if (c >= 0 && c < nx) rows[size_t(r) * nx + size_t(c)] = count > 0;
        }
    }
    for (int c = 0; c < nx; c++) {
        int count = 0;
        for (int r = -cells; r < ny + cells; r++) {
            if (r + cells < ny) count += rows[size_t(r + cells) * nx + size_t(c)];
            if (r - cells - 1 >= 0) count -= rows[size_t(r - cells - 1) * nx + size_t(c)];
            if (r >= 0 && r < ny) out[size_t(r) * nx + size_t(c)] = count > 0;
        }
    }
    return out;
}

}  // namespace multibin::traversability
