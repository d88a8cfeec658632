#include "core/memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <new>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <malloc.h>
#include <omp.h>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

namespace kr {

namespace {

// The first line of a control-group file as a byte count; "max" or anything unreadable is
// no limit.
uint64_t read_limit_file(const std::string& path) {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text == "max") return UINT64_MAX;
    try {
        return std::stoull(text);
    } catch (const std::exception&) {
        return UINT64_MAX;
    }
}

// This process's control-group memory limit: its own group's file, else the root of the
// mounted hierarchy (what a container sees).
uint64_t cgroup_limit() {
    std::ifstream groups("/proc/self/cgroup");
    uint64_t limit = UINT64_MAX;
    for (std::string line; std::getline(groups, line);) {
        const size_t colon = line.find(':'), second = line.find(':', colon + 1);
        if (colon == std::string::npos || second == std::string::npos) continue;
        const std::string controllers = line.substr(colon + 1, second - colon - 1), path = line.substr(second + 1);
        if (controllers.empty()) {  // v2: "0::/path"
            for (const std::string& dir : {"/sys/fs/cgroup" + path, std::string("/sys/fs/cgroup")})
                if (const uint64_t l = read_limit_file(dir + "/memory.max"); l != UINT64_MAX) {
                    limit = std::min(limit, l);
                    break;
                }
        } else if (controllers == "memory") {  // v1: "N:memory:/path"
            for (const std::string& dir : {"/sys/fs/cgroup/memory" + path, std::string("/sys/fs/cgroup/memory")})
                if (const uint64_t l = read_limit_file(dir + "/memory.limit_in_bytes"); l != UINT64_MAX) {
                    limit = std::min(limit, l);
                    break;
                }
        }
    }
    return limit;
}

}  // namespace

MemoryLimit memory_limit() {
    MemoryLimit limit;
    const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGESIZE);
    if (pages > 0 && page_size > 0) limit = {uint64_t(pages) * uint64_t(page_size), "physical memory"};
    rlimit address_space{};
    if (::getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY &&
        uint64_t(address_space.rlim_cur) < limit.bytes)
        limit = {uint64_t(address_space.rlim_cur), "the address-space limit (ulimit -v)"};
    // v1 reports "no limit" as a huge number, which the comparison drops.
    if (const uint64_t group = cgroup_limit(); group < limit.bytes) limit = {group, "the control group's memory limit"};
    return limit;
}

std::string memory_shortfall(uint64_t needed, const std::string& what) {
    const MemoryLimit limit = memory_limit();
    if (needed <= limit.bytes) return "";
    return "not enough memory for " + what + ": it needs about " + format_bytes(needed) + ", above " + limit.what +
           " (" + format_bytes(limit.bytes) + ")";
}

bool is_out_of_memory(const std::exception& e) {
    if (dynamic_cast<const std::bad_alloc*>(&e) || dynamic_cast<const std::length_error*>(&e)) return true;
    const auto* system = dynamic_cast<const std::system_error*>(&e);
    return system && system->code() == std::errc::resource_unavailable_try_again;
}

int start_thread_team() {
    // Under an address-space limit (ulimit -v) every thread shares malloc's one arena: glibc
    // gives each thread that allocates an arena of its own, reserving 64 MiB of address space
    // apiece, which a team started early would take before the work it is for.
    rlimit address_space{};
    if (::getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY)
        ::mallopt(M_ARENA_MAX, 1);
    const int wanted = omp_get_max_threads();
    std::vector<pthread_t> started;
    started.reserve(size_t(std::max(wanted - 1, 0)));
    for (int i = 1; i < wanted; ++i) {
        pthread_t thread{};
        if (::pthread_create(&thread, nullptr, [](void*) -> void* { return nullptr; }, nullptr) != 0) break;
        started.push_back(thread);
    }
    // Joined: their stacks are unmapped (or kept in glibc's cache for the team to take).
    for (const pthread_t thread : started) ::pthread_join(thread, nullptr);
    if (int(started.size()) + 1 < wanted) return int(started.size()) + 1;
#pragma omp parallel
    {
    }
    return wanted;
}

std::string format_bytes(uint64_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double value = double(bytes);
    int unit = 0;
    while (value >= 1024 && unit < 6) value /= 1024, ++unit;
    char text[32];
    std::snprintf(text, sizeof text, unit == 0 ? "%.0f %s" : "%.1f %s", value, units[unit]);
    return text;
}

}  // namespace kr
