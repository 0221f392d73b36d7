/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RawlogSource.h"

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileInputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CActionRobotMovement3D.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>

#include <fstream>
#include <stdexcept>
#include "multibin/io/ErrorMessage.h"

namespace {
/** Uncompressed size of a file [bytes]: a gzip file's trailer holds it (mod 4 GiB). */
uint64_t uncompressedSize(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot open '" + path + "'");
    unsigned char magic[2] = {0, 0};
    f.read(reinterpret_cast<char*>(magic), 2);
    f.seekg(0, std::ios::end);
    const auto size = static_cast<uint64_t>(f.tellg());
    if (magic[0] != 0x1f || magic[1] != 0x8b || size < 18) return size;
    unsigned char t[4];
    f.seekg(-4, std::ios::end);
    f.read(reinterpret_cast<char*>(t), 4);
    return uint64_t(t[0]) | uint64_t(t[1]) << 8 | uint64_t(t[2]) << 16 | uint64_t(t[3]) << 24;
}

void openOrThrow(mrpt::io::CFileGZInputStream& in, const std::string& path,
                 const std::string& what) {
    if (!std::ifstream(path).good()) throw std::runtime_error(what + " '" + path + "' not found");
    if (!in.open(path)) throw std::runtime_error("cannot open " + what + " '" + path + "'");
}
}  // namespace

size_t RawlogSource::forEachInRawlog(const std::string& path, const Visitor& visit,
                                     const Progress& progress) {
    mrpt::io::CFileGZInputStream in;
    openOrThrow(in, path, "rawlog");
    const double total = std::max<double>(1.0, double(uncompressedSize(path)));
    auto arch = mrpt::serialization::archiveFrom(in);

    mrpt::poses::CPose3DPDFGaussian pose;  // latest CObservationRobotPose, or odometry
    bool poseHasCov = false;
    mrpt::poses::CPose3D odometry;
    auto visitObs = [&](const mrpt::obs::CObservation::Ptr& obs) {
        if (const auto rp = std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(obs)) {
            pose = rp->pose;
            poseHasCov = true;
        }
        visit(obs, pose, poseHasCov);
    };
    size_t entries = 0;
    for (;;) {
        mrpt::serialization::CSerializable::Ptr obj;
        const uint64_t entryStart = in.getPosition();
        try {
            obj = arch.ReadObject();
        } catch (const mrpt::serialization::CExceptionEOF& e) {
            if (in.getPosition() == entryStart) break;  // clean end, between two entries
            throw std::runtime_error("rawlog '" + path + "' is truncated inside entry " +
                                     std::to_string(entries));
        } catch (const std::exception& e) {
            throw std::runtime_error("rawlog '" + path + "' is truncated or corrupt at entry " +
                                     std::to_string(entries) + ": " + multibin::oneLineMessage(e));
        }
        entries++;
        if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
            for (const auto& obs : *sf) visitObs(obs);
        } else if (auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(obj)) {
            visitObs(obs);
        } else if (auto acts = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj)) {
            // Odometry, used only while no CObservationRobotPose has been seen.
            if (auto a3 = acts->getBestMovementEstimation(); a3) {
                odometry = odometry + mrpt::poses::CPose3D(a3->poseChange->getMeanVal());
            } else if (auto m3 = acts->getActionByClass<mrpt::obs::CActionRobotMovement3D>()) {
                odometry = odometry + m3->poseChange.mean;
            }
            if (!poseHasCov) pose.mean = odometry;
        } else if (obj) {
            throw std::runtime_error("rawlog '" + path + "': entry " + std::to_string(entries - 1) +
                                     " is a " + obj->GetRuntimeClass()->className +
                                     ", not an observation, sensory frame or action");
        }
        if (progress) progress(double(in.getPosition()) / total, entries);
    }
    return entries;
}

mrpt::maps::CSimpleMap RawlogSource::loadSimplemap(const std::string& path) {
    mrpt::io::CFileGZInputStream in;
    openOrThrow(in, path, "simplemap");
    mrpt::maps::CSimpleMap sm;
    try {
        auto arch = mrpt::serialization::archiveFrom(in);
        arch >> sm;
    } catch (const std::exception& e) {
        throw std::runtime_error("simplemap '" + path +
                                 "' is truncated or corrupt: " + multibin::oneLineMessage(e));
    }
    return sm;
}
