/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RawlogSource.h"

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/lazy_load_path.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CActionRobotMovement3D.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/rtti/CObject.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include <zlib.h>

#include "PoseOverTime.h"
#include "RawlogSourceGuard.h"
#include "RawlogStreamGuard.h"
#include "multibin/io/ErrorMessage.h"

namespace {
struct FileSize {
    uint64_t progress_bytes;  // the bytes MRPT will read, for the progress bar
    uint64_t bound_bytes;     // the bytes MRPT will read (for the read budget)
};

/** The bytes a gz file decompresses to, counted by inflating it as MRPT's stream does (gzread):
 * what follows the gzip members (padding, junk) does not count. An upper bound from the file's
 * size (deflate's 1032:1) grew with such padding: 1 MB of zeros after a small member let an entry
 * ask for 17 GB. */
uint64_t gzDecompressedBytes(const std::string& path) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) throw std::runtime_error("cannot open '" + path + "'");
    std::vector<char> buf(1 << 16);
    uint64_t total = 0;
    for (int n; (n = gzread(f, buf.data(), unsigned(buf.size()))) > 0;) total += uint64_t(n);
    gzclose(f);
    return total;
}

FileSize fileSize(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot open '" + path + "'");
    unsigned char magic[2] = {0, 0};
    f.read(reinterpret_cast<char*>(magic), 2);
    f.clear();
    f.seekg(0, std::ios::end);
    const auto size = static_cast<uint64_t>(f.tellg());
    if (magic[0] != 0x1f || magic[1] != 0x8b) return {size, size};
    const uint64_t inflated = gzDecompressedBytes(path);
    return {inflated, inflated};
}

void openOrThrow(mrpt::io::CFileGZInputStream& in, const std::string& path,
                 const std::string& what) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::is_directory(path, ec))
        throw std::runtime_error(what + " '" + path + "' is a directory, not a file");
    if (!std::ifstream(path).good()) throw std::runtime_error(what + " '" + path + "' not found");
    if (!in.open(path)) throw std::runtime_error("cannot open " + what + " '" + path + "'");
}

std::string gigabytes(uint64_t bytes) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g GB", double(bytes) * 1e-9);
    return b;
}

/** An entry refused by the reading path itself (its message already names the file and the
 * entry), as opposed to an error of MRPT's to be prefixed. */
struct RefusedEntry : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/** Runs `read` (one entry) under the read budget; a refused allocation or content the stream
 * guard refused becomes an error saying so (built after the budget ends: the budget is spent by
 * then). */
template <class Read>
mrpt::serialization::CSerializable::Ptr readBounded(const RawlogStreamGuard& guard,
                                                    uint64_t bytesLeft, const std::string& where,
                                                    const Read& read) {
    uint64_t asked = 0;
    {
        ReadBudget budget(ReadBudget::limitFor(bytesLeft));
        try {
            return read();
        } catch (const std::exception&) {
            asked = ReadBudget::largestRefused();
            if (asked == 0 && guard.refusal().empty()) throw;
        }
    }
    if (asked == 0) throw RefusedEntry(where + ": " + guard.refusal());
    throw RefusedEntry(where + " declares more data than the file holds: reading it asked for " +
                       gigabytes(asked) + " in all, more than 64 MiB + 16 x the " +
                       std::to_string(bytesLeft) + " bytes left");
}

/** What the next object (its header peeked, served again to the next read) is when it is not of
 * a concrete class derived from `base`: "null", "of an unregistered class", "of the abstract
 * class C" or "a C"; empty when it is one. `slot` names it for a header cut short. */
std::string unlessDerivedFrom(RawlogStreamGuard& guard, const mrpt::rtti::TRuntimeClassId* base,
                              const std::string& slot) {
    const RawlogStreamGuard::Header h = guard.peekHeader();
    if (!h.complete) throw std::runtime_error(slot + " is cut short");
    if (h.className == "nullptr") return "null";
    const auto* cls = mrpt::rtti::findRegisteredClass(h.className);
    if (!cls) return "of an unregistered class";
    if (!cls->ptrCreateObject) return std::string("of the abstract class ") + cls->className;
    if (!cls->derivedFrom(base)) return std::string("a ") + cls->className;
    return {};
}

/** The end-of-object flag of an object read here field by field (none in MRPT's framing before
 * 0.5.5). */
void readEndFlag(mrpt::serialization::CArchive& arch, const RawlogStreamGuard::Header& h,
                 const std::string& object) {
    if (h.oldFraming) return;
    uint8_t endFlag = 0;
    arch >> endFlag;
    if (endFlag != 0x88)  // MRPT's SERIALIZATION_END_FLAG
        throw std::runtime_error(object + "'s end-of-object flag is missing");
}

