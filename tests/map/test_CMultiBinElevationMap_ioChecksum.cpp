/* Serialized-map integrity (issue 16.4): version 2 carries a CRC-32 of its payload, so a flipped
 * byte or bit anywhere is an error and the map read into stays as it was. Before, one flipped bit
 * of an uncompressed map loaded silently as another map in 36-64 % of the positions. */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "../common/reliability_helpers.h"

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

/** The flips made in a serialized map of `size` bytes whose payload (covered by its CRC-32) is
 * bytes [payloadBegin, payloadEnd): every byte XOR 0xFF, and each of the 8 bits of every byte
 * outside the payload (MRPT's framing, the version, the payload's length, the CRC). Inside the
 * payload a single bit adds nothing to the byte's 0xFF: a CRC-32 detects every error of up to 32
 * consecutive bits; outside it, one bit makes a nearby value (a version byte with one bit flipped
 * names another version). */
std::vector<std::pair<size_t, uint8_t>> flipsOf(size_t size, size_t payloadBegin,
                                                size_t payloadEnd) {
    std::vector<std::pair<size_t, uint8_t>> flips;
    for (size_t i = 0; i < size; i++) {
        flips.emplace_back(i, uint8_t(0xFF));
        if (i < payloadBegin || i >= payloadEnd)
            for (int bit = 0; bit < 8; bit++) flips.emplace_back(i, uint8_t(1u << bit));
    }
    return flips;
}

// Every flip of flipsOf() (5876 on a 5492-byte map; every bit of every byte, 43936 flips, would
// take minutes under the sanitizers). Two places are MRPT's framing, outside the object's own
// bytes: the class name (bytes 1 to 33), which MRPT does not compare when reading into an
// existing map and matches without its namespace (a flip there loads the same, intact map), and
// the end-of-object marker (the last byte), which MRPT checks after the map was read (an error;
// the map then holds the stored map, intact). Nothing loads as another map.
TEST(MapIntegrity, FlippingAnyByteOrBitIsAnErrorThatLeavesTheMapUnchanged) {
    const auto original = smallMapBytes();
    const std::string name = "mrpt::maps::CMultiBinElevationMap";
    ASSERT_EQ(std::string(original.begin() + 1, original.begin() + 1 + long(name.size())), name);
    // Versions 2 and later: name length, name, version, payload length (uint64), payload, CRC-32,
    // end marker.
    const size_t payloadBegin = 1 + name.size() + 1 + 8, payloadEnd = original.size() - 5;
    uint64_t payloadLength = 0;
    std::memcpy(&payloadLength, &original[1 + name.size() + 1], 8);
    ASSERT_EQ(payloadLength, payloadEnd - payloadBegin);
    const auto flips = flipsOf(original.size(), payloadBegin, payloadEnd);
    size_t unchanged = 0, className = 0, endMarker = 0;
    ReadTarget target;
    ASSERT_NE(target.before(), original);  // else a read that loads would look unchanged
    for (const auto& [i, mask] : flips) {
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
            ADD_FAILURE() << "byte " << i << " of " << original.size() << " ^ " << int(mask) << ": "
                          << (o == Outcome::Loaded ? "loaded without an error"
                              : o == Outcome::ChangedSilently
                                  ? "loaded as another map without an error"
                                  : "error, but the map changed");
            return;
        }
    }
    EXPECT_EQ(unchanged + className + endMarker, flips.size());
    EXPECT_LE(className, 9 * name.size());
    EXPECT_LE(endMarker, 9u);
    std::printf(
        "%zu bytes, %zu flips: %zu errors with the map unchanged, %zu in the class name, "
        "%zu in the end marker\n",
        original.size(), flips.size(), unchanged, className, endMarker);
}
