// Progress bar with rate on stderr; plain one-line-per-step output when stderr is a file or pipe.
#include "channels/cli/progress.h"

#include <unistd.h>

#include <cstdio>

namespace seasense::channels {

Progress::Progress(int64_t total, std::string label)
    : total_(total),
      label_(std::move(label)),
      tty_(isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() {
    if (tty_ && !finished_) std::fputc('\n', stderr);
}

void Progress::Update(int64_t done) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = seconds > 0.0 ? double(done) / seconds : 0.0;
    if (tty_) {
        constexpr int kWidth = 30;
        const int filled = total_ > 0 ? int(kWidth * done / total_) : kWidth;
        std::string bar(size_t(filled), '#');
        bar.resize(kWidth, ' ');
        std::fprintf(stderr, "\r[%s] %lld/%lld %s  %.2f %s/s", bar.c_str(), (long long)done,
                     (long long)total_, label_.c_str(), rate, label_.c_str());
    } else {
        std::fprintf(stderr, "%s %lld/%lld (%.2f/s)\n", label_.c_str(), (long long)done,
                     (long long)total_, rate);
    }
    std::fflush(stderr);
}

void Progress::Finish() {
    if (tty_ && !finished_) std::fputc('\n', stderr);
    finished_ = true;
}

}  // namespace seasense::channels
