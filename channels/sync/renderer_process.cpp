// Renderer processes: posix_spawn, non-blocking reaping, graceful-then-forced termination.
#include "channels/sync/renderer_process.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <thread>

#include "channels/sync/shm_segment.h"
#include "scene/core/error.h"

extern char** environ;

namespace seasense::channels::sync {

std::string Describe(const ProcessExit& e) {
    if (!e.signaled) return "exited with status " + std::to_string(e.code);
    const char* abbrev = ::sigabbrev_np(e.code);
    return "killed by signal " + std::to_string(e.code) +
           (abbrev ? std::string(" (SIG") + abbrev + ")" : std::string());
}

std::vector<std::string> RendererEnvironment(const char* const* env) {
    constexpr std::string_view kName = "GLIBC_TUNABLES=", kHugePages = "glibc.malloc.hugetlb=";
    std::vector<std::string> out;
    bool tunables = false;
    for (; env && *env; ++env) {
        std::string entry = *env;
        if (entry.starts_with(kName)) {
            tunables = true;
            // Tunables are colon-separated name=value pairs; the user's own choice stands.
            bool chosen = false;
            for (size_t at = kName.size(); at <= entry.size();) {
                const size_t end = std::min(entry.find(':', at), entry.size());
                const std::string_view item = std::string_view(entry).substr(at, end - at);
                chosen |= item.starts_with(kHugePages);
                at = end + 1;
            }
            if (!chosen)
                entry += (entry.size() > kName.size() ? ":" : "") + std::string(kHugePages) + "1";
        }
        out.push_back(std::move(entry));
    }
    if (!tunables) out.push_back(std::string(kName) + std::string(kHugePages) + "1");
    return out;
}

pid_t SpawnProcess(const std::vector<std::string>& argv,
                   const std::vector<std::string>& environment) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::vector<char*> envp;
    for (const std::string& e : environment) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    posix_spawnattr_t attr;
    ::posix_spawnattr_init(&attr);
    ::posix_spawnattr_setflags(
        &attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    ::posix_spawnattr_setpgroup(&attr, 0);
    sigset_t none, defaults;
    sigemptyset(&none);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigaddset(&defaults, SIGPIPE);
    ::posix_spawnattr_setsigmask(&attr, &none);
    ::posix_spawnattr_setsigdefault(&attr, &defaults);
    pid_t pid = 0;
    const int err = ::posix_spawn(&pid, args[0], nullptr, &attr, args.data(),
                                  environment.empty() ? environ : envp.data());
    ::posix_spawnattr_destroy(&attr);
    if (err != 0)
        throw RuntimeError("cannot start renderer " + argv[0] + ": " + std::strerror(err));
    return pid;
}

std::optional<ProcessExit> PollProcess(pid_t pid) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == 0) return std::nullopt;
    if (r < 0) return ProcessExit{false, -1};  // not our child any more (already reaped)
    if (WIFSIGNALED(status)) return ProcessExit{true, WTERMSIG(status)};
    return ProcessExit{false, WEXITSTATUS(status)};
}

void TerminateProcesses(const std::vector<pid_t>& pids, double grace_s) {
    std::vector<pid_t> running;
    for (pid_t p : pids)
        if (p > 0 && !PollProcess(p)) running.push_back(p);
    for (pid_t p : running) ::kill(p, SIGTERM);
    const int64_t deadline = MonotonicNs() + int64_t(grace_s * 1e9);
    while (!running.empty() && MonotonicNs() < deadline) {
        std::erase_if(running, [](pid_t p) { return PollProcess(p).has_value(); });
        if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    for (pid_t p : running) {
        ::kill(p, SIGKILL);
        int status = 0;
        ::waitpid(p, &status, 0);
    }
}

std::string SelfExecutable() { return std::filesystem::read_symlink("/proc/self/exe").string(); }

}  // namespace seasense::channels::sync
