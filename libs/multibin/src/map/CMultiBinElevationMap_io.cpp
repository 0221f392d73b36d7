/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: serialization, rasters, images and files. */
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/crc.h>
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "multibin/io/RasterExport.h"
#include "multibin/map/CellSurface.h"

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

/** A grid: its window, then each non-empty cell with its bins (each with its plane moments and
 * its pose sigma codes). */
void writeGrid(mrpt::serialization::CArchive& out, const multibin::BinGrid& grid) {
    const multibin::CellWindow& w = grid.window();
    out << int32_t(w.ix0) << int32_t(w.iy0) << int32_t(w.nx) << int32_t(w.ny);
    uint64_t nonEmpty = 0;
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            bool any = false;
            grid.forEachBin(ix, iy, [&](const multibin::Bin&) { any = true; });
            nonEmpty += any;
        }
    out << nonEmpty;
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++) {
            uint16_t n = 0;
            grid.forEachBin(ix, iy, [&](const multibin::Bin&) { n++; });
            if (!n) continue;
            out << int32_t(ix) << int32_t(iy) << n;
            grid.forEachBin(ix, iy, [&](const multibin::Bin& b) {
                out << b.height_m << b.variance_m2 << b.certainty << b.pointCount << b.index;
                forEachMoment(b.plane, [&](const float& v) { out << v; });
                out << b.poseHeightSigmaCode << b.poseHorizontalSigmaCode;
            });
        }
}

[[noreturn]] void corrupt(const std::string& what) {
    throw std::runtime_error("CMultiBinElevationMap: corrupt serialized map (" + what + ")");
}

/** Reads a grid whose window may have at most maxSideCells cells per side (the stored options'
 * own limit), checked before anything is allocated; its bins carry plane moments if
 * `withPlane` (version 3; before, a loaded bin has none) and pose sigma codes if `withPose`
 * (version 4; before, not known). */
