/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "Terrain.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace terrain_sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/** Clips the 2D ray o + t d to the box [x0, x1] x [y0, y1] within [t0, t1] (slab method). */
bool clipToBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double x0, double x1, double y0,
               double y1, double& t0, double& t1) {
    for (int a = 0; a < 2; ++a) {
        const double lo = a == 0 ? x0 : y0, hi = a == 0 ? x1 : y1;
        if (std::abs(d[a]) < 1e-15) {
            if (o[a] < lo || o[a] > hi) return false;
            continue;
        }
        double ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}

/** Visits the cells of a grid (cell side s, origin (gx, gy), cells [ix0, ix1) x [iy0, iy1)) that
 * the ray crosses for t in [t0, t1] (Amanatides & Woo), in order; visit(ix, iy, tin, tout)
 * returns true to stop. */
template <class Visit>
void traverse(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double gx, double gy, double s,
              int ix0, int ix1, int iy0, int iy1, double t0, double t1, Visit&& visit) {
    const double tm = 0.5 * (t0 + std::min(t1, t0 + 1e-9));
    int ix = static_cast<int>(std::floor((o.x() + tm * d.x() - gx) / s));
    int iy = static_cast<int>(std::floor((o.y() + tm * d.y() - gy) / s));
    ix = std::clamp(ix, ix0, ix1 - 1);
    iy = std::clamp(iy, iy0, iy1 - 1);
    const int sx = d.x() > 0 ? 1 : -1, sy = d.y() > 0 ? 1 : -1;
    auto nextCross = [&](int i, double g, double oc, double dc, int sgn) {
        if (std::abs(dc) < 1e-15) return kInf;
        const double edge = g + (sgn > 0 ? i + 1 : i) * s;
        return (edge - oc) / dc;
    };
    double tMaxX = nextCross(ix, gx, o.x(), d.x(), sx);
    double tMaxY = nextCross(iy, gy, o.y(), d.y(), sy);
    const double tDx = std::abs(d.x()) < 1e-15 ? kInf : s / std::abs(d.x());
    const double tDy = std::abs(d.y()) < 1e-15 ? kInf : s / std::abs(d.y());
    double tin = t0;
    for (;;) {
        const double tout = std::min({tMaxX, tMaxY, t1});
        if (visit(ix, iy, tin, std::max(tin, tout))) return;
        if (tout >= t1) return;
        if (tMaxX < tMaxY) {
            ix += sx;
            tMaxX += tDx;
        } else {
            iy += sy;
            tMaxY += tDy;
        }
        if (ix < ix0 || ix >= ix1 || iy < iy0 || iy >= iy1) return;
        tin = std::max(tin, tout);
    }
}

}  // namespace

Terrain Terrain::fromBoards(const std::vector<multibin::EsriAsciiGrid>& boards, int tilesX,
                            int tilesY, double margin_m) {
    if (boards.empty()) throw std::invalid_argument("terrain: no boards given");
    if (tilesX < 1 || tilesY < 1)
        throw std::invalid_argument("terrain: tile counts must be positive, got " +
                                    std::to_string(tilesX) + "x" + std::to_string(tilesY));
    if (!(margin_m >= 0)) throw std::invalid_argument("terrain: margin must be >= 0");
    for (size_t b = 0; b < boards.size(); ++b) {
        if (boards[b].cols() < 2 || boards[b].rows() < 2)
            throw std::invalid_argument("terrain: board " + std::to_string(b) +
                                        " has fewer than 2x2 samples");
        if (!boards[b].heights_m.allFinite())
            throw std::invalid_argument("terrain: board " + std::to_string(b) +
                                        " has NODATA samples");
    }
    Terrain t;
    const auto& first = boards.front();
    t.cell_ = first.cellsize_m;
    const int n = std::min(first.cols(), first.rows()) - 1;  // samples per tile side
    t.tileSide_ = n * t.cell_;
    t.tilesX_ = tilesX;
    t.tilesY_ = tilesY;
    const int m = static_cast<int>(std::ceil(margin_m / t.cell_ - 1e-9));
    const int cols = 2 * m + tilesX * n + 1, rows = 2 * m + tilesY * n + 1;
    t.x0_ = -m * t.cell_;
    t.y0_ = -0.5 * tilesY * t.tileSide_ - m * t.cell_;
    t.h_.setZero(rows, cols);
    double sum = 0;
    size_t count = 0;
    for (int r = 0; r <= tilesY * n; ++r) {
        const int ty = std::min(r / n, tilesY - 1), j = r - ty * n;
        for (int k = 0; k <= tilesX * n; ++k) {
            const int tx = std::min(k / n, tilesX - 1), i = k - tx * n;
            const auto& b = boards[(ty * tilesX + tx) % boards.size()];
            const double bx = b.xllcenter_m + std::min(i * t.cell_, b.xMax_m() - b.xllcenter_m);
            const double by = b.yllcenter_m + std::min(j * t.cell_, b.yMax_m() - b.yllcenter_m);
            const double z = b.interpolate(bx, by);
            t.h_(m + r, m + k) = static_cast<float>(z);
            sum += z;
            ++count;
        }
    }
    t.meanTile_ = sum / count;
    t.buildBlocks();
    return t;
}

