/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/io/EsriAsciiGrid.h"

namespace multibin::eval {

/** Per-cell layer of the evaluation lattice [m]; NaN where a method has no value. Row = y index
 * (south to north), column = x index. */
using CellArray = Eigen::ArrayXXf;

/** Ground truth on the lattice: a cell's truth is the mean of the truth samples whose centres lie
 * inside it; NaN where none does. The lattice covers exactly the cells that hold samples. */
CellArray groundTruthOnLattice(const EsriAsciiGrid& truth, double cellSize_m, Lattice& latticeOut);

/** The cells of `lattice` whose centres lie inside area_m = {xmin, xmax, ymin, ymax} [m] (to
 * evaluate over part of the truth, e.g. a mock-up without the floor around it). Throws
 * std::invalid_argument naming the problem if the area is malformed or holds no cell centre. */
Lattice subLattice(const Lattice& lattice, const std::vector<double>& area_m);

/** The raw map of eq 17: range points simply registered in the grid, a cell's value being the
 * mean of the points that fall in it. */
class RawPointGrid {
public:
    explicit RawPointGrid(const Lattice& lattice);
    void addPoint(double x_m, double y_m, double z_m);
    CellArray heights_m() const;  //!< mean height per cell, NaN where no point fell

private:
    Lattice m_lattice;
    Eigen::ArrayXXd m_sum_m;
    Eigen::ArrayXXi m_count;
};

/** One method's estimate over the lattice, with what it took to make it. */
struct MethodEstimate {
    std::string name;
    CellArray height_m;
    CellArray sigma_m;     //!< empty (0 x 0) when the method gives no sigma
    std::string baseline;  //!< the raw method that is this method's PI denominator (eq 17)
    double insert_s = 0;   //!< wall time to insert [s]
    double fill_s = 0;     //!< wall time to fill [s]
    /** false for a method built on a crop only (MRPT's GMRF map): its PI divides by the raw
     * map's error over its crop, and it does not narrow the cells every method covers
     * (`pi_shared`) to its crop. */
    bool coversWholeArea = true;
    /** Optional: the method whose valid cells are this one's measured cells (a filled map's
     * unfilled twin); its other valid cells, the filled-only ones, are scored apart. */
    std::string filledFrom;
};

/** Mean squared error over the cells where both the estimate and the truth are finite (and the
 * optional mask is true). */
struct SquaredError {
    double mse_m2 = 0;
    size_t cells = 0;
};
SquaredError meanSquaredError(
    const CellArray& estimate_m, const CellArray& truth_m,
    const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>* mask = nullptr);

/** Eq 17: PI = [sum o_f (h_f - h_t)^2 / N_f] / [sum o_r (h_r - h_t)^2 / N_r]; NaN if the raw map
 * has no valid cell or zero error. */
double performanceIndex(const SquaredError& method, const SquaredError& raw);

/** What the evaluation reports for one method (report.json). */
struct MethodScore {
    double rmse_m = 0;
    double pi = 0;        //!< eq 17 over each map's own valid cells
    double piShared = 0;  //!< eq 17 over the cells every whole-area method covers (and, for a
                          //!< crop-only method, inside its crop)
    double coverage = 0;  //!< share of truth cells with an estimate
    std::optional<double> within3Sigma;  //!< share of valid cells with |h - h_t| <= 3 sigma
    size_t validCells = 0;
    /** The same share over the filled-only cells (valid here, not in MethodEstimate::filledFrom),
     * and their count; set only for a method with filledFrom and a sigma. */
    std::optional<double> within3SigmaFilledOnly;
    size_t filledOnlyCells = 0;
    std::optional<double> rmseFilledOnly_m;  //!< RMSE over the same filled-only cells [m]
    double insert_s = 0, fill_s = 0;
};

/** Scores every method against the truth. Every method's `baseline` must name a method of the
 * list (raw methods name themselves, or nothing). */
std::map<std::string, MethodScore> scoreMethods(const CellArray& truth_m,
                                                const std::vector<MethodEstimate>& methods);

/** Errors of every method over some cells only: a sub-area (the crop MRPT's GMRF map is solved
 * on) or the cells another method leaves without a value (the gaps of MRPT's height grid). */
struct AreaScores {
    std::string name;            //!< what the cells are, e.g. "mrf_crop"
    std::vector<double> area_m;  //!< {xmin, xmax, ymin, ymax} [m] of a sub-area; empty otherwise
    std::map<std::string, SquaredError> errors;
};
/** Scores the methods over the cells of `area` (a sub-lattice of `lattice`). */
AreaScores scoreArea(const std::string& name, const CellArray& truth_m,
                     const std::vector<MethodEstimate>& methods, const Lattice& lattice,
                     const Lattice& area);
/** Scores the methods over the truth cells where the method `gapsOf` has no value. */
AreaScores scoreGapsOf(const std::string& gapsOf, const CellArray& truth_m,
                       const std::vector<MethodEstimate>& methods);

/** report.json: {"methods": {name: {rmse_m, pi, pi_shared, coverage, within_3sigma, insert_s,
 * fill_s, valid_cells[, within_3sigma_filled_only, rmse_filled_only_m, filled_only_cells]}},
 * "cell_size_m", "area_m": [xmin, xmax, ymin, ymax]}; methods in `order`. Each AreaScores adds
 * {"<name>": {["area_m": [...], ]"rmse_m": {method: x}, "cells": {method: n}}}.
 */
std::string reportJson(const std::map<std::string, MethodScore>& scores,
                       const std::vector<std::string>& order, const Lattice& lattice,
                       const std::vector<AreaScores>& areas = {});
/** The same numbers as a fixed-width text table. */
std::string reportTable(const std::map<std::string, MethodScore>& scores,
                        const std::vector<std::string>& order,
                        const std::vector<AreaScores>& areas = {});

}  // namespace multibin::eval
