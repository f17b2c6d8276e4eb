#pragma once

#include <cstdint>

namespace sg {

/// Wall-clock time in microseconds since the Unix epoch, the unit of every message's `utime`.
///
/// Only a process's main loop may call this (DESIGN rule 1): algorithms take time from the
/// messages they are given, so a replayed log gives the same outputs.
int64_t now_utime();

}  // namespace sg
