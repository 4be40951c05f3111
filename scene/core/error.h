// Error types that map to the CLI's exit statuses: InputError → 2, RuntimeError → 1.
#pragma once

#include <stdexcept>
#include <string>

namespace seasense {

// Bad input from the user: config, command line, unreadable input file. Exit status 2.
class InputError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// A failure while running with valid input: unwritable output, dead renderer. Exit status 1.
class RuntimeError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace seasense
