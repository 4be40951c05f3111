// Tests of the validating YAML reader: typed getters, error messages and their locations.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "scene/config/config.h"
#include "scene/config/digest.h"
#include "scene/config/suggest.h"

namespace seasense::scene {
namespace {

constexpr const char* kFile = "test.yaml";

// 1-based line and column of the first occurrence of `part` inside the first occurrence of
// `context` in text, so that expected locations follow the fixture text, not hand counts.
struct LineColumn {
    int line;
    int column;
};

LineColumn Where(const std::string& text, const std::string& context, const std::string& part) {
    const size_t contextAt = text.find(context);
    EXPECT_NE(contextAt, std::string::npos) << "fixture lacks: " << context;
    const size_t at = text.find(part, contextAt);
    EXPECT_NE(at, std::string::npos) << "fixture lacks: " << part;
    int line = 1;
    size_t lineStart = 0;
    for (size_t i = 0; i < at; ++i) {
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    }
    return {line, int(at - lineStart) + 1};
}

std::string Prefix(LineColumn where, const std::string& path, const std::string& file = kFile) {
    return file + ":" + std::to_string(where.line) + ":" + std::to_string(where.column) + ": " +
           path + ": ";
}

// Runs body and returns the ConfigError message it throws ("" if it throws nothing).
template <class Body>
std::string ErrorOf(Body&& body) {
    try {
        body();
    } catch (const ConfigError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError thrown";
    return "";
}

double ReadFov(const std::string& text) {
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    const double fov = root.GetDouble("hfov_deg", NumberRange::Open(0, 180, "deg"));
    root.Finish();
    return fov;
}

TEST(ConfigReader, ReadsTypedValues) {
    const std::string text =
        "x: 1.5\n"
        "n: +12\n"
        "flag: false\n"
        "name: otw\n"
        "label: \"quoted text\"\n"
        "v: [1, -2.5e1, .5]\n"
        "t: 2026-06-21T18:30:00Z\n"
        "list: [a, b, c]\n"
        "sub: {k: 3}\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(map.GetDouble("x", NumberRange::Any()), 1.5);
    EXPECT_EQ(map.GetInt("n", 0, 100), 12);
    EXPECT_FALSE(map.GetBool("flag"));
    EXPECT_EQ(map.GetEnum("name", {"flir", "otw", "nvg"}), 1u);
    EXPECT_EQ(map.GetString("label"), "quoted text");
    EXPECT_EQ(map.GetVec3("v", NumberRange::Any()), glm::dvec3(1.0, -25.0, 0.5));
    // 2026-06-21T18:30:00Z is 1782066600 s after the Unix epoch (date -u -d ... +%s).
    EXPECT_EQ(map.GetTime("t").unixNs, int64_t(1782066600) * 1000000000);
    EXPECT_EQ(map.GetList("list", 1, 5, "names").size(), 3u);
    ConfigMap sub = map.GetMap("sub");
    EXPECT_EQ(sub.GetInt("k", 0, 10), 3);
    sub.Finish();
    // Absent optional keys give the fallback.
    EXPECT_EQ(map.GetDouble("absent", NumberRange::Any(), 7.0), 7.0);
    EXPECT_TRUE(map.GetBool("absent_flag", true));
    map.Finish();
}

TEST(ConfigReader, OpenIntervalExcludesItsEnds) {
    EXPECT_DOUBLE_EQ(ReadFov("hfov_deg: 179.9\n"), 179.9);
    EXPECT_DOUBLE_EQ(ReadFov("hfov_deg: 1e-3\n"), 1e-3);
    for (const char* bad : {"0", "180", "-1", "0.0", "180.0"}) {
        const std::string text = std::string("hfov_deg: ") + bad + "\n";
        EXPECT_EQ(ErrorOf([&] { ReadFov(text); }),
                  Prefix(Where(text, "hfov_deg", bad), "hfov_deg") +
                      "expected a number (deg) in (0, 180), found " + bad);
    }
}

TEST(ConfigReader, RejectsNonFiniteNumbers) {
    for (const char* bad : {".nan", ".NaN", ".inf", "-.inf", "+.Inf", "1e999", "-2e400"}) {
        const std::string text = std::string("a: 1\nhfov_deg: ") + bad + "\n";
        EXPECT_EQ(ErrorOf([&] { ReadFov(text); }),
                  Prefix(Where(text, "hfov_deg", bad), "hfov_deg") +
                      "expected a finite number (deg) in (0, 180), found " + bad)
            << bad;
    }
    // Underflow is not overflow: 1e-400 is a finite (zero) number, outside (0, 180) here.
    const std::string text = "hfov_deg: 1e-400\n";
    EXPECT_EQ(ErrorOf([&] { ReadFov(text); }),
              Prefix(Where(text, "hfov_deg", "1e-400"), "hfov_deg") +
                  "expected a number (deg) in (0, 180), found 1e-400");
}

TEST(ConfigReader, RejectsTextAndQuotedNumbers) {
    for (const char* bad : {"sixty", "\"60\"", "60deg", "0x3C", "1_000", "--1", "1e", "."}) {
        const std::string text = std::string("hfov_deg: ") + bad + "\n";
        const std::string message = ErrorOf([&] { ReadFov(text); });
        EXPECT_EQ(message.rfind(Prefix(Where(text, "hfov_deg", bad), "hfov_deg") +
                                    "expected a number (deg) in (0, 180), found ",
                                0),
                  0u)
            << message;
    }
    const std::string text = "hfov_deg: \"60\"\n";
    EXPECT_NE(ErrorOf([&] { ReadFov(text); }).find("found \"60\""), std::string::npos);
}

TEST(ConfigReader, NegativeSizeNamesTheRange) {
    const std::string text = "wave:\n  wavelength_m: -3\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    ConfigMap wave = root.GetMap("wave");
    EXPECT_EQ(ErrorOf([&] { wave.GetDouble("wavelength_m", NumberRange::Positive("m")); }),
              Prefix(Where(text, "wavelength_m", "-3"), "wave.wavelength_m") +
                  "expected a number (m) > 0, found -3");
}

TEST(ConfigReader, IntegersAreCheckedForFormAndRange) {
    const std::string text = "a: 2.5\nb: 16385\nc: 99999999999999999999\nd: \"4\"\ne: 8\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(ErrorOf([&] { map.GetInt("a", 1, 8); }),
              Prefix(Where(text, "a:", "2.5"), "a") + "expected an integer in [1, 8], found 2.5");
    EXPECT_EQ(
        ErrorOf([&] { map.GetInt("b", 1, 16384); }),
        Prefix(Where(text, "b:", "16385"), "b") + "expected an integer in [1, 16384], found 16385");
    EXPECT_EQ(ErrorOf([&] { map.GetInt("c", 0, 100); }),
              Prefix(Where(text, "c:", "999"), "c") +
                  "expected an integer in [0, 100], found 99999999999999999999");
    EXPECT_EQ(
        ErrorOf([&] { map.GetInt("d", 1, 8); }),
        Prefix(Where(text, "d:", "\"4\""), "d") + "expected an integer in [1, 8], found \"4\"");
    EXPECT_EQ(map.GetInt("e", 1, 8), 8);
}

TEST(ConfigReader, BooleansAreTrueOrFalseOnly) {
    const std::string text = "shadows: yes\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(ErrorOf([&] { map.GetBool("shadows"); }),
              Prefix(Where(text, "shadows", "yes"), "shadows") +
                  "expected a boolean (true or false), found 'yes'");
}

TEST(ConfigReader, BadEnumSuggestsTheClosestName) {
    const std::string text = "channels:\n  - kind: fir\n  - kind: radar\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    const std::vector<ConfigValue> items = root.GetList("channels", 1, 4, "channels");
    const std::vector<std::string> kinds = {"otw", "flir", "nvg"};
    EXPECT_EQ(ErrorOf([&] { ConfigMap(items[0]).GetEnum("kind", kinds); }),
              Prefix(Where(text, "kind: fir", "fir"), "channels[0].kind") +
                  "expected one of otw, flir, nvg, found 'fir' (did you mean 'flir'?)");
    EXPECT_EQ(ErrorOf([&] { ConfigMap(items[1]).GetEnum("kind", kinds); }),
              Prefix(Where(text, "kind: radar", "radar"), "channels[1].kind") +
                  "expected one of otw, flir, nvg, found 'radar'");
}

TEST(ConfigReader, Vec3ChecksCountAndEachElement) {
    const std::string text = "a: [1, 2]\nb: [1, .nan, 3]\nc: 5\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(ErrorOf([&] { map.GetVec3("a", NumberRange::Any("m")); }),
              Prefix(Where(text, "a:", "["), "a") +
                  "expected a sequence of 3 numbers (m), found a sequence of 2 items");
    EXPECT_EQ(
        ErrorOf([&] { map.GetVec3("b", NumberRange::Any("m")); }),
        Prefix(Where(text, "b:", ".nan"), "b[1]") + "expected a finite number (m), found .nan");
    EXPECT_EQ(
        ErrorOf([&] { map.GetVec3("c", NumberRange::Any("m")); }),
        Prefix(Where(text, "c:", "5"), "c") + "expected a sequence of 3 numbers (m), found 5");
}

