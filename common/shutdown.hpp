#pragma once

namespace sg {

/// Installs SIGINT and SIGTERM handlers that only raise a flag, so a main loop can finish its
/// current message, close files and exit cleanly. Calling it twice is harmless.
///
///     sg::install_shutdown_handlers();
///     while (!sg::shutdown_requested()) bus.handle(100ms);
void install_shutdown_handlers();

/// True once SIGINT or SIGTERM has arrived (or request_shutdown() was called).
bool shutdown_requested();

/// Raises the flag from inside the program (tests, or a loop that has finished its work).
void request_shutdown();

/// Lowers the flag again (tests only).
void reset_shutdown();

}  // namespace sg