/** Whether a peeked header announces an object of exactly the class `cls`. */
bool isOfClass(const RawlogStreamGuard::Header& h, const mrpt::rtti::TRuntimeClassId* cls) {
    return h.complete && h.className != "nullptr" &&
           mrpt::rtti::findRegisteredClass(h.className) == cls;
}

/** A top-level action collection (its header peeked as `h`), read here action by action: MRPT
 * assigns each action it reads to a pointer that clones through it unchecked, so a slot that
 * holds a null object or another class is refused before MRPT reads it (finding 14). */
mrpt::serialization::CSerializable::Ptr readActionCollection(mrpt::serialization::CArchive& arch,
                                                             RawlogStreamGuard& guard,
                                                             const RawlogStreamGuard::Header& h,
                                                             uint64_t bytesLeft,
                                                             const std::string& where) {
    guard.dropPeeked();
    if (h.version != 0)
        throw std::runtime_error("an action collection of unknown serialization version " +
                                 std::to_string(h.version));
    uint32_t n = 0;
    arch >> n;
    if (n > bytesLeft)
        throw RefusedEntry(where + " (an action collection) declares " + std::to_string(n) +
                           " actions, more than the " + std::to_string(bytesLeft) +
                           " bytes left can hold");
    auto acts = mrpt::obs::CActionCollection::Create();
    for (uint32_t k = 0; k < n; k++) {
        const std::string slot = "action " + std::to_string(k);
        if (const std::string is = unlessDerivedFrom(guard, CLASS_ID(mrpt::obs::CAction), slot);
            !is.empty())
            throw RefusedEntry(where + " (an action collection): " + slot + " is " + is +
                               ", not an action");
        guard.allowNextAction();
        const auto action = std::dynamic_pointer_cast<mrpt::obs::CAction>(arch.ReadObject());
        if (!action) throw std::runtime_error(slot + " is not an action");
        acts->insert(*action);
    }
    readEndFlag(arch, h, "the action collection");
    return acts;
}

/** A top-level simplemap of serialization version 0 (its header peeked as `h`), read here
 * keyframe by keyframe as MRPT would: its 2D pose PDFs become 3D ones. MRPT 2.5 converts each
 * pose it reads without checking it, so a null pose or an object of another class there is a
 * SIGSEGV (doc/reliability.md, finding 17); here it is an error naming the keyframe. */
mrpt::maps::CSimpleMap readSimplemapVersion0(mrpt::serialization::CArchive& arch,
                                             RawlogStreamGuard& guard,
                                             const RawlogStreamGuard::Header& h) {
    guard.dropPeeked();
    uint32_t n = 0;
    arch >> n;
    mrpt::maps::CSimpleMap sm;
    for (uint32_t k = 0; k < n; k++) {
        const std::string slot = "keyframe " + std::to_string(k);
        if (const std::string is =
                unlessDerivedFrom(guard, CLASS_ID(mrpt::poses::CPosePDF), slot + "'s pose");
            !is.empty())
            throw RefusedEntry(slot +
                               " of a simplemap of serialization version 0 (2D poses) has a pose "
                               "that is " +
                               is + ", not a 2D pose PDF");
        const auto pdf = std::dynamic_pointer_cast<mrpt::poses::CPosePDF>(arch.ReadObject());
        if (!pdf) throw std::runtime_error(slot + " has no pose");
        const auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(arch.ReadObject());
        sm.insert(mrpt::poses::CPose3DPDF::Ptr(mrpt::poses::CPose3DPDF::createFrom2D(*pdf)), sf);
    }
    readEndFlag(arch, h, "the simplemap");
    return sm;
}

/** A point cloud stored outside the rawlog (MRPT's external storage), loaded here before the map
 * would load it: from a regular file only (a device never ends), under the read budget of that
 * file's bytes (MRPT's deserializer allocates the point count the file declares: a 180-byte file
 * declaring 2^28 points took gigabytes). Throws naming `where`, the label and the file. */
void loadExternalPointCloud(const mrpt::obs::CObservationPointCloud& pc, const std::string& where) {
    if (!pc.isExternallyStored() || pc.pointcloud) return;
    const std::string path = mrpt::io::lazy_load_absolute_path(pc.getExternalStorageFile());
    const std::string what =
        where + ": point cloud '" + pc.sensorLabel + "' stored in '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw RefusedEntry(what + " cannot be read: no such file");
    if (!std::filesystem::is_regular_file(path, ec))
        throw RefusedEntry(what + ": not a regular file");
    const uint64_t bound = fileSize(path).bound_bytes;
    uint64_t asked = 0;
    std::string failure;
    {
        ReadBudget budget(ReadBudget::limitFor(bound));
        try {
            pc.load();
        } catch (const std::exception& e) {
            asked = ReadBudget::largestRefused();
            if (asked == 0) failure = e.what();
        }
    }
    if (asked > 0)
        throw RefusedEntry(what + " declares more data than the file holds: loading it asked for " +
                           gigabytes(asked) + " in all, more than 64 MiB + 16 x its " +
                           std::to_string(bound) + " bytes");
    if (!failure.empty())
        throw RefusedEntry(
            what + " cannot be read: " + multibin::oneLineMessage(std::runtime_error(failure)));
    if (!pc.pointcloud) throw RefusedEntry(what + " holds no point cloud");
}

