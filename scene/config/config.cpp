// Typed, located access to YAML configuration nodes.
#include "scene/config/config.h"

#include <fcntl.h>
#include <unistd.h>
#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

#include "scene/config/suggest.h"

namespace seasense::scene {

// ---------------------------------------------------------------- numbers

NumberRange NumberRange::Any(std::string unit) {
    NumberRange r;
    r.unit = std::move(unit);
    return r;
}

NumberRange NumberRange::Closed(double lo, double hi, std::string unit) {
    return NumberRange{lo, hi, false, false, std::move(unit)};
}

NumberRange NumberRange::Open(double lo, double hi, std::string unit) {
    return NumberRange{lo, hi, true, true, std::move(unit)};
}

NumberRange NumberRange::OpenClosed(double lo, double hi, std::string unit) {
    return NumberRange{lo, hi, true, false, std::move(unit)};
}

NumberRange NumberRange::Positive(std::string unit) {
    return NumberRange{0.0, std::numeric_limits<double>::infinity(), true, false, std::move(unit)};
}

NumberRange NumberRange::NonNegative(std::string unit) {
    return NumberRange{0.0, std::numeric_limits<double>::infinity(), false, false, std::move(unit)};
}

bool NumberRange::Contains(double x) const {
    const bool aboveLo = loOpen ? x > lo : x >= lo;
    const bool belowHi = hiOpen ? x < hi : x <= hi;
    return aboveLo && belowHi;
}

std::string FormatNumber(double x) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
    return std::string(buffer, result.ptr);
}

std::string NumberRange::Describe(bool finite) const {
    std::string text = finite ? "a finite number" : "a number";
    if (!unit.empty()) text += " (" + unit + ")";
    const bool hasLo = std::isfinite(lo), hasHi = std::isfinite(hi);
    if (hasLo && hasHi) {
        text += std::string(" in ") + (loOpen ? "(" : "[") + FormatNumber(lo) + ", " +
                FormatNumber(hi) + (hiOpen ? ")" : "]");
    } else if (hasLo) {
        text += std::string(loOpen ? " > " : " >= ") + FormatNumber(lo);
    } else if (hasHi) {
        text += std::string(hiOpen ? " < " : " <= ") + FormatNumber(hi);
    }
    return text;
}

namespace {

constexpr const char* kIsoExample = "an ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z)";

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// Plain scalars and explicitly tagged numbers may be numbers; quoted scalars are strings.
bool MayBeNumber(const YAML::Node& node) {
    const std::string& tag = node.Tag();
    return tag == "?" || tag == "tag:yaml.org,2002:float" || tag == "tag:yaml.org,2002:int";
}

// Decimal exponent of the leading significant digit of a number matching the grammar below
// (without sign): "123e4" -> 6, "0.05" -> -2. Zero has magnitude 0.
int64_t DecimalMagnitude(std::string_view body) {
    const size_t e = body.find_first_of("eE");
    const std::string_view mantissa = body.substr(0, e);
    int64_t exponent = 0;
    if (e != std::string_view::npos) {
        std::string_view digits = body.substr(e + 1);
        const bool negative = !digits.empty() && digits[0] == '-';
        if (!digits.empty() && (digits[0] == '+' || digits[0] == '-')) digits.remove_prefix(1);
        for (char c : digits) exponent = std::min<int64_t>(exponent * 10 + (c - '0'), 1000000);
        if (negative) exponent = -exponent;
    }
    const size_t point = std::min(mantissa.find('.'), mantissa.size());
    for (size_t i = 0; i < mantissa.size(); ++i) {
        if (mantissa[i] == '.' || mantissa[i] == '0') continue;
        // Position of the first non-zero digit relative to the decimal point.
        const int64_t place = i < point ? int64_t(point - i) - 1 : -int64_t(i - point);
        return place + exponent;
    }
    return 0;
}

enum class FloatKind { NotANumber, Finite, NonFinite };

// A float of the YAML 1.2 core schema (section 10.3.2):
// [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?, plus [-+]?.inf and .nan spellings.
FloatKind ParseYamlFloat(std::string_view text, double& value) {
    std::string_view body = text;
    bool negative = false;
    if (!body.empty() && (body[0] == '+' || body[0] == '-')) {
        negative = body[0] == '-';
        body.remove_prefix(1);
    }
    if (body == ".inf" || body == ".Inf" || body == ".INF") {
        value = negative ? -std::numeric_limits<double>::infinity()
                         : std::numeric_limits<double>::infinity();
        return FloatKind::NonFinite;
    }
    if (body == ".nan" || body == ".NaN" || body == ".NAN") {
        value = std::numeric_limits<double>::quiet_NaN();
        return FloatKind::NonFinite;
    }
    size_t i = 0, mantissaDigits = 0;
    while (i < body.size() && IsDigit(body[i])) ++i, ++mantissaDigits;
    if (i < body.size() && body[i] == '.') {
        ++i;
        while (i < body.size() && IsDigit(body[i])) ++i, ++mantissaDigits;
    }
    if (mantissaDigits == 0) return FloatKind::NotANumber;
    if (i < body.size() && (body[i] == 'e' || body[i] == 'E')) {
        ++i;
        if (i < body.size() && (body[i] == '+' || body[i] == '-')) ++i;
        size_t exponentDigits = 0;
        while (i < body.size() && IsDigit(body[i])) ++i, ++exponentDigits;
        if (exponentDigits == 0) return FloatKind::NotANumber;
    }
    if (i != body.size()) return FloatKind::NotANumber;
    // from_chars takes no '+' but accepts everything the grammar above admits.
    std::string_view digits = text[0] == '+' ? text.substr(1) : text;
    double parsed = 0.0;
    const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), parsed);
    if (result.ec == std::errc::result_out_of_range) {
        // Overflow is non-finite; underflow is an ordinary tiny number. Which one it is
        // follows from the decimal exponent of the leading significant digit.
        value = DecimalMagnitude(body) > 0 ? std::numeric_limits<double>::infinity() : 0.0;
        return std::isfinite(value) ? FloatKind::Finite : FloatKind::NonFinite;
    }
    if (result.ec != std::errc() || result.ptr != digits.data() + digits.size())
        return FloatKind::NotANumber;
    value = parsed;
    return std::isfinite(parsed) ? FloatKind::Finite : FloatKind::NonFinite;
}

