// How much memory this process may use, for refusing work that cannot fit before starting
// it, and the size of things in words.
#pragma once

#include <cstdint>
#include <exception>
#include <string>

namespace kr {

struct MemoryLimit {
    uint64_t bytes = UINT64_MAX;
    std::string what;  // "physical memory", "the address-space limit (ulimit -v)", ...
};

// The smallest of physical memory, the address-space limit (ulimit -v) and the memory limit
// of the process's control group (v2 memory.max or v1 memory.limit_in_bytes). Not the memory
// free at this moment: that changes from one second to the next, and a job that fits in the
// machine may wait for it.
MemoryLimit memory_limit();

// "" when `needed` bytes fit within memory_limit(), else the one message render and the
// viewer give: "not enough memory for WHAT: it needs about 274.0 GiB, above physical
// memory (15.5 GiB)".
std::string memory_shortfall(uint64_t needed, const std::string& what);

// Whether `e` is an allocation failure: new's bad_alloc, a container asked for more elements
// than it can hold (length_error, e.g. vector::_M_default_append), or a thread that could not
// be started for want of resources (system_error EAGAIN: its stack did not fit the address
// space; Embree starts threads so). Every command says these as "FILE: not enough memory
// for ...", never by their C++ names.
bool is_out_of_memory(const std::exception& e);

// Starts this thread's OpenMP team now, at the start of a command or of the viewer's render
// thread, and returns how many of its omp_get_max_threads() threads could be started. libgomp
// starts the team at the first parallel region and, when a thread's stack does not fit the
// address space left, ends the process with its own message ("libgomp: Thread creation
// failed"). So the threads are tried first with pthread_create, all alive at once with the
// stack libgomp gives them (the default): where all fit, an empty parallel region starts the
// team, which every later region reuses; where fewer fit, nothing is started and the caller
// says "not enough memory for the stacks of N threads". Under an address-space limit the
// threads share malloc's one arena.
int start_thread_team();

// "512 B", "3.2 MiB", "47.9 GiB".
std::string format_bytes(uint64_t bytes);

}  // namespace kr
