/* Part of the multibin elevation-mapping library. */
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/traversability/TerrainFeatures.h"

namespace multibin::traversability {

/** The truth of each cell of `lattice` (metric, the truth's frame): the features of the truth
 * raster's samples within options.radius_m of the cell's centre (DiscAccumulator: the layers'
 * own definitions, on a raster far finer than a cell), 1 untraversable, 0 traversable, -1 where
 * fewer than min_known_fraction of the disc's samples are known. */
std::vector<int8_t> truthClasses(const EsriAsciiGrid& truth, const Lattice& lattice,
                                 const TraversabilityOptions& options,
                                 std::vector<DiscFeatures>* features = nullptr);

/** Heights per cell of `lattice` (row-major, NaN unknown, 1 sample per cell, no bins) as
 * SurfaceSamples with sigma 0: the input of the thresholded-height baselines. */
SurfaceSamples cellHeightSamples(const Lattice& lattice, const std::vector<float>& height_m);

/** One decile of a reliability table: the cells whose probability lies in it. */
struct ReliabilityBin {
    size_t cells = 0;
    double meanProbability = 0;  //!< mean predicted P(untraversable) [-]
    double observed = 0;         //!< share of them untraversable in truth [-]
};

/** How a probability layer scores against the truth's classes. */
struct ClassifierScore {
    size_t truthCells = 0;  //!< cells the truth classifies
    size_t scored = 0;      //!< of them, known in the layer
    size_t truePositive = 0, falsePositive = 0, falseNegative = 0, trueNegative = 0;  //!< P > 0.5
    double precision = 0, recall = 0, f1 = 0;
    double coverage = 0;  //!< scored / truthCells
    /** Expected calibration error: sum over deciles of cells/scored x |mean P - observed|. */
    double ece = 0;
    std::array<ReliabilityBin, 10> reliability;
};

/** Scores `probability` (NaN unknown) against `truth` (truthClasses()), cell by cell. */
ClassifierScore scoreProbabilities(const std::vector<float>& probability,
                                   const std::vector<int8_t>& truth);

/** JSON of named scores (with their reliability tables), in `order`. */
std::string scoresJson(const std::map<std::string, ClassifierScore>& scores,
                       const std::vector<std::string>& order, const TraversabilityOptions& o);
/** A text table of named scores, then the reliability table of the first. */
std::string scoresTable(const std::map<std::string, ClassifierScore>& scores,
                        const std::vector<std::string>& order);

}  // namespace multibin::traversability
