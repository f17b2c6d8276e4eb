#pragma once

// Waiting on conditions with a deadline, instead of fixed sleeps: a test waits for what it needs
// (a message arrived, a file exists, a process joined the bus) and goes on as soon as it holds,
// and a slow machine only makes it wait longer, up to a generous deadline.
//
//     ASSERT_TRUE(eventually([&] { return fs::exists(device); }, 10s, "the simulator's device"));
//     ASSERT_TRUE(eventually(bus, [&] { return got >= 30; }, 60s, "30 OBJECT_POSITION"));

#include <gtest/gtest.h>
#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>

namespace sg {
class Bus;
}

namespace sg::test {

/// Checks `condition` every `poll` until it holds or `deadline` has passed since the call, and
/// once more at the deadline (never waiting past it); returns whether it held. The first check is
/// immediate.
bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds deadline,
                std::chrono::milliseconds poll = std::chrono::milliseconds(10));

/// wait_until() that handles `bus`'s messages while it waits (bus.handle(poll) between checks, so
/// the condition is checked after every message): for conditions on what has arrived.
bool wait_until(Bus& bus, const std::function<bool()>& condition,
                std::chrono::milliseconds deadline,
                std::chrono::milliseconds poll = std::chrono::milliseconds(20));

/// wait_until() for gtest assertions; on time-out the failure reads
/// "timed out after <deadline> ms waiting for <what>".
::testing::AssertionResult eventually(
    const std::function<bool()>& condition, std::chrono::milliseconds deadline,
    const std::string& what, std::chrono::milliseconds poll = std::chrono::milliseconds(10));

/// eventually() that handles `bus`'s messages while it waits, as wait_until(bus, ...) does.
::testing::AssertionResult eventually(
    Bus& bus, const std::function<bool()>& condition, std::chrono::milliseconds deadline,
    const std::string& what, std::chrono::milliseconds poll = std::chrono::milliseconds(20));

/// Handles `bus`'s messages for `duration` (a window in which a test watches what arrives).
void handle_for(Bus& bus, std::chrono::milliseconds duration);

/// True when process `pid` has joined the udpm bus on `port`, as LCM does at its first subscribe:
/// it binds a receive socket to the port and joins the group on it, and then publishes a self-test
/// message, which binds its send socket too. So: `pid` holds a UDP socket bound to `port` and
/// another bound one (for a process that published before it subscribed, only the first says
/// anything; the join is the system call after the bind).
bool joined_bus(pid_t pid, int port);

/// joined_bus() and then idle(): `pid` has joined the bus and has gone to sleep waiting for
/// messages, so its handlers are in place. LCM's lcm_subscribe() binds and joins (in the
/// provider) before it registers the handler, and udpm's receive thread drops a datagram on a
/// channel with no handler: a message sent the moment joined_bus() turns true can be lost. Use
/// this before sending a finite stream whose every message must arrive.
bool listening_on_bus(pid_t pid, int port);

/// True when process `pid` has taken every datagram that reached its socket on udpm port `port`
/// off that socket (its receive queue is empty): once this test has itself received the last
/// message sent, the other subscriber has read it too. Read, not yet handled: LCM passes it to the
/// handler through its own ring buffer, and lcm-logger then to its write thread. See
/// handled_bus().
bool drained_bus(pid_t pid, int port);

/// True when every thread of process `pid` sleeps (state S in /proc/PID/task/TID/stat: none
/// runnable, none in disk wait), seen twice 20 ms apart.
bool idle(pid_t pid);

/// True when every thread of process `pid` is stopped (state T: SIGSTOP takes effect some time
/// after kill() returns).
bool stopped(pid_t pid);

/// drained_bus() and idle(): `pid` has read what reached it and has handled it, nothing of it
/// waits in a queue between its threads. lcm-logger needs this before it is stopped: on SIGINT its
/// write thread exits at its next event and drops what is still queued for it (LCM 1.3.1's
/// lcm_logger.c, write_thread_exit_flag).
bool handled_bus(pid_t pid, int port);

}  // namespace sg::test