TEST(ConfigReader, BadTimeGivesTheExpectedForm) {
    const std::string text = "world:\n  start_utc: 2026-13-21T18:30:00Z\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    ConfigMap world = root.GetMap("world");
    EXPECT_EQ(ErrorOf([&] { world.GetTime("start_utc"); }),
              Prefix(Where(text, "start_utc", "2026"), "world.start_utc") +
                  "expected an ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found "
                  "'2026-13-21T18:30:00Z'");
}

TEST(ConfigReader, WrongNodeTypeNamesBothTypes) {
    const std::string text = "sun: 25\nhfov_deg: {value: 60}\nlist: {a: 1}\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(ErrorOf([&] { map.GetMap("sun"); }),
              Prefix(Where(text, "sun", "25"), "sun") + "expected a mapping, found 25");
    EXPECT_EQ(ErrorOf([&] { map.GetDouble("hfov_deg", NumberRange::Open(0, 180, "deg")); }),
              Prefix(Where(text, "hfov_deg", "{"), "hfov_deg") +
                  "expected a number (deg) in (0, 180), found a mapping");
    EXPECT_EQ(ErrorOf([&] { map.GetList("list", 1, 3, "items"); }),
              Prefix(Where(text, "list", "{"), "list") +
                  "expected a sequence of 1 to 3 items, found a mapping");
    const std::string root = "- a\n- b\n";
    ConfigDocument listDoc = ParseConfigText(root, kFile);
    EXPECT_EQ(
        ErrorOf([&] { ConfigMap{listDoc.root}; }),
        std::string(kFile) + ":1:1: (top level): expected a mapping, found a sequence of 2 items");
}

