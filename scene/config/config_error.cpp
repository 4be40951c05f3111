// Message formatting for ConfigError.
#include "scene/config/config_error.h"

#include <utility>

namespace seasense::scene {

namespace {

std::string Prefix(const ConfigLocation& location) {
    return location.file + ":" + std::to_string(location.line) + ":" +
           std::to_string(location.column) + ": ";
}

}  // namespace

ConfigError::ConfigError(ConfigLocation location, std::string keyPath, std::string expected,
                         std::string found)
    : InputError(Prefix(location) + (keyPath.empty() ? std::string("(top level)") : keyPath) +
                 ": expected " + expected + ", found " + found),
      location_(std::move(location)),
      keyPath_(std::move(keyPath)),
      expected_(std::move(expected)),
      found_(std::move(found)) {}

ConfigError::ConfigError(std::string message, ConfigLocation location)
    : InputError(std::move(message)), location_(std::move(location)) {}

ConfigError ConfigError::SyntaxError(ConfigLocation location, const std::string& message) {
    std::string text = Prefix(location) + "YAML syntax error: " + message;
    return ConfigError(std::move(text), std::move(location));
}

ConfigError ConfigError::Unreadable(const std::string& file, const std::string& reason) {
    return ConfigError(file + ": cannot read file: " + reason, ConfigLocation{file, 0, 0});
}

}  // namespace seasense::scene
