/* Strict ini reading (StrictConfigSection.h): a choice among listed words. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "multibin/io/StrictConfigSection.h"

TEST(StrictConfigSection, ReadChoiceTakesOnlyTheListedWords) {
    mrpt::config::CConfigFileMemory ini;
    ini.write("s", "mode", "hot");
    ini.write("s", "bad", "warm");
    multibin::StrictConfigSection s(ini, "s");
    enum class Mode { Jet, Hot, Grey } mode = Mode::Jet, absent = Mode::Grey;
    const std::vector<std::pair<std::string, Mode>> choices{
        {"jet", Mode::Jet}, {"hot", Mode::Hot}, {"grayscale", Mode::Grey}};
    s.readChoice("mode", mode, choices);
    EXPECT_EQ(mode, Mode::Hot);
    s.readChoice("missing", absent, choices);
    EXPECT_EQ(absent, Mode::Grey);  // absent keys keep their value
    try {
        s.readChoice("bad", mode, choices);
        ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(),
                     "ini section 's', key 'bad': expected jet, hot or grayscale, got 'warm'");
    }
    EXPECT_EQ(mode, Mode::Hot);
}
