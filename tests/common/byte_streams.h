/* Byte streams of tests: what MRPT serializes, what zlib decodes. */
#pragma once

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>
#include <zlib.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace test_bytes {

/** The bytes `archive << o` writes. */
inline std::vector<uint8_t> serialized(const mrpt::serialization::CSerializable& o) {
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << o;
    const auto* p = static_cast<const uint8_t*>(mem.getRawBufferData());
    return {p, p + mem.getTotalBytesCount()};
}

/** zlib's inflate of a zlib (windowBits 15) or gzip (31) stream of at most `expected` bytes;
 * throws on any error (a bad code, a wrong Adler-32 or CRC-32 or length, bytes after the
 * stream). The caller links ZLIB::ZLIB. */
inline std::vector<uint8_t> inflated(const std::vector<uint8_t>& in, size_t expected,
                                     int windowBits) {
    z_stream z{};
    if (inflateInit2(&z, windowBits) != Z_OK) throw std::runtime_error("inflateInit2");
    std::vector<uint8_t> out(expected + 16);
    z.next_in = const_cast<Bytef*>(in.data());
    z.avail_in = uInt(in.size());
    z.next_out = out.data();
    z.avail_out = uInt(out.size());
    const int rc = inflate(&z, Z_FINISH);
    const size_t n = z.total_out, left = z.avail_in;
    inflateEnd(&z);
    if (rc != Z_STREAM_END) throw std::runtime_error("inflate: " + std::to_string(rc));
    if (left != 0) throw std::runtime_error("bytes after the stream");
    out.resize(n);
    return out;
}

}  // namespace test_bytes