Terrain Terrain::fromSamples(const Eigen::MatrixXf& heights_m, double x0_m, double y0_m,
                             double cell_m) {
    if (heights_m.rows() < 2 || heights_m.cols() < 2 || !(cell_m > 0) || !heights_m.allFinite())
        throw std::invalid_argument("terrain: need >= 2x2 finite samples and a positive cell");
    Terrain t;
    t.h_ = heights_m;
    t.x0_ = x0_m;
    t.y0_ = y0_m;
    t.cell_ = cell_m;
    t.buildBlocks();
    return t;
}

Terrain Terrain::withSamples(const Eigen::MatrixXf& heights_m) const {
    if (heights_m.rows() != h_.rows() || heights_m.cols() != h_.cols() || !heights_m.allFinite())
        throw std::invalid_argument("terrain: replacement samples must be finite, same shape");
    Terrain t = *this;
    t.h_ = heights_m;
    t.buildBlocks();
    return t;
}

void Terrain::buildBlocks() {
    zMin_ = std::min(0.0, double(h_.minCoeff()));
    zMax_ = std::max(0.0, double(h_.maxCoeff()));
    const int ncx = h_.cols() - 1, ncy = h_.rows() - 1;
    const int nbx = (ncx + kBlock - 1) / kBlock, nby = (ncy + kBlock - 1) / kBlock;
    blockMax_.resize(nby, nbx);
    for (int by = 0; by < nby; ++by)
        for (int bx = 0; bx < nbx; ++bx) {
            const int r0 = by * kBlock, c0 = bx * kBlock;
            const int nr = std::min(kBlock, ncy - r0) + 1, nc = std::min(kBlock, ncx - c0) + 1;
            blockMax_(by, bx) = h_.block(r0, c0, nr, nc).maxCoeff();
        }
}

double Terrain::height(double x_m, double y_m) const {
    const double fx = (x_m - x0_) / cell_, fy = (y_m - y0_) / cell_;
    if (!(fx >= 0 && fy >= 0 && fx <= h_.cols() - 1 && fy <= h_.rows() - 1)) return 0.0;
    const int i = std::min(static_cast<int>(fx), int(h_.cols()) - 2);
    const int j = std::min(static_cast<int>(fy), int(h_.rows()) - 2);
    const double u = fx - i, v = fy - j;
    return (1 - u) * (1 - v) * h_(j, i) + u * (1 - v) * h_(j, i + 1) + (1 - u) * v * h_(j + 1, i) +
           u * v * h_(j + 1, i + 1);
}

Eigen::Vector3d Terrain::normal(double x_m, double y_m) const {
    const double e = cell_;
    const double gx = (height(x_m + e, y_m) - height(x_m - e, y_m)) / (2 * e);
    const double gy = (height(x_m, y_m + e) - height(x_m, y_m - e)) / (2 * e);
    return Eigen::Vector3d(-gx, -gy, 1.0).normalized();
}

int Terrain::surfaceId(double x_m, double y_m) const {
    if (tilesX_ == 0) return 0;
    const double fx = x_m / tileSide_, fy = (y_m + 0.5 * tilesY_ * tileSide_) / tileSide_;
    if (!(fx >= 0 && fy >= 0 && fx < tilesX_ && fy < tilesY_)) return 0;
    return 1 + static_cast<int>(fy) * tilesX_ + static_cast<int>(fx);
}

double Terrain::hitInCell(int ix, int iy, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                          double t0, double t1) const {
    const double h00 = h_(iy, ix), h10 = h_(iy, ix + 1), h01 = h_(iy + 1, ix),
                 h11 = h_(iy + 1, ix + 1);
    const double b = h10 - h00, e = h01 - h00, g = h11 - h10 - h01 + h00;
    const Eigen::Vector3d p = o + t0 * d;
    const double u0 = (p.x() - (x0_ + ix * cell_)) / cell_,
                 v0 = (p.y() - (y0_ + iy * cell_)) / cell_;
    const double du = d.x() / cell_, dv = d.y() / cell_;
    // Height along the ray, h(s) = A + B s + C s^2 with s = t - t0: bilinear in (u, v), both
    // linear in s. f(s) = z(s) - h(s) = qc + qb s + qa s^2; the hit is its first root.
    const double A = h00 + b * u0 + e * v0 + g * u0 * v0;
    const double B = b * du + e * dv + g * (u0 * dv + v0 * du);
    const double C = g * du * dv;
    const double qc = p.z() - A, qb = d.z() - B, qa = -C;
    if (qc <= 0) return t0;  // entered below the surface: wall at the lattice edge, or start
    const double T = t1 - t0;
    double best = kInf;
    auto consider = [&](double s) {
        if (s >= 0 && s <= T * (1 + 1e-12) + 1e-15 && s < best) best = s;
    };
    if (std::abs(qa) < 1e-12 * (std::abs(qb) + 1e-12)) {
        if (qb < 0) consider(-qc / qb);
    } else {
        const double disc = qb * qb - 4 * qa * qc;
        if (disc >= 0) {
            const double sq = std::sqrt(disc);
            const double q = -0.5 * (qb + (qb >= 0 ? sq : -sq));  // stable roots
            if (q != 0) consider(qc / q);
            consider(q / qa);
        }
    }
    return best == kInf ? kInf : t0 + std::min(best, T);
}

