// Runs a shell command for end-to-end CLI tests and captures its exit status and output.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace seasense::testing {

struct ShellResult {
    int status = -1;  // exit status, or 128 + signal
    std::string output;
};

// Runs command with /bin/sh; stderr is merged into output unless mergeStderr is false.
inline ShellResult Shell(const std::string& command, bool mergeStderr = true) {
    ShellResult r;
    FILE* p = popen((command + (mergeStderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    const int s = pclose(p);
    r.status = WIFEXITED(s) ? WEXITSTATUS(s) : 128 + WTERMSIG(s);
    return r;
}

}  // namespace seasense::testing
