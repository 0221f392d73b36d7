/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: serialization. */
#include <libdeflate.h>
#include <mrpt/config.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/core/reverse_bytes.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

using namespace mrpt::maps;

namespace {
constexpr const char* kCreationSection = "creation";
constexpr const char* kInsertionSection = "insertion";
// The options travel as ini text of a few kB; a longer one is corrupt (and must be refused before
// MRPT's string reader allocates whatever length the stream claims).
constexpr uint32_t kMaxOptionsTextBytes = 1u << 20;
// Version 1 ends with the bin count and then this tag. MRPT's CArchive reads a value cut in the
// middle without a word, so a stream that loses its last bytes would otherwise load a garbage last
// bin; a cut tag never matches (its high bytes are non-zero).
constexpr uint32_t kTrailerTag = 0x4D42454D;  // "MBEM"

/** The plane moments of a bin, in their declaration order (serialization version 3). */
template <class Moments, class Visit>
void forEachMoment(Moments& m, Visit&& visit) {
    for (auto* v :
         {&m.weight, &m.mx_m, &m.my_m, &m.mz_m, &m.sxx, &m.sxy, &m.syy, &m.sxz, &m.syz, &m.szz})
        visit(*v);
}

/** Numbers written as CArchive's operator<< writes them (little-endian) into a buffer sized in
 * advance: a CArchive write per field costs about a hundred instructions. */
struct ByteCursor {
    uint8_t* at;
    template <typename T>
    void put(T v) {
        static_assert(std::is_arithmetic_v<T>, "a number");
#if MRPT_IS_BIG_ENDIAN
        mrpt::reverseBytesInPlace(v);
#endif
        std::memcpy(at, &v, sizeof v);
        at += sizeof v;
    }
};

/** Bytes of a stored cell's header (ix, iy, bin count) and of each of its bins. */
constexpr size_t kCellHeaderBytes = 4 + 4 + 2;
constexpr size_t kStoredBinBytes = 3 * 4 + 4 + 2 + 10 * 4 + 2;

/** A grid: its window, then each non-empty cell with its bins (each with its plane moments and
 * its pose sigma codes). */
void writeGrid(mrpt::serialization::CArchive& out, const multibin::BinGrid& grid) {
    const multibin::CellWindow& w = grid.window();
    out << int32_t(w.ix0) << int32_t(w.iy0) << int32_t(w.nx) << int32_t(w.ny);
    // The non-empty cells found tile by tile (not over the window: a route's window is mostly
    // empty), then written row by row as the reader expects, their records gathered in chunks:
    // a CArchive write per field costs about a hundred instructions, a copy of the whole grid's
    // records as much memory as the serialized map.
    struct StoredCell {
        int32_t iy, ix;
        uint16_t bins;
        bool operator<(const StoredCell& o) const { return iy != o.iy ? iy < o.iy : ix < o.ix; }
    };
    std::vector<StoredCell> cells;
    grid.store().forEachStoredBin([&](int ix, int iy, const multibin::Bin&) {
        if (cells.empty() || ix != cells.back().ix || iy != cells.back().iy)
            cells.push_back({int32_t(iy), int32_t(ix), 0});
        cells.back().bins++;
    });
    std::sort(cells.begin(), cells.end());
    out << uint64_t(cells.size());
    constexpr size_t kChunkBytes = size_t(1) << 20;
    std::vector<uint8_t> chunk(kChunkBytes);
    ByteCursor to{chunk.data()};
    const auto flush = [&] {
        if (to.at != chunk.data()) out.WriteBuffer(chunk.data(), size_t(to.at - chunk.data()));
        to.at = chunk.data();
    };
    for (const StoredCell& c : cells) {
        const size_t need = kCellHeaderBytes + c.bins * kStoredBinBytes;
        if (size_t(to.at - chunk.data()) + need > chunk.size()) flush();
        if (need > chunk.size()) {  // a cell of more than 17 k bins
            chunk.resize(need);
            to.at = chunk.data();
        }
        to.put(c.ix), to.put(c.iy), to.put(c.bins);
        grid.forEachBin(c.ix, c.iy, [&](const multibin::Bin& b) {
            to.put(b.height_m), to.put(b.variance_m2), to.put(b.certainty), to.put(b.pointCount);
            to.put(b.index);
            forEachMoment(b.plane, [&](const float& v) { to.put(v); });
            to.put(b.poseHeightSigmaCode), to.put(b.poseHorizontalSigmaCode);
        });
    }
    flush();
}

/** `text` without its lines that start with `key` followed by a space or '='. */
std::string withoutLines(const std::string& text, const std::string& key) {
    std::string out;
    size_t begin = 0;
    while (begin < text.size()) {
        size_t end = text.find('\n', begin);
        end = end == std::string::npos ? text.size() : end + 1;
        const bool drop = text.compare(begin, key.size(), key) == 0 &&
                          begin + key.size() < text.size() &&
                          (text[begin + key.size()] == ' ' || text[begin + key.size()] == '=');
        if (!drop) out.append(text, begin, end - begin);
        begin = end;
    }
    return out;
}

[[noreturn]] void corrupt(const std::string& what) {
    throw std::runtime_error("CMultiBinElevationMap: corrupt serialized map (" + what + ")");
}

/** What a stored grid holds, read and checked before the grid allocates its window. */
struct StoredGrid {
    multibin::CellWindow window;
    struct Cell {
        int32_t ix, iy;
        size_t firstBin;
        uint16_t bins;
    };
    std::vector<Cell> cells;
    std::vector<multibin::Bin> bins;
};

/** Cells a stored window may span whatever it holds (16 bytes each in BinStore: 256 MB), and
 * per non-empty cell beyond that: a map of real data is never sparser (a 1 km walk along the
 * diagonal of a 2 cm window leaves one cell in 100 non-empty), a lying 1 kB file is. */
constexpr uint64_t kWindowCellsFree = uint64_t(1) << 24;
constexpr uint64_t kWindowCellsPerNonEmptyCell = 1024;

/** Checks a stored window: sides within the stored options' limit (maxSideCells), every cell
 * index within what BinStore can index (its clamp of coordinates), so that ix0 + nx cannot
 * overflow. */
void checkWindow(const multibin::CellWindow& w, double maxSideCells) {
    const std::string sides = std::to_string(w.nx) + " x " + std::to_string(w.ny) + " cells";
    if (w.nx < 0 || w.ny < 0) corrupt("window of " + sides + ", a negative side");
    // maxSideCells is infinite for a growing grid: only a finite limit is ever printed.
    if (double(w.nx) > maxSideCells || double(w.ny) > maxSideCells)
        corrupt("window of " + sides + ", beyond the stored options' limit of " +
                std::to_string(int64_t(maxSideCells)) + " per side");
    const double maxIndex =
        multibin::BinStore::clampedCellCoordinate(std::numeric_limits<double>::infinity());
    for (const int64_t i :
         {int64_t(w.ix0), int64_t(w.iy0), int64_t(w.ix0) + w.nx, int64_t(w.iy0) + w.ny})
        if (double(std::abs(i)) > maxIndex)
            corrupt("window from cell (" + std::to_string(w.ix0) + ", " + std::to_string(w.iy0) +
                    ") over " + std::to_string(w.nx) + " x " + std::to_string(w.ny) +
                    " cells, beyond the cell indices the grid supports (+-" +
                    std::to_string(int64_t(maxIndex)) + ")");
}

/** Checks a stored bin for sense: finite, non-negative variance and certainty, its height inside
 * its own vertical bin [index, index + 1) * binHeight_m, give or take float rounding (a point
 * just below a bin's top, stored as float, may round onto it). */
void checkBin(const multibin::Bin& b, int ix, int iy, double binHeight_m) {
    const std::string where = "bin " + std::to_string(b.index) + " of cell (" + std::to_string(ix) +
                              ", " + std::to_string(iy) + ")";
    if (!std::isfinite(b.height_m) || !(b.variance_m2 >= 0) || !std::isfinite(b.variance_m2) ||
        !(b.certainty >= 0) || !std::isfinite(b.certainty))
        corrupt("invalid " + where);
    const double bottom_m = b.index * binHeight_m, top_m = (b.index + 1) * binHeight_m;
    const double rounding_m = 1e-3 * binHeight_m + 1e-6 * std::abs(double(b.height_m));
    if (!(b.height_m >= bottom_m - rounding_m && b.height_m <= top_m + rounding_m)) {
        char text[160];
        std::snprintf(text, sizeof text, " holds the height %.9g m, outside its bin [%.9g, %.9g) m",
                      b.height_m, bottom_m, top_m);
        corrupt(where + text);
    }
}

/** Reads a grid (see readGrid) into memory that grows only with the bytes read. */
StoredGrid readStoredGrid(mrpt::serialization::CArchive& in, double maxSideCells,
                          double binHeight_m, bool withPlane, bool withPose) {
    StoredGrid g;
    multibin::CellWindow& w = g.window;
    int32_t ix0, iy0, nx, ny;
    in >> ix0 >> iy0 >> nx >> ny;
    w = multibin::CellWindow{ix0, iy0, nx, ny};
    checkWindow(w, maxSideCells);
    uint64_t nonEmpty;
    in >> nonEmpty;
    if (nonEmpty > w.cellCount())
        corrupt(std::to_string(nonEmpty) + " cells in a window of " +
                std::to_string(w.cellCount()));
    std::vector<uint8_t> seen(size_t(1) << 16);  // the bin indices of the cell being read
    for (uint64_t c = 0; c < nonEmpty; c++) {
        StoredGrid::Cell cell{0, 0, g.bins.size(), 0};
        in >> cell.ix >> cell.iy >> cell.bins;
        if (!w.contains(cell.ix, cell.iy)) corrupt("cell outside the window");
        // Written row by row, each cell once: a cell out of that order is a duplicate or a lie.
        if (!g.cells.empty() && std::make_pair(cell.iy, cell.ix) <=
                                    std::make_pair(g.cells.back().iy, g.cells.back().ix))
            corrupt("cell (" + std::to_string(cell.ix) + ", " + std::to_string(cell.iy) +
                    ") listed twice or out of order");
        if (cell.bins == 0) corrupt("a non-empty cell with no bins");
        for (uint16_t k = 0; k < cell.bins; k++) {
            multibin::Bin b;
            in >> b.height_m >> b.variance_m2 >> b.certainty >> b.pointCount >> b.index;
            checkBin(b, cell.ix, cell.iy, binHeight_m);
            if (seen[size_t(b.index - std::numeric_limits<int16_t>::min())]++)
                corrupt("bin " + std::to_string(b.index) + " of cell (" + std::to_string(cell.ix) +
                        ", " + std::to_string(cell.iy) + ") stored twice");
            if (withPlane) {
                bool finite = true;
                forEachMoment(b.plane, [&](float& v) {
                    in >> v;
                    finite = finite && std::isfinite(v);
                });
                // Weights and centred squares are sums of non-negative terms.
                const multibin::PlaneMoments& m = b.plane;
                if (!finite || !(m.weight >= 0) || !(m.sxx >= 0) || !(m.syy >= 0) || !(m.szz >= 0))
                    corrupt("invalid plane moments");
            }
            if (withPose) in >> b.poseHeightSigmaCode >> b.poseHorizontalSigmaCode;
            g.bins.push_back(b);
        }
        for (size_t k = cell.firstBin; k < g.bins.size(); k++)
            seen[size_t(g.bins[k].index - std::numeric_limits<int16_t>::min())] = 0;
        g.cells.push_back(cell);
    }
    const uint64_t allowed =
        std::max(kWindowCellsFree, kWindowCellsPerNonEmptyCell * g.cells.size());
    if (w.cellCount() > allowed)
        corrupt("window of " + std::to_string(w.nx) + " x " + std::to_string(w.ny) + " cells for " +
                std::to_string(g.cells.size()) + " non-empty cells: more than " +
                std::to_string(allowed) + " cells, sparser than any map of data");
    return g;
}

/** Reads a grid whose window may have at most maxSideCells cells per side (the stored options'
 * own limit); its bins carry plane moments if `withPlane` (version 3; before, a loaded bin has
 * none) and pose sigma codes if `withPose` (version 4; before, not known). Everything is read and
 * checked for sense before the grid allocates its window. */
void readGrid(mrpt::serialization::CArchive& in, multibin::BinGrid& grid, double cellSize_m,
              double maxSideCells, double binHeight_m, bool withPlane, bool withPose) {
    const StoredGrid g = readStoredGrid(in, maxSideCells, binHeight_m, withPlane, withPose);
    grid.reset(cellSize_m, g.window);
    for (const StoredGrid::Cell& c : g.cells)
        for (size_t k = 0; k < c.bins; k++) grid.appendBin(c.ix, c.iy, g.bins[c.firstBin + k]);
}
/** What a serialized map holds, read completely (and checked) before the map is touched. */
struct StoredMap {
    /** Options text without the origin keys (written before the map had an origin): the grid's
     * cells are relative to (0, 0). */
    bool originAtZero = false;
    CMultiBinElevationMap::TCreationOptions creation;
    CMultiBinElevationMap::TInsertionOptions insertion;
    multibin::BinGrid grid, local;
};

/** The body: options text, grid(s), and (from version 1) the bin count and tag; from version 3
 * each bin carries its plane moments, from version 4 its pose sigma codes. */
StoredMap readBody(mrpt::serialization::CArchive& in, uint8_t version) {
    const bool withPlane = version >= 3, withPose = version >= 4;
    StoredMap m;
    // Same layout as MRPT's string (uint32 length, bytes), read with a bound first.
    uint32_t textBytes = 0;
    in >> textBytes;
    if (textBytes > kMaxOptionsTextBytes)
        corrupt("options text of " + std::to_string(textBytes) + " bytes");
    std::string iniText(textBytes, '\0');
    if (textBytes > 0 && in.ReadBuffer(iniText.data(), textBytes) != textBytes)
        corrupt("options text cut short");
    // Maps written before the storage was tiled hold `max_size_m`: not a user's ini, so no
    // message about the retired key, which is dropped.
    mrpt::config::CConfigFileMemory ini(withoutLines(iniText, "max_size_m"));
    m.originAtZero = !ini.keyExists(kCreationSection, "origin_auto");
    m.creation.loadFromConfigFile(ini, kCreationSection);
    m.insertion.loadFromConfigFile(ini, kInsertionSection);
    multibin::BinGrid &grid = m.grid, &local = m.local;
    // A window never exceeds what the options allow: a growing grid (the single one, the dual
    // grid's global one) any size the cell indices allow (checkWindow), a fixed extent or the
    // local grid their size (the margin covers rounding at the window's edges).
    const auto& c = m.creation;
    constexpr double kAnySize = std::numeric_limits<double>::infinity();
    if (c.dual_grid) {
        readGrid(in, grid, c.global_resolution_m, kAnySize, c.bin_height_m, withPlane, withPose);
        readGrid(in, local, c.local_resolution_m, c.local_size_m / c.local_resolution_m + 2,
                 c.bin_height_m, withPlane, withPose);
    } else {
        const double fixedSide_m = std::max(c.max_x - c.min_x, c.max_y - c.min_y);
        readGrid(in, grid, c.resolution_m, c.grow ? kAnySize : fixedSide_m / c.resolution_m + 2,
                 c.bin_height_m, withPlane, withPose);
    }
    if (version >= 1) {
        uint32_t tag = 0;
        uint64_t bins = 0;
        in >> bins >> tag;
        if (tag != kTrailerTag || bins != grid.binCount() + local.binCount())
            throw std::runtime_error(
                "CMultiBinElevationMap: corrupt serialized map (truncated: its trailer is "
                "missing or does not match the bins read)");
    }
    return m;
}
}  // namespace

