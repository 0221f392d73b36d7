/* Part of the multibin elevation-mapping library's tests: gzip files coded by libdeflate
 * (Gzip.h), read back by zlib's gzip decoder and by MRPT's CFileGZInputStream. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "../common/byte_streams.h"
#include "../common/test_files.h"
#include "multibin/io/Gzip.h"

namespace {

/** Bytes like a serialized map's: records of floats with zeros, random bytes, runs. */
std::vector<uint8_t> mapLikeBytes(size_t size, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<uint8_t> d;
    while (d.size() < size) {
        const int kind = int(rng() % 3);
        if (kind == 0) {
            for (int k = 0; k < 60; k++) d.push_back(k % 4 == 3 ? 0x3d : uint8_t(rng() % 7));
        } else if (kind == 1) {
            for (size_t k = 1 + rng() % 50; k > 0; k--) d.push_back(uint8_t(rng()));
        } else {
            d.insert(d.end(), 1 + rng() % 400, uint8_t(rng()));
        }
    }
    d.resize(size);
    return d;
}

}  // namespace

// Every byte comes back through zlib's decoder, which checks the gzip CRC-32 and length.
TEST(Gzip, ZlibReadsBackEveryByte) {
    for (const size_t size : {size_t(0), size_t(1), size_t(1000), size_t(300000)}) {
        const std::vector<uint8_t> data = mapLikeBytes(size, uint32_t(size) + 7);
        const std::vector<uint8_t> gz = multibin::gzipCompressed(data.data(), data.size());
        ASSERT_GE(gz.size(), 18u) << "a gzip header and trailer at least";
        EXPECT_EQ(gz[0], 0x1f);
        EXPECT_EQ(gz[1], 0x8b);
        EXPECT_EQ(test_bytes::inflated(gz, size, 15 + 16), data) << size << " bytes";
        if (size >= 1000) EXPECT_LT(gz.size(), size) << "map-like bytes shrink";
    }
}

// A file of it is what MRPT's CFileGZInputStream (elevation_map.bin's reader) reads.
TEST(Gzip, MrptGzInputStreamReadsTheFile) {
    const std::vector<uint8_t> data = mapLikeBytes(100000, 3);
    const std::vector<uint8_t> gz = multibin::gzipCompressed(data.data(), data.size());
    const std::filesystem::path path = test_files::scratchDir("io", "gzip") / "map.gz";
    test_files::writeAll(path, std::string(gz.begin(), gz.end()));
    mrpt::io::CFileGZInputStream in(path.string());
    std::vector<uint8_t> back(data.size() + 10);
    const size_t n = in.Read(back.data(), back.size());
    in.close();
    back.resize(n);
    EXPECT_EQ(back, data);
}
