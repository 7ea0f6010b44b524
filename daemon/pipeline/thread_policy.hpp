#pragma once
// Per-stage thread name, CPU affinity and SCHED_FIFO priority from the config. Where the process
// may not raise its priority (no CAP_SYS_NICE, RLIMIT_RTPRIO too low) it degrades to normal
// scheduling with one warning for the whole process, not one per thread.

#include <string_view>

#include "daemon/config/posed_config.hpp"

namespace posed::pipeline {

/// Applies `policy` to the calling thread; `name` is truncated to 15 characters (kernel limit).
void apply_thread_policy(std::string_view name, const config::ThreadSection& policy);

}  // namespace posed::pipeline
