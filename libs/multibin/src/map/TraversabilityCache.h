/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap's traversability layers as last computed, and what they were computed
 * from: kept so a later call recomputes only where the map changed. */
#pragma once

#include <cstdint>
#include <mutex>
#include <vector>

#include "multibin/traversability/TerrainFeatures.h"

namespace multibin {

struct TraversabilityCache {
    /** Readers share the map's lock; this one serialises their updates of the cache. */
    mutable std::mutex mutex;
    bool valid = false;
    traversability::TraversabilityOptions options;  //!< the options the layers were made with
    traversability::SurfaceSamples samples;
    traversability::TraversabilityLayers layers;
    std::vector<uint64_t> signature;  //!< per cell: a digest of its bins and fill

    TraversabilityCache() = default;
    // A copy of a map recomputes its layers when first asked: only the lock is not copied.
    TraversabilityCache(const TraversabilityCache&) {}
    TraversabilityCache& operator=(const TraversabilityCache&) {
        valid = false;
        return *this;
    }
};

}  // namespace multibin
