/* Part of the multibin elevation-mapping library: gzip files coded by libdeflate. */
#include "multibin/io/Gzip.h"

#include <libdeflate.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <memory>
#include <stdexcept>

namespace multibin {

std::vector<uint8_t> gzipCompressed(const uint8_t* data, size_t size) {
    const std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> compressor(
        libdeflate_alloc_compressor(1), libdeflate_free_compressor);
    if (!compressor) throw std::runtime_error("gzip compression could not start (out of memory)");
    std::vector<uint8_t> gz(libdeflate_gzip_compress_bound(compressor.get(), size));
    // The bound is what libdeflate needs for any input: 0 (no room) cannot happen.
    gz.resize(libdeflate_gzip_compress(compressor.get(), data, size, gz.data(), gz.size()));
    if (gz.empty()) throw std::runtime_error("gzip compression failed");
    return gz;
}

std::vector<uint8_t> gzipSerialized(const mrpt::serialization::CSerializable& object) {
    // In memory, so the file is written whole by writeFileAtomically(): MRPT's
    // compress_gz_data_block() goes through a temporary file whose write errors it ignores.
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << object;
    return gzipCompressed(static_cast<const uint8_t*>(mem.getRawBufferData()),
                          size_t(mem.getTotalBytesCount()));
}

}  // namespace multibin
