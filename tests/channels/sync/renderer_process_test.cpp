// Renderer processes: the environment a run gives its renderers (huge pages for glibc's malloc,
// the user's own tunables kept), and that a spawned process really gets it.
#include "channels/sync/renderer_process.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace seasense::channels::sync {
namespace {

std::vector<std::string> Env(std::vector<const char*> entries) {
    entries.push_back(nullptr);
    return RendererEnvironment(entries.data());
}

TEST(RendererEnvironment, AddsHugePagesToTheTunablesAndKeepsEverythingElse) {
    // No tunables: one entry added after the others, which keep their order.
    EXPECT_EQ(
        Env({"A=1", "PATH=/bin"}),
        (std::vector<std::string>{"A=1", "PATH=/bin", "GLIBC_TUNABLES=glibc.malloc.hugetlb=1"}));
    // Other tunables: appended to them (colon-separated).
    EXPECT_EQ(Env({"GLIBC_TUNABLES=glibc.malloc.arena_max=2", "B=2"}),
              (std::vector<std::string>{
                  "GLIBC_TUNABLES=glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1", "B=2"}));
    EXPECT_EQ(Env({"GLIBC_TUNABLES="}),
              (std::vector<std::string>{"GLIBC_TUNABLES=glibc.malloc.hugetlb=1"}));
    // The user's own hugetlb setting stands, wherever it is in the list.
    EXPECT_EQ(Env({"GLIBC_TUNABLES=glibc.malloc.hugetlb=0"}),
              (std::vector<std::string>{"GLIBC_TUNABLES=glibc.malloc.hugetlb=0"}));
    EXPECT_EQ(Env({"GLIBC_TUNABLES=glibc.malloc.arena_max=2:glibc.malloc.hugetlb=2"}),
              (std::vector<std::string>{
                  "GLIBC_TUNABLES=glibc.malloc.arena_max=2:glibc.malloc.hugetlb=2"}));
    // A tunable whose name only begins like it is another tunable; a variable whose name ends
    // like GLIBC_TUNABLES is another variable.
    EXPECT_EQ(
        Env({"GLIBC_TUNABLES=glibc.malloc.hugetlbx=1", "MY_GLIBC_TUNABLES=x"}),
        (std::vector<std::string>{"GLIBC_TUNABLES=glibc.malloc.hugetlbx=1:glibc.malloc.hugetlb=1",
                                  "MY_GLIBC_TUNABLES=x"}));
    EXPECT_EQ(Env({}), (std::vector<std::string>{"GLIBC_TUNABLES=glibc.malloc.hugetlb=1"}));
}

TEST(RendererEnvironment, SpawnedProcessSeesTheEnvironmentItIsGiven) {
    const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                      ("seasense_env_" + std::to_string(::getpid()) + ".txt");
    std::filesystem::remove(out);
    const char* parent[] = {"SEASENSE_ENV_TEST=kept", nullptr};
    const pid_t pid = SpawnProcess(
        {"/bin/sh", "-c",
         "printf '%s|%s' \"$SEASENSE_ENV_TEST\" \"$GLIBC_TUNABLES\" > " + out.string()},
        RendererEnvironment(parent));
    std::optional<ProcessExit> exit;
    for (int i = 0; i < 2000 && !exit; ++i) {
        exit = PollProcess(pid);
        if (!exit) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(exit.has_value());
    EXPECT_FALSE(exit->signaled);
    EXPECT_EQ(exit->code, 0);
    std::ifstream in(out);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "kept|glibc.malloc.hugetlb=1");
    std::filesystem::remove(out);
}

}  // namespace
}  // namespace seasense::channels::sync