double Terrain::castRay(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                        double maxRange_m) const {
    // The plane z = 0 outside the lattice.
    double tPlane = kInf;
    if (d.z() < 0 && o.z() >= 0) tPlane = -o.z() / d.z();
    double ta = 0, tb = maxRange_m;
    bool inLattice = clipToBox(o, d, x0_, xMax_m(), y0_, yMax_m(), ta, tb);
    auto planeOutside = [&](double t) {
        if (t > maxRange_m) return false;
        const double x = o.x() + t * d.x(), y = o.y() + t * d.y();
        return !(x >= x0_ && x <= xMax_m() && y >= y0_ && y <= yMax_m());
    };
    if (tPlane < kInf && planeOutside(tPlane) && (!inLattice || tPlane < ta)) return tPlane;
    if (inLattice) {
        // Only where the ray is below the highest sample can it hit; below the lowest it has.
        if (std::abs(d.z()) < 1e-15) {
            if (o.z() > zMax_) inLattice = false;
        } else {
            const double tTop = (zMax_ - o.z()) / d.z(), tBottom = (zMin_ - o.z()) / d.z();
            if (d.z() < 0) {
                ta = std::max(ta, tTop);
                tb = std::min(tb, tBottom + 1e-9);
            } else {
                tb = std::min(tb, tTop);
            }
            inLattice = ta <= tb;
        }
    }
    if (inLattice) {
        const int ncx = h_.cols() - 1, ncy = h_.rows() - 1;
        const int nbx = blockMax_.cols(), nby = blockMax_.rows();
        double hit = kInf;
        traverse(o, d, x0_, y0_, kBlock * cell_, 0, nbx, 0, nby, ta, tb,
                 [&](int bx, int by, double tin, double tout) {
                     const double zLow = std::min(o.z() + tin * d.z(), o.z() + tout * d.z());
                     if (zLow > blockMax_(by, bx)) return false;
                     const int cx0 = bx * kBlock, cy0 = by * kBlock;
                     traverse(o, d, x0_, y0_, cell_, cx0, std::min(cx0 + kBlock, ncx), cy0,
                              std::min(cy0 + kBlock, ncy), tin, tout,
                              [&](int ix, int iy, double cin, double cout) {
                                  hit = hitInCell(ix, iy, o, d, cin, cout);
                                  return hit < kInf;
                              });
                     return hit < kInf;
                 });
        if (hit < kInf) return hit;
    }
    if (tPlane < kInf && planeOutside(tPlane)) return tPlane;
    return kInf;
}

multibin::EsriAsciiGrid Terrain::groundTruth(double cell_m) const {
    if (!(cell_m > 0)) throw std::invalid_argument("ground truth: cell size must be positive");
    const int i0 = static_cast<int>(std::ceil(x0_ / cell_m - 1e-9));
    const int i1 = static_cast<int>(std::floor(xMax_m() / cell_m + 1e-9));  // exclusive
    const int j0 = static_cast<int>(std::ceil(y0_ / cell_m - 1e-9));
    const int j1 = static_cast<int>(std::floor(yMax_m() / cell_m + 1e-9));
    if (i1 <= i0 || j1 <= j0)
        throw std::invalid_argument("ground-truth cell size " + std::to_string(cell_m) +
                                    " m is larger than the terrain");
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(j1 - j0, i1 - i0);
    Eigen::MatrixXi count = Eigen::MatrixXi::Zero(j1 - j0, i1 - i0);
    for (int r = 0; r < h_.rows(); ++r) {
        const int gj = static_cast<int>(std::floor((y0_ + r * cell_) / cell_m + 1e-9)) - j0;
        if (gj < 0 || gj >= j1 - j0) continue;
        for (int k = 0; k < h_.cols(); ++k) {
            const int gi = static_cast<int>(std::floor((x0_ + k * cell_) / cell_m + 1e-9)) - i0;
            if (gi < 0 || gi >= i1 - i0) continue;
            sum(gj, gi) += h_(r, k);
            count(gj, gi)++;
        }
    }
    multibin::EsriAsciiGrid g;
    g.cellsize_m = cell_m;
    g.xllcenter_m = (i0 + 0.5) * cell_m;
    g.yllcenter_m = (j0 + 0.5) * cell_m;
    g.heights_m.resize(j1 - j0, i1 - i0);
    for (int r = 0; r < g.rows(); ++r)
        for (int c = 0; c < g.cols(); ++c)
            g.heights_m(r, c) = count(r, c) > 0 ? static_cast<float>(sum(r, c) / count(r, c))
                                                : std::numeric_limits<float>::quiet_NaN();
    return g;
}

}  // namespace terrain_sim
