// How much memory this process may still take: the machine's MemAvailable, lowered by a
// cgroup memory limit when one applies (a container or a farm slot), or a figure set with
// SHELLMPM_AVAILABLE_MEMORY (for tests, and farms whose limits are not visible here).
#pragma once
#include <string>

namespace shellmpm {

struct AvailableMemory {
  double bytes = 0;    ///< what a run may still allocate [bytes]; 0 when unknown
  bool known = false;  ///< false: no figure could be read (the run is not guarded)
  std::string source;  ///< where `bytes` comes from, for messages: "MemAvailable in /proc/meminfo"
};

/// SHELLMPM_AVAILABLE_MEMORY (bytes, or with a suffix K, M, G, T: powers of 1024) when set,
/// else the smaller of MemAvailable and, for each cgroup (v2 memory.max, v1
/// memory.limit_in_bytes) on the path of this process, its limit less its usage.
/// @throws UserError when SHELLMPM_AVAILABLE_MEMORY is set but is not such a number.
AvailableMemory available_memory();

/// Parses "2G", "1536M", "4294967296": bytes, or a negative value when it is not a size.
double parse_memory_size(const std::string& text);

/// Resident set size of this process now (VmRSS), bytes; 0 when it cannot be read.
double resident_bytes();

/// "1.5 GiB", "320 MiB", "12 KiB".
std::string format_bytes(double bytes);

}  // namespace shellmpm
