/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/GapFilling.h"

#include <stdexcept>

#include "multibin/fill/HarmonicFill.h"
#include "multibin/fill/KrigingFill.h"
#include "multibin/fill/ModelSelection.h"
#include "multibin/fill/ShadowOccluders.h"
#include "multibin/fill/detail/MedianFiller.h"
#include "multibin/fill/detail/OneGap.h"
#include "multibin/fill/detail/ResultSetup.h"

namespace multibin::fill {

namespace {

/** Fills one gap from its support area by eq 16 (kriging or surface path); false if the area
 * holds too little data (the caller then falls back to the repeated median). */
bool fillWithGaussianSurface(const HeightRaster& r, const FillOptions& o,
                             const std::vector<int>& cells, FillResult& out) {
    const SupportArea area(r, o, cells);
    // Fewer than this and even m = 1 cannot be judged by the criterion.
    if (area.samples.size() < 12) return false;
    if (o.residualCorrection && o.residualModel == ResidualModel::Kriging &&
        o.criterion != ModelCriterion::Holdout) {
        const KrigingPlan plan = planKriging(o, area);
        try {
            fillByKriging(r, o, area, plan, out);
            return true;
        } catch (const std::runtime_error&) {
            // K not positive definite (not seen; K has every sample's sensor variance on its
            // diagonal): fill this gap by the surface path below instead of failing the map.
        }
    }
    const GaussianFitOptions fitOptions = surfaceFitOptions(o, area);
    fillByHarmonic(r, o, area, selectSurfaceModel(r, o, area, fitOptions), out);
    return true;
}

/** A shadow behind a step (ShadowOccluders.h): `masked` no longer holds the occluders, and the
 * gap is the harmonic interpolation of the hidden side's rim (eq 16 with m = 0 plus harmonic
 * rim residuals), the occluders' place a no-flux boundary: the far surface carried up to the
 * edge. Not the kriging: its covariance reaches the occluder's top beyond the masked cells.
 * Sigma: the surface path's (semivariogram at the distance to the data). False if too little
 * data. */
bool fillShadow(const HeightRaster& masked, const FillOptions& o, const std::vector<int>& cells,
                FillResult& out) {
    const SupportArea area(masked, o, cells);
    if (area.samples.size() < 12) return false;
    const GaussianSurface flat =
        fitGaussianSurfaceFixed(area.samples, area.side, 0, o.gaussianFitOptions());
    FillOptions harmonic = o;
    harmonic.residualModel = ResidualModel::Harmonic;
    fillByHarmonic(masked, harmonic, area, flat, out);
    return true;
}

}  // namespace

namespace detail {

void fillGap(const HeightRaster& r, const FillOptions& o, const Gap& gap,
             const std::vector<char>& measured, MedianFiller& median, FillResult& out) {
    if (gap.cells.empty()) return;  // too large: stays Unknown
    if (gap.medianReach) {
        // The median of a small gap uses measured cells only.
        for (int k : gap.cells) median.fillCell(k % r.nx(), k / r.nx(), out, measured);
        return;
    }
    if (o.gaussianEnabled && o.shadowOccluders.enabled) {
        // A shadow behind a step: the step's top is not data of the hidden surface.
        const ShadowOccluders occ = findShadowOccluders(r, gap.cells, o);
        if (!occ.cells.empty() && fillShadow(withoutOccluders(r, occ), o, gap.cells, out)) {
            out.stats.shadowGaps++;
            out.stats.shadowCells += int(gap.cells.size());
            return;
        }
    }
    if (o.gaussianEnabled && fillWithGaussianSurface(r, o, gap.cells, out)) return;
    // Fallback: rim-inwards median; its intermediate cells must not leak into other gaps.
    std::vector<char> local = measured;
    median.fillRepeated(gap.cells, out, local);
}

}  // namespace detail

FillResult fillGaps(const HeightRaster& r, const FillOptions& o) {
    r.validate();
    o.validate();
    std::vector<char> measured;
    FillResult out = detail::initResult(r, measured);
    out.stats.cellsVisited = r.size();
    std::vector<int> sizes;
    const std::vector<int> label = labelGaps(r, sizes);
    out.stats.gapComponents = int(sizes.size());
    if (!o.enabled || sizes.empty()) {
        detail::countSources(out);
        return out;
    }
    detail::MedianFiller median(r, o);
    for (const Gap& gap : collectGaps(r, label, sizes, o))
        detail::fillGap(r, o, gap, measured, median, out);
    detail::countSources(out);
    return out;
}

}  // namespace multibin::fill
