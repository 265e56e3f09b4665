// Counting heap allocations in a test program: tests/support/heap_counter.cpp replaces the global
// operator new and, outside AddressSanitizer builds (whose runtime owns malloc), interposes
// malloc, calloc and realloc, which is where Eigen's dynamic matrices get their memory. Link that
// file into a test program (saltus_test_folder(... HEAP_COUNTER)) to use these.
#pragma once

namespace saltus::testing {
// Number of heap allocations so far in this process.
long heapAllocations();
// Whether malloc itself is counted (false under AddressSanitizer: then only operator new is).
bool mallocCounted();
}  // namespace saltus::testing
