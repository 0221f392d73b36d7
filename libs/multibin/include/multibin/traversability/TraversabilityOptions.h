/* Part of the multibin elevation-mapping library. */
#pragma once

#include <string>

#include "multibin/io/OptionsFwd.h"

namespace multibin::traversability {

/** Limits of a robot and how the traversability layers are computed (ini section
 * `<section>_multiBinElevationMap_NN_traversabilityOpts`; doc/traversability.md). The defaults
 * are the hexapod preset (ini/traversability-hexapod.ini). */
struct TraversabilityOptions {
    /** [radius_m] radius of the disc around a cell's centre the features describe [m] */
    double radius_m = 0.05;
    /** [max_step_m] a disc whose highest and lowest surface differ by more is untraversable [m] */
    double max_step_m = 0.08;
    /** [max_slope_deg] a disc whose least-squares plane is steeper is untraversable [deg] */
    double max_slope_deg = 35.0;
    /** [max_roughness_m] a disc whose RMS residual about that plane is larger is untraversable
     * [m] */
    double max_roughness_m = 0.02;
    /** Where a foot can rest (the foothold layer). */
    struct Foothold {
        /** [foot_radius_m] radius of a foot: the disc that must be flat for a foothold [m] */
        double radius_m = 0.02;
        /** [foothold_flatness_m] largest height range under the foot of a good foothold [m] */
        double flatness_m = 0.01;
        /** [foothold_clearance_m] margin around the foot that must hold no step above max_step_m
         * [m] */
        double clearance_m = 0.02;
    } foothold;
    /** [samples_per_cell] surface samples per cell side (the sub-cell surface at k x k points of
     * each cell) [-] */
    int samples_per_cell = 2;
    /** [monte_carlo_draws] draws of the map's height errors per cell [-] */
    int monte_carlo_draws = 128;
    /** [linear_uncertainty] the features' sigmas and P(untraversable) by linear propagation of the
     * samples' errors through the features (Gaussian, closed form) instead of Monte Carlo draws;
     * the foothold too */
    bool linear_uncertainty = false;
    /** [min_known_fraction] a cell whose disc has a smaller share of known samples is unknown
     * [-] */
    double min_known_fraction = 0.5;
    /** [use_bins] whether the certain bins a cell holds beside its surface count as surface for
     * the step (a step inside the cell that the cell's one height flattens) */
    bool use_bins = true;
    /** [bin_min_certainty_share] such a bin counts only with at least this share of the
     * surface's certainty (a stray return or a mixed pixel makes a bin of its own) [-] */
    double bin_min_certainty_share = 0.25;

    /** How a feature of the map relates to the truth's at the map's resolution: the truth's
     * feature is bias + gain x the map's, give or take a Gaussian error of sigma model_sigma
     * (what the lattice cannot resolve), on top of the map's own uncertainty. Identity (0, 1, 0)
     * by default; the presets carry a fit on the tuning boards (doc/traversability.md). */
    struct FeatureCalibration {
        double bias = 0;         //!< [m] or [deg]
        double gain = 1;         //!< [-]
        double model_sigma = 0;  //!< [m] or [deg]
        double apply(double mapFeature) const { return bias + gain * mapFeature; }
    };
    FeatureCalibration step;       //!< [step_bias_m, step_gain, step_model_sigma_m]
    FeatureCalibration slope;      //!< [slope_bias_deg, slope_gain, slope_model_sigma_deg]
    FeatureCalibration roughness;  //!< [roughness_bias_m, roughness_gain, roughness_model_sigma_m]
    /** [step_roughness_gain] the truth's step also grows with the map's roughness by this much
     * (relief finer than the lattice, gaps between stones, shows in the roughness before the
     * step) [m/m]; 0 by default. */
    double step_roughness_gain = 0;
    /** [step_slope_gain] and with the map's slope by this much (a tilted disc's range, which
     * outliers do not make) [m/deg]; 0 by default. */
    double step_slope_gain = 0;

    /** These options with the identity calibration (the map's features are the truth's). */
    TraversabilityOptions uncalibrated() const;

    /** The radius of the largest disc any layer reads [m]. */
    double reach_m() const;

    /** Reads the keys through a strict reader of the section they live in (the caller owns the
     * reader and calls finish()); absent keys keep their value. Then validate(). */
    void read(StrictConfigSection& section);
    /** Reads a section holding only these keys (unknown keys are an error). */
    void loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                            const std::string& section);
    /** Writes every key to `section`. */
    void write(mrpt::config::CConfigFileBase& target, const std::string& section) const;
    /** Every key and value as one line of text ("radius_m=0.05; ..."): equal texts, equal
     * options. */
    std::string text() const;
    /** Throws std::invalid_argument naming the ini key of the first bad value. */
    void validate() const;
};

}  // namespace multibin::traversability
