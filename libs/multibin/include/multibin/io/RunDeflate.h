/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace cv {
class Mat;  // image() needs <opencv2/core.hpp>
}

namespace multibin {

/** A zlib stream (RFC 1950) of `size` bytes that codes only runs: stretches where every byte
 * equals the one `period` bytes before (a pixel or a float sample repeated) or, when rowBytes is
 * given (at most 32768), the one a row before (a row repeated); other bytes are literals. One
 * DEFLATE block (RFC 1951) with Huffman codes fitted to the symbols. For rasters that are mostly
 * runs (previews of a sparse map, GeoTIFF tiles mostly NaN): the files are about the size zlib
 * makes at its fastest level, for a cost that follows the runs, not the bytes (a general
 * compressor hashes or scans every byte for matches these rasters do not have). period 1 to 8. */
std::vector<uint8_t> runDeflateZlib(const uint8_t* data, size_t size, int period,
                                    size_t rowBytes = 0);

/** The same coding as a gzip file (RFC 1952; what zlib's gzread and MRPT's CFileGZInputStream
 * read), without row matches. */
std::vector<uint8_t> runDeflateGzip(const uint8_t* data, size_t size, int period);

/** The scanlines of an 8-bit RGB PNG image (each a filter byte 0, "none", then R, G, B per
 * pixel), white, to draw into through image(); encode() makes the PNG file, compressed by
 * runDeflateZlib(): decoders read back exactly the pixels drawn. */
class PngScanlines {
public:
    PngScanlines(int cols, int rows);  //!< throws std::invalid_argument unless both >= 1
    /** An OpenCV image over the pixels (CV_8UC3, channels R, G, B, row step 3 cols + 1). */
    cv::Mat image();
    std::vector<uint8_t> encode() const;

private:
    int m_cols, m_rows;
    std::vector<uint8_t> m_bytes;
};

/** A PNG file of `rows` x `cols` pixels given as contiguous R, G, B bytes (PngScanlines). */
std::vector<uint8_t> rgbPng(const uint8_t* rgb, int cols, int rows);

}  // namespace multibin
