// Replay's checks of each frame (its digests, the recorded display digest, the thumbnail
// comparison, the frames it writes) on a thread of their own, so that they overlap the drawing of
// the next frames instead of adding to them. One thread takes the frames in the order they were
// drawn: the digests file and every check come out as they did on the frame thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <pipeline/render/renderer.h>
#include <recordings/recording.h>

namespace replica::platform {

class FrameWorker
{
public:
    using Check = std::function<void(const recordings::FrameRecord& frame,
                                     const pipeline::render::RenderedFrame& image)>;
    // 'check' runs on the worker thread, one frame at a time, in the order push() was called.
    // At most 'depth' frames wait for it; push() blocks while that many do.
    explicit FrameWorker(Check check, std::size_t depth = 2);
    ~FrameWorker();
    FrameWorker(const FrameWorker&) = delete;
    FrameWorker& operator=(const FrameWorker&) = delete;

    // Takes the frame for the check: its buffers are swapped for spare ones that the check is done
    // with (of the same size once the first frames have passed, so the renderer's read-back into
    // them allocates nothing), not copied.
    void push(const recordings::FrameRecord& frame, pipeline::render::RenderedFrame& image);
    // Waits until every pushed frame has been checked; the checks' results are then the caller's
    // to read. A check that threw: the frames after it went unchecked, and finish() throws what
    // it threw. The destructor waits too (without throwing).
    void finish();
    // How long push() waited for the worker, in all (seconds): the checks' share of the wall time
    // that did not overlap the drawing.
    double waitedS() const { return waitedS_; }

private:
    struct Item {
        recordings::FrameRecord frame;
        pipeline::render::RenderedFrame image;
    };
    void loop();
    void drain();

    Check check_;
    std::size_t depth_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Item> queue_;
    std::vector<pipeline::render::RenderedFrame> spare_;
    bool busy_ = false;
    bool stopping_ = false;
    std::exception_ptr failure_; // written by the worker while busy_, read once it is idle
    double waitedS_ = 0.0;
    std::thread thread_; // last: started once the members above exist
};

} // namespace replica::platform
