// CONUS_DCHECK as a Debug build has it (this file turns it on whatever the build type): a failed
// check names the condition and prints both values; a check that holds costs nothing but the test.
#undef NDEBUG
#include "conus/core/check.h"

#include <gtest/gtest.h>

namespace {
int twice(int x) { return 2 * x; }
}  // namespace

TEST(CheckDeathTest, AFailedCheckPrintsTheConditionAndBothValues) {
    EXPECT_DEATH(CONUS_DCHECK_EQ(twice(3), 7), "CoNUS invariant failed: twice\\(3\\) == 7: 6 vs 7");
    EXPECT_DEATH(CONUS_DCHECK_LT(2.5, 1.0), "2.5 < 1.0: 2.5 vs 1");
    EXPECT_DEATH(CONUS_DCHECK(twice(2) == 5), "check_test.cpp:[0-9]+: CoNUS invariant failed: twice\\(2\\) == 5");
}

TEST(Check, AHoldingCheckEvaluatesItsArgumentsOnce) {
    int calls = 0;
    const auto counted = [&](int x) {
        ++calls;
        return x;
    };
    CONUS_DCHECK_LE(counted(1), counted(2));
    CONUS_DCHECK_GE(counted(3), 3);
    CONUS_DCHECK(counted(1) == 1);
    EXPECT_EQ(calls, 4);
}
