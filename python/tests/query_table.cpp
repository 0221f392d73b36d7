/* Part of the multibin elevation-mapping library: a C++ helper of the Python module's tests
 * and benchmark. It loads a serialized map as any C++ program would (MRPT archive) and answers
 * the module's height query (HeightQuery.h) at given points:
 *
 *   multibin_query_table [--fill] MAP XY_IN TABLE_OUT
 *       x, y float64 pairs in; x, y, height, sigma, source float64 rows out (NaN where unknown);
 *       with --fill the gaps are filled first (a loaded map holds no fill: it is lazy)
 *   multibin_query_table [--fill] --time N [--one-by-one] MAP XY_IN
 *       the query over the points, timed per block of kTimedBlock points in CPU time of the
 *       thread (the fastest of N runs of each block: a shared machine's other work is not
 *       counted); prints the sum of the blocks' times [s]. The block as one batch (the module's
 *       queryHeights), or with --one-by-one a loop of single height() calls */
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "HeightQuery.h"

using mrpt::maps::CMultiBinElevationMap;

namespace {
/** Points per timed block (python/bench/bench_height.py times the same blocks). */
constexpr size_t kTimedBlock = 100000;

/** CPU time of the calling thread [s] (Python's time.thread_time()). */
double threadCpu_s() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::vector<double> readDoubles(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw std::runtime_error("cannot read '" + path + "'");
    std::vector<double> v(size_t(in.tellg()) / sizeof(double));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * sizeof(double)));
    return v;
}

void loadMap(const std::string& path, CMultiBinElevationMap& map) {
    mrpt::io::CFileGZInputStream in(path);
    auto arch = mrpt::serialization::archiveFrom(in);
    arch.ReadObject(&map);
}

/** The points' x and y (split from the interleaved pairs). */
void split(const std::vector<double>& xy, std::vector<double>& x, std::vector<double>& y) {
    x.resize(xy.size() / 2);
    y.resize(xy.size() / 2);
    for (size_t i = 0; i < x.size(); i++) {
        x[i] = xy[2 * i];
        y[i] = xy[2 * i + 1];
    }
}
}  // namespace

int main(int argc, char** argv) {
    try {
        std::vector<std::string> a(argv + 1, argv + argc);
        const bool fill = !a.empty() && a[0] == "--fill";
        if (fill) a.erase(a.begin());
        const bool oneByOne = a.size() == 5 && a[0] == "--time" && a[2] == "--one-by-one";
        if (oneByOne) a.erase(a.begin() + 2);
        const bool timing = a.size() == 4 && a[0] == "--time";
        if (!timing && a.size() != 3) {
            std::cerr << "usage: multibin_query_table [--fill] MAP XY_IN TABLE_OUT | [--fill] "
                         "--time N [--one-by-one] MAP XY_IN\n";
            return 2;
        }
        const auto query =
            oneByOne ? multibin::python::queryHeightsOneByOne : multibin::python::queryHeights;
        CMultiBinElevationMap map;
        loadMap(timing ? a[2] : a[0], map);
        if (fill) map.dem_update_map();
        std::vector<double> x, y;
        split(readDoubles(timing ? a[3] : a[1]), x, y);
        const size_t n = x.size();
        std::vector<double> h(n), s(n);
        std::vector<uint8_t> src(n);
        if (timing) {
            double total_s = 0;
            for (size_t b = 0; b < n; b += kTimedBlock) {
                const size_t m = std::min(kTimedBlock, n - b);
                double best_s = 1e300;
                for (int run = 0; run < std::stoi(a[1]); run++) {
                    const double t0_s = threadCpu_s();
                    query(map, x.data() + b, y.data() + b, m, h.data() + b, s.data() + b,
                          src.data() + b);
                    best_s = std::min(best_s, threadCpu_s() - t0_s);
                }
                total_s += best_s;
            }
            std::printf("%.9f\n", total_s);
            return 0;
        }
        multibin::python::queryHeights(map, x.data(), y.data(), n, h.data(), s.data(), src.data());
        std::ofstream out(a[2], std::ios::binary);
        for (size_t i = 0; i < n; i++) {
            const double row[5] = {x[i], y[i], h[i], s[i], double(src[i])};
            out.write(reinterpret_cast<const char*>(row), sizeof row);
        }
        if (!out) throw std::runtime_error("cannot write '" + a[2] + "'");
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "multibin_query_table: " << e.what() << "\n";
        return 1;
    }
}
