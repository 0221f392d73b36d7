/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/io/CStream.h>

#include <cstdint>
#include <string>
#include <vector>

/** The stream MRPT reads rawlogs and simplemaps through: it refuses, before MRPT dereferences
 * it, the content that crashes MRPT 2.5's deserializers (doc/reliability.md, finding 14). MRPT
 * assigns what it read for an action of a CActionCollection, and for the pose change of a
 * CActionRobotMovement2D, to a deepcopy_poly_ptr, whose assignment clones through the pointer
 * without checking it: an object there that is null or of another class (cast to null) is a
 * SIGSEGV. MRPT reads any class wherever an object is stored, so such an action can sit in a
 * sensory frame or a simplemap too.
 *
 * The guard sees every object header MRPT reads (MRPT reads one as a 1-byte read of the name
 * length, a read of that many bytes of name, the version; or the pre-0.5.5 framing) and refuses:
 * - an action or action collection except the actions RawlogSource reads itself, one by one, as
 *   the entries of a top-level action collection (allowNextAction());
 * - an object of an abstract class (MRPT reads it as null);
 * - a CActionRobotMovement2D whose pose change object (read for serialization versions 0 and 1,
 *   and for later ones when the estimation method is not odometry) is null or not a CPosePDF;
 * - a CSimpleMap of serialization version 0 (2D poses, which MRPT converts unchecked) anywhere
 *   but at the top of a simplemap file, which RawlogSource reads itself.
 * A refusal throws from Read(), before MRPT has the bytes; refusal() keeps its text (MRPT
 * replaces the text of errors inside nested objects by "EOF"). A false alarm needs a 1-byte
 * read followed by a read of exactly that many bytes that name an action class. */
class RawlogStreamGuard : public mrpt::io::CStream {
public:
    explicit RawlogStreamGuard(mrpt::io::CStream& in) : m_in(in) {}

    size_t Read(void* buffer, size_t count) override;
    size_t Write(const void* buffer, size_t count) override;  // throws: read-only
    uint64_t Seek(int64_t offset, TSeekOrigin origin = sFromBeginning) override;
    uint64_t getTotalBytesCount() const override { return m_in.getTotalBytesCount(); }
    /** The position of the next byte MRPT will get (peeked bytes not yet served excluded). */
    uint64_t getPosition() const override { return m_in.getPosition() - m_peeked.size(); }

    /** The header of the next object, read ahead and served again by the next reads. */
    struct Header {
        size_t bytes = 0;         //!< header bytes available (0: the stream ended)
        bool complete = false;    //!< a whole header was read
        bool oldFraming = false;  //!< MRPT before 0.5.5: no end-of-object flag
        std::string className;    //!< "nullptr" for a null object
        int version = -1;
    };
    Header peekHeader();
    /** Drops the peeked bytes (the caller parsed the header itself). */
    void dropPeeked() { m_peeked.clear(); }
    /** The next object header may be an action (RawlogSource reads the actions of a top-level
     * collection one by one). */
    void allowNextAction() { m_actionAllowed = true; }

    /** Why the last read was refused ("" if none was). */
    const std::string& refusal() const { return m_refusal; }

private:
    void observe(const uint8_t* data, size_t n);
    void headerRead(const std::string& className, int version);
    [[noreturn]] void refuse(const std::string& why);

    mrpt::io::CStream& m_in;
    std::vector<uint8_t> m_peeked;  // read ahead by peekHeader(), served first
    // Header recognition over the sequence of reads.
    enum class Step { Idle, NewName, OldZeros, OldName, NewVersion, OldVersion };
    Step m_step = Step::Idle;
    size_t m_nameLength = 0;
    std::string m_name;
    // What the next reads must be.
    enum class Expect { Nothing, EstimationMethod, PoseChange };
    Expect m_expect = Expect::Nothing;
    int m_actionVersion = 0;
    bool m_actionAllowed = false;
    std::string m_refusal;
};
