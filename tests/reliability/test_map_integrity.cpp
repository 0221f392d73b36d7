/* Serialized-map integrity (issue 16.4): version 2 carries a CRC-32 of its payload, so a flipped
 * byte or bit anywhere is an error and the map read into stays as it was. Before, one flipped bit
 * of an uncompressed map loaded silently as another map in 36-64 % of the positions. */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <memory>

#include "reliability_helpers.h"

using namespace reliability;

namespace {
/** A small map: the fixed 2 m map with one scan of 40 beams. */
std::vector<uint8_t> smallMapBytes() {
    Map map(fixedTwoMetreMap());
    map.insertObservation(*floorScan(40), posePdf());
    return serialize(map);
}

enum class Outcome { Unchanged, Loaded, ChangedSilently, ChangedWithError };

/** The map flipped streams are read into: one map holding other data, serialized after each
 * read to show whether the read changed it, and built again only when one did (building and
 * serializing it anew for each flip was half of the test's time). */
class ReadTarget {
public:
    ReadTarget() { rebuild(); }

    /** Reads `bytes` into the target; `original` is the stream the flips were made in. */
    Outcome readInto(const std::vector<uint8_t>& bytes, const std::vector<uint8_t>& original) {
        Outcome o;
        try {
            deserializeInto(*m_map, bytes);
            o = serialize(*m_map) == original ? Outcome::Loaded : Outcome::ChangedSilently;
        } catch (const std::exception&) {
            const auto after = serialize(*m_map);
            // MRPT checks its end-of-object marker after serializeFrom() returned: a flip there
            // leaves the map holding the stored map, intact (its checksum held).
            o = after == m_before   ? Outcome::Unchanged
                : after == original ? Outcome::Loaded
                                    : Outcome::ChangedWithError;
        }
        if (o != Outcome::Unchanged) rebuild();
        return o;
    }

    /** The target's bytes before any read. */
    const std::vector<uint8_t>& before() const { return m_before; }

private:
    void rebuild() {
        // The fixed 2 m map seen from elsewhere (its bytes serialized after every read: a small
        // map, not mapWithOtherData's growing one of twice the size).
        m_map = std::make_unique<Map>(fixedTwoMetreMap());
        m_map->insertObservation(*floorScan(40), posePdf(0.5, 0.5));
        m_before = serialize(*m_map);
    }
    std::unique_ptr<Map> m_map;
    std::vector<uint8_t> m_before;
};
}  // namespace

TEST(MapIntegrity, TheCurrentVersionCarriesAChecksumAndRoundTrips) {
    const auto bytes = smallMapBytes();
    EXPECT_EQ(ReadTarget().readInto(bytes, bytes), Outcome::Loaded);
}

// Every byte XOR 0xFF, and one bit of every byte (bit i mod 8 of byte i; all 8 bits took a
// minute). Two places are MRPT's framing, outside the object's
// own bytes: the class name (bytes 1 to 33), which MRPT does not compare when reading into an
// existing map and matches without its namespace (a flip there loads the same, intact map), and
// the end-of-object marker (the last byte), which MRPT checks after the map was read (an error;
// the map then holds the stored map, intact). Nothing loads as another map.
TEST(MapIntegrity, FlippingAnyByteOrBitIsAnErrorThatLeavesTheMapUnchanged) {
    const auto original = smallMapBytes();
    const std::string name = "mrpt::maps::CMultiBinElevationMap";
    ASSERT_EQ(std::string(original.begin() + 1, original.begin() + 1 + long(name.size())), name);
    size_t unchanged = 0, className = 0, endMarker = 0;
    ReadTarget target;
    ASSERT_NE(target.before(), original);  // else a read that loads would look unchanged
    for (size_t i = 0; i < original.size(); i++) {
        for (const uint8_t mask : {uint8_t(0xFF), uint8_t(1u << (i % 8))}) {
            auto bytes = original;
            bytes[i] ^= mask;
            const Outcome o = target.readInto(bytes, original);
            if (o == Outcome::Unchanged) {
                unchanged++;
            } else if (o == Outcome::Loaded && i >= 1 && i <= name.size()) {
                className++;
            } else if (o == Outcome::Loaded && i + 1 == original.size()) {
                endMarker++;
            } else {
                ADD_FAILURE() << "byte " << i << " of " << original.size() << " ^ " << int(mask)
                              << ": "
                              << (o == Outcome::Loaded ? "loaded without an error"
                                  : o == Outcome::ChangedSilently
                                      ? "loaded as another map without an error"
                                      : "error, but the map changed");
                return;
            }
        }
    }
    EXPECT_EQ(unchanged + className + endMarker, 2 * original.size());
    EXPECT_LE(className, 2 * name.size());
    EXPECT_LE(endMarker, 2u);
    std::printf(
        "%zu bytes x 2 flips: %zu errors with the map unchanged, %zu in the class name, "
        "%zu in the end marker\n",
        original.size(), unchanged, className, endMarker);
}