bool IsYamlInteger(std::string_view text) {
    if (!text.empty() && (text[0] == '+' || text[0] == '-')) text.remove_prefix(1);
    if (text.empty()) return false;
    for (char c : text)
        if (!IsDigit(c)) return false;
    return true;
}

bool IsYamlBool(std::string_view text, bool& value) {
    if (text == "true" || text == "True" || text == "TRUE") {
        value = true;
        return true;
    }
    if (text == "false" || text == "False" || text == "FALSE") {
        value = false;
        return true;
    }
    return false;
}

// Makes user text safe and short for a one-line message.
std::string Printable(std::string_view text) {
    constexpr size_t kMaxChars = 60;
    std::string out;
    for (size_t i = 0; i < text.size(); ++i) {
        if (out.size() >= kMaxChars) {
            out += "...";
            break;
        }
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\t') {
            out += "\\t";
        } else if (c < 0x20 || c == 0x7F) {
            static constexpr char kHex[] = "0123456789abcdef";
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 0xF];
        } else {
            out += char(c);
        }
    }
    return out;
}

std::string Quoted(std::string_view text) {
    std::string out = "'";
    out += Printable(text);
    out += "'";
    return out;
}

std::string JoinNames(const std::vector<std::string>& names) {
    std::string out;
    for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
    return out;
}

// 1-based location of node, or the fallback when yaml-cpp has none. Null nodes take the
// fallback too: yaml-cpp marks an empty value at the start of the following token, which
// may be on a later line.
void NodeLocation(const YAML::Node& node, int fallbackLine, int fallbackColumn, int& line,
                  int& column) {
    const YAML::Mark mark = node.Mark();
    if (node.IsNull() || mark.is_null() || mark.line < 0 || mark.column < 0) {
        line = fallbackLine;
        column = fallbackColumn;
    } else {
        line = mark.line + 1;
        column = mark.column + 1;
    }
}

}  // namespace

// ---------------------------------------------------------------- ConfigValue

ConfigValue::ConfigValue(YAML::Node node, std::string path, std::shared_ptr<const std::string> file,
                         int line, int column)
    : node_(std::move(node)), path_(std::move(path)), file_(std::move(file)) {
    NodeLocation(node_, line, column, line_, column_);
}

std::string ConfigValue::Describe() const {
    switch (node_.Type()) {
        case YAML::NodeType::Undefined:
            return "nothing";
        case YAML::NodeType::Null:
            return "null (no value)";
        case YAML::NodeType::Map:
            return "a mapping";
        case YAML::NodeType::Sequence: {
            const size_t n = node_.size();
            return "a sequence of " + std::to_string(n) + (n == 1 ? " item" : " items");
        }
        case YAML::NodeType::Scalar:
            break;
    }
    const std::string& text = node_.Scalar();
    if (node_.Tag() == "!") return "\"" + Printable(text) + "\"";
    double ignored;
    bool ignoredBool;
    if (ParseYamlFloat(text, ignored) != FloatKind::NotANumber || IsYamlBool(text, ignoredBool))
        return Printable(text);
    return Quoted(text);
}

