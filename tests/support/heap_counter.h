// Bytes the test binary holds through operator new, now and at the peak since the last
// reset (malloc_usable_size of each block). tests/support/heap_counter.cpp replaces the
// global operator new and delete of the test binary to count them.
#pragma once
#include <cstddef>

namespace shellmpm_test {

/// Bytes allocated through operator new and not yet freed.
std::size_t heap_current();
/// The most heap_current() has been since the last reset_heap_peak().
std::size_t heap_peak();
/// Starts a new peak at the current level.
void reset_heap_peak();

}  // namespace shellmpm_test
