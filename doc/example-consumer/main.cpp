// Names the elevation map only in an ini string and uses no symbol of the library: the exported
// target keeps the library linked (Debian links with --as-needed), so MRPT's map registry knows
// "multiBinElevationMap" and the CMultiMetricMap gets the map.
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiMetricMap.h>

#include <iostream>

int main() {
    mrpt::config::CConfigFileMemory ini(
        "[map]\n"
        "multiBinElevationMap_count = 1\n"
        "[map_multiBinElevationMap_00_creationOpts]\n"
        "resolution_m = 0.05\n");
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, "map");
    mrpt::maps::CMultiMetricMap maps(inits);
    for (const auto& m : maps.maps) std::cout << m->GetRuntimeClass()->className << "\n";
    const bool ok =
        maps.maps.size() == 1 && std::string(maps.maps[0]->GetRuntimeClass()->className) ==
                                     "mrpt::maps::CMultiBinElevationMap";
    std::cout << (ok ? "got the map" : "the map is missing") << "\n";
    return ok ? 0 : 1;
}
