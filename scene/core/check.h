// Always-on internal invariant checks: a failed CHECK is a bug in seasense, never bad input.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace seasense {

// Thrown when an internal invariant fails. The CLI reports it and exits with status 1.
class InternalError : public std::logic_error {
  public:
    using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] inline void CheckFailed(const char* expr, const char* file, int line,
                                     const std::string& message) {
    std::ostringstream out;
    out << file << ":" << line << ": internal check failed: " << expr;
    if (!message.empty()) out << " (" << message << ")";
    throw InternalError(out.str());
}
}  // namespace detail

}  // namespace seasense

// CHECK(cond) and CHECK_MSG(cond, streamable) stay on in Release builds.
#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (!(cond)) ::seasense::detail::CheckFailed(#cond, __FILE__, __LINE__, {}); \
    } while (0)
#define CHECK_MSG(cond, msg)                                                                \
    do {                                                                                    \
        if (!(cond)) {                                                                      \
            std::ostringstream checkStream_;                                                \
            checkStream_ << msg;                                                            \
            ::seasense::detail::CheckFailed(#cond, __FILE__, __LINE__, checkStream_.str()); \
        }                                                                                   \
    } while (0)
