/* Part of the multibin elevation-mapping library. */
#pragma once

#include <optional>
#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/SupportArea.h"

namespace multibin::fill {

/** How the kriging path fills one gap (ResidualModel::Kriging). */
struct KrigingPlan {
    GaussianFitOptions fitOptions;  //!< eq 16 settings for the area (surfaceFitOptions)
    /** The neighbourhood: the krigingMaxPoints training points nearest the gap. Its likelihood
     * chooses m; without `moving` it is also where every gap cell is kriged from. */
    std::vector<SurfaceSample> near;
    /** Moving neighbourhoods: each 8 x 8 tile of the gap is kriged from its own krigingMaxPoints
     * measured cells of the area nearest the tile (the trend's amplitudes re-estimated there). */
    bool moving = false;
    /** The rim check's alternative (eq 16 by AIC on independent residuals, to which the harmonic
     * rim residuals are added); empty: no rim check. */
    std::optional<GaussianSurface> rimCheckSurface;
};

/** The plan options imply for `area`: `near` and `moving` from krigingNeighbourhood (auto:
 * moving when the two rings of measured cells around the gap do not fit in `near`), and the rim
 * check's surface for a moving gap when movingRimCheck is on. */
KrigingPlan planKriging(const FillOptions& options, const SupportArea& area);

/** The kriging path: the models of searchKrigingModels() predict the gap (one factorisation, or
 * tile by tile when plan.moving); the gap gets the kriged heights of the best m, or their
 * Akaike-weighted mean (modelAveraging), and sigma from the kriging variance (plus, when
 * averaging, the models' spread) times gaussianSigmaGain. With a rim check, the two rings of
 * measured cells around the gap are hidden and predicted both by this kriging (best m, tiles
 * from the cells beyond the rings) and by the rim-check surface plus harmonic rim residuals; if
 * the latter predicts them better, the gap takes its heights (and keeps the kriging sigma).
 * Throws std::runtime_error if a kriging matrix is not positive definite. */
void fillByKriging(const HeightRaster& raster, const FillOptions& options, const SupportArea& area,
                   const KrigingPlan& plan, FillResult& out);

}  // namespace multibin::fill