void ConfigValue::Fail(const std::string& expected) const { Fail(expected, Describe()); }

void ConfigValue::Fail(const std::string& expected, const std::string& found) const {
    throw ConfigError(Location(), path_, expected, found);
}

double ConfigValue::AsDouble(const NumberRange& range) const {
    if (!node_.IsScalar() || !MayBeNumber(node_)) Fail(range.Describe());
    double value = 0.0;
    switch (ParseYamlFloat(node_.Scalar(), value)) {
        case FloatKind::NotANumber:
            Fail(range.Describe());
        case FloatKind::NonFinite:
            Fail(range.Describe(true));
        case FloatKind::Finite:
            break;
    }
    if (!range.Contains(value)) Fail(range.Describe());
    return value;
}

int64_t ConfigValue::AsInt(int64_t lo, int64_t hi) const {
    const std::string expected =
        "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!node_.IsScalar() || !MayBeNumber(node_) || !IsYamlInteger(node_.Scalar())) Fail(expected);
    std::string_view text = node_.Scalar();
    if (text[0] == '+') text.remove_prefix(1);
    int64_t value = 0;
    const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
    if (result.ec != std::errc() || value < lo || value > hi) Fail(expected);
    return value;
}

bool ConfigValue::AsBool() const {
    const std::string expected = "a boolean (true or false)";
    bool value = false;
    if (!node_.IsScalar() || node_.Tag() == "!" || !IsYamlBool(node_.Scalar(), value))
        Fail(expected);
    return value;
}

std::string ConfigValue::AsString() const {
    if (!node_.IsScalar()) Fail("a string");
    return node_.Scalar();
}

size_t ConfigValue::AsEnum(const std::vector<std::string>& names) const {
    const std::string expected = "one of " + JoinNames(names);
    if (!node_.IsScalar()) Fail(expected);
    const std::string& text = node_.Scalar();
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == text) return i;
    const std::optional<std::string> suggestion = SuggestClosest(text, names);
    Fail(expected,
         Describe() + (suggestion ? " (did you mean '" + *suggestion + "'?)" : std::string()));
}

glm::dvec3 ConfigValue::AsVec3(const NumberRange& range) const {
    const std::vector<ConfigValue> items =
        AsList(3, 3, range.unit.empty() ? "numbers" : "numbers (" + range.unit + ")");
    return {items[0].AsDouble(range), items[1].AsDouble(range), items[2].AsDouble(range)};
}

UtcTime ConfigValue::AsTime() const {
    if (!node_.IsScalar()) Fail(kIsoExample);
    const std::optional<UtcTime> time = ParseIso8601(node_.Scalar());
    if (!time) Fail(kIsoExample);
    return *time;
}

std::vector<ConfigValue> ConfigValue::AsList(size_t minCount, size_t maxCount,
                                             const std::string& itemsNoun) const {
    std::string expected = "a sequence of ";
    if (minCount == maxCount)
        expected += std::to_string(minCount);
    else if (maxCount == SIZE_MAX)
        expected += "at least " + std::to_string(minCount);
    else
        expected += std::to_string(minCount) + " to " + std::to_string(maxCount);
    expected += " " + itemsNoun;
    if (!node_.IsSequence()) Fail(expected);
    const size_t n = node_.size();
    if (n < minCount || n > maxCount) Fail(expected);
    std::vector<ConfigValue> items;
    items.reserve(n);
    size_t index = 0;
    for (const YAML::Node& item : node_) {
        items.emplace_back(item, path_ + "[" + std::to_string(index) + "]", file_, line_, column_);
        ++index;
    }
    return items;
}

ConfigMap ConfigValue::AsMap() const { return ConfigMap(*this); }

// ---------------------------------------------------------------- ConfigMap

namespace {

std::string ChildPath(const std::string& parent, std::string_view key) {
    const std::string printable = Printable(key);
    return parent.empty() ? printable : parent + "." + printable;
}

}  // namespace

