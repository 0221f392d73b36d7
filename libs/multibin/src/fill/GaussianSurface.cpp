/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/GaussianSurface.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace multibin::fill {

double GaussianSurface::operator()(double i, double j) const {
    double h = c0_m;
    for (const auto& t : terms)
        h += t.c_m *
             std::exp(t.lambda1 * (i - t.a1) * (i - t.a1) + t.lambda2 * (j - t.a2) * (j - t.a2));
    return h;
}

double correctedAic(double chi2, int n, int k) {
    if (n <= k + 1) return std::numeric_limits<double>::infinity();
    // A perfect fit (noise-free data) would give ln 0: floor the mean residual so that ties go to
    // the smaller model through the penalty.
    const double meanChi2 = std::max(chi2 / n, 1e-12);
    return n * std::log(meanChi2) + 2.0 * k + 2.0 * k * (k + 1.0) / (n - k - 1.0);
}

double bayesianCriterion(double chi2, int n, int k) {
    return n * std::log(std::max(chi2 / n, 1e-12)) + k * std::log(double(n));
}

double amplitudePriorPrecision(const std::vector<SurfaceSample>& samples) {
    double lo = samples.at(0).h_m, hi = lo, maxSigma = 0;
    for (const auto& s : samples) {
        lo = std::min(lo, s.h_m), hi = std::max(hi, s.h_m);
        maxSigma = std::max(maxSigma, s.sigma_m);
    }
    const double sigmaC = std::max(hi - lo, 3 * maxSigma);
    return 1.0 / (sigmaC * sigmaC);
}

namespace {

/** Shape parameters of one term in normalised coordinates u = (i - centre) / halfSide:
 * (a1, a2, ln s1, ln s2), s the standard deviation. The swarm searches this space so that the
 * bounds do not depend on the size of the support area. */
constexpr int kShapeParams = 4;

struct Fitter {
    const std::vector<SurfaceSample>& samples;
    int side;
    double centre, halfSide;
    Eigen::VectorXd sqrtW, y;        // sqrt(1/sigma^2), sqrt(w) h
    Eigen::MatrixXd A;               // sqrt(w) * design matrix, n x (m + 1)
    Eigen::MatrixXd rowTab, colTab;  // per term: exp factor for each column / row index
    Eigen::VectorXd c;
    double amplitudePrior = 0;  // 1 / sigma_c^2 [1/m^2]
    double yy = 0;              // |y|^2
    Eigen::MatrixXd G;
    Eigen::VectorXd rhs;
    Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower> ldlt;

    // Excluded box for the centres in normalised coordinates (lo > hi: none).
    double exI0 = 1, exI1 = 0, exJ0 = 1, exJ1 = 0;

    /** Moves a centre (u, v) out of the excluded box, to its nearest side. */
    void project(double& u, double& v) const {
        if (!(exI0 < exI1) || u <= exI0 || u >= exI1 || v <= exJ0 || v >= exJ1) return;
        const double d[4] = {u - exI0, exI1 - u, v - exJ0, exJ1 - v};
        const int k = int(std::min_element(d, d + 4) - d);
        if (k == 0) u = exI0;
        if (k == 1) u = exI1;
        if (k == 2) v = exJ0;
        if (k == 3) v = exJ1;
    }

    Fitter(const std::vector<SurfaceSample>& s, int sideCells)
        : samples(s),
          side(sideCells),
          centre(0.5 * (sideCells - 1)),
          halfSide(std::max(0.5 * sideCells, 1.0)) {
        const int n = int(samples.size());
        sqrtW.resize(n);
        y.resize(n);
        for (int k = 0; k < n; k++) {
            sqrtW[k] = 1.0 / samples[k].sigma_m;
            y[k] = sqrtW[k] * samples[k].h_m;
        }
        amplitudePrior = amplitudePriorPrecision(samples);
        yy = y.squaredNorm();
    }

    /** Amplitudes by weighted least squares for the given shapes; returns chi2. */
    double solve(const double* shape, int m) {
        const int n = int(samples.size());
        rowTab.resize(side, m);
        colTab.resize(side, m);
        // exp(lambda (i - a)^2) factorises per axis: 2 * side exponentials per term, not n.
        for (int q = 0; q < m; q++) {
            const double* p = shape + kShapeParams * q;
            const double s1 = std::exp(p[2]), s2 = std::exp(p[3]);
            const double k1 = -0.5 / (s1 * s1), k2 = -0.5 / (s2 * s2);
            double a1 = p[0], a2 = p[1];
            project(a1, a2);
            for (int i = 0; i < side; i++) {
                const double u = (i - centre) / halfSide;
                rowTab(i, q) = std::exp(k1 * (u - a1) * (u - a1));
                colTab(i, q) = std::exp(k2 * (u - a2) * (u - a2));
            }
        }
        A.resize(n, m + 1);
        for (int k = 0; k < n; k++) {
            const auto& s = samples[k];
            A(k, 0) = sqrtW[k];
            for (int q = 0; q < m; q++) A(k, q + 1) = sqrtW[k] * rowTab(s.i, q) * colTab(s.j, q);
        }
        // Gram matrix plus the amplitude prior (also keeps coincident terms solvable).
        // With c the least-squares solution, |y - A c|^2 + prior |c|^2 = |y|^2 - b^T c: no
        // second pass over the samples. Buffers are members: no allocation per evaluation.
        G.setZero(m + 1, m + 1);
        G.selfadjointView<Eigen::Lower>().rankUpdate(A.transpose());
        G.diagonal().tail(m).array() += amplitudePrior;
        G(0, 0) += 1e-12 * G(0, 0);
        rhs.noalias() = A.transpose() * y;
        ldlt.compute(G);  // reads the lower triangle only
        c = ldlt.solve(rhs);
        return std::max(yy - rhs.dot(c), 0.0);
    }

    /** The residual vector whose squared norm solve() returns (data, then amplitude prior). */
    Eigen::VectorXd residual(const double* shape, int m) {
        solve(shape, m);
        Eigen::VectorXd r(A.rows() + m);
        r.head(A.rows()) = y - A * c;
        r.tail(m) = std::sqrt(amplitudePrior) * c.tail(m);
        return r;
    }

    /** Levenberg-Marquardt polish of the swarm's best shapes (forward-difference Jacobian of the
     * variable-projection residual), kept inside the box. The swarm finds the basin; this finds
     * its bottom, which the swarm alone reaches slowly in 8+ dimensions. */
    void polish(std::vector<double>& shape, double& cost, int m, const std::vector<double>& lo,
                const std::vector<double>& hi, int maxIterations) {
        const int d = int(shape.size());
        double mu = 1e-3;
        Eigen::VectorXd r = residual(shape.data(), m);
        cost = r.squaredNorm();
        Eigen::MatrixXd J(r.size(), d);
        std::vector<double> trial(shape);
        for (int it = 0; it < maxIterations; it++) {
            for (int k = 0; k < d; k++) {
                constexpr double kStep = 1e-6;
                trial = shape;
                trial[k] += kStep;
                J.col(k) = (residual(trial.data(), m) - r) / kStep;
            }
            const Eigen::MatrixXd JtJ = J.transpose() * J;
            const Eigen::VectorXd g = J.transpose() * r;
            bool improved = false;
            for (int tries = 0; tries < 8 && !improved; tries++) {
                Eigen::MatrixXd H = JtJ;
                H.diagonal() += mu * (JtJ.diagonal().array() + 1e-12).matrix();
                const Eigen::VectorXd step = H.ldlt().solve(-g);
                for (int k = 0; k < d; k++)
                    trial[k] = std::clamp(shape[k] + step[k], lo[size_t(k)], hi[size_t(k)]);
                Eigen::VectorXd rt = residual(trial.data(), m);
                const double ct = rt.squaredNorm();
                if (ct < cost) {
                    const double gain = (cost - ct) / cost;
                    shape = trial;
                    r = rt;
                    cost = ct;
                    mu = std::max(mu / 3, 1e-9);
                    improved = true;
                    if (gain < 1e-7) return;  // converged
                } else {
                    mu *= 4;
                }
            }
            if (!improved) return;
        }
    }

    GaussianSurface build(const double* shape, int m) {
        GaussianSurface g;
        solve(shape, m);
        const double chi2 = (y - A * c).squaredNorm();
        g.c0_m = c[0];
        for (int q = 0; q < m; q++) {
            const double* p = shape + kShapeParams * q;
            const double s1 = std::exp(p[2]) * halfSide, s2 = std::exp(p[3]) * halfSide;
            double a1 = p[0], a2 = p[1];
            project(a1, a2);
            g.terms.push_back(GaussianTerm{c[q + 1], -0.5 / (s1 * s1), centre + a1 * halfSide,
                                           -0.5 / (s2 * s2), centre + a2 * halfSide});
        }
        g.samples = int(samples.size());
        g.chi2 = chi2;
        g.aicc = correctedAic(chi2, g.samples, g.parameters());
        g.bic = bayesianCriterion(chi2, g.samples, g.parameters());
        double sw = 0, swr = 0;
        for (const auto& s : samples) {
            const double w = 1.0 / (s.sigma_m * s.sigma_m), r = s.h_m - g(s.i, s.j);
            sw += w;
            swr += w * r * r;
        }
        g.rmsResidual_m = std::sqrt(swr / sw);
        return g;
    }
};

void checkInputs(const std::vector<SurfaceSample>& samples, int side, int m) {
    if (samples.empty()) throw std::invalid_argument("fitGaussianSurface: no samples");
    if (side < 2) throw std::invalid_argument("fitGaussianSurface: side must be >= 2 cells");
    if (m < 0) throw std::invalid_argument("fitGaussianSurface: m must be >= 0");
    for (const auto& s : samples) {
        if (s.i < 0 || s.j < 0 || s.i >= side || s.j >= side)
            throw std::invalid_argument("fitGaussianSurface: sample (" + std::to_string(s.i) +
                                        ", " + std::to_string(s.j) + ") outside the " +
                                        std::to_string(side) + "-cell support area");
        if (!(s.sigma_m > 0) || !std::isfinite(s.h_m))
            throw std::invalid_argument(
                "fitGaussianSurface: sample sigma must be > 0 and height finite");
    }
}

}  // namespace

GaussianSurface fitGaussianSurfaceFixed(const std::vector<SurfaceSample>& samples, int side, int m,
                                        const GaussianFitOptions& options,
                                        const GaussianSurface* seed) {
    checkInputs(samples, side, m);
    Fitter f(samples, side);
    if (options.excludeI0 < options.excludeI1 && options.excludeJ0 < options.excludeJ1) {
        f.exI0 = (options.excludeI0 - f.centre) / f.halfSide;
        f.exI1 = (options.excludeI1 - f.centre) / f.halfSide;
        f.exJ0 = (options.excludeJ0 - f.centre) / f.halfSide;
        f.exJ1 = (options.excludeJ1 - f.centre) / f.halfSide;
    }
    if (m == 0) return f.build(nullptr, 0);

    const double lnMin = std::log(std::max(options.minWidth_cells, 0.3) / f.halfSide);
    const double lnMax = std::log(std::max(options.maxWidthFactor, 0.1) * side / f.halfSide);
    std::vector<double> lo, hi;
    for (int q = 0; q < m; q++) {
        // Centres may sit a little outside the area: a term centred beyond the edge makes a slope.
        lo.insert(lo.end(), {-1.2, -1.2, lnMin, lnMin});
        hi.insert(hi.end(), {1.2, 1.2, std::max(lnMax, lnMin), std::max(lnMax, lnMin)});
    }

    // Seeds: the previous (m - 1)-term fit plus one term at its largest weighted residual, at
    // a few widths; the rest of the swarm starts at random.
    std::vector<std::vector<double>> initial;
    if (seed && int(seed->terms.size()) == m - 1) {
        std::vector<double> base;
        for (const auto& t : seed->terms) {
            base.push_back((t.a1 - f.centre) / f.halfSide);
            base.push_back((t.a2 - f.centre) / f.halfSide);
            base.push_back(std::log(std::sqrt(-0.5 / t.lambda1) / f.halfSide));
            base.push_back(std::log(std::sqrt(-0.5 / t.lambda2) / f.halfSide));
        }
        size_t worst = 0;
        double worstR = -1;
        for (size_t k = 0; k < samples.size(); k++) {
            const double r =
                std::abs(samples[k].h_m - (*seed)(samples[k].i, samples[k].j)) / samples[k].sigma_m;
            if (r > worstR) worstR = r, worst = k;
        }
        const double u = (samples[worst].i - f.centre) / f.halfSide;
        const double v = (samples[worst].j - f.centre) / f.halfSide;
        for (double width_cells : {2.0, 4.0, 0.25 * side}) {
            auto p = base;
            const double ln = std::log(std::max(width_cells, options.minWidth_cells) / f.halfSide);
            p.insert(p.end(), {u, v, ln, ln});
            initial.push_back(p);
        }
    }

    std::vector<double> shape(size_t(kShapeParams * m));
    auto objective = [&](const std::vector<double>& p) { return f.solve(p.data(), m); };
    ParticleSwarmOptions swarm = options.swarm;
    swarm.seed = options.swarm.seed + 7919u * unsigned(m);  // distinct, reproducible per m
    auto best = minimizeParticleSwarm(objective, lo, hi, swarm, initial);
    if (options.polishIterations > 0)
        f.polish(best.x, best.value, m, lo, hi, options.polishIterations);
    return f.build(best.x.data(), m);
}

GaussianSurface fitGaussianSurface(const std::vector<SurfaceSample>& samples, int side,
                                   const GaussianFitOptions& options) {
    auto score = [&](const GaussianSurface& g) {
        return options.criterion == ModelCriterion::BIC ? g.bic : g.aicc;
    };
    GaussianSurface best = fitGaussianSurfaceFixed(samples, side, 0, options);
    GaussianSurface prev = best;
    for (int m = 1; m <= options.maxTerms; m++) {
        if (int(samples.size()) <= 1 + 5 * m + 1) break;  // AICc undefined: too few samples
        GaussianSurface g = fitGaussianSurfaceFixed(samples, side, m, options, &prev);
        if (!(score(g) < score(best))) break;  // the criterion stopped improving
        best = g;
        prev = g;
    }
    return best;
}

}  // namespace multibin::fill
