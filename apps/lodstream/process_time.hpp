// CPU seconds of the whole process, all threads together (CLOCK_PROCESS_CPUTIME_ID). Beside wall time it
// shows how many cores a job kept busy, and it is steadier than wall time on a loaded machine.
#pragma once

#include <time.h>

namespace lodstream::cli {

inline double process_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

}  // namespace lodstream::cli
