// Integer division rounding toward minus infinity (C++'s / rounds toward zero).
#pragma once

namespace seasense {

// ⌊a / b⌋ for b > 0.
constexpr int FloorDiv(int a, int b) { return a >= 0 ? a / b : -((b - 1 - a) / b); }

}  // namespace seasense
