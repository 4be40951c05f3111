// A renderer's presenter: frames wait at the frame-lock barrier and are presented, in order, on
// a thread of their own while the render thread goes on with the next frame.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "channels/sync/shm_segment.h"

namespace seasense::channels::sync {

// A rendered frame waiting to be presented: its index, timing and display image.
struct PresentItem {
    uint32_t index = 0;
    FrameTiming timing;
    std::vector<uint8_t> rgb;
};

// Presents items in the order pushed. The present function waits at the barrier and presents;
// it returns an exit status when the wait ends the run (stop, host gone, signal, timeout),
// after which no further item is presented.
class Presenter {
  public:
    using PresentFn = std::function<std::optional<int>(PresentItem&)>;
    explicit Presenter(PresentFn present);
    ~Presenter();
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    // Queues item for the presenter thread.
    void Push(PresentItem item);
    // Presents item on the calling thread when nothing is queued or being presented before it
    // and ready() holds (its barrier is already complete: this channel finished last), else
    // queues it. Waking the presenter thread costs a scheduler wake-up on a machine whose cores
    // the renderers keep busy (tens of milliseconds of skew, measured).
    void PresentOrPush(PresentItem item, const std::function<bool()>& ready);
    // The exit status once the present function has ended the run.
    std::optional<int> Ended();
    // With status 0, waits until every queued item is presented or the run ends; then stops
    // the thread. Returns the present function's status if it ended the run and status is 0,
    // else status.
    int Finish(int status);

  private:
    void Close();
    void Loop();

    PresentFn present_;
    std::mutex mutex_;
    std::condition_variable cv_, drained_;
    std::deque<PresentItem> queue_;
    bool closing_ = false, busy_ = false;
    std::optional<int> exit_;
    std::thread thread_;  // last: starts after every member above is constructed
};

}  // namespace seasense::channels::sync