TEST(ConfigReader, MissingRequiredKeyPointsAtItsMapping) {
    const std::string text = "world:\n  origin: {latitude_deg: 33.2}\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    ConfigMap world = root.GetMap("world");
    ConfigMap origin = world.GetMap("origin");
    origin.GetDouble("latitude_deg", NumberRange::Closed(-90, 90, "deg"));
    EXPECT_EQ(
        ErrorOf([&] { origin.GetDouble("longitude_deg", NumberRange::Closed(-180, 180, "deg")); }),
        Prefix(Where(text, "origin", "{"), "world.origin.longitude_deg") +
            "expected a number (deg) in [-180, 180], found nothing (the key is required)");
}

TEST(ConfigReader, MissingKeyIsNotConfusedWithASiblingKey) {
    // longitude_deg is a valid key read later, not a misspelt latitude_deg.
    const std::string text = "origin: {longitude_deg: 10}\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    ConfigMap origin = root.GetMap("origin");
    EXPECT_EQ(
        ErrorOf([&] { origin.GetDouble("latitude_deg", NumberRange::Closed(-90, 90, "deg")); }),
        Prefix(Where(text, "origin", "{"), "origin.latitude_deg") +
            "expected a number (deg) in [-90, 90], found nothing (the key is required)");
}

TEST(ConfigReader, NullValueIsReportedAtItsKey) {
    const std::string text = "a:\nb: 2\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    EXPECT_EQ(ErrorOf([&] { map.GetDouble("a", NumberRange::Any()); }),
              Prefix(Where(text, "a:", "a"), "a") + "expected a number, found null (no value)");
}

