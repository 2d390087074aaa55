#include "animrt/runtime/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace animrt {

RealtimeStatus request_realtime(int priority) {
  RealtimeStatus status;
  sched_param param{};
  param.sched_priority = priority;
  if (int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); err == 0) {
    status.sched_fifo = true;
    status.priority = priority;
  } else {
    status.sched_note = std::string("SCHED_FIFO refused: ") + std::strerror(err) +
                        " (run as root or grant CAP_SYS_NICE / an rtprio limit)";
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    status.memory_locked = true;
  } else {
    status.mlock_note = std::string("mlockall refused: ") + std::strerror(errno) +
                        " (raise the memlock limit or grant CAP_IPC_LOCK)";
  }
  return status;
}

void release_realtime() {
  sched_param param{};
  param.sched_priority = 0;
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &param);
  munlockall();
}

}  // namespace animrt
