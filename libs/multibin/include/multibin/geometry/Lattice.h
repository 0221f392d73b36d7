/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <vector>

namespace multibin {

/** Cell window in integer cell indices: cells ix0 .. ix0+nx-1, iy0 .. iy0+ny-1. Cell (ix, iy)
 * covers [ix, ix+1) x [iy, iy+1) * cellSize [m]: the lattice is anchored to the map origin, so
 * moving or growing the window never resamples a cell. */
struct CellWindow {
    int ix0 = 0, iy0 = 0;
    int nx = 0, ny = 0;
    bool contains(int ix, int iy) const {
        return ix >= ix0 && iy >= iy0 && ix < ix0 + nx && iy < iy0 + ny;
    }
    size_t cellCount() const { return size_t(nx) * size_t(ny); }
    bool operator==(const CellWindow& o) const {
        return ix0 == o.ix0 && iy0 == o.iy0 && nx == o.nx && ny == o.ny;
    }
};

/** A window of cells with their size: the one lattice of the library (grid, gap filling,
 * evaluation, exporters). Cell (ix, iy) covers [ix, ix+1) x [iy, iy+1) * cellSize_m [m]; column
 * `col` and row `row` of the lattice are cells window.ix0 + col and window.iy0 + row; rasters over
 * it are stored row-major with row 0 the southernmost (smallest y). */
struct Lattice {
    double cellSize_m = 0.02;  //!< cell side [m]
    CellWindow window;         //!< the cells covered

    int nx() const { return window.nx; }
    int ny() const { return window.ny; }
    size_t cellCount() const { return window.cellCount(); }
    /** Row-major index of (col, row): row * nx + col. */
    size_t index(int col, int row) const { return size_t(row) * size_t(window.nx) + size_t(col); }
    bool inside(int col, int row) const {
        return col >= 0 && row >= 0 && col < window.nx && row < window.ny;
    }
    /** Centre of column `col` / row `row` [m]. */
    double cellCenterX_m(int col) const { return (window.ix0 + col + 0.5) * cellSize_m; }
    double cellCenterY_m(int row) const { return (window.iy0 + row + 0.5) * cellSize_m; }
    /** Area covered [m]: {xmin, xmax, ymin, ymax}. */
    std::vector<double> area_m() const {
        return {window.ix0 * cellSize_m, (window.ix0 + window.nx) * cellSize_m,
                window.iy0 * cellSize_m, (window.iy0 + window.ny) * cellSize_m};
    }
    /** Column/row of the cell containing (x, y) [m]; false if outside the lattice (or NaN). */
    bool cellOf(double x_m, double y_m, int& col, int& row) const;
    bool operator==(const Lattice& o) const {
        return cellSize_m == o.cellSize_m && window == o.window;
    }
};

}  // namespace multibin
