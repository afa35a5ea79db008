// Counts global operator new calls, so a test can show a real-time path
// (Kinematics::Update, a driver's Update/ReadState, Trajectory::Sample) does
// not allocate: read g_allocations before and after. Link
// tests/support/allocation_counter.cpp into the test (it replaces the global
// operator new/delete for that binary; one replacement per binary).
#pragma once

extern long g_allocations;
