// Progress reporting on stderr: a redrawn bar on a terminal, plain lines otherwise.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace seasense::channels {

class Progress {
  public:
    // total: number of steps; label: what is counted ("frames").
    Progress(int64_t total, std::string label);
    ~Progress();
    // Reports that `done` steps are complete.
    void Update(int64_t done);
    void Finish();

  private:
    int64_t total_;
    std::string label_;
    bool tty_;
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace seasense::channels
