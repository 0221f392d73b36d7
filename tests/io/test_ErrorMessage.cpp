/* What a user is shown of an error (ErrorMessage.h): never empty, never a library's internals
 * without what was being done, user text escaped so that it cannot forge a line or reach the
 * terminal as an escape sequence. The mapper's messages: map/test_MapperMessages.cpp. */
#include <gtest/gtest.h>

#include <new>
#include <stdexcept>
#include <string>

#include "multibin/io/ErrorMessage.h"

// What the mapper prints for an exception: in words, with what was being done, never empty.
TEST(Messages, LibraryInternalsAndEmptyMessagesSayWhatWasBeingDone) {
    const std::string context = "reading rawlog 'x.rawlog'";
    const std::string oom = multibin::userMessage(std::bad_alloc(), context);
    EXPECT_EQ(oom.rfind(context + ": out of memory", 0), 0u) << oom;
    const std::string len =
        multibin::userMessage(std::length_error("basic_string::_M_create"), context);
    EXPECT_EQ(len.rfind(context + ": a size beyond what memory can hold", 0), 0u) << len;
    const std::string empty = multibin::userMessage(std::runtime_error(""), context);
    EXPECT_EQ(empty.rfind(context + ": an error without a message", 0), 0u) << empty;
    // A message that names its input stays as it is.
    EXPECT_EQ(multibin::userMessage(std::runtime_error("rawlog 'a' is truncated"), context),
              "rawlog 'a' is truncated");
}

// User text printed raw: ESC started terminal escape sequences, a newline forged a line.
TEST(Messages, UserTextIsEscapedWhenPrinted) {
    EXPECT_EQ(multibin::printableText("LASER\x1b[2J"), "LASER\\x1B[2J");
    EXPECT_EQ(multibin::printableText("A\nelevation-mapper: error: forged"),
              "A\\nelevation-mapper: error: forged");
    EXPECT_EQ(multibin::printableText("cam\x9b"
                                      "31m"),
              "cam\\x9B31m");  // 8-bit CSI
    EXPECT_EQ(multibin::printableText("cam\xc2\x9b"
                                      "31m"),
              "cam\\xC2\\x9B31m");  // UTF-8 CSI
    EXPECT_EQ(multibin::printableText("Kamera \xc3\xa9t\xc3\xa9"), "Kamera \xc3\xa9t\xc3\xa9");
}

// MRPT's wrapper of an object reader's error ("Exception while parsing typed object ... for
// file ...") keeps the reader's own message, which says what is wrong, after the wrapper's,
// which says where: a corrupt map file's checksum is named in the one line shown.
TEST(Messages, AnObjectReadersErrorKeepsItsReasonAfterMrptsWrapper) {
    const std::runtime_error wrapped(
        "==== MRPT exception ====\n"
        "Message:  Exception while parsing typed object 'mrpt::maps::CMultiBinElevationMap' from "
        "mrpt::io::CFileGZInputStream for file 'm.bin'\n"
        "Original exception:\n"
        "CMultiBinElevationMap: corrupt serialized map (checksum mismatch)\n"
        "Location: ./libs/serialization/src/CArchive.cpp:475: [void ...]\n"
        "Call stack backtrace:\n[0 ]     0x7fb3c175a90b \n");
    EXPECT_EQ(multibin::oneLineMessage(wrapped),
              "Exception while parsing typed object 'mrpt::maps::CMultiBinElevationMap' from "
              "mrpt::io::CFileGZInputStream for file 'm.bin': CMultiBinElevationMap: corrupt "
              "serialized map (checksum mismatch)");
    const std::runtime_error nested(  // the reader's error itself an MRPT exception
        "==== MRPT exception ====\nMessage:  Exception while parsing typed object 'X'\n"
        "Original exception:\n==== MRPT exception ====\nMessage:  truncated at byte 12\n"
        "Location: a.cpp:1\n");
    EXPECT_EQ(multibin::oneLineMessage(nested),
              "Exception while parsing typed object 'X': truncated at byte 12");
    const std::runtime_error plain(  // no wrapper: the message alone
        "==== MRPT exception ====\nMessage:  bad key 'k'\nLocation: a.cpp:1\n");
    EXPECT_EQ(multibin::oneLineMessage(plain), "bad key 'k'");
}
