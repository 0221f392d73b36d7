/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RawlogStreamGuard.h"

#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/rtti/CObject.h>

#include <algorithm>
#include <stdexcept>

namespace {
const std::string kActionClass = "CActionRobotMovement2D";  // the name MRPT resolves, any prefix
constexpr size_t kMaxClassName = 120;                       // MRPT refuses longer names
constexpr size_t kRecentBytes = 2 * (kMaxClassName + 8);    // an old-framing header fits twice

bool isAction(const uint8_t* name, size_t length) {
    const auto* cls =
        mrpt::rtti::findRegisteredClass(std::string(reinterpret_cast<const char*>(name), length));
    return cls == CLASS_ID(mrpt::obs::CActionRobotMovement2D);
}
}  // namespace

size_t RawlogStreamGuard::Read(void* buffer, size_t count) {
    const size_t n = m_in.Read(buffer, count);
    const auto* bytes = static_cast<const uint8_t*>(buffer);
    for (size_t i = 0; i < n; i++) watch(bytes[i]);
    return n;
}

size_t RawlogStreamGuard::Write(const void*, size_t) {
    throw std::logic_error("RawlogStreamGuard is read-only");
}

uint64_t RawlogStreamGuard::Seek(int64_t offset, TSeekOrigin origin) {
    m_recent.clear();
    m_readingPoseChange = false;
    return m_in.Seek(offset, origin);
}

void RawlogStreamGuard::watch(uint8_t byte) {
    if (m_recent.size() >= 2 * kRecentBytes)
        m_recent.erase(m_recent.begin(), m_recent.end() - kRecentBytes);
    m_recent.push_back(byte);
    if (m_readingPoseChange) {
        m_poseChange.push_back(byte);
        checkPoseChangeHeader();
    } else if (byte <= 1 && endsOldActionHeader()) {
        m_readingPoseChange = true;
        m_poseChange.clear();
    }
}

bool RawlogStreamGuard::endsOldActionHeader() {
    const size_t n = m_recent.size();
    const uint8_t* r = m_recent.data();
    const size_t s = kActionClass.size();
    auto nameEndsAt = [&](size_t end) {
        return end >= s && std::equal(kActionClass.begin(), kActionClass.end(), r + end - s);
    };
    // MRPT >= 0.5.5: [0x80 | name length] [name] [int8 version]
    if (nameEndsAt(n - 1)) {
        for (size_t len = s; len <= kMaxClassName && len + 2 <= n; len++)
            if (r[n - 2 - len] == (0x80 | len) && isAction(r + n - 1 - len, len)) {
                m_actionVersion = r[n - 1];
                return true;
            }
    }
    // Before: [name length as int32] [name] [int32 version]
    if (n >= 4 && r[n - 1] == 0 && r[n - 2] == 0 && r[n - 3] == 0 && r[n - 4] <= 1 &&
        nameEndsAt(n - 4)) {
        for (size_t len = s; len <= kMaxClassName && len + 8 <= n; len++) {
            const uint8_t* h = r + n - 8 - len;
            if (h[0] == len && h[1] == 0 && h[2] == 0 && h[3] == 0 && isAction(h + 4, len)) {
                m_actionVersion = r[n - 4];
                return true;
            }
        }
    }
    return false;
}

void RawlogStreamGuard::checkPoseChangeHeader() {
    const std::vector<uint8_t>& h = m_poseChange;
    const bool newFraming = h[0] & 0x80;
    const size_t nameLength = newFraming ? (h[0] & 0x7F) : h[0];
    const size_t nameStart = newFraming ? 1 : 4;
    if (!newFraming && h.size() >= 2 && h.size() <= 4 && h.back() != 0) {
        m_readingPoseChange = false;  // not an object header: MRPT refuses it
        return;
    }
    if (nameLength > kMaxClassName) m_readingPoseChange = false;  // MRPT refuses it
    if (!m_readingPoseChange || h.size() < nameStart + nameLength) return;
    m_readingPoseChange = false;
    const std::string name(h.begin() + nameStart, h.end());
    const std::string what =
        "a 2D odometry action of serialization version " + std::to_string(m_actionVersion) + " ";
    if (name == "nullptr") {
        m_refusal = what + "has no pose change (a null object)";
        throw std::runtime_error(m_refusal);
    }
    const auto* cls = mrpt::rtti::findRegisteredClass(name);
    if (cls && !cls->derivedFrom(CLASS_ID(mrpt::poses::CPosePDF))) {
        m_refusal = what + "holds a " + cls->className + " where its pose change PDF belongs";
        throw std::runtime_error(m_refusal);
    }
}
