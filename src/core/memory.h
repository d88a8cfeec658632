// How much memory this process may use, for refusing work that cannot fit before starting
// it, and the size of things in words.
#pragma once

#include <cstdint>
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

// "512 B", "3.2 MiB", "47.9 GiB".
std::string format_bytes(uint64_t bytes);

}  // namespace kr
