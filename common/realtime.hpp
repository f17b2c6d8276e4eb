#pragma once

#include <string>

namespace sg {

/// Real-time scheduling for a latency-bound program (sg-vision's `vision.realtime_priority`):
/// SCHED_FIFO at `priority` (1-99) for the calling thread and every thread it creates after
/// (call it before sg::Bus, whose LCM receive thread then inherits it); mlockall, and malloc
/// neither trimming its heap nor mapping large blocks, so no page of the process is faulted in
/// or out while a frame waits (the RT-Linux wiki's recipe). Needs CAP_SYS_NICE and
/// CAP_IPC_LOCK (root, or `ulimit -r` / `ulimit -l` raised); without them it changes nothing
/// and says why. Linux's RT throttling (sched_rt_runtime_us, 95 % by default) still leaves
/// the other processes a share if a thread ever spins.
///
///     if (const std::string e = sg::enter_realtime(settings.realtime_priority); !e.empty())
///       spdlog::warn("{}", e);
///
/// Returns "" when both took effect, else one line saying what did not. priority 0: nothing.
std::string enter_realtime(int priority);

}  // namespace sg
