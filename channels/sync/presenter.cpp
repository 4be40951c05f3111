// A renderer's presenter thread (see presenter.h).
#include "channels/sync/presenter.h"

namespace seasense::channels::sync {

Presenter::Presenter(PresentFn present)
    : present_(std::move(present)), thread_([this] { Loop(); }) {}

Presenter::~Presenter() { Close(); }

void Presenter::Push(PresentItem item) {
    {
        std::lock_guard<std::mutex> guard(mutex_);
        queue_.push_back(std::move(item));
    }
    cv_.notify_one();
}

void Presenter::PresentOrPush(PresentItem item, const std::function<bool()>& ready) {
    {
        std::lock_guard<std::mutex> guard(mutex_);
        if (queue_.empty() && !busy_ && !exit_ && ready()) {
            exit_ = present_(item);
            return;
        }
    }
    Push(std::move(item));
}

std::optional<int> Presenter::Ended() {
    std::lock_guard<std::mutex> guard(mutex_);
    return exit_;
}

int Presenter::Finish(int status) {
    if (status == 0) {
        std::unique_lock<std::mutex> guard(mutex_);
        drained_.wait(guard, [&] { return (queue_.empty() && !busy_) || exit_; });
    }
    Close();
    std::lock_guard<std::mutex> guard(mutex_);
    return exit_ && status == 0 ? *exit_ : status;
}

void Presenter::Close() {
    {
        std::lock_guard<std::mutex> guard(mutex_);
        closing_ = true;
    }
    cv_.notify_one();
    if (thread_.joinable()) thread_.join();
}

void Presenter::Loop() {
    for (;;) {
        PresentItem item;
        {
            std::unique_lock<std::mutex> guard(mutex_);
            cv_.wait(guard, [&] { return closing_ || !queue_.empty() || exit_; });
            // After an ending status nothing more is presented; when closing, what is queued
            // is still presented (its waits end at once if the run is over).
            if (exit_ || queue_.empty()) return;
            item = std::move(queue_.front());
            queue_.pop_front();
            busy_ = true;
        }
        const std::optional<int> e = present_(item);
        std::lock_guard<std::mutex> guard(mutex_);
        busy_ = false;
        if (e) exit_ = e;
        drained_.notify_all();
    }
}

}  // namespace seasense::channels::sync
