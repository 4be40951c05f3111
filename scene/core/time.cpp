// ISO-8601 UTC parsing and formatting with integer civil-date arithmetic.
#include "scene/core/time.h"

#include <cmath>
#include <cstdio>

namespace seasense::scene {

// Howard Hinnant, "chrono-Compatible Low-Level Date Algorithms" (2013), days_from_civil.
int64_t DaysFromCivil(int64_t y, unsigned m, unsigned d) {
    y -= m <= 2;
    const int64_t era = (y >= 0 ? y : y - 399) / 400;
    const unsigned yoe = unsigned(y - era * 400);
    const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
    const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + int64_t(doe) - 719468;
}

namespace {

// Inverse of DaysFromCivil (Hinnant, civil_from_days).
void CivilFromDays(int64_t z, int64_t& y, unsigned& m, unsigned& d) {
    z += 719468;
    const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
    const unsigned doe = unsigned(z - era * 146097);
    const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    y = int64_t(yoe) + era * 400;
    const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const unsigned mp = (5 * doy + 2) / 153;
    d = doy - (153 * mp + 2) / 5 + 1;
    m = mp < 10 ? mp + 3 : mp - 9;
    y += m <= 2;
}

bool IsLeap(int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

unsigned DaysInMonth(int64_t y, unsigned m) {
    static constexpr unsigned kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return m == 2 && IsLeap(y) ? 29 : kDays[m - 1];
}

// Reads exactly n decimal digits at pos.
bool Digits(std::string_view s, size_t& pos, int n, int& value) {
    if (pos + size_t(n) > s.size()) return false;
    value = 0;
    for (int i = 0; i < n; ++i) {
        char c = s[pos + size_t(i)];
        if (c < '0' || c > '9') return false;
        value = value * 10 + (c - '0');
    }
    pos += size_t(n);
    return true;
}

bool Expect(std::string_view s, size_t& pos, char c) {
    if (pos < s.size() && s[pos] == c) {
        ++pos;
        return true;
    }
    return false;
}

}  // namespace

UtcTime UtcTime::PlusSeconds(double seconds) const {
    return UtcTime{unixNs + int64_t(std::llround(seconds * 1e9))};
}

std::optional<UtcTime> ParseIso8601(std::string_view s) {
    size_t pos = 0;
    int year, month, day, hour, minute, second = 0;
    if (!Digits(s, pos, 4, year) || !Expect(s, pos, '-') || !Digits(s, pos, 2, month) ||
        !Expect(s, pos, '-') || !Digits(s, pos, 2, day))
        return std::nullopt;
    if (!(Expect(s, pos, 'T') || Expect(s, pos, 't') || Expect(s, pos, ' '))) return std::nullopt;
    if (!Digits(s, pos, 2, hour) || !Expect(s, pos, ':') || !Digits(s, pos, 2, minute))
        return std::nullopt;
    int64_t fractionNs = 0;
    if (Expect(s, pos, ':')) {
        if (!Digits(s, pos, 2, second)) return std::nullopt;
        if (Expect(s, pos, '.') || Expect(s, pos, ',')) {
            int64_t scale = 100000000;
            size_t start = pos;
            while (pos < s.size() && s[pos] >= '0' && s[pos] <= '9') {
                fractionNs += (s[pos] - '0') * scale;
                scale /= 10;
                ++pos;
            }
            if (pos == start) return std::nullopt;
        }
    }
    int offsetMinutes = 0;
    if (pos < s.size()) {
        if (s[pos] == 'Z' || s[pos] == 'z') {
            ++pos;
        } else if (s[pos] == '+' || s[pos] == '-') {
            int sign = s[pos] == '-' ? -1 : 1;
            ++pos;
            int oh, om = 0;
            if (!Digits(s, pos, 2, oh)) return std::nullopt;
            if (Expect(s, pos, ':')) {
                if (!Digits(s, pos, 2, om)) return std::nullopt;
            } else if (pos < s.size() && !Digits(s, pos, 2, om)) {
                return std::nullopt;
            }
            if (oh > 23 || om > 59) return std::nullopt;
            offsetMinutes = sign * (oh * 60 + om);
        }
    }
    if (pos != s.size()) return std::nullopt;
    if (month < 1 || month > 12 || day < 1 || unsigned(day) > DaysInMonth(year, unsigned(month)) ||
        hour > 23 || minute > 59 || second > 60)
        return std::nullopt;
    int64_t days = DaysFromCivil(year, unsigned(month), unsigned(day));
    int64_t secs = days * 86400 + hour * 3600 + minute * 60 + second - offsetMinutes * 60;
    return UtcTime{secs * 1000000000LL + fractionNs};
}

std::string FormatIso8601(UtcTime t) {
    int64_t ns = t.unixNs;
    int64_t days =
        ns >= 0 ? ns / 86400000000000LL : -((-ns + 86400000000000LL - 1) / 86400000000000LL);
    int64_t rem = ns - days * 86400000000000LL;
    int64_t y;
    unsigned m, d;
    CivilFromDays(days, y, m, d);
    int64_t secOfDay = rem / 1000000000LL;
    int64_t ms = (rem % 1000000000LL) / 1000000LL;
    char buf[80];
    std::snprintf(buf, sizeof buf, "%04lld-%02u-%02uT%02lld:%02lld:%02lld.%03lldZ", (long long)y, m,
                  d, (long long)(secOfDay / 3600), (long long)(secOfDay / 60 % 60),
                  (long long)(secOfDay % 60), (long long)ms);
    return buf;
}

}  // namespace seasense::scene
