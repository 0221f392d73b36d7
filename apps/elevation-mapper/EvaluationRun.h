/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/maps/CHeightGridMap2D_MRF.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <memory>
#include <string>
#include <vector>

#include "multibin/eval/Evaluation.h"
#include "multibin/sensors/SensorDispatch.h"

class OutputFolder;

/** Builds, side by side and from the same points, the maps that `--ground-truth` compares:
 * - raw_laser, raw_all: the range points simply registered in the grid (eq 17's raw map), from
 *   the laser alone and from every sensor;
 * - laser_only: a CMultiBinElevationMap with the evaluated map's options fed only laser scans;
 * - multibin, multibin_filled: the evaluated map before and after gap filling;
 * - mrpt_height_grid: MRPT's CHeightGridMap2D fed the same map-frame points;
 * - mrpt_height_grid_mrf (optional): MRPT's CHeightGridMap2D_MRF fed the same points inside a
 *   crop of at most 35 x 35 cells and solved once.
 * The raw points are the evaluated map's sensor geometry (the same sensor models, calibration
 * and mean robot pose) with every rejection rule off (intensity, mixed pixels, continuity,
 * stereo halos and near clusters): what a map that simply registers the range data would get. */
class EvaluationRun {
public:
    struct Options {
        std::string groundTruthPath;
        bool withMrf = false;
        int mrfMaxCells = 35;  //!< side of the MRF crop [cells]
        /** Profile line for the height-profile figure [m]: x0, y0, x1, y1; empty = along x through
         * the middle of the evaluated area. */
        std::vector<double> profile_m;
        /** Evaluate only the truth cells whose centres lie in {xmin, xmax, ymin, ymax} [m];
         * empty = the whole truth. */
        std::vector<double> area_m;
    };

    EvaluationRun(const Options& options, mrpt::maps::CMultiBinElevationMap& evaluated);

    /** Feeds one observation to the raw grids, MRPT's height maps and the laser-only map (the
     * evaluated map gets it from the caller). */
    void observe(const mrpt::obs::CObservation& obs,
                 const mrpt::poses::CPose3DPDFGaussian& robotPose, bool poseHasCovariance);

    /** Scores and writes report.json, profile.csv and the per-method rasters eval_*.asc into the
     * folder; returns the text table. The evaluated map must be filled already (dem_update_map());
     * its insertion and fill times [s] go into the report. */
    std::string finish(const OutputFolder& out, double multibinInsert_s, double multibinFill_s);

private:
    void insertRawPoints(const mrpt::obs::CObservation& obs,
                         const mrpt::poses::CPose3DPDFGaussian& robotPose);
    multibin::eval::MethodEstimate sampleMap(const std::string& name,
                                             const mrpt::maps::CMultiBinElevationMap& map,
                                             bool filled) const;
    /** profile.csv: the profile line's samples of the truth and the maps. */
    std::string profileCsv(const multibin::eval::CellArray& truth,
                           const std::vector<multibin::eval::MethodEstimate>& methods) const;

    Options m_options;
    mrpt::maps::CMultiBinElevationMap& m_evaluated;
    mrpt::maps::CMultiBinElevationMap m_laserOnly;
    multibin::Lattice m_lattice;
    multibin::eval::CellArray m_truth;
    multibin::eval::RawPointGrid m_rawLaser, m_rawAll;
    mrpt::maps::CHeightGridMap2D m_heightGrid;
    std::unique_ptr<mrpt::maps::CHeightGridMap2D_MRF> m_mrf;
    multibin::Lattice m_mrfLattice;                            //!< the crop, in the same lattice
    multibin::sensors::SensorModelOptions m_rawSensorOptions;  //!< rejection rules off
    multibin::sensors::SensorModelState m_rawSensorState;
    double m_raw_s = 0, m_heightGrid_s = 0, m_mrf_s = 0, m_laserOnly_s = 0;
};
