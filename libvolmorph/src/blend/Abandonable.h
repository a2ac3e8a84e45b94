// Work that cannot be interrupted throughout (an OpenVDB tool without an interrupter, Eigen's dense
// LU) run so that a stop request is still answered at once: the work runs on a thread of its own,
// owning everything it reads (capture by value or shared_ptr, never a reference or the caller's
// interrupter), and the caller polls its interrupter meanwhile. Asked to stop, the caller throws
// Interrupted and abandons the work. The work is handed an interrupter of its own, which asks it to
// stop once it is abandoned: the parts of it that can stop (volmorph's own loops) end it early; the
// rest finishes alone. Its thread frees it, counted meanwhile by abandonedWorkRunning() (a program
// that exits before it is done must skip static destructors). This is the one way such work stops.
#pragma once

#include <volmorph/core/Interrupter.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace volmorph::detail {

/// work(stop) (which must own what it reads), returned; Interrupted as soon as `interrupter` asks
/// to stop (polled every 10 ms), and then `stop` asks the abandoned work to stop; work's own
/// exception rethrown. Without an interrupter, work(stop) here, with a `stop` that never asks.
template <typename Work>
auto abandonable(Work work, Interrupter* interrupter)
    -> decltype(work(std::declval<Interrupter&>()))
{
    using Result = decltype(work(std::declval<Interrupter&>()));
    if (!interrupter) {
        Interrupter never;
        return work(never);
    }
    struct Shared {
        Interrupter stop; ///< the work's own: asks it to stop once it is abandoned
        std::mutex mutex;
        std::condition_variable done;
        std::optional<Result> result;
        std::exception_ptr error;
        bool finished = false, abandoned = false;
    };
    auto shared = std::make_shared<Shared>();
    std::thread([shared, work = std::move(work)]() mutable {
        bool abandoned = false;
        {
            Work job = std::move(work); // what the work owns is freed at the end of this scope
            std::optional<Result> result;
            std::exception_ptr error;
            try {
                result.emplace(job(shared->stop));
            } catch (...) {
                error = std::current_exception();
            }
            std::lock_guard<std::mutex> lock(shared->mutex);
            abandoned = shared->abandoned;
            if (!abandoned) {
                shared->result = std::move(result);
                shared->error = error;
                shared->finished = true;
                shared->done.notify_all();
            }
        }
        shared.reset();
        if (abandoned) countAbandonedWork(-1); // the last thing this thread does with it
    }).detach();
    std::unique_lock<std::mutex> lock(shared->mutex);
    while (!shared->done.wait_for(lock, std::chrono::milliseconds(10),
                                  [&] { return shared->finished; }))
        if (interrupter->wasInterrupted()) {
            shared->abandoned = true;
            shared->stop.requestStop();
            countAbandonedWork(+1);
            throw Interrupted();
        }
    if (shared->error) std::rethrow_exception(shared->error);
    return std::move(*shared->result);
}

} // namespace volmorph::detail
