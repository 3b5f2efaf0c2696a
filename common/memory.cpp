#include "common/memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace fem {

std::int64_t peak_resident_bytes()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::int64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
}

namespace {

// The process's resident memory from /proc/self/status: VmRSS (now) or VmHWM (the peak), in bytes;
// nullopt where the file does not exist (not Linux).
std::optional<double> status_bytes(const std::string& key)
{
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind(key + ":", 0) == 0)
            return 1024.0 * std::stod(line.substr(key.size() + 1));  // "VmHWM:   13476 kB"
    return std::nullopt;
}

}  // namespace

PeakMemoryRise::PeakMemoryRise()
{
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";
    clear.close();
    reset_ok_ = static_cast<bool>(clear);
    start_ = status_bytes("VmRSS");
}

std::optional<double> PeakMemoryRise::rise_bytes() const
{
    const std::optional<double> peak = status_bytes("VmHWM");
    if (!reset_ok_ || !peak || !start_)
        return std::nullopt;
    return std::max(0.0, *peak - *start_);
}

}  // namespace fem
