#include <gtest/gtest.h>
TEST(Fill, Placeholder2) {}
