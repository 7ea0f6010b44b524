#include "daemon/pipeline/thread_policy.hpp"

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <cstring>
#include <string>

#include "drivers/common/log.hpp"

namespace posed::pipeline {
namespace {
std::atomic<bool> g_warned_priority{false};
std::atomic<bool> g_warned_affinity{false};
}  // namespace

void apply_thread_policy(std::string_view name, const config::ThreadSection& policy) {
  const std::string short_name(name.substr(0, 15));
  pthread_setname_np(pthread_self(), short_name.c_str());

  if (policy.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(policy.cpu), &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    if (rc != 0 && !g_warned_affinity.exchange(true)) {
      POSED_LOG_WARN("cannot pin thread %s to CPU %d (%s); threads run on any CPU",
                     short_name.c_str(), policy.cpu, std::strerror(rc));
    }
  }
  if (policy.priority > 0) {
    sched_param param{};
    param.sched_priority = policy.priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    if (rc != 0 && !g_warned_priority.exchange(true)) {
      POSED_LOG_WARN(
          "cannot set SCHED_FIFO priority %d for thread %s (%s): running with normal scheduling. "
          "Grant CAP_SYS_NICE or LimitRTPRIO (systemd/posed.service does), or set "
          "threads.*.priority to 0 to silence this",
          policy.priority, short_name.c_str(), std::strerror(rc));
    }
  }
}

}  // namespace posed::pipeline
