/* Threads (issue 16.3): one writer with concurrent readers is safe (doc/reliability.md,
 * "Threads"). Two threads inserting into one map while a third read corrupted the heap before.
 * Built alone under ThreadSanitizer by scripts/tsan.sh. */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>
#include <vector>

#include "../common/reliability_helpers.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapStatistics.h"

using namespace reliability;

namespace {
/** The writer: `scans` scans along x, the robot moving 2 cm per scan. */
void write(Map& map, int scans, std::atomic<bool>& done, const std::atomic<int>& started) {
    while (started < 2) std::this_thread::yield();  // both readers run while it writes
    for (int i = 0; i < scans; i++) map.insertObservation(*floorScan(200), posePdf(0.02 * i, 0));
    map.dem_update_map();
    done = true;
}

/** A reader: queries until the writer is done; counts the queries and the bad answers. */
void read(const Map& map, const std::atomic<bool>& done, std::atomic<int>& started,
          std::atomic<long>& queries, std::atomic<long>& bad) {
    started++;
    multibin::MapStatistics last;
    while (!done) {
        for (double x = -0.5; x < 1.5; x += 0.1) {
            double h = 0, s = 0, z = 0;
            if (map.getHeight(x, 0.3, h, s) && (!std::isfinite(h) || !(s >= 0))) bad++;
            if (map.getElevation(x, 0.3, h, s, true) != Map::HeightSource::Unknown &&
                !std::isfinite(h))
                bad++;
            if (map.dem_get_z(x, 0.3, z) && !std::isfinite(z)) bad++;
            queries += 3;
        }
        // The extent getters read the window growth moves (a race before they took the lock).
        if (!(map.getXMax() >= map.getXMin()) || !(map.getYMax() >= map.getYMin())) bad++;
        queries += 4;
        // The counts: one snapshot copied under the lock (read as references, a race); they
        // only grow while the writer inserts.
        const multibin::MapStatistics now = map.statistics();
        if (now.insert.accepted < last.insert.accepted ||
            now.visibility.raysCast < last.visibility.raysCast ||
            now.sensorModels.laser.beams < last.sensorModels.laser.beams)
            bad++;
        last = now;
        queries++;
        const auto raster = map.toRaster(Map::RasterLayer::Height);
        if (raster.rows() < 0) bad++;
        mrpt::io::CMemoryStream mem;
        auto arch = mrpt::serialization::archiveFrom(mem);
        arch << map;
        queries += 2;
    }
}

void oneWriterTwoReaders(const Map::TCreationOptions& c) {
    Map map(c);
    std::atomic<bool> done{false};
    std::atomic<int> started{0};
    std::atomic<long> queries{0}, bad{0};
    std::thread r1(read, std::cref(map), std::cref(done), std::ref(started), std::ref(queries),
                   std::ref(bad));
    std::thread r2(read, std::cref(map), std::cref(done), std::ref(started), std::ref(queries),
                   std::ref(bad));
    write(map, 100, done, started);
    r1.join();
    r2.join();
    EXPECT_EQ(bad, 0);
    EXPECT_GT(queries, 0);
    double h, s;
    ASSERT_TRUE(map.getHeight(0.5, 0.3, h, s));
    EXPECT_NEAR(h, 0.0, 0.02);
}
}  // namespace

TEST(Threads, OneWriterAndTwoReadersOfAGrowingMap) { oneWriterTwoReaders(Map::TCreationOptions()); }

TEST(Threads, OneWriterAndTwoReadersOfADualGridThatScrolls) {
    Map::TCreationOptions c;
    c.dual_grid = true;
    c.local_size_m = 1.0;
    oneWriterTwoReaders(c);
}

TEST(Threads, TwoMapsOnTheSecondCoreEqualOneCore) {
    // insertion_threads = 2: the process's one helper thread serves one insertion at a time, so
    // of two maps written at once one pipelines while the other finds the helper busy and stays
    // on its own thread. Both must equal a map written on one thread, bit for bit, with a
    // reader querying one of them meanwhile (ThreadSanitizer: scripts/tsan.sh).
    constexpr size_t kBeams = 6000;  // 24 blocks of 256 points: pipelined
    constexpr int kScans = 30;
    auto writeAll = [](Map& map) {
        for (int i = 0; i < kScans; i++)
            map.insertObservation(*floorScan(kBeams), posePdf(0.02 * i, 0.01 * (i % 3)));
    };
    Map reference;
    writeAll(reference);
    Map a, b;
    a.insertionOptions.insertion_threads = 2;
    b.insertionOptions.insertion_threads = 2;
    std::atomic<bool> done{false};
    std::atomic<int> started{1};  // the reader does not wait for a second reader
    std::atomic<long> queries{0}, bad{0};
    std::thread reader([&] { read(a, done, started, queries, bad); });
    std::thread writerB([&] { writeAll(b); });
    writeAll(a);
    writerB.join();
    done = true;
    reader.join();
    EXPECT_EQ(bad, 0);
    ASSERT_GT(reference.statistics().insert.accepted, size_t(kScans) * kBeams / 2);
    for (const Map* m : {&a, &b}) {
        EXPECT_EQ(m->statistics().insert.accepted, reference.statistics().insert.accepted);
        for (const auto layer : {Map::RasterLayer::Height, Map::RasterLayer::Sigma}) {
            const auto x = reference.toRaster(layer), y = m->toRaster(layer);
            ASSERT_EQ(x.rows(), y.rows());
            ASSERT_EQ(x.cols(), y.cols());
            EXPECT_EQ(x.xllcenter_m, y.xllcenter_m);
            EXPECT_EQ(std::memcmp(x.heights_m.data(), y.heights_m.data(),
                                  sizeof(float) * size_t(x.heights_m.size())),
                      0);
        }
    }
}