TEST(ConfigReader, UnknownKeySuggestsTheClosestAcceptedKey) {
    const std::string text = "sun:\n  azimuth_deg: 240\n  elevaton_deg: 25\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    ConfigMap sun = root.GetMap("sun");
    sun.GetDouble("azimuth_deg", NumberRange::Any("deg"));
    sun.GetDouble("elevation_deg", NumberRange::Closed(-90, 90, "deg"), 0.0);
    sun.GetDouble("illuminance_lux", NumberRange::NonNegative("lux"), 1e5);
    const std::string message = ErrorOf([&] { sun.Finish(); });
    EXPECT_EQ(message, Prefix(Where(text, "elevaton_deg", "elevaton_deg"), "sun.elevaton_deg") +
                           "expected one of the keys azimuth_deg, elevation_deg, illuminance_lux, "
                           "found unknown key 'elevaton_deg' (did you mean 'elevation_deg'?)");
}

TEST(ConfigReader, UnknownKeyWithoutNearMatchListsTheKeys) {
    const std::string text = "a: 1\nzebra: 2\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    map.GetInt("a", 0, 9);
    map.GetInt("bb", 0, 9, 0);
    EXPECT_EQ(ErrorOf([&] { map.Finish(); }),
              Prefix(Where(text, "zebra", "zebra"), "zebra") +
                  "expected one of the keys a, bb, found unknown key 'zebra'");
}

TEST(ConfigReader, KeyNeverReadIsAnErrorLikeAnUnknownKey) {
    // The parser reads only "a"; "b" is in the file but no getter asked for it.
    const std::string text = "a: 1\nb: 2\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    EXPECT_EQ(
        ErrorOf([&] { ReadMap(doc.root, [](ConfigMap& m) { m.GetInt("a", 0, 9); }); }),
        Prefix(Where(text, "b:", "b"), "b") + "expected one of the keys a, found unknown key 'b'");
    // Entries() reads every key, so a free-form mapping passes.
    EXPECT_NO_THROW(ReadMap(doc.root, [](ConfigMap& m) { m.Entries(); }));
}

TEST(ConfigReader, MisspeltRequiredKeyIsReportedAtTheMisspelling) {
    const std::string text = "name: a\nhfvo_deg: 60\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    map.GetString("name");
    EXPECT_EQ(ErrorOf([&] { map.GetDouble("hfov_deg", NumberRange::Open(0, 180, "deg")); }),
              Prefix(Where(text, "hfvo_deg", "hfvo_deg"), "hfvo_deg") +
                  "expected the required key 'hfov_deg', found unknown key 'hfvo_deg' (did you "
                  "mean 'hfov_deg'?)");
}

TEST(ConfigReader, MissingUnitSuffixIsSuggested) {
    const std::string text = "hfov: 60\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    map.GetDouble("hfov_deg", NumberRange::Open(0, 180, "deg"), 60.0);
    EXPECT_NE(ErrorOf([&] { map.Finish(); }).find("(did you mean 'hfov_deg'?)"), std::string::npos);
}

TEST(ConfigReader, DuplicateKeyIsAnError) {
    const std::string text = "a: 1\nb: 2\na: 3\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    const LineColumn second = Where(text, "b: 2\na", "a");
    EXPECT_EQ(ErrorOf([&] { ConfigMap{doc.root}; }),
              Prefix(second, "a") +
                  "expected each key at most once per mapping (first at line 1), "
                  "found it again");
}

TEST(ConfigReader, SyntaxErrorCarriesLineAndColumn) {
    const std::string text = "a: 1\nb: [1, 2]]\nc: 3\n";
    const LineColumn where = Where(text, "]]", "]]");
    EXPECT_EQ(ErrorOf([&] { ParseConfigText(text, kFile); }),
              std::string(kFile) + ":" + std::to_string(where.line) + ":" +
                  std::to_string(where.column + 1) + ": YAML syntax error: illegal flow end");
    const std::string alias = "a: &x 1\nb: *y\n";
    const LineColumn star = Where(alias, "*y", "*y");
    const std::string message = ErrorOf([&] { ParseConfigText(alias, kFile); });
    EXPECT_EQ(message.rfind(std::string(kFile) + ":" + std::to_string(star.line) + ":" +
                                std::to_string(star.column) + ": YAML syntax error: ",
                            0),
              0u)
        << message;
}

