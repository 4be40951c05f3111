// An ordered queue of file-writing jobs run on one background thread, bounded, errors kept.
#include "sensors/output/write_queue.h"

#include <utility>

#include "scene/core/check.h"

namespace seasense::sensors {

WriteQueue::WriteQueue(size_t capacity) : capacity_(capacity) {
    CHECK(capacity > 0);
    thread_ = std::thread([this] { Loop(); });
}

WriteQueue::~WriteQueue() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
}

void WriteQueue::RethrowLocked(std::unique_lock<std::mutex>& lock) {
    if (!error_) return;
    std::exception_ptr error = std::exchange(error_, nullptr);
    lock.unlock();
    std::rethrow_exception(error);
}

void WriteQueue::Push(std::function<void()> job) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.size() < capacity_ || error_; });
    RethrowLocked(lock);
    jobs_.push_back(std::move(job));
    lock.unlock();
    changed_.notify_all();
}

void WriteQueue::Finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return (jobs_.empty() && !running_) || error_; });
    RethrowLocked(lock);
}

void WriteQueue::Loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        // On stop the jobs still queued are run first: their frames were rendered and their
        // files are due complete.
        changed_.wait(lock, [&] { return !jobs_.empty() || stop_; });
        if (jobs_.empty()) return;
        std::function<void()> job = std::move(jobs_.front());
        jobs_.pop_front();
        running_ = true;
        lock.unlock();
        std::exception_ptr error;
        try {
            job();
        } catch (...) {
            error = std::current_exception();
        }
        job = nullptr;  // the job's copied images are freed outside the lock
        lock.lock();
        running_ = false;
        if (error) {
            error_ = error;
            jobs_.clear();
        }
        changed_.notify_all();
    }
}

}  // namespace seasense::sensors
