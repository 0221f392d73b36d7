/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/traversability/TraversabilityOptions.h"

namespace multibin::traversability {

/** The features of one disc of surface, with the definitions of doc/traversability.md: `step`
 * the highest minus the lowest height, `slope` the inclination of the least-squares plane z = a
 * + b x + c y, `roughness` the RMS residual about that plane. */
struct DiscFeatures {
    double step_m = 0, slope_deg = 0, roughness_m = 0;
};

/** The least-squares plane z = mh + g . ((x, y) - (mx, my)) of a disc's points, and their
 * centred second moments (cxx = sum (x - mx)^2, ...). */
struct DiscPlane {
    double mx_m = 0, my_m = 0, mh_m = 0;  //!< the points' mean offset and height [m]
    double gx = 0, gy = 0;                //!< the gradient [-]
    double cxx = 0, cxy = 0, cyy = 0;     //!< [m^2]
    double rss_m2 = 0;                    //!< residual sum of squares about the plane [m^2]
};

/** Half the range of relief of variance var spread uniformly: sqrt(3 var) [m]. */
inline double reliefHalfWidth_m(double variance_m2) { return std::sqrt(3 * variance_m2); }

/** Accumulates points of a disc (offsets from its centre [m] and heights [m]) and gives their
 * DiscFeatures: the one home of the feature definitions, for the map's surface and the truth's. */
class DiscAccumulator {
public:
    void add(double dx_m, double dy_m, double h_m);
    /** A point with the relief it stands for: heights spread uniformly with variance
     * reliefVariance_m2 about h_m (inside a cell, below the lattice); it adds that variance to
     * the roughness and its range (h +- sqrt(3 var)) to the step. */
    void add(double dx_m, double dy_m, double h_m, double reliefVariance_m2);
    /** A height that counts for the step only (a bin beside a cell's surface) [m]. */
    void addStepOnly(double h_m);
    size_t count() const { return m_n; }
    /** False with fewer than 3 points or collinear ones (no plane). */
    bool features(DiscFeatures& out) const;
    /** The plane features() reads; false as features(). */
    bool plane(DiscPlane& out) const;
    double reliefSum_m2() const { return m_relief; }

private:
    size_t m_n = 0;
    double m_sx = 0, m_sy = 0, m_sxx = 0, m_sxy = 0, m_syy = 0;  // geometry of the points
    double m_h0 = 0;                                             // first height (conditioning)
    double m_sh = 0, m_sxh = 0, m_syh = 0, m_shh = 0;
    double m_max = -1e300, m_min = 1e300;
    double m_relief = 0;  // sum of the points' relief variances [m^2]
};

/** The map's surface as the traversability layers read it: k x k samples per cell of a lattice
 * (the sub-cell surface at sample (sc, sr), at ((sc + 0.5) / k, (sr + 0.5) / k) cells from the
 * lattice's corner), each with the sigma of its error apart from what all samples share (the pose
 * part: a common offset, which no feature sees); and per cell the certain bins beside its surface
 * (the lowest and the highest), which the step reads. The errors of one cell's samples are one
 * error (one plane per cell); those of different cells are independent. */
struct SurfaceSamples {
    Lattice lattice;
    int perCell = 2;              //!< k: samples per cell side
    std::vector<float> height_m;  //!< (ny k) x (nx k), row-major from the south-west; NaN unknown
    std::vector<float> sigma_m;   //!< 1-sigma of each sample [m]
    std::vector<float> binLow_m;  //!< per cell: the lowest other certain bin [m]; NaN if none
    std::vector<float> binLowSigma_m;
    std::vector<float> binHigh_m;  //!< per cell: the highest other certain bin [m]; NaN if none
    std::vector<float> binHighSigma_m;
    /** per cell: the variance of its surface's points about their plane beyond their noise
     * (relief finer than the samples) [m^2]; 0 if none or unknown */
    std::vector<float> relief_m2;

    SurfaceSamples() = default;
    /** Every sample unknown, no bins. */
    SurfaceSamples(const Lattice& lattice, int perCell);
    int sx() const { return lattice.nx() * perCell; }  //!< sample columns
    int sy() const { return lattice.ny() * perCell; }  //!< sample rows
    size_t sampleIndex(int sc, int sr) const { return size_t(sr) * size_t(sx()) + size_t(sc); }
    /** Copies the cells of `o` that lie inside this lattice (same cell size and k). */
    void copyFrom(const SurfaceSamples& o);
    /** Sets all k x k samples of cell (col, row) to one height and sigma (a filled cell). */
    void setCell(int col, int row, float h_m, float sigma_m);
};

/** What the traversability layers say of each cell of a lattice. NaN where unknown (a cell never
 * seen and not filled, or whose disc is mostly unknown): unknown is a state of its own, neither
 * safe nor forbidden. */
struct TraversabilityLayers {
    Lattice lattice;
    std::vector<float> step_m, stepSigma_m;            //!< [m]
    std::vector<float> slope_deg, slopeSigma_deg;      //!< [deg]
    std::vector<float> roughness_m, roughnessSigma_m;  //!< [m]
    /** P(step > max_step_m or slope > max_slope_deg or roughness > max_roughness_m) [-] */
    std::vector<float> untraversable;
    /** P(a foot of foothold.radius_m here rests on ground flat within foothold.flatness_m, with no
     * step above max_step_m within foothold.clearance_m of it) [-] */
    std::vector<float> foothold;

    TraversabilityLayers() = default;
    /** Every cell unknown. */
    explicit TraversabilityLayers(const Lattice& lattice);
    bool known(size_t k) const { return untraversable[k] == untraversable[k]; }
    size_t size() const { return untraversable.size(); }
    /** Copies the cells of `o` that lie inside this lattice (same cell size). */
    void copyFrom(const TraversabilityLayers& o);
};

/** Computes the layers of the cells whose `cellMask` entry is non-zero (one per cell of
 * samples.lattice, row-major; all cells if empty) into `out` (on samples.lattice), from the samples
 * within options.reach_m() of each cell's centre. Each feature is that of the map's surface (the
 * samples' heights and the bins); its sigma and the probabilities are Monte Carlo over
 * options.monte_carlo_draws draws of the samples' errors (fixed draws: the same map gives the same
 * layers). With 0 draws the probabilities are the thresholded features (0 or 1) and the sigmas 0.
 * With options.linear_uncertainty, the sigmas and probabilities are propagated linearly instead
 * (closed form, no draws; doc/traversability.md).
 */
void computeLayers(const SurfaceSamples& samples, const TraversabilityOptions& options,
                   TraversabilityLayers& out, const std::vector<uint8_t>& cellMask = {});

/** `mask` (nx x ny, row-major) grown by `cells` cells each way (a square), for the cells whose
 * layers a change can reach. */
std::vector<uint8_t> dilateMask(const std::vector<uint8_t>& mask, int nx, int ny, int cells);

}  // namespace multibin::traversability
