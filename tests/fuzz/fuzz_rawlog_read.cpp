/* libFuzzer target: bytes -> the elevation-mapper's reading path (RawlogSource, with its read
 * budget) -> insertObservation() into a growing map, as the program does. The first byte picks
 * the format: even = rawlog, odd = simplemap; the rest is the file's (uncompressed) content.
 * Properties: no crash, sanitizer report or allocation over the read budget (libFuzzer's 2 GB
 * malloc limit would catch one); a bad input is a std::runtime_error naming the input; after
 * every observation every bin holds a finite height, variance >= 0 and certainty >= 0. */
#include <mrpt/maps/CSimpleMap.h>

#include "RawlogSource.h"
#include "fuzz_common.h"

namespace {
using Map = mrpt::maps::CMultiBinElevationMap;
constexpr size_t kMaxObservations = 16;  // bounds the time of one input
const std::string kName = "fuzz input";

void expectNamed(const std::exception& e) {
    if (std::string(e.what()).find(kName) == std::string::npos)
        fuzz::fail("a reading error does not name the input");
    fuzz::debugRejected(e);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    const bool simplemap = data[0] & 1;
    mrpt::io::CMemoryStream mem;
    mem.assignMemoryNotOwn(data + 1, size - 1);
    Map map;
    size_t inserted = 0;
    auto insert = [&](const mrpt::obs::CObservation& obs,
                      const mrpt::poses::CPose3DPDFGaussian& pose, bool hasCov) {
        if (inserted++ >= kMaxObservations) return;
        try {
            if (hasCov)
                map.insertObservation(obs, pose);
            else
                map.insertObservation(obs, pose.mean);
        } catch (const std::exception& e) {
            fuzz::debugRejected(e);
            return;
        }
        fuzz::checkInvariants(map);
    };
    try {
        if (simplemap) {
            const auto sm = RawlogSource::readSimplemap(mem, kName, size - 1);
            Map::forEachObservationWithPosePdf(
                sm,
                [&](const mrpt::obs::CObservation& obs,
                    const mrpt::poses::CPose3DPDFGaussian& pdf) { insert(obs, pdf, true); },
                nullptr);
        } else {
            RawlogSource::forEachInStream(
                mem, kName, size - 1,
                [&](const mrpt::obs::CObservation::Ptr& obs,
                    const mrpt::poses::CPose3DPDFGaussian& pose,
                    bool hasCov) { insert(*obs, pose, hasCov); },
                nullptr);
        }
    } catch (const std::exception& e) {
        expectNamed(e);
    }
    return 0;
}
