// FloorDiv: ⌊a / b⌋, the floor of the exact quotient, for either sign of a.
#include "scene/core/int_div.h"

#include <gtest/gtest.h>

#include <cmath>

namespace seasense {
namespace {

TEST(FloorDiv, IsTheFloorOfTheExactQuotient) {
    for (int b = 1; b <= 9; ++b)
        for (int a = -100; a <= 100; ++a)
            EXPECT_EQ(FloorDiv(a, b), int(std::floor(double(a) / double(b)))) << a << " / " << b;
}

}  // namespace
}  // namespace seasense