void readGrid(mrpt::serialization::CArchive& in, multibin::BinGrid& grid, double cellSize_m,
              double maxSideCells, bool withPlane, bool withPose) {
    int32_t ix0, iy0, nx, ny;
    in >> ix0 >> iy0 >> nx >> ny;
    if (nx < 0 || ny < 0 || double(nx) > maxSideCells || double(ny) > maxSideCells)
        corrupt("window of " + std::to_string(nx) + " x " + std::to_string(ny) +
                " cells, beyond the stored options' limit of " +
                std::to_string(int64_t(maxSideCells)) + " per side");
    grid.reset(cellSize_m, multibin::CellWindow{ix0, iy0, nx, ny});
    uint64_t nonEmpty;
    in >> nonEmpty;
    if (nonEmpty > uint64_t(nx) * uint64_t(ny))
        corrupt(std::to_string(nonEmpty) + " cells in a window of " +
                std::to_string(uint64_t(nx) * uint64_t(ny)));
    for (uint64_t c = 0; c < nonEmpty; c++) {
        int32_t ix, iy;
        uint16_t n;
        in >> ix >> iy >> n;
        if (!grid.window().contains(ix, iy)) corrupt("cell outside the window");
        for (uint16_t k = 0; k < n; k++) {
            multibin::Bin b;
            in >> b.height_m >> b.variance_m2 >> b.certainty >> b.pointCount >> b.index;
            if (!std::isfinite(b.height_m) || !(b.variance_m2 >= 0) || !(b.certainty >= 0))
                corrupt("invalid bin");
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
            grid.appendBin(ix, iy, b);
        }
    }
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
    mrpt::config::CConfigFileMemory ini(iniText);
    m.originAtZero = !ini.keyExists(kCreationSection, "origin_auto");
    m.creation.loadFromConfigFile(ini, kCreationSection);
    m.insertion.loadFromConfigFile(ini, kInsertionSection);
    multibin::BinGrid &grid = m.grid, &local = m.local;
    // A window never exceeds what the options allow (growth stops at max_size_m; the margin
    // covers rounding at the window's edges).
    const auto& c = m.creation;
    const double singleSide_m = std::max({c.max_size_m, c.max_x - c.min_x, c.max_y - c.min_y});
    if (c.dual_grid) {
        readGrid(in, grid, c.global_resolution_m, c.global_size_m / c.global_resolution_m + 2,
                 withPlane, withPose);
        readGrid(in, local, c.local_resolution_m, c.local_size_m / c.local_resolution_m + 2,
                 withPlane, withPose);
    } else {
        readGrid(in, grid, c.resolution_m, singleSide_m / c.resolution_m + 2, withPlane, withPose);
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
}  // namespace

void CMultiBinElevationMap::serializeTo(mrpt::serialization::CArchive& out) const {
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
    out << mrpt::system::compute_CRC32(payload, n);
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
            const uint32_t actual = mrpt::system::compute_CRC32(payload.data(), payload.size());
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

multibin::EsriAsciiGrid CMultiBinElevationMap::toRaster(RasterLayer layer) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    const multibin::CellWindow& w = m_impl->grid.window();
    multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice(m_impl->grid.lattice());
    const Eigen::Vector2d& o = m_impl->origin_m;  // the raster is in the pose frame
    g.xllcenter_m += o.x();
    g.yllcenter_m += o.y();
    for (int r = 0; r < w.ny; r++)
        for (int c = 0; c < w.nx; c++) {
            const int ix = w.ix0 + c, iy = w.iy0 + r;
            double h, s;
            const HeightSource src = cellElevation(o.x() + m_impl->grid.cellCenter_m(ix),
                                                   o.y() + m_impl->grid.cellCenter_m(iy), h, s,
                                                   insertionOptions.dem_return_filled);
            if (src == HeightSource::Unknown) continue;
            float& out = g.heights_m(r, c);
            switch (layer) {
                case RasterLayer::Height:
                    out = float(h);
                    break;
                case RasterLayer::Sigma:
                    out = float(s);
                    break;
                case RasterLayer::Source:
                    out = float(static_cast<int>(src));
                    break;
                case RasterLayer::Certainty: {
                    // The certainty of the surface the height layer reports (0 where filled).
                    multibin::CellSurface c;
                    out = src == HeightSource::Measured &&
                                  multibin::surfaceAt(
                                      m_impl->grid, isDualGrid() ? &m_impl->local : nullptr,
                                      m_impl->grid.cellCenter_m(ix), m_impl->grid.cellCenter_m(iy),
                                      binUpdateParams(), false, c)
                              ? float(c.certainty)
                              : 0.f;
                } break;
            }
        }
    return g;
}

void CMultiBinElevationMap::getAsImage(mrpt::img::CImage& img, bool sigma) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    const multibin::EsriAsciiGrid g = toRaster(sigma ? RasterLayer::Sigma : RasterLayer::Height);
    const int rows = g.rows(), cols = g.cols();
    img.resize(std::max(cols, 1), std::max(rows, 1), mrpt::img::CH_RGB);
    img.filledRectangle(0, 0, std::max(cols, 1) - 1, std::max(rows, 1) - 1,
                        mrpt::img::TColor(0, 0, 0));
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const float v = g.heights_m(r, c);
            if (std::isnan(v)) continue;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    if (!(lo <= hi)) return;
    const float span = hi > lo ? hi - lo : 1.f;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const float v = g.heights_m(r, c);
            if (std::isnan(v)) continue;
            float R, G, B;
            mrpt::img::colormap(insertionOptions.colormap, (v - lo) / span, R, G, B);
            img.setPixel(c, rows - 1 - r,
                         mrpt::img::TColor(uint8_t(255 * R), uint8_t(255 * G), uint8_t(255 * B)));
        }
}

void CMultiBinElevationMap::saveMetricMapRepresentationToFile(
    const std::string& filNamePrefix) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    // Rasters cover the known cells plus a margin, not the whole grown window.
    const multibin::RasterBox box = multibin::knownBox(toRaster(RasterLayer::Height), 5);
    const auto raster = [&](RasterLayer l) { return multibin::cropRaster(toRaster(l), box); };
    for (const bool sigma : {false, true}) {
        const std::string layer = sigma ? "_sigma" : "_height";
        mrpt::img::CImage img;
        getAsImage(img, sigma);
        if (!img.saveToFile(filNamePrefix + layer + ".png"))
            throw std::runtime_error("CMultiBinElevationMap: cannot write " + filNamePrefix +
                                     layer + ".png");
        raster(sigma ? RasterLayer::Sigma : RasterLayer::Height)
            .save(filNamePrefix + layer + ".asc");
    }
    raster(RasterLayer::Certainty).save(filNamePrefix + "_certainty.asc");
    raster(RasterLayer::Source).save(filNamePrefix + "_source.asc");
    const multibin::EsriAsciiGrid heights = raster(RasterLayer::Height);
    if (heights.rows() > 0 && heights.cols() > 0) {
        multibin::saveFloatTiff(heights, filNamePrefix + "_height.tif");
        multibin::saveMeshPly(heights, filNamePrefix + ".ply");
    }
    mrpt::opengl::COpenGLScene scene;
    auto obj = mrpt::opengl::CSetOfObjects::Create();
    getVisualizationInto(*obj);
    scene.insert(obj);
    if (!scene.saveToFile(filNamePrefix + ".3Dscene"))
        throw std::runtime_error("CMultiBinElevationMap: cannot write " + filNamePrefix +
                                 ".3Dscene");
}
