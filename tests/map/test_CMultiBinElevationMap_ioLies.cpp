/* Serialized maps that pass the checksum but lie (issue 37, kind 4): the payload is written here
 * field by field as the map writes it (version 4), with a correct CRC-32, so only the checks for
 * sense can refuse it. Each must be an exception naming the problem, the map read into unchanged;
 * an honest payload written the same way loads. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/crc.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "../common/reliability_helpers.h"
#include "multibin/map/MapInternals.h"

using namespace reliability;

namespace {

struct LyingBin {
    float height_m = 0.02f;
    int16_t index = 0;
};
struct LyingCell {
    int32_t ix, iy;
    std::vector<LyingBin> bins;
};
/** What the payload says: the options (as a map's saveToConfigFile writes them), one grid. */
struct LyingMap {
    Map::TCreationOptions creation;
    int32_t ix0 = -50, iy0 = -50, nx = 100, ny = 100;
    std::vector<LyingCell> cells{{0, 0, {LyingBin{}}}, {1, 0, {LyingBin{}}}};
};

std::vector<uint8_t> bytesOf(mrpt::io::CMemoryStream& mem) {
    const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
    return std::vector<uint8_t>(p, p + mem.getTotalBytesCount());
}

/** The serialized map (class header, version 4, length, payload, CRC-32, end flag) of `m`. */
std::vector<uint8_t> serialized(const LyingMap& m) {
    mrpt::io::CMemoryStream body;
    {
        auto out = mrpt::serialization::archiveFrom(body);
        mrpt::config::CConfigFileMemory ini;
        m.creation.saveToConfigFile(ini, "creation");
        Map::TInsertionOptions().saveToConfigFile(ini, "insertion");
        std::string text;
        ini.getContent(text);
        out << text << m.ix0 << m.iy0 << m.nx << m.ny << uint64_t(m.cells.size());
        uint64_t bins = 0;
        for (const LyingCell& c : m.cells) {
            out << c.ix << c.iy << uint16_t(c.bins.size());
            for (const LyingBin& b : c.bins) {
                out << b.height_m << 1e-4f << 1.0f << uint32_t(1) << b.index;
                for (int k = 0; k < 10; k++) out << 0.0f;  // plane moments
                out << uint8_t(0) << uint8_t(0);           // pose sigma codes
                bins++;
            }
        }
        out << bins << uint32_t(0x4D42454D);
    }
    const std::vector<uint8_t> payload = bytesOf(body);
    // The class header as the map writes it: everything before the payload length.
    const std::vector<uint8_t> real = serialize(Map());
    const size_t realPayload = real.size() - 8 - 4 - 1;  // minus length, CRC, end flag
    size_t header = 0;
    for (; header + 8 <= real.size(); header++) {
        uint64_t n;
        std::memcpy(&n, real.data() + header, 8);
        if (n == realPayload - header) break;
    }
    std::vector<uint8_t> out(real.begin(), real.begin() + header);
    mrpt::io::CMemoryStream tail;
    {
        auto arch = mrpt::serialization::archiveFrom(tail);
        arch << uint64_t(payload.size());
        arch.WriteBuffer(payload.data(), payload.size());
        arch << mrpt::system::compute_CRC32(payload.data(), payload.size());
    }
    const std::vector<uint8_t> t = bytesOf(tail);
    out.insert(out.end(), t.begin(), t.end());
    out.push_back(0x88);  // MRPT's end-of-object flag
    return out;
}

/** Loading `m` throws a message containing `what`; the map read into is unchanged. With
 * MULTIBIN_LIES_CORPUS set to a folder, each input is also written there (the seeds of
 * tests/fuzz/corpus/map_deserialize/lies-*). */
