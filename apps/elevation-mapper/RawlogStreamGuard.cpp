/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "RawlogStreamGuard.h"

#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CAction.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/rtti/CObject.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace {
constexpr size_t kMaxClassName = 120;  // MRPT refuses longer names

/** A class name as MRPT takes it: up to the first NUL of the bytes read. */
std::string nameOf(const uint8_t* bytes, size_t n) {
    const auto* c = reinterpret_cast<const char*>(bytes);
    return std::string(c, std::find(c, c + n, '\0'));
}

int32_t int32At(const uint8_t* p) {
    int32_t v;
    std::memcpy(&v, p, 4);
    return v;
}
}  // namespace

size_t RawlogStreamGuard::Read(void* buffer, size_t count) {
    auto* out = static_cast<uint8_t*>(buffer);
    size_t n = std::min(count, m_peeked.size());
    std::copy_n(m_peeked.begin(), n, out);
    m_peeked.erase(m_peeked.begin(), m_peeked.begin() + long(n));
    if (n < count) n += m_in.Read(out + n, count - n);
    observe(out, n);
    return n;
}

size_t RawlogStreamGuard::Write(const void*, size_t) {
    throw std::logic_error("RawlogStreamGuard is read-only");
}

uint64_t RawlogStreamGuard::Seek(int64_t offset, TSeekOrigin origin) {
    m_peeked.clear();
    m_step = Step::Idle;
    m_expect = Expect::Nothing;
    return m_in.Seek(offset, origin);
}

RawlogStreamGuard::Header RawlogStreamGuard::peekHeader() {
    Header h;
    // Appends k bytes of the stream to m_peeked; false if it ends first.
    auto take = [&](size_t k) {
        const size_t start = m_peeked.size();
        m_peeked.resize(start + k);
        const size_t got = k ? m_in.Read(m_peeked.data() + start, k) : 0;
        m_peeked.resize(start + got);
        h.bytes = m_peeked.size();
        return got == k;
    };
    const size_t at = m_peeked.size();
    if (!take(1)) return h;
    const uint8_t first = m_peeked[at];
    h.oldFraming = !(first & 0x80);
    const size_t length = first & 0x7F;
    if (length == 0 || length > kMaxClassName) return h;
    if (h.oldFraming &&
        (!take(3) || m_peeked[at + 1] != 0 || m_peeked[at + 2] != 0 || m_peeked[at + 3] != 0))
        return h;
    const size_t nameAt = m_peeked.size();
    if (!take(length)) return h;
    h.className = nameOf(m_peeked.data() + nameAt, length);
    if (h.oldFraming) {
        if (!take(4)) return h;
        h.version = int32At(m_peeked.data() + m_peeked.size() - 4);
    } else if (h.className != "nullptr") {
        if (!take(1)) return h;
        h.version = int8_t(m_peeked.back());
    }
    h.complete = true;
    return h;
}

void RawlogStreamGuard::observe(const uint8_t* d, size_t n) {
    // Version >= 2 of a CActionRobotMovement2D: its first field, the estimation method, says
    // whether a pose change object follows (not for odometry, 0).
    if (m_expect == Expect::EstimationMethod && m_step == Step::Idle) {
        m_expect = n == 4 && int32At(d) != 0 ? Expect::PoseChange : Expect::Nothing;
        if (n == 4) return;
    }
    const Step step = m_step;
    m_step = Step::Idle;
    switch (step) {
        case Step::NewName:
        case Step::OldName:
            if (n == m_nameLength) {
                m_name = nameOf(d, n);
                if (step == Step::OldName)
                    m_step = Step::OldVersion;
                else if (m_name == "nullptr")
                    headerRead(m_name, -1);
                else
                    m_step = Step::NewVersion;
                return;
            }
            break;
        case Step::OldZeros:
            if (n == 3 && d[0] == 0 && d[1] == 0 && d[2] == 0) {
                m_step = Step::OldName;
                return;
            }
            break;
        case Step::NewVersion:
            if (n == 1) return headerRead(m_name, int8_t(d[0]));
            break;
        case Step::OldVersion:
            if (n == 4) return headerRead(m_name, int32At(d));
            break;
        case Step::Idle:
            break;
    }
    // Not the next step of a header: perhaps the first byte of one.
    m_nameLength = n == 1 ? d[0] & 0x7F : 0;
    if (m_nameLength > 0 && m_nameLength <= kMaxClassName)
        m_step = (d[0] & 0x80) ? Step::NewName : Step::OldZeros;
    else if (m_expect == Expect::PoseChange)
        m_expect = Expect::Nothing;  // not a header where one was due: MRPT fails on it
}

void RawlogStreamGuard::headerRead(const std::string& className, int version) {
    const Expect expect = m_expect;
    const bool allowed = m_actionAllowed;
    m_expect = Expect::Nothing;
    m_actionAllowed = false;
    const bool null = className == "nullptr";
    const auto* cls = null ? nullptr : mrpt::rtti::findRegisteredClass(className);
    // MRPT reads an object of an abstract class as null (and prints a line): never in a file.
    if (cls && !cls->ptrCreateObject)
        refuse(std::string("an object of the abstract class ") + cls->className);
    if (expect == Expect::PoseChange) {
        const std::string what = "a 2D odometry action of serialization version " +
                                 std::to_string(m_actionVersion) + " ";
        if (null) refuse(what + "has no pose change (a null object)");
        if (cls && !cls->derivedFrom(CLASS_ID(mrpt::poses::CPosePDF)))
            refuse(what + "holds a " + cls->className + " where its pose change PDF belongs");
        return;
    }
    if (!cls) return;  // null, or not registered (MRPT refuses it)
    // MRPT converts the 2D poses of a version-0 simplemap without checking them (a null pose or
    // another class is a SIGSEGV); RawlogSource reads a top-level one itself.
    if (cls == CLASS_ID(mrpt::maps::CSimpleMap) && version == 0)
        refuse("a simplemap of serialization version 0 (2D poses) inside another object");
    const bool action = cls->derivedFrom(CLASS_ID(mrpt::obs::CAction));
    if (!action && cls != CLASS_ID(mrpt::obs::CActionCollection)) return;
    if (!allowed || !action)
        refuse(std::string("a ") + cls->className +
               " where no action belongs (actions are read only as the entries of a rawlog's "
               "action collections)");
    if (cls == CLASS_ID(mrpt::obs::CActionRobotMovement2D)) {
        m_actionVersion = version;
        m_expect = version <= 1 ? Expect::PoseChange : Expect::EstimationMethod;
    }
}

void RawlogStreamGuard::refuse(const std::string& why) {
    m_refusal = why;
    throw std::runtime_error(why);
}