bool finitePose(const mrpt::poses::CPose3D& p) {
    for (int i = 0; i < 6; i++)
        if (!std::isfinite(p[i])) return false;
    return true;
}
}  // namespace

size_t RawlogSource::forEachInRawlog(const std::string& path, const Visitor& visit,
                                     const Progress& progress, double robotPoseMaxDt_s,
                                     PoseCounts* counts, MrptWarnings* warnings) {
    mrpt::io::CFileGZInputStream in;
    openOrThrow(in, path, "rawlog");
    const FileSize size = fileSize(path);
    const double total = std::max<double>(1.0, double(size.progress_bytes));
    return forEachInStream(
        in, "rawlog '" + path + "'", size.bound_bytes, visit,
        [&](double, size_t n) {
            if (progress) progress(double(in.getPosition()) / total, n);
        },
        robotPoseMaxDt_s, counts, warnings);
}

size_t RawlogSource::forEachInStream(mrpt::io::CStream& in, const std::string& name,
                                     uint64_t sizeBound_bytes, const Visitor& visit,
                                     const Progress& progress, double robotPoseMaxDt_s,
                                     PoseCounts* counts, MrptWarnings* warnings) {
    RawlogStreamGuard guard(in);
    auto arch = mrpt::serialization::archiveFrom(guard);
    const uint64_t start = in.getPosition();
    PoseOverTime poses(robotPoseMaxDt_s);
    size_t entries = 0;
    auto entryName = [&] { return name + ": entry " + std::to_string(entries); };
    auto visitObs = [&](const mrpt::obs::CObservation::Ptr& obs) {
        if (const auto* pc = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(obs.get()))
            loadExternalPointCloud(*pc, entryName());
        if (const auto rp = std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(obs)) {
            if (!finitePose(rp->pose.mean))
                throw std::runtime_error(entryName() + ": robot pose '" + rp->sensorLabel +
                                         "' is not finite");
            poses.robotPose(rp->pose, rp->timestamp);
        }
        try {
            if (std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(obs)) {
                const auto& rp = static_cast<const mrpt::obs::CObservationRobotPose&>(*obs);
                visit(obs, rp.pose, true);  // itself: not a pose to count
            } else {
                const PoseOverTime::Pose p = poses.at(obs->timestamp);
                visit(obs, p.pdf, p.hasCovariance);
            }
        } catch (const std::exception& e) {
            throw std::runtime_error(entryName() + ": " + multibin::oneLineMessage(e));
        }
    };
    for (;; entries++) {
        mrpt::serialization::CSerializable::Ptr obj;
        const uint64_t entryStart = in.getPosition();
        const uint64_t read = entryStart - start;
        const uint64_t left = sizeBound_bytes > read ? sizeBound_bytes - read : 0;
        try {
            const RawlogStreamGuard::Header h = guard.peekHeader();
            if (h.bytes == 0) break;  // clean end, between two entries
            const MrptWarnings::Capture capture(warnings, entryName());
            obj = readBounded(guard, left, entryName(), [&] {
                return isOfClass(h, CLASS_ID(mrpt::obs::CActionCollection))
                           ? readActionCollection(arch, guard, h, left, entryName())
                           : arch.ReadObject();
            });
        } catch (const RefusedEntry&) {
            throw;
        } catch (const mrpt::serialization::CExceptionEOF&) {
            if (in.getPosition() == entryStart) break;  // clean end, between two entries
            throw std::runtime_error(name + " is truncated inside entry " +
                                     std::to_string(entries));
        } catch (const std::exception& e) {
            throw std::runtime_error(name + " is truncated or corrupt at entry " +
                                     std::to_string(entries) + ": " + multibin::oneLineMessage(e));
        }
        if (!obj) throw std::runtime_error(entryName() + " is empty (a null object)");
        if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
            size_t k = 0;
            for (const auto& obs : *sf) {
                if (!obs)
                    throw std::runtime_error(entryName() + " (a sensory frame): observation " +
                                             std::to_string(k) +
                                             " is null or an object that is not an observation");
                k++;
            }
            for (const auto& obs : *sf) visitObs(obs);
        } else if (auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) {
            visitObs(obs);
        } else if (auto acts = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj)) {
            size_t k = 0;
            for (const auto& a : *acts) {
                if (!a.get())
                    throw std::runtime_error(entryName() + " (an action collection): action " +
                                             std::to_string(k) +
                                             " is null or an object that is not an action");
                if (const auto* m2 =
                        dynamic_cast<const mrpt::obs::CActionRobotMovement2D*>(a.get());
                    m2 && !m2->poseChange.get())
                    throw std::runtime_error(entryName() + ": action " + std::to_string(k) +
                                             " (2D odometry) has no pose change");
                k++;
            }
            // Odometry: the pose from the origin, and since the latest robot pose (PoseOverTime).
            mrpt::poses::CPose3DPDFGaussian step;
            bool haveStep = false;
            // MRPT's best estimate compares covariances: none when they are NaN.
            auto a2 = acts->getBestMovementEstimation();
            if (!a2) a2 = acts->getActionByClass<mrpt::obs::CActionRobotMovement2D>();
            if (a2) {
                step.copyFrom(*a2->poseChange);
                haveStep = true;
            } else if (auto m3 = acts->getActionByClass<mrpt::obs::CActionRobotMovement3D>()) {
                step = m3->poseChange;
                haveStep = true;
            }
            if (haveStep && !finitePose(step.mean))
                throw std::runtime_error(entryName() +
                                         " (an action collection): the odometry "
                                         "is not finite");
            if (haveStep) poses.odometry(step);
        } else {
            throw std::runtime_error(entryName() + " is a " + obj->GetRuntimeClass()->className +
                                     ", not an observation, sensory frame or action");
        }
        if (progress) progress(0.0, entries + 1);
    }
    if (counts) *counts = poses.counts();
    return entries;
}

