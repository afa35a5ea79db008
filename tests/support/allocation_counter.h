// Counts heap allocations, so a test can show a real-time path
// (Kinematics::Update, a driver's Update/ReadState, Trajectory::Sample) does
// not allocate: read a counter before and after. Link
// tests/support/allocation_counter.cpp into the test (it replaces the global
// operator new/delete and malloc/calloc/realloc for that binary; one
// replacement per binary).
#pragma once

/// Global operator new calls.
extern long g_allocations;
/// Every heap allocation: operator new's and Eigen's (which calls malloc directly).
extern long g_mallocs;
/// Fault injection: when > 0, the g_fail_allocation-th operator new from now
/// throws std::bad_alloc (counting down; 0: never). What the code under test
/// does when an allocation fails where it may (a throw it must contain).
extern long g_fail_allocation;

/// Heap bytes the malloc family holds (usable sizes, so glibc's rounding is
/// counted; its per-block header is not), and the most it held since the
/// last ResetHeapBytesPeak(). Blocks from memalign/posix_memalign are not seen.
long HeapBytesInUse();
long HeapBytesPeak();
void ResetHeapBytesPeak();