TEST(ConfigReader, EmptyAndMultiDocumentFilesAreErrors) {
    EXPECT_EQ(
        ErrorOf([&] { ParseConfigText("", kFile); }),
        std::string(kFile) + ":1:1: (top level): expected a YAML mapping, found an empty document");
    EXPECT_EQ(
        ErrorOf([&] { ParseConfigText("# only a comment\n", kFile); }),
        std::string(kFile) + ":1:1: (top level): expected a YAML mapping, found an empty document");
    const std::string text = "a: 1\n---\nb: 2\n";
    EXPECT_EQ(ErrorOf([&] { ParseConfigText(text, kFile); }),
              Prefix(Where(text, "b: 2", "b"), "(top level)") +
                  "expected a single YAML document, found another document (2 in total)");
}

TEST(ConfigReader, UnreadableFilesGiveTheSystemReason) {
    // The process id keeps concurrent runs (several build folders) apart.
    const std::string unique = std::to_string(::getpid());
    const std::filesystem::path missing = std::filesystem::path(::testing::TempDir()) /
                                          ("seasense_config_no_such_file_" + unique + ".yaml");
    std::filesystem::remove(missing);
    EXPECT_EQ(ErrorOf([&] { LoadConfigFile(missing); }),
              missing.string() + ": cannot read file: " + std::strerror(ENOENT));
    const std::filesystem::path folder = std::filesystem::path(::testing::TempDir()) /
                                         ("seasense_config_folder_" + unique + ".yaml");
    std::filesystem::create_directories(folder);
    EXPECT_EQ(ErrorOf([&] { LoadConfigFile(folder); }),
              folder.string() + ": cannot read file: " + std::strerror(EISDIR));
    std::filesystem::remove(folder);
}

TEST(ConfigReader, ConfigErrorIsAnInputError) {
    // InputError is what the CLI maps to exit status 2.
    EXPECT_THROW(ParseConfigText("a: [", kFile), InputError);
}

TEST(ConfigReader, MessagesEscapeControlCharactersAndStayShort) {
    const std::string text = "a: \"x\\ty\\u0001" + std::string(100, 'z') + "\"\n";
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap map(doc.root);
    const std::string message = ErrorOf([&] { map.GetDouble("a", NumberRange::Any()); });
    EXPECT_NE(message.find("found \"x\\ty\\x01zzz"), std::string::npos) << message;
    EXPECT_NE(message.find("...\""), std::string::npos) << message;
    EXPECT_LT(message.size(), 140u);
}

TEST(EditDistance, MatchesTextbookExamples) {
    // Levenshtein's classic example: kitten -> sitting takes 3 edits.
    EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(EditDistance("", "abc"), 3u);
    EXPECT_EQ(EditDistance("abc", "abc"), 0u);
    // A transposition of neighbours is one edit (Damerau 1964).
    EXPECT_EQ(EditDistance("hfvo_deg", "hfov_deg"), 1u);
    // Optimal string alignment edits no substring twice: "ca" -> "abc" is 3 (unrestricted
    // Damerau-Levenshtein would give 2).
    EXPECT_EQ(EditDistance("ca", "abc"), 3u);
}

TEST(SuggestClosest, PicksNearNamesOnly) {
    const std::vector<std::string> keys = {"name", "kind", "resolution", "hfov_deg", "near_m"};
    EXPECT_EQ(SuggestClosest("resolutoin", keys), "resolution");
    EXPECT_EQ(SuggestClosest("HFOV_DEG", keys), "hfov_deg");
    EXPECT_EQ(SuggestClosest("hfov_rad", keys), "hfov_deg");
    EXPECT_EQ(SuggestClosest("near", keys), "near_m");
    EXPECT_EQ(SuggestClosest("altitude", keys), std::nullopt);
    EXPECT_EQ(SuggestClosest("kind", keys), std::nullopt);  // the word itself is not a typo
}

TEST(Fnv1a64, MatchesReferenceVectors) {
    // Test vectors of the FNV reference implementation (draft-eastlake-fnv, test suite).
    EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);
    EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
    EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
    EXPECT_EQ(Fnv1a64Hex("a"), "af63dc4c8601ec8c");
}

}  // namespace
}  // namespace seasense::scene
