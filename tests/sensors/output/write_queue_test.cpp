// WriteQueue: jobs run in order on one other thread, Push waits while full, a failure stops the
// queue and is reported once, destruction runs what is queued. Also built with ThreadSanitizer.
#include "sensors/output/write_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <stdexcept>
#include <thread>
#include <vector>

namespace seasense::sensors {
namespace {

TEST(WriteQueue, RunsJobsInPushOrderOnAnotherThread) {
    std::vector<int> order;  // touched by the queue's thread only, read after Finish
    std::vector<std::thread::id> threads;
    WriteQueue queue(3);
    for (int i = 0; i < 1000; ++i)
        queue.Push([&, i] {
            order.push_back(i);
            threads.push_back(std::this_thread::get_id());
        });
    queue.Finish();
    ASSERT_EQ(order.size(), 1000u);
    for (int i = 0; i < 1000; ++i) EXPECT_EQ(order[size_t(i)], i);
    for (const std::thread::id id : threads) {
        EXPECT_NE(id, std::this_thread::get_id());
        EXPECT_EQ(id, threads.front());
    }
}

TEST(WriteQueue, PushWaitsWhileCapacityJobsAreQueued) {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::atomic<int> ran{0};
    WriteQueue queue(2);
    queue.Push([&] {
        released.wait();
        ++ran;
    });
    // The first job is taken off the queue (or about to be); give it the time to start.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    queue.Push([&] { ++ran; });
    queue.Push([&] { ++ran; });  // two queued: full
    std::atomic<bool> fourthQueued{false};
    std::thread pusher([&] {
        queue.Push([&] { ++ran; });
        fourthQueued = true;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_FALSE(fourthQueued.load());  // still waiting for room
    EXPECT_EQ(ran.load(), 0);
    release.set_value();
    pusher.join();
    EXPECT_TRUE(fourthQueued.load());
    queue.Finish();
    EXPECT_EQ(ran.load(), 4);
}

TEST(WriteQueue, AFailureDropsTheQueuedJobsAndIsReportedOnce) {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::atomic<bool> laterRan{false};
    WriteQueue queue(4);
    queue.Push([&] {
        released.wait();
        throw std::runtime_error("disk full");
    });
    queue.Push([&] { laterRan = true; });
    queue.Push([&] { laterRan = true; });
    release.set_value();
    try {
        queue.Finish();
        FAIL() << "expected the job's exception";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "disk full");
    }
    EXPECT_NO_THROW(queue.Finish());  // reported once; waits for anything still running
    EXPECT_FALSE(laterRan.load());
    // The queue takes jobs again afterwards.
    std::atomic<bool> ranAfter{false};
    queue.Push([&] { ranAfter = true; });
    queue.Finish();
    EXPECT_TRUE(ranAfter.load());
}

TEST(WriteQueue, PushRethrowsAnEarlierFailureAndDoesNotQueue) {
    std::atomic<bool> ran{false};
    WriteQueue queue(4);
    queue.Push([] { throw std::runtime_error("no space"); });
    // Wait for the failure to be recorded without Finish (which would report it).
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_THROW(queue.Push([&] { ran = true; }), std::runtime_error);
    queue.Finish();
    EXPECT_FALSE(ran.load());
}

TEST(WriteQueue, DestructionRunsTheJobsStillQueued) {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    std::atomic<int> ran{0};
    std::thread releaser;
    {
        WriteQueue queue(8);
        queue.Push([&] {
            released.wait();
            ++ran;
        });
        for (int i = 0; i < 5; ++i) queue.Push([&] { ++ran; });
        releaser = std::thread([&] {
            std::this_thread::sleep_for(std::chrono::milliseconds(30));
            release.set_value();
        });
    }  // destroyed while the jobs wait behind the first
    releaser.join();
    EXPECT_EQ(ran.load(), 6);
}

}  // namespace
}  // namespace seasense::sensors
