/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mrpt::serialization {
class CSerializable;
}

namespace multibin {

/** A gzip file (RFC 1952) of `size` bytes, coded by libdeflate at its fastest level: what zlib's
 * gzread and MRPT's CFileGZInputStream read. About 2.5 times as fast as zlib's fastest level on
 * a serialized map, and a few per cent smaller. Throws std::runtime_error when libdeflate cannot
 * start (out of memory). */
std::vector<uint8_t> gzipCompressed(const uint8_t* data, size_t size);

/** `object` as MRPT serializes it (CArchive::WriteObject) in a gzip file (gzipCompressed()):
 * what MRPT's CFileGZInputStream and CArchive::ReadObject read back, a map file as
 * elevation-mapper and the Python module save it (with writeFileAtomically(), OutputFile.h). */
std::vector<uint8_t> gzipSerialized(const mrpt::serialization::CSerializable& object);

}  // namespace multibin