ConfigMap::ConfigMap(ConfigValue value) : value_(std::move(value)) {
    const YAML::Node& node = value_.Node();
    if (!node.IsMap()) value_.Fail("a mapping");
    for (auto it = node.begin(); it != node.end(); ++it) {
        int keyLine, keyColumn;
        NodeLocation(it->first, value_.Location().line, value_.Location().column, keyLine,
                     keyColumn);
        const ConfigValue keyValue(it->first, value_.Path(), value_.File(), keyLine, keyColumn);
        if (!it->first.IsScalar()) keyValue.Fail("a key name", keyValue.Describe());
        std::string key = it->first.Scalar();
        for (const Entry& earlier : entries_) {
            if (earlier.key == key) {
                throw ConfigError(ConfigLocation{*value_.File(), keyLine, keyColumn},
                                  ChildPath(value_.Path(), key),
                                  "each key at most once per mapping (first at line " +
                                      std::to_string(earlier.keyLine) + ")",
                                  "it again");
            }
        }
        ConfigValue child(it->second, ChildPath(value_.Path(), key), value_.File(), keyLine,
                          keyColumn);
        entries_.push_back(Entry{std::move(key), keyLine, keyColumn, std::move(child)});
    }
}

ConfigMap::Entry* ConfigMap::Lookup(std::string_view key) {
    bool known = false;
    for (const std::string& k : accepted_) known = known || k == key;
    if (!known) accepted_.emplace_back(key);
    for (Entry& entry : entries_) {
        if (entry.key == key) {
            entry.read = true;
            return &entry;
        }
    }
    return nullptr;
}

std::optional<ConfigValue> ConfigMap::Find(std::string_view key) {
    if (Entry* entry = Lookup(key)) return entry->value;
    return std::nullopt;
}

ConfigValue ConfigMap::Require(std::string_view key, const std::string& expected) {
    if (Entry* entry = Lookup(key)) return entry->value;
    // A required key that is missing is most often misspelt: point at the misspelling.
    for (const Entry& entry : entries_) {
        if (entry.read) continue;
        if (std::optional<std::string> s = SuggestClosest(entry.key, {std::string(key)}))
            FailUnknownKey(entry, "the required key '" + std::string(key) + "'", s);
    }
    throw ConfigError(value_.Location(), ChildPath(value_.Path(), key), expected,
                      "nothing (the key is required)");
}

void ConfigMap::FailUnknownKey(const Entry& entry, const std::string& expected,
                               const std::optional<std::string>& suggestion) const {
    std::string found = "unknown key " + Quoted(entry.key);
    if (suggestion) found += " (did you mean '" + *suggestion + "'?)";
    throw ConfigError(ConfigLocation{*value_.File(), entry.keyLine, entry.keyColumn},
                      ChildPath(value_.Path(), entry.key), expected, found);
}

void ConfigMap::Finish() const {
    for (const Entry& entry : entries_) {
        if (entry.read) continue;
        const std::string expected = accepted_.empty() ? std::string("no keys in this mapping")
                                                       : "one of the keys " + JoinNames(accepted_);
        FailUnknownKey(entry, expected, SuggestClosest(entry.key, accepted_));
    }
}

double ConfigMap::GetDouble(std::string_view key, const NumberRange& range) {
    return Require(key, range.Describe()).AsDouble(range);
}

double ConfigMap::GetDouble(std::string_view key, const NumberRange& range, double fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsDouble(range) : fallback;
}

int64_t ConfigMap::GetInt(std::string_view key, int64_t lo, int64_t hi) {
    return Require(key, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]")
        .AsInt(lo, hi);
}

int64_t ConfigMap::GetInt(std::string_view key, int64_t lo, int64_t hi, int64_t fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsInt(lo, hi) : fallback;
}

bool ConfigMap::GetBool(std::string_view key) {
    return Require(key, "a boolean (true or false)").AsBool();
}

bool ConfigMap::GetBool(std::string_view key, bool fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsBool() : fallback;
}

std::string ConfigMap::GetString(std::string_view key) {
    return Require(key, "a string").AsString();
}

std::string ConfigMap::GetString(std::string_view key, const std::string& fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsString() : fallback;
}

size_t ConfigMap::GetEnum(std::string_view key, const std::vector<std::string>& names) {
    return Require(key, "one of " + JoinNames(names)).AsEnum(names);
}

size_t ConfigMap::GetEnum(std::string_view key, const std::vector<std::string>& names,
                          size_t fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsEnum(names) : fallback;
}

glm::dvec3 ConfigMap::GetVec3(std::string_view key, const NumberRange& range) {
    return Require(key, "a sequence of 3 numbers" +
                            (range.unit.empty() ? std::string() : " (" + range.unit + ")"))
        .AsVec3(range);
}

glm::dvec3 ConfigMap::GetVec3(std::string_view key, const NumberRange& range,
                              const glm::dvec3& fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsVec3(range) : fallback;
}

