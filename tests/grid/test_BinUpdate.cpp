/* The bin update rule (BinUpdate.h): certainty added at once as the sequence adds it. */
#include <gtest/gtest.h>

#include <cstdint>

#include "multibin/grid/BinUpdate.h"

using namespace multibin;

TEST(BinUpdate, CertaintyAddedAtOnceEqualsTheSequenceBitForBit) {
    // addCertainty adds whole numbers in one step (exact below 2^24) and runs the sequence
    // otherwise: both must give the float the sequence gives.
    for (const float start : {0.f, 3.f, -4.f, 2.5f, 16777200.f, 1e-3f})
        for (const float increment : {1.f, 2.f, 0.5f, 0.1f, 3.f})
            for (const uint32_t times : {0u, 1u, 2u, 7u, 100u}) {
                float sequence = start;
                for (uint32_t k = 0; k < times; k++) sequence += increment;
                float atOnce = start;
                addCertainty(atOnce, increment, times);
                EXPECT_EQ(atOnce, sequence) << start << " + " << times << " x " << increment;
            }
}
