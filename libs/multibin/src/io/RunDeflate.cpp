/* Part of the multibin elevation-mapping library: a DEFLATE coder of runs for rasters (PNG
 * previews, GeoTIFF tiles). */
#include "multibin/io/RunDeflate.h"

#include <libdeflate.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>

namespace multibin {
namespace {

constexpr uint32_t kAdlerMod = 65521;
constexpr int kMinMatch = 3, kMaxMatch = 258, kMaxDistance = 32768;
constexpr int kLitLenSymbols = 286, kDistSymbols = 30, kMaxCodeBits = 15;

// RFC 1951, 3.2.5: the lengths' and distances' base values and extra bits per code.
constexpr int kLengthBase[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr int kLengthExtra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                  2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
constexpr int kDistBase[30] = {1,    2,    3,    4,    5,    7,    9,    13,    17,    25,
                               33,   49,   65,   97,   129,  193,  257,  385,   513,   769,
                               1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
constexpr int kDistExtra[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

/** The index into kLengthBase of each match length, and into kDistBase of each distance up to
 * a row of 1024 floats (GeoTIFF tiles): tables built by the compiler. */
constexpr int kTabledDistance = 4096;
template <size_t N, size_t Codes>
constexpr std::array<uint8_t, N> codeTable(const int (&base)[Codes], int first) {
    std::array<uint8_t, N> t{};
    for (size_t v = size_t(first), c = 0; v < N; v++) {
        while (c + 1 < Codes && size_t(base[c + 1]) <= v) c++;
        t[v] = uint8_t(c);
    }
    return t;
}
constexpr std::array<uint8_t, kMaxMatch + 1> kLengthCodeOf =
    codeTable<kMaxMatch + 1>(kLengthBase, kMinMatch);
constexpr std::array<uint8_t, kTabledDistance + 1> kDistCodeOf =
    codeTable<kTabledDistance + 1>(kDistBase, 1);

int lengthCode(int len) { return kLengthCodeOf[size_t(len)]; }
int distCode(int dist) {  // farther: a search
    if (dist <= kTabledDistance) return kDistCodeOf[size_t(dist)];
    return int(std::upper_bound(kDistBase, kDistBase + 30, dist) - kDistBase) - 1;
}

/** Adler-32 kept as its two sums, updated by a span of bytes or, in O(period), by a periodic
 * run. */
struct Adler {
    uint64_t a = 1, b = 0;
    void bytes(const uint8_t* p, size_t n) {
        const uint32_t v = libdeflate_adler32(uint32_t((b << 16) | a), p, n);  // vectorised
        a = v & 0xffff, b = v >> 16;
    }
    /** `len` bytes continuing the pattern q[0..d-1] periodically: byte t is q[t mod d]. */
    void periodic(const uint8_t* q, int d, uint64_t len) {
        // b gains len * a plus sum over t of (len - t) q[t mod d]; a gains sum of q[t mod d].
        uint64_t sumA = 0, sumB = 0;
        const uint64_t whole = len / uint64_t(d), rest = len % uint64_t(d);  // one division
        for (int j = 0; j < d && uint64_t(j) < len; j++) {
            const uint64_t n = whole + (uint64_t(j) < rest);  // the bytes t = j mod d
            const uint64_t weight = n * (len - uint64_t(j)) - uint64_t(d) * (n * (n - 1) / 2);
            sumA += (n % kAdlerMod) * q[j];
            sumB += (weight % kAdlerMod) * q[j];
        }
        b = (b + (len % kAdlerMod) * a + sumB) % kAdlerMod;
        a = (a + sumA) % kAdlerMod;
    }
    uint32_t value() const { return uint32_t((b << 16) | a); }
};

/** Bytes equal to the ones `d` before, from `i` on (at most `limit`). */
size_t runLength(const uint8_t* p, size_t i, size_t d, size_t limit) {
    size_t k = 0;
    for (uint64_t x, y; k + 8 <= limit; k += 8) {  // eight at a time while all agree
        std::memcpy(&x, p + i + k, 8);
        std::memcpy(&y, p + i + k - d, 8);
        if (x != y) {
            if constexpr (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__)
                return k + size_t(__builtin_ctzll(x ^ y) >> 3);  // the first byte that differs
            break;
        }
    }
    while (k < limit && p[i + k] == p[i + k - d]) k++;
    return k;
}

/** Literals (< 256) and matches ((length << 16) | distance), with their symbol counts. */
struct Tokens {
    std::vector<uint32_t> list;
    std::array<uint32_t, kLitLenSymbols> litLen{};
    std::array<uint32_t, kDistSymbols> dist{};
    void literal(uint8_t v) {
        list.push_back(v);
        litLen[v]++;
    }
    /** A run of `len` >= 3 bytes at `distance`, as matches of at most 258 (none shorter than 3). */
    void run(size_t len, int distance) {
        while (len > 0) {
            size_t m = std::min<size_t>(len, kMaxMatch);
            if (len - m > 0 && len - m < size_t(kMinMatch)) m = len - kMinMatch;
            list.push_back(uint32_t(m) << 16 | uint32_t(distance));
            litLen[size_t(257 + lengthCode(int(m)))]++;
            dist[size_t(distCode(distance))]++;
            len -= m;
        }
    }
};

/** Huffman code lengths of at most kMaxCodeBits for `freq` (0 for unused symbols); at least two
 * symbols are used, so the code is complete (what zlib's and libdeflate's decoders require). */
template <size_t N>
std::array<uint8_t, N> codeLengths(std::array<uint32_t, N> freq) {
    std::array<uint8_t, N> bits{};
    for (;;) {
        // Two-queue Huffman over the used symbols sorted by count: leaves, then merged nodes.
        std::vector<int> leaves;
        for (size_t s = 0; s < N; s++)
            if (freq[s] > 0) leaves.push_back(int(s));
        std::stable_sort(leaves.begin(), leaves.end(),
                         [&](int x, int y) { return freq[size_t(x)] < freq[size_t(y)]; });
        const size_t n = leaves.size();
        std::vector<uint64_t> weight(2 * n);
        std::vector<int> parent(2 * n, -1);
        for (size_t k = 0; k < n; k++) weight[k] = freq[size_t(leaves[k])];
        size_t leaf = 0, node = n, next = n;
        const auto smallest = [&]() {
            if (leaf < n && (node >= next || weight[leaf] <= weight[node])) return leaf++;
            return node++;
        };
        for (; next < 2 * n - 1; next++) {
            const size_t x = smallest(), y = smallest();
            weight[next] = weight[x] + weight[y];
            parent[x] = parent[y] = int(next);
        }
        std::vector<int> depth(2 * n, 0);
        int deepest = 0;
        for (size_t k = 2 * n - 2; k-- > 0;) {
            depth[k] = depth[size_t(parent[k])] + 1;
            deepest = std::max(deepest, depth[k]);
        }
        if (deepest <= kMaxCodeBits) {
            for (size_t k = 0; k < n; k++) bits[size_t(leaves[k])] = uint8_t(depth[k]);
            return bits;
        }
        for (uint32_t& f : freq)  // too deep: flatten the counts and build again
            if (f > 0) f = f / 2 + 1;
    }
}

/** Canonical codes (RFC 1951, 3.2.2), bit-reversed for the LSB-first stream. */
template <size_t N>
std::array<uint16_t, N> canonicalCodes(const std::array<uint8_t, N>& bits) {
    std::array<int, kMaxCodeBits + 2> count{}, next{};
    for (const uint8_t b : bits) count[b]++;
    count[0] = 0;
    for (int b = 1, code = 0; b <= kMaxCodeBits; b++)
        next[size_t(b)] = code = (code + count[size_t(b) - 1]) << 1;
    std::array<uint16_t, N> codes{};
    for (size_t s = 0; s < N; s++) {
        const int len = bits[s];
        if (len == 0) continue;
        const int code = next[size_t(len)]++;
        int reversed = 0;
        for (int k = 0; k < len; k++) reversed |= ((code >> k) & 1) << (len - 1 - k);
        codes[s] = uint16_t(reversed);
    }
    return codes;
}

/** DEFLATE's bit stream (least significant bit first) appended to `out`, four bytes at a time
 * into room made for `maxBits`; finish() writes the last bits and gives back the room unused. */
class BitWriter {
public:
    BitWriter(std::vector<uint8_t>& out, size_t maxBits) : m_out(out), m_used(out.size()) {
        m_out.resize(m_used + maxBits / 8 + 8);
    }
    void put(uint32_t value, int bits) {  // bits <= 32: the buffer holds at most 63 bits
        m_buffer |= uint64_t(value) << m_count;
        m_count += bits;
        if (m_count >= 32) {
            uint8_t* at = m_out.data() + m_used;
            for (int k = 0; k < 4; k++) at[k] = uint8_t(m_buffer >> (8 * k));
            m_used += 4;
            m_buffer >>= 32;
            m_count -= 32;
        }
    }
    void finish() {
        for (; m_count > 0; m_count -= 8, m_buffer >>= 8) m_out[m_used++] = uint8_t(m_buffer);
        m_out.resize(m_used);
    }

private:
    std::vector<uint8_t>& m_out;
    size_t m_used;  // bytes of m_out written
    uint64_t m_buffer = 0;
    int m_count = 0;
};

/** One final dynamic-Huffman block of the tokens. */
void writeBlock(Tokens& t, std::vector<uint8_t>& out) {
    t.litLen[256] = 1;  // end of block
    if (std::count_if(t.litLen.begin(), t.litLen.end(), [](uint32_t f) { return f > 0; }) < 2)
        t.litLen[0]++;  // two symbols at least: a complete code
    for (size_t s = 0;
         std::count_if(t.dist.begin(), t.dist.end(), [](uint32_t f) { return f > 0; }) < 2; s++)
        if (t.dist[s] == 0) t.dist[s] = 1;  // the same for the distances
    const auto litBits = codeLengths(t.litLen);
    const auto distBits = codeLengths(t.dist);
    const auto litCodes = canonicalCodes(litBits);
    const auto distCodes = canonicalCodes(distBits);
    int nLit = kLitLenSymbols, nDist = kDistSymbols;
    while (nLit > 257 && litBits[size_t(nLit) - 1] == 0) nLit--;
    while (nDist > 1 && distBits[size_t(nDist) - 1] == 0) nDist--;

    // 48 bits a token at most (and the end of block), 1 400 bits of header and code lengths.
    BitWriter w(out, (t.list.size() + 1) * 48 + 1400);
    w.put(1, 1);  // final block
    w.put(2, 2);  // dynamic Huffman codes
    w.put(uint32_t(nLit - 257), 5);
    w.put(uint32_t(nDist - 1), 5);
    w.put(19 - 4, 4);
    // The code-length code: lengths 0..15 four bits each (complete), 16..18 unused.
    static const int kOrder[19] = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                   11, 4,  12, 3, 13, 2, 14, 1, 15};
    for (const int s : kOrder) w.put(s >= 16 ? 0 : 4, 3);
    const auto lengthSymbol = [&](int len) {  // canonical code len of 4 bits, reversed
        int r = 0;
        for (int k = 0; k < 4; k++) r |= ((len >> k) & 1) << (3 - k);
        w.put(uint32_t(r), 4);
    };
    for (int s = 0; s < nLit; s++) lengthSymbol(litBits[size_t(s)]);
    for (int s = 0; s < nDist; s++) lengthSymbol(distBits[size_t(s)]);

    for (const uint32_t token : t.list) {
        const uint32_t len = token >> 16;
        if (len == 0) {
            w.put(litCodes[token], litBits[token]);
            continue;
        }
        const int lc = lengthCode(int(len)), dist = int(token & 0xffff);
        const int dc = distCode(dist);
        // Each code with its extra bits in one put (at most 15 + 13 bits).
        const int lb = litBits[size_t(257 + lc)], db = distBits[size_t(dc)];
        w.put(litCodes[size_t(257 + lc)] | uint32_t(int(len) - kLengthBase[lc]) << lb,
              lb + kLengthExtra[lc]);
        w.put(distCodes[size_t(dc)] | uint32_t(dist - kDistBase[dc]) << db, db + kDistExtra[dc]);
    }
    w.put(litCodes[256], litBits[256]);
    w.finish();
}

void put32be(std::vector<uint8_t>& out, uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back(uint8_t(v >> shift));
}

/** The DEFLATE block of `data` into `out`, its Adler-32 into `adler` when given. */
void deflateRuns(const uint8_t* data, size_t size, int period, size_t rowBytes, Adler* adler,
                 std::vector<uint8_t>& out) {
    if (period < 1 || period > 8)
        throw std::invalid_argument("runDeflate: period " + std::to_string(period) +
                                    " outside 1..8");
    if (rowBytes > size_t(kMaxDistance) || rowBytes <= size_t(period)) rowBytes = 0;
    Tokens t;
    t.list.reserve(size / 64 + 16);
    const size_t d = size_t(period);
    size_t i = 0, literalsFrom = 0;  // the literals since literalsFrom: checksummed together
    const auto checksumLiterals = [&] {
        if (adler && i > literalsFrom) adler->bytes(data + literalsFrom, i - literalsFrom);
    };
    while (i < size) {
        const size_t byPeriod = i >= d ? runLength(data, i, d, size - i) : 0;
        const size_t byRow =
            rowBytes && i >= rowBytes && byPeriod < size_t(kMaxMatch)
                ? runLength(data, i, rowBytes, std::min(size - i, size_t(kMaxMatch)))
                : 0;
        if (std::max(byPeriod, byRow) < size_t(kMinMatch)) {
            t.literal(data[i]);
            i++;
            continue;
        }
        checksumLiterals();
        if (byPeriod >= byRow) {  // the whole run at once, its checksum in O(period)
            t.run(byPeriod, period);
            if (adler) adler->periodic(data + i - d, period, byPeriod);
            i += byPeriod;
        } else {
            t.run(byRow, int(rowBytes));
            if (adler) adler->bytes(data + i, byRow);
            i += byRow;
        }
        literalsFrom = i;
    }
    checksumLiterals();
    writeBlock(t, out);
}

}  // namespace

std::vector<uint8_t> runDeflateZlib(const uint8_t* data, size_t size, int period, size_t rowBytes) {
    std::vector<uint8_t> out{0x78, 0x01};  // deflate, 32 kB window, "fastest" (RFC 1950)
    Adler adler;
    deflateRuns(data, size, period, rowBytes, &adler, out);
    put32be(out, adler.value());
    return out;
}

std::vector<uint8_t> runDeflateGzip(const uint8_t* data, size_t size, int period) {
    // RFC 1952: magic, deflate, no flags, no time, fastest, unknown OS.
    std::vector<uint8_t> out{0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 4, 0xff};
    deflateRuns(data, size, period, 0, nullptr, out);
    const uint32_t crc = libdeflate_crc32(0, data, size), n = uint32_t(size);
    for (const uint32_t v : {crc, n})
        for (int shift = 0; shift < 32; shift += 8) out.push_back(uint8_t(v >> shift));
    return out;
}

PngScanlines::PngScanlines(int cols, int rows) : m_cols(cols), m_rows(rows) {
    if (cols < 1 || rows < 1)
        throw std::invalid_argument("PNG of " + std::to_string(cols) + " x " +
                                    std::to_string(rows) + " pixels: empty");
    const size_t rowBytes = size_t(cols) * 3 + 1;
    m_bytes.assign(rowBytes * size_t(rows), 255);
    for (size_t r = 0; r < size_t(rows); r++) m_bytes[r * rowBytes] = 0;  // filter: none
}

cv::Mat PngScanlines::image() {
    return cv::Mat(m_rows, m_cols, CV_8UC3, m_bytes.data() + 1, size_t(m_cols) * 3 + 1);
}

std::vector<uint8_t> PngScanlines::encode() const {
    const std::vector<uint8_t> z =
        runDeflateZlib(m_bytes.data(), m_bytes.size(), 3, size_t(m_cols) * 3 + 1);
    std::vector<uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    const auto chunk = [&](const char* type, const uint8_t* body, size_t n) {
        put32be(png, uint32_t(n));
        const size_t start = png.size();
        png.insert(png.end(), type, type + 4);
        png.insert(png.end(), body, body + n);
        put32be(png, libdeflate_crc32(0, png.data() + start, n + 4));
    };
    std::vector<uint8_t> header;
    put32be(header, uint32_t(m_cols));
    put32be(header, uint32_t(m_rows));
    header.insert(header.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, filters, no interlace
    chunk("IHDR", header.data(), header.size());
    chunk("IDAT", z.data(), z.size());
    chunk("IEND", nullptr, 0);
    return png;
}

std::vector<uint8_t> rgbPng(const uint8_t* rgb, int cols, int rows) {
    PngScanlines png(cols, rows);
    const cv::Mat from(rows, cols, CV_8UC3, const_cast<uint8_t*>(rgb));
    cv::Mat to = png.image();
    from.copyTo(to);
    return png.encode();
}

}  // namespace multibin
