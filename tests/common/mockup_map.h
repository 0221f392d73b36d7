/* The shipped mock-up map (rawlogs/mockup.simplemap mapped as elevation-mapper maps it with
 * ini/mockup.ini, gaps filled), for tests and benchmarks that need a real map. */
#pragma once

#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/CSimpleMap.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace test_maps {

/** The maps of ini/mockup.ini holding the mock-up; its CMultiBinElevationMap is filled. */
inline std::shared_ptr<mrpt::maps::CMultiMetricMap> mockupMaps() {
    const std::string src = MULTIBIN_SOURCE_DIR;
    const mrpt::config::CConfigFile ini(src + "/ini/mockup.ini");
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, "MappingApplication");
    auto maps = std::make_shared<mrpt::maps::CMultiMetricMap>(inits);
    mrpt::maps::CSimpleMap simplemap;
    if (!simplemap.loadFromFile(src + "/rawlogs/mockup.simplemap"))
        throw std::runtime_error("cannot read " + src + "/rawlogs/mockup.simplemap");
    auto map = maps->mapByClass<mrpt::maps::CMultiBinElevationMap>();
    map->insertSimpleMapWithPosePdfs(simplemap);
    map->dem_update_map();
    return maps;
}

}  // namespace test_maps
