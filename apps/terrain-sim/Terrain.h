/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include <multibin/io/EsriAsciiGrid.h>

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace terrain_sim {

/** A seamless heightfield built from scanned boards tiled side by side, surrounded by flat ground.
 *
 * Map frame: +x forward, +y left, +z up [m]. The tiled area spans x in [0, tilesX * L] and
 * y in [-tilesY * L / 2, +tilesY * L / 2], L being the board side (512 samples of the first
 * board's spacing). Boards are placed in row-major order, cycling through the list. Outside the
 * tiles the ground is the plane z = 0: within `margin_m` of the tiles it is stored as zero samples
 * (so ground truth and ray casting see one lattice), beyond that it is analytic. */
class Terrain {
public:
    /** Tiles `boards` (cycled) into tilesX x tilesY tiles with a flat margin [m] around them.
     * Boards whose spacing differs from the first board's are resampled bilinearly at their own
     * physical coordinates (so their size in metres is kept; a larger board is cropped). Throws
     * std::invalid_argument on an empty board list, non-positive tile counts or NODATA samples. */
    static Terrain fromBoards(const std::vector<multibin::EsriAsciiGrid>& boards, int tilesX,
                              int tilesY, double margin_m);

    /** A terrain given directly by its samples (tests): heights_m(row = y, col = x), sample (0,0)
     * at (x0_m, y0_m), spacing cell_m; no tiles (every sample is surface 0). */
    static Terrain fromSamples(const Eigen::MatrixXf& heights_m, double x0_m, double y0_m,
                               double cell_m);

    /** The same terrain (lattice, tiles, surfaces) with other samples, e.g. an object drawn in
     * (random scenes). `heights_m` must have the lattice's shape. */
    Terrain withSamples(const Eigen::MatrixXf& heights_m) const;

    /** Bilinear height [m] at (x, y) [m]; 0 outside the sample lattice. */
    double height(double x_m, double y_m) const;
    /** Unit surface normal (map frame) from central differences of height(). */
    Eigen::Vector3d normal(double x_m, double y_m) const;

    /** Distance [m] along the unit direction `dir` from `origin` to the first intersection with
     * the surface (bilinear patches solved exactly, then the plane z = 0 beyond the lattice), or
     * +infinity if there is none within maxRange_m. */
    double castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                   double maxRange_m) const;

    /** Surface index at (x, y): 1 + tile index on a tile, 0 on the flat ground. */
    int surfaceId(double x_m, double y_m) const;
    int surfaceCount() const { return tilesX_ * tilesY_ + 1; }

    /** Ground truth at `cell_m`: cells aligned at multiples of cell_m (cell i covers
     * [i * cell_m, (i+1) * cell_m), as the map's grid), covering the sample lattice; a cell's value
     * is the mean of the lattice samples whose position lies inside it (board samples on the
     * tiles, zero samples on the flat margin). Cells only partly covered by the lattice are left
     * out. */
    multibin::EsriAsciiGrid groundTruth(double cell_m) const;

    const Eigen::MatrixXf& samples_m() const { return h_; }
    double x0_m() const { return x0_; }
    double y0_m() const { return y0_; }
    double cell_m() const { return cell_; }
    double tileSide_m() const { return tileSide_; }
    int tilesX() const { return tilesX_; }
    int tilesY() const { return tilesY_; }
    double xMax_m() const { return x0_ + (h_.cols() - 1) * cell_; }
    double yMax_m() const { return y0_ + (h_.rows() - 1) * cell_; }
    /** Mean height of the tiled area's samples [m] (0 with no tiles). */
    double meanTileHeight_m() const { return meanTile_; }

private:
    void buildBlocks();
    /** First hit inside lattice cell (ix, iy) for t in [t0, t1]; +inf if none. */
    double hitInCell(int ix, int iy, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t0,
                     double t1) const;

    Eigen::MatrixXf h_;  // [m], rows = y, cols = x
    double x0_ = 0, y0_ = 0, cell_ = 1;
    double zMin_ = 0, zMax_ = 0;
    int tilesX_ = 0, tilesY_ = 0;
    double tileSide_ = 0;
    double meanTile_ = 0;
    static constexpr int kBlock = 16;  // cells per block side of the coarse max-height level
    Eigen::MatrixXf blockMax_;         // max sample height per block [m]
};

}  // namespace terrain_sim
