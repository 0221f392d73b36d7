/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/SupportArea.h"

namespace multibin::fill {

/** The residual h - g of the measured cells of `area` around a gap, carried into `cells` as a
 * harmonic function (Laplace equation, Dirichlet data on the rim, solved by over-relaxed
 * Gauss-Seidel): the filled surface then meets every rim cell instead of passing near it.
 * `cells` (raster indices inside the area) may include measured cells, which are then treated
 * as unknown (held out). Returns one value per cell [m]. */
std::vector<double> harmonicResiduals(const HeightRaster& raster, const GaussianSurface& g,
                                      const std::vector<int>& cells, const SupportArea& area);

/** As harmonicResiduals, but a biharmonic function (thin-plate equation: the 13-point stencil of
 * the squared Laplacian set to zero at every gap cell, the two rings of measured cells around it
 * as boundary data), solved directly (sparse LU). A gap cell whose stencil reaches a cell that is
 * neither measured nor in the gap (raster edge, another gap) takes the harmonic equation over its
 * measured or gap neighbours. */
std::vector<double> biharmonicResiduals(const HeightRaster& raster, const GaussianSurface& g,
                                        const std::vector<int>& cells, const SupportArea& area);

/** The surface path (ResidualModel::Harmonic / Biharmonic, the fallback of the kriging, and
 * eq 16 alone without residual correction): the gap of `area` gets g plus its rim residuals
 * (harmonic or biharmonic per options.residualModel; none if !residualCorrection), clamped to
 * the training heights widened by the extrapolation margin, with sigma from the semivariogram
 * of the area's heights at the distance to the data (FillSigmaModel::Calibrated) or the
 * training points' mean sigma (Paper). */
void fillByHarmonic(const HeightRaster& raster, const FillOptions& options,
                    const SupportArea& area, const GaussianSurface& g, FillResult& out);

}  // namespace multibin::fill
