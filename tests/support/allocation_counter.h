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
