/* libFuzzer target: ini text -> TCreationOptions / TInsertionOptions::loadFromConfigFile through
 * mrpt::config::CConfigFileMemory, then a map built from what loaded.
 * Properties: errors are std::invalid_argument (or another std::exception from MRPT's parser);
 * options that load validate, survive a save/load round trip unchanged, and give a map that can be
 * constructed without an allocation beyond the stated limits (libFuzzer's -malloc_limit_mb). */
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cmath>
#include <sstream>

#include "fuzz_common.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;

template <typename Options>
std::string dump(const Options& o) {
    mrpt::config::CConfigFileMemory ini;
    o.saveToConfigFile(ini, "s");
    std::string text;
    ini.getContent(text);
    return text;
}

template <typename Options>
void roundTrip(const Options& o) {
    const std::string text = dump(o);
    mrpt::config::CConfigFileMemory ini(text);
    Options back;
    back.loadFromConfigFile(ini, "s");  // what was saved must load
    if (dump(back) != text) fuzz::fail("options changed in a save/load round trip");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    mrpt::config::CConfigFileMemory ini;
    try {
        ini.setContent(text);
    } catch (const std::exception& e) {
        fuzz::debugRejected(e);
        return 0;  // MRPT's own parser refused the text
    }
    Map::TCreationOptions creation;
    bool creationOk = false;
    try {
        creation.loadFromConfigFile(ini, "creation");
        creationOk = true;
    } catch (const std::exception& e) {
        fuzz::debugRejected(e);
    }
    if (creationOk) {
        roundTrip(creation);
        // validate() passed: construction must not fail. Maps validate() allows can still take
        // gigabytes (up to its cell limit); those are built only below 2e7 cells (~240 MB), so
        // that fuzzing stays within libFuzzer's 2 GB and fast.
        const auto cells = [](double size_m, double cell_m) {
            return std::pow(size_m / cell_m, 2);
        };
        const double extentCells = ((creation.max_x - creation.min_x) / creation.resolution_m) *
                                   ((creation.max_y - creation.min_y) / creation.resolution_m);
        const double allocated =
            creation.dual_grid ? cells(creation.local_size_m, creation.local_resolution_m) +
                                     cells(creation.global_size_m, creation.global_resolution_m)
                               : extentCells;
        if (allocated <= 2e7) {
            Map map(creation);
            fuzz::checkInvariants(map);
        }
    }
    Map::TInsertionOptions insertion;
    try {
        insertion.loadFromConfigFile(ini, "insertion");
    } catch (const std::exception& e) {
        fuzz::debugRejected(e);
        return 0;
    }
    roundTrip(insertion);
    return 0;
}
