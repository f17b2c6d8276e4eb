#pragma once

// Whether this build runs under a sanitizer (scripts/test.sh --sanitize), for the few figures a
// sanitizer's own bookkeeping changes, such as a process's memory:
//
//     const int64_t bound = kMaxGrowth + kAddressSanitizerQuarantine;

#include <cstdint>

namespace sg::test {

#if defined(__SANITIZE_ADDRESS__)  // GCC
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)  // clang
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

/// The memory AddressSanitizer may hold in a process beyond what the program holds: freed blocks
/// wait in its quarantine (to catch a use after free) up to `quarantine_size_mb`, 256 MB by
/// default on 64-bit Linux, and the resident set counts them. 0 without ASan.
inline constexpr int64_t kAddressSanitizerQuarantine = kAddressSanitizer ? (256LL << 20) : 0;

}  // namespace sg::test
