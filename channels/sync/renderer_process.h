// Child processes of a run: spawning renderers, reaping them without blocking, naming how
// they ended, and stopping them (SIGTERM, then SIGKILL after a grace period).
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace seasense::channels::sync {

struct ProcessExit {
    bool signaled = false;
    int code = 0;  // exit status, or the signal number when signaled
};

// "exited with status 3" / "killed by signal 9 (SIGKILL)".
std::string Describe(const ProcessExit& exit);

// Starts argv[0] with arguments argv (posix_spawn, safe in a threaded parent) in its own
// process group so that a terminal's Ctrl-C reaches only the host, which then stops the
// renderers itself. RuntimeError on failure.
// environment: the child's NAME=value entries (empty: the parent's own).
pid_t SpawnProcess(const std::vector<std::string>& argv,
                   const std::vector<std::string>& environment = {});

// A renderer's environment: env (NAME=value entries, null-terminated) with glibc's malloc
// asked to back its heap with transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1,
// glibc ≥ 2.35: madvise(MADV_HUGEPAGE) on the memory malloc takes from the kernel), added to
// any tunables already set unless those choose glibc.malloc.hugetlb themselves. A renderer's
// frame walks ~100 MB of heap (visibility buffer, images, meshes, lists) and on the 2-core
// machine its channels ran 3–5 % faster with it (README, Performance); the kernel honours it
// where transparent huge pages are enabled as "madvise" or "always", and it changes no result.
std::vector<std::string> RendererEnvironment(const char* const* env);

// Reaps pid if it has ended (waitpid WNOHANG); nullopt while it runs.
std::optional<ProcessExit> PollProcess(pid_t pid);

// Sends SIGTERM to each still running pid, waits up to grace_s for them to exit, then
// SIGKILLs and reaps the rest. Already reaped pids (≤ 0) are skipped.
void TerminateProcesses(const std::vector<pid_t>& pids, double grace_s);

// The path of the running executable (/proc/self/exe).
std::string SelfExecutable();

}  // namespace seasense::channels::sync
