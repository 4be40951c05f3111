// An ordered queue of file-writing jobs run on one background thread, bounded, errors kept.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace seasense::sensors {

// Runs jobs one at a time, in the order pushed, on a thread of its own, so that a renderer
// goes on with its next frame while the last frame's files are encoded, synced and renamed.
// At most `capacity` jobs wait: Push blocks while the queue is full, which bounds the memory
// held by copied images. A job that throws stops the queue: the jobs still waiting are
// dropped (their files are never written) and the exception is rethrown, once, by the next
// Push or Finish on the pushing thread.
class WriteQueue {
  public:
    explicit WriteQueue(size_t capacity);
    // Runs the jobs still queued (their files complete), then joins the thread. An error not
    // yet reported by Push or Finish is lost: call Finish first when it matters.
    ~WriteQueue();
    WriteQueue(const WriteQueue&) = delete;
    WriteQueue& operator=(const WriteQueue&) = delete;

    // Queues job; waits while `capacity` jobs are queued. Rethrows an earlier job's failure
    // (and then does not queue job).
    void Push(std::function<void()> job);
    // Waits until every queued job has run; rethrows the first failure not yet reported.
    void Finish();

  private:
    void Loop();
    void RethrowLocked(std::unique_lock<std::mutex>& lock);

    const size_t capacity_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::function<void()>> jobs_;
    bool running_ = false;  // a job is being run (taken off jobs_)
    bool stop_ = false;
    std::exception_ptr error_;
    std::thread thread_;
};

}  // namespace seasense::sensors
