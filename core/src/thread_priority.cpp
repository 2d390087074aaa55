#include "animrt/core/thread_priority.hpp"

#include <pthread.h>
#include <sched.h>

#include <cstring>

namespace animrt {

std::string set_fifo_priority(std::thread& thread, int priority) {
  const std::string what = "SCHED_FIFO " + std::to_string(priority);
  if (!thread.joinable()) return what + " not set: the thread is not running";
  sched_param param{};
  param.sched_priority = priority;
  if (const int err = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param); err != 0) {
    return what + " not permitted (" + std::strerror(err) + ")";
  }
  return "";
}

}  // namespace animrt
