// Replay's frame checks on their own thread (replay_worker.h).
#include <algorithm>
#include <chrono>
#include <exception>
#include <utility>

#include <pthread.h>

#include <platform/cli/replay_worker.h>

namespace replica::platform {

FrameWorker::FrameWorker(Check check, std::size_t depth)
    : check_(std::move(check)), depth_(std::max<std::size_t>(depth, 1)), thread_([this] { loop(); })
{}

FrameWorker::~FrameWorker()
{
    drain();
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
}

void FrameWorker::push(const recordings::FrameRecord& frame, pipeline::render::RenderedFrame& image)
{
    std::unique_lock lock(mutex_);
    if (queue_.size() >= depth_) {
        const auto start = std::chrono::steady_clock::now();
        changed_.wait(lock, [this] { return queue_.size() < depth_; });
        waitedS_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    Item item{frame, {}};
    if (!spare_.empty()) {
        item.image = std::move(spare_.back());
        spare_.pop_back();
    }
    std::swap(item.image.xyz, image.xyz);
    std::swap(item.image.rgba, image.rgba);
    item.image.width = image.width;
    item.image.height = image.height;
    item.image.gamut = image.gamut;
    item.image.displayFramebuffer = image.displayFramebuffer;
    queue_.push_back(std::move(item));
    lock.unlock();
    changed_.notify_all();
}

void FrameWorker::drain()
{
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

void FrameWorker::finish()
{
    drain();
    if (failure_) {
        std::rethrow_exception(std::exchange(failure_, nullptr));
    }
}

void FrameWorker::loop()
{
    pthread_setname_np(pthread_self(), "replay-checks"); // as top and perf name it
    std::unique_lock lock(mutex_);
    for (;;) {
        changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
        if (queue_.empty()) {
            return; // stopping, and every frame checked
        }
        Item item = std::move(queue_.front());
        queue_.pop_front();
        busy_ = true;
        lock.unlock();
        changed_.notify_all(); // room for the next frame while this one is checked
        if (!failure_) {
            try {
                check_(item.frame, item.image);
            } catch (...) {
                failure_ = std::current_exception(); // finish() throws it on the caller's thread
            }
        }
        lock.lock();
        busy_ = false;
        spare_.push_back(std::move(item.image));
        changed_.notify_all();
    }
}

} // namespace replica::platform
