/* libFuzzer target: ini text -> TCreationOptions / TInsertionOptions::loadFromConfigFile through
 * mrpt::config::CConfigFileMemory, then a map built from what loaded.
 * Properties: errors are std::invalid_argument (or another std::exception from MRPT's parser);
 * options that load validate, survive a save/load round trip unchanged, and give a map that can be
 * constructed without an allocation beyond the stated limits (libFuzzer's -malloc_limit_mb). */
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

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
    // Finding 8 (doc/reliability.md): a value holding a NUL byte loads but is cut at the NUL when
    // saved, so such inputs skip the round-trip check.
    const bool hasNul = text.find('\0') != std::string::npos;
    if (creationOk) {
        if (!hasNul) roundTrip(creation);
        Map map(creation);  // validate() passed: construction must not fail or exhaust memory
        fuzz::checkInvariants(map);
    }
    Map::TInsertionOptions insertion;
    try {
        insertion.loadFromConfigFile(ini, "insertion");
    } catch (const std::exception& e) {
        fuzz::debugRejected(e);
        return 0;
    }
    if (!hasNul) roundTrip(insertion);
    return 0;
}