uint8_t CMultiBinElevationMap::serializeGetVersion() const { return 4; }

namespace {
/** Versions 2 to 4 wrap the body (the payload) as: uint64 payload bytes, the payload, the CRC-32
 * of the payload. A flipped bit anywhere in it is an error before anything is parsed. Version 3's
 * body is version 1's with each bin's plane moments after its estimate; version 4's adds the
 * bin's two pose sigma codes (Bin.h) after the moments. */
constexpr size_t kPayloadChunkBytes = size_t(1) << 20;

/** The payload's checksum as MRPT's compute_CRC32 defines it (CRC-32's reflected polynomial
 * 0xEDB88320, the register starting at 0, no final inversion), so every file written before reads
 * back, computed by libdeflate's vectorised CRC-32 instead of MRPT's bit by bit: it inverts the
 * register on entry and on exit (as zlib's), so it starts from ~0 and its result is inverted
 * back. */
uint32_t payloadCrc32(const uint8_t* data, uint64_t n) {
    return ~libdeflate_crc32(0xFFFFFFFFu, data, size_t(n));
}
}  // namespace

void CMultiBinElevationMap::serializeTo(mrpt::serialization::CArchive& out) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    mrpt::io::CMemoryStream mem;
    {
        auto body = mrpt::serialization::archiveFrom(mem);
        // Options travel as ini text: readable, and keys can be added without a new version.
        mrpt::config::CConfigFileMemory ini;
        // A fixed origin travels as an explicit one: the stored cells are relative to it.
        TCreationOptions creation = creationOptions;
        if (m_impl->originFixed) {
            creation.origin_auto = false;
            creation.origin_x_m = m_impl->origin_m.x();
            creation.origin_y_m = m_impl->origin_m.y();
        }
        creation.saveToConfigFile(ini, kCreationSection);
        insertionOptions.saveToConfigFile(ini, kInsertionSection);
        std::string iniText;
        ini.getContent(iniText);
        body << iniText;
        writeGrid(body, m_impl->grid);
        if (creationOptions.dual_grid) writeGrid(body, m_impl->local);
        body << uint64_t(m_impl->grid.binCount() + m_impl->local.binCount()) << kTrailerTag;
    }
    const auto* payload = static_cast<const uint8_t*>(mem.getRawBufferData());
    const uint64_t n = mem.getTotalBytesCount();
    out << n;
    out.WriteBuffer(payload, n);
    out << payloadCrc32(payload, n);
}

