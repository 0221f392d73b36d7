/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/Kriging.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace multibin::fill {

double Covariance::correlation(double d) const {
    const double r = std::max(range_cells, 1e-9);
    if (family == CovarianceFamily::Matern32) {
        const double x = std::sqrt(3.0) * d / r;
        return (1 + x) * std::exp(-x);
    }
    return std::exp(-d / r);
}

std::vector<double> gridSemivariogram(const std::vector<double>& v, int w, int h, int maxLag,
                                      std::vector<double>* pairsOut) {
    maxLag = std::max(maxLag, 1);
    std::vector<double> sum(size_t(maxLag) + 1, 0.0), cnt(size_t(maxLag) + 1, 0.0);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const double z = v[size_t(y) * size_t(w) + size_t(x)];
            if (!std::isfinite(z)) continue;
            for (int lag = 1; lag <= maxLag; lag++) {
                if (x + lag < w) {
                    const double zz = v[size_t(y) * size_t(w) + size_t(x + lag)];
                    if (std::isfinite(zz))
                        sum[size_t(lag)] += (zz - z) * (zz - z), cnt[size_t(lag)]++;
                }
                if (y + lag < h) {
                    const double zz = v[size_t(y + lag) * size_t(w) + size_t(x)];
                    if (std::isfinite(zz))
                        sum[size_t(lag)] += (zz - z) * (zz - z), cnt[size_t(lag)]++;
                }
            }
        }
    std::vector<double> gamma(size_t(maxLag) + 1, 0.0);
    for (int lag = 1; lag <= maxLag; lag++)
        gamma[size_t(lag)] = cnt[size_t(lag)] > 0 ? 0.5 * sum[size_t(lag)] / cnt[size_t(lag)]
                                                  : gamma[size_t(lag) - 1];
    if (pairsOut) *pairsOut = cnt;
    return gamma;
}

Covariance fitCovariance(const std::vector<double>& gamma, const std::vector<double>& pairs,
                         double sensorVariance_m2, CovarianceFamily family, double maxRange_cells) {
    Covariance best;
    best.family = family;
    double bestSse = std::numeric_limits<double>::infinity();
    const int lags = int(gamma.size()) - 1;
    constexpr int kSteps = 40;
    const double rLo = 0.5, rHi = std::max(maxRange_cells, 1.0);
    for (int s = 0; s < kSteps; s++) {
        Covariance c;
        c.family = family;
        c.range_cells = rLo * std::pow(rHi / rLo, double(s) / (kSteps - 1));
        // gamma_h - sensor = nugget + sill x_h, x_h = 1 - rho(h): weighted linear LS, both >= 0.
        double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (int h = 1; h <= lags; h++) {
            const double w = pairs[size_t(h)];
            if (w <= 0) continue;
            const double x = 1 - c.correlation(h), y = gamma[size_t(h)] - sensorVariance_m2;
            sw += w, sx += w * x, sy += w * y, sxx += w * x * x, sxy += w * x * y;
        }
        if (sw <= 0) continue;
        const double det = sw * sxx - sx * sx;
        double nug = det > 0 ? (sxx * sy - sx * sxy) / det : sy / sw;
        double sill = det > 0 ? (sw * sxy - sx * sy) / det : 0;
        if (sill < 0) sill = 0, nug = sy / sw;
        if (nug < 0) nug = 0, sill = sxx > 0 ? std::max(sxy / sxx, 0.0) : 0;
        double sse = 0;
        for (int h = 1; h <= lags; h++) {
            const double w = pairs[size_t(h)];
            if (w <= 0) continue;
            const double e =
                gamma[size_t(h)] - sensorVariance_m2 - nug - sill * (1 - c.correlation(h));
            sse += w * e * e;
        }
        if (sse < bestSse) {
            bestSse = sse;
            c.sill_m2 = sill;
            c.nugget_m2 = nug;
            best = c;
        }
    }
    return best;
}

void UniversalKriging::basis(double i, double j, double* a) const {
    a[0] = 1;
    for (size_t q = 0; q < m_trend.terms.size(); q++) {
        const auto& t = m_trend.terms[q];
        a[q + 1] =
            std::exp(t.lambda1 * (i - t.a1) * (i - t.a1) + t.lambda2 * (j - t.a2) * (j - t.a2));
    }
}

