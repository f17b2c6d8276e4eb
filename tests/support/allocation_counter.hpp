#pragma once

/// Counts every allocation of the test program that links it: replaces the global operator new
/// (and its deletes) with a counting one. For tests that assert a hot path allocates nothing:
///
///     const long before = sg::test::allocations();
///     ... the hot path ...
///     EXPECT_EQ(sg::test::allocations() - before, 0);
///
/// Link `sg_allocation_counter`; calling allocations() pulls the replacement in.

namespace sg::test {

/// Allocations through operator new since the program started.
long allocations();

}  // namespace sg::test
