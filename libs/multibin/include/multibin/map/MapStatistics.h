/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>

#include "multibin/grid/InsertStats.h"
#include "multibin/grid/VisibilityParams.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin {

/** Everything a CMultiBinElevationMap counted since its last clear(), as one snapshot
 * (CMultiBinElevationMap::statistics(), copied under the map's lock). */
struct MapStatistics {
    InsertStats insert;                      //!< what every insertion did with its points
    VisibilityStats visibility;              //!< what the visibility constraint did
    sensors::SensorModelStats sensorModels;  //!< what the sensor models did, per sensor kind
    /** Observations inserted with the default pose covariance: no valid pose PDF was known. */
    size_t poseFallbacks = 0;
    /** Observations skipped: their sensor label is not in insertionOptions.sensor_labels. */
    size_t skippedByLabel = 0;
    /** Observations refused (an error): their robot pose has a NaN or infinite component. */
    size_t nonFinitePoses = 0;
};

}  // namespace multibin
