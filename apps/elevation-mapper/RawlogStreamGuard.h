/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/io/CStream.h>

#include <cstdint>
#include <string>
#include <vector>

/** A read-only view of a stream that refuses, before MRPT dereferences it, the content that
 * crashes MRPT 2.5's deserializers (doc/reliability.md, finding 14): a CActionRobotMovement2D of
 * serialization version 0 or 1 whose pose change is null or not a pose PDF. For those versions
 * MRPT's serializeFrom reads the pose change and then calls getMean() on it, null or not.
 *
 * The bytes are watched as MRPT reads them, so the action is caught wherever it sits (an action
 * collection, an observation slot of a sensory frame, a simplemap): on an object header of that
 * class (any class name MRPT resolves to it, new or pre-0.5.5 framing) with version 0 or 1, the
 * next object header is parsed; if it names no pose PDF the read throws, before MRPT gets the
 * bytes. MRPT replaces the text of errors inside nested objects by "EOF", so refusal() keeps it.
 * A false alarm needs the exact header bytes (24 or more) inside other data, followed by bytes
 * that are no pose PDF header. */
class RawlogStreamGuard : public mrpt::io::CStream {
public:
    explicit RawlogStreamGuard(mrpt::io::CStream& in) : m_in(in) {}

    size_t Read(void* buffer, size_t count) override;
    size_t Write(const void* buffer, size_t count) override;  // throws: read-only
    uint64_t Seek(int64_t offset, TSeekOrigin origin = sFromBeginning) override;
    uint64_t getTotalBytesCount() const override { return m_in.getTotalBytesCount(); }
    uint64_t getPosition() const override { return m_in.getPosition(); }

    /** Why the last read was refused ("" if none was). */
    const std::string& refusal() const { return m_refusal; }

private:
    void watch(uint8_t byte);
    /** Whether the bytes just read end an object header of CActionRobotMovement2D whose version
     * is 0 or 1; sets m_actionVersion. */
    bool endsOldActionHeader();
    void checkPoseChangeHeader();

    mrpt::io::CStream& m_in;
    std::vector<uint8_t> m_recent;      // the last bytes read (at least 128 of them)
    bool m_readingPoseChange = false;   // inside the pose change's object header
    std::vector<uint8_t> m_poseChange;  // its header bytes so far
    int m_actionVersion = 0;
    std::string m_refusal;
};