void expectRefused(const LyingMap& m, const std::string& what) {
    if (const char* corpus = std::getenv("MULTIBIN_LIES_CORPUS")) {
        static int n = 0;
        const auto bytes = serialized(m);
        std::ofstream(std::filesystem::path(corpus) / ("lies-" + std::to_string(n++)),
                      std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    Map map = mapWithOtherData();
    const auto before = serialize(map);
    try {
        deserializeInto(map, serialized(m));
        ADD_FAILURE() << "loaded; heightAt(0.01, 0.01) " <<
            [&] {
                double h = 0, s = 0;
                map.heightAt(0.01, 0.01, h, s);
                return h;
            }() << ", window x "
                      << map.getXMin() << ".." << map.getXMax();
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
    EXPECT_EQ(serialize(map), before);
}

}  // namespace

// The encoder above is right: an honest payload loads, and holds what it says.
TEST(SerializedLies, AnHonestPayloadWrittenTheSameWayLoads) {
    Map map;
    deserializeInto(map, serialized(LyingMap{}));
    EXPECT_EQ(multibin::MapInternals::grid(map).binCount(), 2u);
}

// A window index near 2^31: ix0 + nx overflowed int, and the map spanned x 4.29e7 to -4.29e7.
TEST(SerializedLies, AWindowBeyondTheSupportedCellIndicesIsRefused) {
    LyingMap m;
    m.ix0 = std::numeric_limits<int32_t>::max() - 10;
    m.cells = {{m.ix0, 0, {LyingBin{}}}};
    m.iy0 = -5;
    expectRefused(m, "beyond the cell indices the grid supports");
    LyingMap low;
    low.iy0 = std::numeric_limits<int32_t>::min() + 5;
    low.cells = {{0, low.iy0, {LyingBin{}}}};
    expectRefused(low, "beyond the cell indices the grid supports");
}

// A vast window holding one cell: a few hundred bytes that claim a window no data would leave
// (queries and rasters cover the window). Refused before allocating.
TEST(SerializedLies, AWindowFarLargerThanItsDataIsRefusedBeforeAllocating) {
    for (const int side : {5000, 9000}) {
        SCOPED_TRACE(side);
        LyingMap m;
        m.creation.resolution_m = 0.01;
        m.ix0 = m.iy0 = -side / 2;
        m.nx = m.ny = side;
        expectRefused(m, "sparser than any map of data");
    }
}

// Heights outside their own bin (heightAt answered 1e30).
TEST(SerializedLies, ABinWhoseHeightIsOutsideItsBinIsRefused) {
    for (const float h : {1e30f, 0.5f, -0.01f}) {
        SCOPED_TRACE(h);
        LyingMap m;
        m.creation.bin_height_m = 0.05;  // bin 0 holds [0, 0.05) m
        m.cells[0].bins[0] = LyingBin{h, 0};
        expectRefused(m, "outside its bin");
    }
}

// The same bin twice in a cell, the same cell twice in the grid.
TEST(SerializedLies, DuplicatedBinsOrCellsAreRefused) {
    LyingMap bins;
    bins.cells[0].bins = {LyingBin{0.01f, 0}, LyingBin{0.02f, 0}};
    expectRefused(bins, "stored twice");
    LyingMap cells;
    cells.cells = {{3, 4, {LyingBin{}}}, {3, 4, {LyingBin{0.02f, 0}}}};
    expectRefused(cells, "listed twice or out of order");
}

#ifdef ELEVATION_MAPPER_EXE
// The checks refuse no honest map: the maps of the shipped scenarios, as the mapper writes them
// (single grid: the mock-up; dual grid: the walk), load.
TEST(SerializedLies, TheShippedScenariosMapsLoad) {
    const std::filesystem::path src = MULTIBIN_SOURCE_DIR;
    for (const char* scenario : {"mockup", "walk"}) {
        SCOPED_TRACE(scenario);
        const auto dir = scratchDir(std::string("lies_") + scenario);
        const std::string cmd = std::string(ELEVATION_MAPPER_EXE) + " --config " +
                                (src / "rawlogs" / (std::string(scenario) + ".ini")).string() +
                                " --rawlog " +
                                (src / "rawlogs" / (std::string(scenario) + ".rawlog")).string() +
                                " --outputs map --out " + (dir / "out").string() + " > " +
                                (dir / "log.txt").string() + " 2>&1";
        ASSERT_EQ(std::system(cmd.c_str()), 0) << readAll(dir / "log.txt");
        mrpt::io::CFileGZInputStream in((dir / "out" / "elevation_map.bin").string());
        auto arch = mrpt::serialization::archiveFrom(in);
        Map map;
        EXPECT_NO_THROW(arch >> map);
        EXPECT_GT(multibin::MapInternals::grid(map).binCount(), 1000u);
    }
}
#endif