mrpt::maps::CSimpleMap RawlogSource::loadSimplemap(const std::string& path,
                                                   MrptWarnings* warnings) {
    mrpt::io::CFileGZInputStream in;
    openOrThrow(in, path, "simplemap");
    return readSimplemap(in, "simplemap '" + path + "'", fileSize(path).bound_bytes, warnings);
}

mrpt::maps::CSimpleMap RawlogSource::readSimplemap(mrpt::io::CStream& in, const std::string& name,
                                                   uint64_t sizeBound_bytes,
                                                   MrptWarnings* warnings) {
    mrpt::maps::CSimpleMap sm;
    uint64_t asked = 0;
    RawlogStreamGuard guard(in);
    try {
        const MrptWarnings::Capture capture(warnings, name);
        ReadBudget budget(ReadBudget::limitFor(sizeBound_bytes));
        try {
            auto arch = mrpt::serialization::archiveFrom(guard);
            const RawlogStreamGuard::Header h = guard.peekHeader();
            if (isOfClass(h, CLASS_ID(mrpt::maps::CSimpleMap)) && h.version == 0)
                sm = readSimplemapVersion0(arch, guard, h);
            else
                arch >> sm;
        } catch (const RefusedEntry&) {
            throw;
        } catch (const std::exception&) {
            asked = ReadBudget::largestRefused();
            if (asked == 0 && guard.refusal().empty()) throw;
        }
    } catch (const RefusedEntry& e) {
        throw std::runtime_error(name + ": " + e.what());
    } catch (const std::exception& e) {
        throw std::runtime_error(name + " is truncated or corrupt: " + multibin::oneLineMessage(e));
    }
    if (asked == 0 && !guard.refusal().empty())
        throw std::runtime_error(name + ": " + guard.refusal());
    if (asked > 0)
        throw std::runtime_error(name +
                                 " declares more data than the file holds: reading it asked for " +
                                 gigabytes(asked) + " in all, more than 64 MiB + 16 x its " +
                                 std::to_string(sizeBound_bytes) + " bytes");
    for (size_t i = 0; i < sm.size(); i++) {
        const auto& [posePdf, sf] = sm.get(i);
        const std::string where = name + ": keyframe " + std::to_string(i);
        if (!posePdf) throw std::runtime_error(where + " has no pose (null or not a 3D pose PDF)");
        if (!sf) throw std::runtime_error(where + " has no sensory frame (null or another class)");
        size_t k = 0;
        for (const auto& obs : *sf) {
            if (!obs)
                throw std::runtime_error(where + ": observation " + std::to_string(k) +
                                         " is null or an object that is not an observation");
            if (const auto* pc = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(obs.get()))
                loadExternalPointCloud(*pc, where);
            k++;
        }
        if (!finitePose(posePdf->getMeanVal()))
            throw std::runtime_error(where + ": the pose is not finite");
    }
    return sm;
}
