// UTC instants as integer nanoseconds since the Unix epoch, with ISO-8601 parsing and printing.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace seasense::scene {

// A UTC instant. Leap seconds are not counted (POSIX time), as in ISO-8601 civil time.
struct UtcTime {
    int64_t unixNs = 0;

    double UnixSeconds() const { return double(unixNs) * 1e-9; }
    // Julian date (UTC) of this instant; the Unix epoch is JD 2440587.5.
    double JulianDate() const { return 2440587.5 + double(unixNs) / 86400e9; }
    UtcTime PlusSeconds(double seconds) const;
    friend bool operator==(UtcTime, UtcTime) = default;
    friend auto operator<=>(UtcTime, UtcTime) = default;
};

// Parses "YYYY-MM-DDThh:mm[:ss[.fff]](Z|±hh:mm)"; a missing zone means UTC.
// Returns nullopt on any malformed or out-of-range field.
std::optional<UtcTime> ParseIso8601(std::string_view text);

// Formats as "YYYY-MM-DDThh:mm:ss.fffZ" (millisecond precision, truncated toward the past).
std::string FormatIso8601(UtcTime t);

// Days since 1970-01-01 of a proleptic Gregorian civil date (Hinnant's days_from_civil).
int64_t DaysFromCivil(int64_t year, unsigned month, unsigned day);

}  // namespace seasense::scene
