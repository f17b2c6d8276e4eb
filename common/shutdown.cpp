#include "common/shutdown.hpp"

#include <atomic>
#include <csignal>

namespace sg {
namespace {

// Lock-free atomics are async-signal-safe; static_assert keeps it that way.
std::atomic<bool> g_shutdown{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void on_signal(int /*signum*/) { g_shutdown.store(true); }

}  // namespace

void install_shutdown_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking wait returns with EINTR
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool shutdown_requested() { return g_shutdown.load(); }
void request_shutdown() { g_shutdown.store(true); }
void reset_shutdown() { g_shutdown.store(false); }

}  // namespace sg
