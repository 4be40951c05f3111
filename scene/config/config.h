// A validating reader over yaml-cpp nodes: typed getters whose every failure is a ConfigError
// naming file, line, column, key path, what was expected and what was found.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "scene/config/config_error.h"
#include "scene/core/time.h"

namespace seasense::scene {

// The accepted interval of a real-valued setting and its unit, for checks and messages.
struct NumberRange {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;  // lo itself excluded
    bool hiOpen = false;  // hi itself excluded
    std::string unit;     // as written in key names ("deg", "m", "lux"); empty if dimensionless

    static NumberRange Any(std::string unit = {});
    static NumberRange Closed(double lo, double hi, std::string unit = {});      // [lo, hi]
    static NumberRange Open(double lo, double hi, std::string unit = {});        // (lo, hi)
    static NumberRange OpenClosed(double lo, double hi, std::string unit = {});  // (lo, hi]
    static NumberRange Positive(std::string unit = {});                          // > 0
    static NumberRange NonNegative(std::string unit = {});                       // >= 0

    bool Contains(double x) const;
    // "a number (deg) in (0, 180)", or "a finite number ..." when finite is true.
    std::string Describe(bool finite = false) const;
};

// Formats a number for messages in its shortest round-trip form ("60", "0.25", "1e+30").
std::string FormatNumber(double x);

class ConfigMap;

// One YAML node together with the file it came from and its key path ("channels[1].hfov_deg").
// Conversions check type, finiteness and range and throw ConfigError pointing at the node.
class ConfigValue {
  public:
    // line and column are 1-based; they locate the node when the node has no mark of its own.
    ConfigValue(YAML::Node node, std::string path, std::shared_ptr<const std::string> file,
                int line, int column);

    const YAML::Node& Node() const { return node_; }
    const std::string& Path() const { return path_; }
    ConfigLocation Location() const { return {*file_, line_, column_}; }
    const std::shared_ptr<const std::string>& File() const { return file_; }

    // What the node is, for "found ...": its text as written for scalars, else its kind.
    std::string Describe() const;

    // Throws ConfigError at this node: "expected <expected>, found <found or Describe()>".
    [[noreturn]] void Fail(const std::string& expected) const;
    [[noreturn]] void Fail(const std::string& expected, const std::string& found) const;

    double AsDouble(const NumberRange& range) const;
    int64_t AsInt(int64_t lo, int64_t hi) const;  // inclusive range
    bool AsBool() const;                          // true/false (YAML 1.2 core schema)
    std::string AsString() const;                 // any scalar, quoted or not
    // Index into names of the scalar, which must equal one of them exactly.
    size_t AsEnum(const std::vector<std::string>& names) const;
    glm::dvec3 AsVec3(const NumberRange& range) const;  // a sequence of exactly 3 numbers
    UtcTime AsTime() const;                             // ISO-8601 (scene/core/time.h)
    // The items of a sequence with minCount..maxCount entries; itemsNoun names them in
    // messages ("channels", "numbers (m)").
    std::vector<ConfigValue> AsList(size_t minCount, size_t maxCount,
                                    const std::string& itemsNoun) const;
    ConfigMap AsMap() const;

  private:
    YAML::Node node_;
    std::string path_;
    std::shared_ptr<const std::string> file_;
    int line_;
    int column_;
};

// A YAML mapping being read. Every key the parser asks for (present or not) is recorded;
// Finish() rejects the keys in the file that were never asked for, suggesting the closest
// asked-for key. One mechanism thus catches both unknown keys and keys a parser forgot.
// Duplicate keys are rejected on construction.
class ConfigMap {
  public:
    explicit ConfigMap(ConfigValue value);

    const ConfigValue& Value() const { return value_; }
    const std::string& Path() const { return value_.Path(); }

    // The value of key, or nullopt when absent. Marks key as accepted.
    std::optional<ConfigValue> Find(std::string_view key);
    // The value of key; when absent throws "key.path: expected <expected>, found nothing".
    ConfigValue Require(std::string_view key, const std::string& expected);

    // Required (no fallback) and optional (fallback) typed getters.
    double GetDouble(std::string_view key, const NumberRange& range);
    double GetDouble(std::string_view key, const NumberRange& range, double fallback);
    int64_t GetInt(std::string_view key, int64_t lo, int64_t hi);
    int64_t GetInt(std::string_view key, int64_t lo, int64_t hi, int64_t fallback);
    bool GetBool(std::string_view key);
    bool GetBool(std::string_view key, bool fallback);
    std::string GetString(std::string_view key);
    std::string GetString(std::string_view key, const std::string& fallback);
    size_t GetEnum(std::string_view key, const std::vector<std::string>& names);
    size_t GetEnum(std::string_view key, const std::vector<std::string>& names, size_t fallback);
    glm::dvec3 GetVec3(std::string_view key, const NumberRange& range);
    glm::dvec3 GetVec3(std::string_view key, const NumberRange& range, const glm::dvec3& fallback);
    UtcTime GetTime(std::string_view key);
    UtcTime GetTime(std::string_view key, UtcTime fallback);
    ConfigMap GetMap(std::string_view key);
    std::optional<ConfigMap> FindMap(std::string_view key);
    std::vector<ConfigValue> GetList(std::string_view key, size_t minCount, size_t maxCount,
                                     const std::string& itemsNoun);

    // All entries in file order, for mappings whose keys are names chosen by the user
    // (e.g. the material table). Marks every key as read.
    std::vector<std::pair<std::string, ConfigValue>> Entries();

    // Throws for the first key (in file order) that no getter asked for.
    void Finish() const;

  private:
    struct Entry {
        std::string key;
        int keyLine;
        int keyColumn;
        ConfigValue value;
        bool read = false;
    };

    Entry* Lookup(std::string_view key);
    [[noreturn]] void FailUnknownKey(const Entry& entry, const std::string& expected,
                                     const std::optional<std::string>& suggestion) const;

    ConfigValue value_;
    std::vector<Entry> entries_;
    std::vector<std::string> accepted_;  // keys asked for, in the order first asked
};

// Reads a mapping with body(ConfigMap&) and then checks that every key was read.
template <class Body>
auto ReadMap(const ConfigValue& value, Body&& body) {
    ConfigMap map(value);
    if constexpr (std::is_void_v<std::invoke_result_t<Body, ConfigMap&>>) {
        body(map);
        map.Finish();
    } else {
        auto result = body(map);
        map.Finish();
        return result;
    }
}

// A parsed configuration file: its bytes (for digests) and the root node of its one document.
struct ConfigDocument {
    std::string file;  // the path as given, used in messages
    std::string bytes;
    ConfigValue root;
};

// Files larger than this are refused rather than read (a config is a few kilobytes; this
// also stops /dev/zero from reading forever).
inline constexpr size_t kMaxConfigFileBytes = size_t(64) << 20;

// Reads a whole file. Throws ConfigError "file: cannot read file: <strerror>" when it cannot.
std::string ReadConfigFileBytes(const std::filesystem::path& file);

// Why file cannot be opened and read (strerror text), or nullopt when it can.
std::optional<std::string> FileReadProblem(const std::filesystem::path& file);

// Reads and parses a YAML file holding exactly one non-empty document.
ConfigDocument LoadConfigFile(const std::filesystem::path& file);
// Parses YAML text as if read from a file named fileName.
ConfigDocument ParseConfigText(std::string text, const std::string& fileName);

}  // namespace seasense::scene
