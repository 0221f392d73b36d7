/* Bad files: truncated or corrupt rawlogs and simplemaps given to the elevation-mapper program
 * (exit code 1 and a one-line error naming the file), and truncated, corrupt or unknown-version
 * serialized maps read through CArchive (an exception, and the map being read into unchanged). */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "multibin/grid/BinGrid.h"
#include "reliability_helpers.h"

namespace fs = std::filesystem;
using namespace reliability;

namespace {
void writeAll(const fs::path& p, const std::string& bytes) {
    std::ofstream f(p, std::ios::binary);
    f << bytes;
}

/** The shipped file's bytes, gz-decompressed if it is gz (rawlogs and simplemaps may be either). */
std::string plainBytes(const fs::path& p) {
    mrpt::io::CFileGZInputStream in(p.string());
    std::string out;
    char buf[65536];
    for (size_t n; (n = in.Read(buf, sizeof buf)) > 0;) out.append(buf, n);
    return out;
}

#ifdef ELEVATION_MAPPER_EXE
struct RunResult {
    int exitCode;
    std::string stderrText;
};

/** Runs elevation-mapper with the shipped walk.ini on `input` (--rawlog or --simplemap). */
RunResult runMapper(const std::string& flag, const fs::path& input, const fs::path& dir) {
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = std::string(ELEVATION_MAPPER_EXE) + " --config " +
                            (fs::path(MULTIBIN_SOURCE_DIR) / "rawlogs" / "walk.ini").string() +
                            " " + flag + " " + input.string() + " --out " + (dir / "out").string() +
                            " > " + (dir / "stdout.txt").string() + " 2> " + err.string() +
                            " < /dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readAll(err)};
}

/** Exit code 1 and exactly one line on stderr that names the file. */
void expectOneLineErrorNaming(const RunResult& r, const fs::path& file) {
    EXPECT_EQ(r.exitCode, 1) << r.stderrText;
    ASSERT_FALSE(r.stderrText.empty());
    EXPECT_EQ(std::count(r.stderrText.begin(), r.stderrText.end(), '\n'), 1) << r.stderrText;
    EXPECT_NE(r.stderrText.find(file.filename().string()), std::string::npos) << r.stderrText;
}

const fs::path kShipped = fs::path(MULTIBIN_SOURCE_DIR) / "rawlogs";
#endif
}  // namespace

#ifdef ELEVATION_MAPPER_EXE
TEST(BadInputFiles, TruncatedRawlogIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("truncated_rawlog");
    const std::string bytes = plainBytes(kShipped / "walk.rawlog");
    // Cut inside an entry a little way in (entries are observations of a few kB).
    const fs::path f = dir / "cut.rawlog";
    writeAll(f, bytes.substr(0, 20000));
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, CorruptRawlogIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("corrupt_rawlog");
    std::string bytes = plainBytes(kShipped / "walk.rawlog");
    bytes.resize(60000);
    // Overwrite 64 bytes in the middle of the stream (inside the second or third entry).
    for (size_t i = 30000; i < 30064; i++) bytes[i] = char(0xA5 ^ (i * 37));
    const fs::path f = dir / "corrupt.rawlog";
    writeAll(f, bytes);
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, RawlogOfAnotherFormatIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("text_rawlog");
    const fs::path f = dir / "notes.rawlog";
    writeAll(f, "this is not a rawlog\n");
    expectOneLineErrorNaming(runMapper("--rawlog", f, dir), f);
}

TEST(BadInputFiles, TruncatedSimplemapIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("truncated_simplemap");
    const std::string bytes = plainBytes(kShipped / "walk.simplemap");
    const fs::path f = dir / "cut.simplemap";
    writeAll(f, bytes.substr(0, bytes.size() / 3));
    expectOneLineErrorNaming(runMapper("--simplemap", f, dir), f);
}

TEST(BadInputFiles, CorruptSimplemapIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratchDir("corrupt_simplemap");
    std::string bytes = plainBytes(kShipped / "walk.simplemap");
    for (size_t i = 40; i < 104; i++) bytes[i] = char(0x5A ^ (i * 13));
    const fs::path f = dir / "corrupt.simplemap";
    writeAll(f, bytes);
    expectOneLineErrorNaming(runMapper("--simplemap", f, dir), f);
}

TEST(BadInputFiles, MissingInputAndEmptyFileAreOneLineErrors) {
    const fs::path dir = scratchDir("missing");
    expectOneLineErrorNaming(runMapper("--rawlog", dir / "nowhere.rawlog", dir),
                             dir / "nowhere.rawlog");
    const fs::path empty = dir / "empty.simplemap";
    writeAll(empty, "");
    expectOneLineErrorNaming(runMapper("--simplemap", empty, dir), empty);
}
#endif

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
