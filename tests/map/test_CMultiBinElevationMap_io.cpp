/* Serialized maps (the elevation_map.bin that elevation-mapper writes) read through CArchive:
 * truncated, corrupt or of an unknown version, an exception and the map being read into
 * unchanged; the class registered when the library loads. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>

#include "../common/reliability_helpers.h"
#include "multibin/grid/BinGrid.h"

namespace fs = std::filesystem;
using namespace reliability;
using test_files::writeAll;

// ---------------------------------------------------------------------------------------------
// Serialized maps (the elevation_map.bin that elevation-mapper writes), read through CArchive
// ---------------------------------------------------------------------------------------------
// Found by the first clang build: the class registered itself with MRPT_INITIALIZER (a
// constructor attribute), which clang ran before the C++ initialiser of its class id (a
// std::function member): a null name was registered and no clang build could read a map. Fixed
// by registering from a C++ dynamic initialiser after IMPLEMENTS_SERIALIZABLE. Nothing in this
// program calls registerMultiBinElevationMap(): the load-time registration alone is tested.
TEST(BadInputFiles, MapClassIsRegisteredWhenTheLibraryLoads) {
    EXPECT_NE(mrpt::rtti::findRegisteredClass("mrpt::maps::CMultiBinElevationMap"), nullptr);
}

namespace {
/** A serialized map with data, as bytes. */
std::vector<uint8_t> goodMapBytes() { return serialize(mapWithData()); }

/** Reads `bytes` into a map that holds other data; expects an exception naming the map class
 * and `problem`, and the target map unchanged. */
void expectRejected(const std::vector<uint8_t>& bytes, const std::string& problem) {
    Map target = mapWithOtherData();
    const auto before = serialize(target);
    try {
        deserializeInto(target, bytes);
        ADD_FAILURE() << "no exception";
    } catch (const std::exception& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(problem), std::string::npos) << msg;
    }
    EXPECT_EQ(serialize(target), before) << "a rejected stream changed the map";
}
}  // namespace

TEST(BadInputFiles, SerializedMapRoundTripIsExact) {
    // The control case for the three below.
    const auto bytes = goodMapBytes();
    Map m;
    deserializeInto(m, bytes);
    EXPECT_EQ(serialize(m), bytes);
}

TEST(BadInputFiles, TruncatedSerializedMapIsRejected) {
    const auto bytes = goodMapBytes();
    for (const size_t keep : {size_t(3), size_t(40), bytes.size() / 2, bytes.size() - 4}) {
        SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(bytes.size()));
        expectRejected(std::vector<uint8_t>(bytes.begin(), bytes.begin() + long(keep)), "");
    }
}

// MRPT's CArchive throws only when a read gets ZERO bytes; a value cut in the middle is read
// partially without a word. Serialization version 1 therefore ends with the bin count and a tag
// that serializeFrom() checks before it touches the map: any cut into the map's own bytes leaves
// the map unchanged. A stream missing only MRPT's one-byte end-of-object marker holds the whole
// map: it is loaded, and MRPT then reports the missing marker.
TEST(BadInputFiles, SerializedMapCutInItsLastBytesLeavesTheMapUnchanged) {
    const auto bytes = goodMapBytes();
    for (const size_t keep : {bytes.size() - 5, bytes.size() - 3, bytes.size() - 2}) {
        SCOPED_TRACE("kept " + std::to_string(keep) + " of " + std::to_string(bytes.size()));
        expectRejected(std::vector<uint8_t>(bytes.begin(), bytes.begin() + long(keep)), "");
    }
}

TEST(BadInputFiles, SerializedMapOfAnUnknownVersionIsRejected) {
    auto bytes = goodMapBytes();
    // CArchive layout: 0x80 | name length, the class name, then the version byte.
    const std::string name = "CMultiBinElevationMap";
    const auto at = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
    ASSERT_NE(at, bytes.end());
    const size_t versionByte = size_t(at - bytes.begin()) + name.size();
    ASSERT_EQ(bytes[versionByte], 4u);  // version 4 today (checksum, plane moments, pose codes)
    bytes[versionByte] = 7;
    expectRejected(bytes, "version");
}

TEST(BadInputFiles, SerializedMapWithCorruptGridIsRejected) {
    // A window of -5 cells, and a bin with a NaN height: both found by the reader's checks.
    Map::TCreationOptions c;
    c.grow = false;
    c.min_x = -1, c.max_x = 1, c.min_y = -1, c.max_y = 1;
    auto bytes = serialize(mapWithData(c));
    // The grid follows the options text; its window is the first 16 bytes after it. Find the
    // window by its known values.
    const multibin::CellWindow w = multibin::MapInternals::grid(mapWithData(c)).window();
    std::vector<uint8_t> pattern(16);
    const int32_t win[4] = {w.ix0, w.iy0, w.nx, w.ny};
    std::memcpy(pattern.data(), win, 16);
    const auto at = std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end());
    ASSERT_NE(at, bytes.end());
    auto negative = bytes;
    const int32_t minus5 = -5;
    std::memcpy(&negative[size_t(at - bytes.begin()) + 8], &minus5, 4);
    expectRejected(negative, "corrupt");

    // First bin's height: after the window (16 B), the non-empty count (8 B), ix, iy (8 B) and
    // the bin count (2 B).
    auto nanBin = bytes;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&nanBin[size_t(at - bytes.begin()) + 16 + 8 + 8 + 2], &nan, 4);
    expectRejected(nanBin, "corrupt");
}

TEST(BadInputFiles, SerializedMapFileCutShortIsRejected) {
    // The same through a gz file, as elevation_map.bin is written.
    const fs::path dir = scratchDir("map_file");
    const fs::path f = dir / "elevation_map.bin";
    {
        mrpt::io::CFileGZOutputStream out(f.string());
        auto arch = mrpt::serialization::archiveFrom(out);
        arch << mapWithData();
    }
    const std::string plain = plainBytes(f);
    const fs::path cut = dir / "cut.bin";
    writeAll(cut, plain.substr(0, plain.size() / 2));
    Map target = mapWithData();
    const auto before = serialize(target);
    mrpt::io::CFileGZInputStream in(cut.string());
    auto arch = mrpt::serialization::archiveFrom(in);
    EXPECT_ANY_THROW(arch >> target);
    EXPECT_EQ(serialize(target), before);
}