void CMultiBinElevationMap::serializeFrom(mrpt::serialization::CArchive& in, uint8_t version) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    auto apply = [this](StoredMap&& m) {
        creationOptions = m.creation;
        insertionOptions = m.insertion;
        internal_clear();
        if (m.originAtZero) {
            m_impl->origin_m = {0, 0};
            m_impl->originFixed = true;
        }
        m_impl->grid = std::move(m.grid);
        m_impl->local = std::move(m.local);
    };
    switch (version) {
        case 0:
        case 1:
            apply(readBody(in, version));
            break;
        case 2:
        case 3:
        case 4: {
            uint64_t n = 0;
            in >> n;
            // Read in chunks: the buffer grows only as bytes arrive, whatever length is claimed.
            std::vector<uint8_t> payload;
            while (payload.size() < n) {
                const size_t chunk =
                    size_t(std::min<uint64_t>(n - payload.size(), kPayloadChunkBytes));
                const size_t at = payload.size();
                payload.resize(at + chunk);
                if (in.ReadBuffer(payload.data() + at, chunk) != chunk)
                    corrupt("payload cut short: " + std::to_string(n) + " bytes declared");
            }
            uint32_t storedCrc = 0;
            in >> storedCrc;
            const uint32_t actual = payloadCrc32(payload.data(), payload.size());
            if (storedCrc != actual)
                corrupt("checksum mismatch: the " + std::to_string(n) +
                        "-byte payload has CRC-32 " + std::to_string(actual) + ", stored " +
                        std::to_string(storedCrc));
            mrpt::io::CMemoryStream mem;
            mem.assignMemoryNotOwn(payload.data(), payload.size());
            auto body = mrpt::serialization::archiveFrom(mem);
            StoredMap stored = readBody(body, version == 2 ? 1 : version);
            if (mem.getPosition() != payload.size()) corrupt("bytes after the payload's trailer");
            apply(std::move(stored));
        } break;
        default:
            MRPT_THROW_UNKNOWN_SERIALIZATION_VERSION(version);
    }
}
