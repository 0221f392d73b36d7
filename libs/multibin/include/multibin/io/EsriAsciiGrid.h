/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <string>

#include "multibin/geometry/Lattice.h"

namespace multibin {

/** A height raster in ESRI ASCII grid format (GDAL driver AAIGrid).
 *
 * Row 0 of `heights_m` is the SOUTHERNMOST row (smallest y), unlike the file, whose first row is
 * the largest y: `heights_m(row, col)` is the sample centred at
 * (xllcenter + col * cellsize, yllcenter + row * cellsize). NODATA samples are NaN in memory. */
struct EsriAsciiGrid {
    Eigen::MatrixXf heights_m;    //!< [m], rows = y (south to north), cols = x
    double xllcenter_m = 0;       //!< x of the centre of the lower-left sample [m]
    double yllcenter_m = 0;       //!< y of the centre of the lower-left sample [m]
    double cellsize_m = 1;        //!< sample spacing [m]
    double nodata_value = -9999;  //!< written for NaN samples

    /** A raster with one NaN sample at the centre of every cell of `lattice`. */
    static EsriAsciiGrid onLattice(const Lattice& lattice);

    int cols() const { return static_cast<int>(heights_m.cols()); }
    int rows() const { return static_cast<int>(heights_m.rows()); }
    double xMax_m() const { return xllcenter_m + (cols() - 1) * cellsize_m; }
    double yMax_m() const { return yllcenter_m + (rows() - 1) * cellsize_m; }

    /** Bilinear interpolation at (x, y) [m]; NaN outside the sample lattice or next to NODATA. */
    double interpolate(double x_m, double y_m) const;

    /** Reads a file; throws std::runtime_error naming the file and the problem (missing header
     * key, wrong number of values, non-numeric value, non-positive cell size). */
    static EsriAsciiGrid load(const std::string& path);
    /** Writes a file (heights with 6 decimals, NaN as NODATA); throws on I/O failure. */
    void save(const std::string& path) const;
};

}  // namespace multibin