UtcTime ConfigMap::GetTime(std::string_view key) { return Require(key, kIsoExample).AsTime(); }

UtcTime ConfigMap::GetTime(std::string_view key, UtcTime fallback) {
    const std::optional<ConfigValue> value = Find(key);
    return value ? value->AsTime() : fallback;
}

ConfigMap ConfigMap::GetMap(std::string_view key) { return Require(key, "a mapping").AsMap(); }

std::optional<ConfigMap> ConfigMap::FindMap(std::string_view key) {
    const std::optional<ConfigValue> value = Find(key);
    if (!value) return std::nullopt;
    return value->AsMap();
}

std::vector<ConfigValue> ConfigMap::GetList(std::string_view key, size_t minCount, size_t maxCount,
                                            const std::string& itemsNoun) {
    return Require(key, "a sequence of " + itemsNoun).AsList(minCount, maxCount, itemsNoun);
}

std::vector<std::pair<std::string, ConfigValue>> ConfigMap::Entries() {
    std::vector<std::pair<std::string, ConfigValue>> out;
    out.reserve(entries_.size());
    for (Entry& entry : entries_) {
        entry.read = true;
        out.emplace_back(entry.key, entry.value);
    }
    return out;
}

// ---------------------------------------------------------------- files

namespace {

// Closes a POSIX file descriptor on scope exit.
class FileDescriptor {
  public:
    explicit FileDescriptor(int fd) : fd_(fd) {}
    ~FileDescriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    int Get() const { return fd_; }

  private:
    int fd_;
};

// Reads up to maxBytes + 1 bytes (so that "too large" is detectable); errno text on failure.
std::optional<std::string> ReadUpTo(const std::filesystem::path& file, size_t maxBytes,
                                    std::string& bytes) {
    FileDescriptor fd(::open(file.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.Get() < 0) return std::string(std::strerror(errno));
    bytes.clear();
    char buffer[1 << 16];
    while (bytes.size() <= maxBytes) {
        const ssize_t n = ::read(fd.Get(), buffer, sizeof(buffer));
        if (n < 0) {
            if (errno == EINTR) continue;
            return std::string(std::strerror(errno));
        }
        if (n == 0) break;
        bytes.append(buffer, size_t(n));
    }
    return std::nullopt;
}

}  // namespace

std::string ReadConfigFileBytes(const std::filesystem::path& file) {
    std::string bytes;
    if (std::optional<std::string> problem = ReadUpTo(file, kMaxConfigFileBytes, bytes))
        throw ConfigError::Unreadable(file.string(), *problem);
    if (bytes.size() > kMaxConfigFileBytes)
        throw ConfigError::Unreadable(file.string(), "larger than the " +
                                                         std::to_string(kMaxConfigFileBytes >> 20) +
                                                         " MiB limit for configuration files");
    return bytes;
}

std::optional<std::string> FileReadProblem(const std::filesystem::path& file) {
    std::string firstBytes;
    return ReadUpTo(file, 0, firstBytes);
}

ConfigDocument LoadConfigFile(const std::filesystem::path& file) {
    return ParseConfigText(ReadConfigFileBytes(file), file.string());
}

ConfigDocument ParseConfigText(std::string text, const std::string& fileName) {
    auto name = std::make_shared<const std::string>(fileName);
    std::vector<YAML::Node> documents;
    auto where = [&](const YAML::Mark& mark) {
        const bool hasMark = !mark.is_null() && mark.line >= 0 && mark.column >= 0;
        return ConfigLocation{fileName, hasMark ? mark.line + 1 : 1, hasMark ? mark.column + 1 : 1};
    };
    try {
        documents = YAML::LoadAll(text);
    } catch (const YAML::DeepRecursion& e) {
        // yaml-cpp's own message for this case is the misleading "bad file".
        throw ConfigError::SyntaxError(where(e.mark), "nesting too deep");
    } catch (const YAML::Exception& e) {
        throw ConfigError::SyntaxError(where(e.mark), e.msg);
    }
    if (documents.empty() || documents[0].IsNull()) {
        throw ConfigError(ConfigLocation{fileName, 1, 1}, "", "a YAML mapping",
                          "an empty document");
    }
    if (documents.size() > 1) {
        const ConfigValue second(documents[1], "", name, 1, 1);
        second.Fail("a single YAML document",
                    "another document (" + std::to_string(documents.size()) + " in total)");
    }
    ConfigValue root(documents[0], "", name, 1, 1);
    return ConfigDocument{fileName, std::move(text), std::move(root)};
}

}  // namespace seasense::scene
