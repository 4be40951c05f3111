// ConfigError: a bad configuration file, reported as "file:line:column: key.path: expected ...,
// found ...".
#pragma once

#include <string>

#include "scene/core/error.h"

namespace seasense::scene {

// Where in a configuration file something is; line and column are 1-based (0 = unknown).
struct ConfigLocation {
    std::string file;
    int line = 0;
    int column = 0;
};

// Bad configuration input (exit status 2). what() is exactly
// "FILE:LINE:COLUMN: KEY.PATH: expected EXPECTED, found FOUND" for a bad value,
// "FILE:LINE:COLUMN: YAML syntax error: MESSAGE" for a syntax error and
// "FILE: cannot read file: REASON" for a file that cannot be read.
class ConfigError : public InputError {
  public:
    // A value that does not match the schema. An empty keyPath means the whole document.
    ConfigError(ConfigLocation location, std::string keyPath, std::string expected,
                std::string found);

    static ConfigError SyntaxError(ConfigLocation location, const std::string& message);
    static ConfigError Unreadable(const std::string& file, const std::string& reason);

    const ConfigLocation& Location() const { return location_; }
    const std::string& KeyPath() const { return keyPath_; }
    const std::string& Expected() const { return expected_; }
    const std::string& Found() const { return found_; }

  private:
    ConfigError(std::string message, ConfigLocation location);

    ConfigLocation location_;
    std::string keyPath_;
    std::string expected_;
    std::string found_;
};

}  // namespace seasense::scene
