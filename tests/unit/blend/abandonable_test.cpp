// blend/Abandonable.h: work that takes no interrupter, run so that a stop request is answered at
// once, and counted while it runs on abandoned (the CLI must not run static destructors under it).
#include "blend/Abandonable.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

namespace {

using namespace std::chrono_literals;
using volmorph::Interrupter;

/// Polls `done` for up to 20 s (the test machine may be busy); whether it came true.
template <typename Done>
bool eventually(Done done)
{
    for (int i = 0; i < 2000 && !done(); ++i) std::this_thread::sleep_for(10ms);
    return done();
}

} // namespace

TEST(Abandonable, ReturnsTheWorksResultAndRethrowsItsError)
{
    Interrupter interrupter;
    EXPECT_EQ(volmorph::detail::abandonable([](Interrupter&) { return 42; }, &interrupter), 42);
    EXPECT_THROW(volmorph::detail::abandonable(
                     [](Interrupter&) -> int { throw std::runtime_error("the work's own error"); },
                     &interrupter),
                 std::runtime_error);
    EXPECT_EQ(volmorph::abandonedWorkRunning(), 0);
}

TEST(Abandonable, AStopRequestAbandonsTheWorkWhichIsCountedUntilItEnds)
{
    Interrupter interrupter;
    auto release = std::make_shared<std::atomic<bool>>(false);
    auto freed = std::make_shared<std::atomic<bool>>(false);
    // What the work owns: freed by its own thread once it is done.
    struct Owned {
        std::shared_ptr<std::atomic<bool>> freed;
        ~Owned() { *freed = true; }
    };
    auto owned = std::make_shared<Owned>();
    owned->freed = freed;
    std::thread stopper([&] {
        std::this_thread::sleep_for(50ms);
        interrupter.requestStop();
    });
    EXPECT_THROW(volmorph::detail::abandonable(
                     [release, owned = std::move(owned)](Interrupter&) {
                         // Work that cannot stop: it ignores its own interrupter.
                         while (!*release) std::this_thread::sleep_for(1ms);
                         return 1;
                     },
                     &interrupter),
                 volmorph::Interrupted);
    stopper.join();
    // Abandoned and still running: counted, and what it owns still alive.
    EXPECT_EQ(volmorph::abandonedWorkRunning(), 1);
    EXPECT_FALSE(*freed);
    *release = true;
    EXPECT_TRUE(eventually([] { return volmorph::abandonedWorkRunning() == 0; }));
    EXPECT_TRUE(*freed);
}

// The abandoned work's own interrupter asks it to stop, so that work that can stop (volmorph's own
// loops inside it) ends early: this work would run forever otherwise.
TEST(Abandonable, AbandonedWorkIsAskedToStop)
{
    Interrupter interrupter;
    interrupter.requestStop();
    auto asked = std::make_shared<std::atomic<bool>>(false);
    EXPECT_THROW(volmorph::detail::abandonable(
                     [asked](Interrupter& stop) {
                         while (!stop.wasInterrupted()) std::this_thread::sleep_for(1ms);
                         *asked = true;
                         throw volmorph::Interrupted();
                         return 1;
                     },
                     &interrupter),
                 volmorph::Interrupted);
    EXPECT_TRUE(eventually([] { return volmorph::abandonedWorkRunning() == 0; }));
    EXPECT_TRUE(*asked);
    // Not abandoned, the work's interrupter never asks.
    Interrupter running;
    EXPECT_FALSE(volmorph::detail::abandonable(
        [](Interrupter& stop) { return stop.wasInterrupted(); }, &running));
    EXPECT_FALSE(volmorph::detail::abandonable(
        [](Interrupter& stop) { return stop.wasInterrupted(); }, nullptr));
}
