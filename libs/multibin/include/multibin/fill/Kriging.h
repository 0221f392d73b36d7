/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "multibin/fill/GaussianSurface.h"

namespace multibin::fill {

/** Covariance of the residual field z(x) - trend(x) at two cells d apart [cells]:
 * C(d) = sill_m2 rho(d / range_cells) for d > 0 and C(0) = sill_m2 + nugget_m2 (micro-scale
 * variance of a cell beyond the sensor noise, which each sample adds on its own). */
struct Covariance {
    CovarianceFamily family = CovarianceFamily::Exponential;
    double sill_m2 = 0;      //!< partial sill [m^2]
    double range_cells = 1;  //!< scale r of rho [cells]
    double nugget_m2 = 0;    //!< micro-scale variance, uncorrelated between cells [m^2]
    double correlation(double d_cells) const;  //!< rho(d) [-], 1 at d = 0
};

/** Fits a covariance to an empirical semivariogram: gamma[h], h = 1 .. gamma.size() - 1 [m^2]
 * with pairs[h] pairs each, is matched by nugget + sensorVariance_m2 + sill (1 - rho(h / r)) in
 * weighted least squares (weights = pair counts), r searched on a log grid from 0.5 to
 * maxRange_cells, sill and nugget >= 0 by linear least squares at each r. */
Covariance fitCovariance(const std::vector<double>& gamma, const std::vector<double>& pairs,
                         double sensorVariance_m2, CovarianceFamily family, double maxRange_cells);

/** Semivariogram of values on a w x h grid (row-major, NaN where there is no value), along rows
 * and columns, lags 1 .. maxLag: gamma[h] = 0.5 mean (z(x) - z(x + h))^2, pairs[h] the count;
 * gamma[0] = 0. A lag with no pair takes the previous lag's value (and 0 pairs). */
std::vector<double> gridSemivariogram(const std::vector<double>& values, int w, int h, int maxLag,
                                      std::vector<double>* pairs = nullptr);

/** Universal kriging (best linear unbiased prediction) on a support area: the trend is eq 16 with
 * the given shapes (centres, widths) and amplitudes by generalised least squares under the
 * covariance K = C(d_kl) + diag(sigma_k^2) of the samples (plus the weak amplitude prior of the
 * eq 16 fit); the residuals about it are interpolated by the covariance. */
class UniversalKriging {
public:
    /** Builds and factorises K; `amplitudePrior` is 1 / sigma_c^2 [1/m^2] on the c_q, q >= 1.
     * Throws std::runtime_error if K is not positive definite. */
    UniversalKriging(const std::vector<SurfaceSample>& samples, const GaussianSurface& shapes,
                     const Covariance& cov, double amplitudePrior);

    /** -2 ln L of the samples with the scale of K profiled out (K -> s K, s = Q / n with
     * Q = r^T K^-1 r): n ln(Q / n) + ln det K, up to a constant shared by all models. */
    double minusTwoLogLikelihood() const { return m_m2ll; }
    /** Scale of K estimated from the data, Q / (n - p) with p = m + 1 amplitudes (the
     * maximum-likelihood Q / n without its bias); multiplies the kriging variance [-]. */
    double varianceScale() const { return m_scale; }
    /** The trend with its GLS amplitudes. */
    const GaussianSurface& trend() const { return m_trend; }

    /** Kriged height [m] and kriging variance [m^2] (of the cell's true height: the
     * micro-scale nugget included, sensor noise not; times varianceScale()) at each (i, j),
     * including the uncertainty of the GLS amplitudes. */
    void predict(const std::vector<double>& i, const std::vector<double>& j,
                 std::vector<double>& mean_m, std::vector<double>& variance_m2) const;

private:
    /** Trend basis (1, then one unit Gaussian per term) at (i, j). */
    void basis(double i, double j, double* a) const;

    std::vector<SurfaceSample> m_samples;
    GaussianSurface m_trend;
    Covariance m_cov;
    double m_m2ll = 0, m_scale = 1;
    Eigen::LLT<Eigen::MatrixXd> m_llt;  // K = L L^T
    Eigen::MatrixXd m_W;                // L^-1 A, n x p
    Eigen::VectorXd m_alpha;            // K^-1 (y - A c)
    Eigen::MatrixXd m_Ginv;             // (A^T K^-1 A + prior)^-1, p x p
};

}  // namespace multibin::fill