UniversalKriging::UniversalKriging(const std::vector<SurfaceSample>& samples,
                                   const GaussianSurface& shapes, const Covariance& cov,
                                   double amplitudePrior)
    : m_samples(samples), m_trend(shapes), m_cov(cov) {
    const int n = int(samples.size()), p = 1 + int(shapes.terms.size());
    if (n < 1) throw std::invalid_argument("UniversalKriging: no samples");
    // Correlations depend on the squared integer distance only: one table, no exp per pair.
    int maxD2 = 0;
    for (const auto& s : samples)
        for (const auto& t : samples)
            maxD2 = std::max(maxD2, (s.i - t.i) * (s.i - t.i) + (s.j - t.j) * (s.j - t.j));
    std::vector<double> rho(size_t(maxD2) + 1);
    for (int d2 = 0; d2 <= maxD2; d2++) rho[size_t(d2)] = cov.correlation(std::sqrt(double(d2)));
    Eigen::MatrixXd K(n, n);
    for (int k = 0; k < n; k++) {
        const auto& s = samples[size_t(k)];
        for (int l = 0; l < k; l++) {
            const auto& t = samples[size_t(l)];
            K(k, l) =
                cov.sill_m2 * rho[size_t((s.i - t.i) * (s.i - t.i) + (s.j - t.j) * (s.j - t.j))];
        }
        // Own variance: field, micro-scale nugget and the sample's sensor noise.
        K(k, k) = cov.sill_m2 + cov.nugget_m2 + s.sigma_m * s.sigma_m;
    }
    m_llt.compute(K);  // reads the lower triangle
    if (m_llt.info() != Eigen::Success)
        throw std::runtime_error("UniversalKriging: covariance matrix not positive definite");
    const auto L = m_llt.matrixL();

    Eigen::MatrixXd A(n, p);
    Eigen::VectorXd y(n);
    std::vector<double> a(static_cast<size_t>(p));
    for (int k = 0; k < n; k++) {
        basis(samples[size_t(k)].i, samples[size_t(k)].j, a.data());
        for (int q = 0; q < p; q++) A(k, q) = a[size_t(q)];
        y[k] = samples[size_t(k)].h_m;
    }
    m_W = L.solve(A);
    const Eigen::VectorXd z = L.solve(y);
    Eigen::MatrixXd G = m_W.transpose() * m_W;
    G.diagonal().tail(p - 1).array() += amplitudePrior;
    G(0, 0) += 1e-12 * G(0, 0);
    Eigen::LDLT<Eigen::MatrixXd> gl(G);
    const Eigen::VectorXd c = gl.solve(m_W.transpose() * z);
    m_Ginv = gl.solve(Eigen::MatrixXd::Identity(p, p));
    m_trend.c0_m = c[0];
    for (int q = 1; q < p; q++) m_trend.terms[size_t(q - 1)].c_m = c[q];

    const Eigen::VectorXd v = z - m_W * c;  // L^-1 (y - A c)
    const double Q = std::max(v.squaredNorm(), 1e-300);
    m_alpha = L.transpose().solve(v);  // K^-1 (y - A c)
    double logDet = 0;
    for (int k = 0; k < n; k++) logDet += 2 * std::log(m_llt.matrixLLT()(k, k));
    m_m2ll = n * std::log(Q / n) + logDet;
    // The variance scale without the bias of the maximum-likelihood Q / n (p fitted amplitudes).
    m_scale = Q / std::max(n - p, 1);
}

void UniversalKriging::predict(const std::vector<double>& ci, const std::vector<double>& cj,
                               std::vector<double>& mean, std::vector<double>& var) const {
    const int n = int(m_samples.size()), p = int(m_W.cols()), t = int(ci.size());
    Eigen::MatrixXd k(n, t);
    std::vector<double> rho;  // by squared distance, for targets on the cell grid
    for (int c = 0; c < t; c++) {
        const bool onGrid = ci[size_t(c)] == std::floor(ci[size_t(c)]) &&
                            cj[size_t(c)] == std::floor(cj[size_t(c)]);
        for (int s = 0; s < n; s++) {
            const double di = ci[size_t(c)] - m_samples[size_t(s)].i;
            const double dj = cj[size_t(c)] - m_samples[size_t(s)].j;
            const double d2 = di * di + dj * dj;
            if (onGrid && d2 < 1e6) {
                const size_t key = size_t(d2);
                while (rho.size() <= key)
                    rho.push_back(m_cov.correlation(std::sqrt(double(rho.size()))));
                k(s, c) = m_cov.sill_m2 * rho[key];
            } else {
                k(s, c) = m_cov.sill_m2 * m_cov.correlation(std::sqrt(d2));
            }
        }
    }
    const Eigen::VectorXd kAlpha = k.transpose() * m_alpha;
    m_llt.matrixL().solveInPlace(k);                 // k <- L^-1 k
    const Eigen::MatrixXd Wk = m_W.transpose() * k;  // A^T K^-1 k, p x t
    mean.resize(size_t(t));
    var.resize(size_t(t));
    std::vector<double> a(static_cast<size_t>(p));
    const double c0 = m_cov.sill_m2 + m_cov.nugget_m2;
    for (int c = 0; c < t; c++) {
        basis(ci[size_t(c)], cj[size_t(c)], a.data());
        Eigen::VectorXd u(p);
        double trend = 0;
        for (int q = 0; q < p; q++) {
            u[q] = a[size_t(q)] - Wk(q, c);
            trend += a[size_t(q)] * (q == 0 ? m_trend.c0_m : m_trend.terms[size_t(q - 1)].c_m);
        }
        mean[size_t(c)] = trend + kAlpha[c];
        const double v = c0 - k.col(c).squaredNorm() + u.dot(m_Ginv * u);
        var[size_t(c)] = m_scale * std::max(v, 0.0);
    }
}

}  // namespace multibin::fill
